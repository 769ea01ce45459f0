"""Contact forces on the robot's pads, read from the plant's ContactResults."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import Value
from pydrake.geometry import GeometryId
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import Context, LeafSystem


def pad_forces(results: ContactResults, pad_ids: dict[GeometryId, int], n_pads: int) -> np.ndarray:
    """Net world-frame force on each pad (rows in pad order), N.

    Hydroelastic: F_Ac_W acts on the body of geometry M. Point contact
    (fallback): contact_force acts on body B. Signs follow from which side of
    the pair the pad is on.
    """
    # Summed in floats (the same additions as numpy's rows, in the same order): a
    # row's += on a 3-vector costs more than the contact's own reads.
    forces = [[0.0, 0.0, 0.0] for _ in range(n_pads)]
    get = pad_ids.get
    for i in range(results.num_hydroelastic_contacts()):
        info = results.hydroelastic_contact_info(i)
        surface = info.contact_surface()
        fx, fy, fz = info.F_Ac_W().translational().tolist()
        if (row := get(surface.id_M())) is not None:
            sums = forces[row]
            sums[0] += fx
            sums[1] += fy
            sums[2] += fz
        if (row := get(surface.id_N())) is not None:
            sums = forces[row]
            sums[0] -= fx
            sums[1] -= fy
            sums[2] -= fz
    for i in range(results.num_point_pair_contacts()):
        info = results.point_pair_contact_info(i)
        pair = info.point_pair()
        fx, fy, fz = info.contact_force().tolist()
        if (row := get(pair.id_B)) is not None:
            sums = forces[row]
            sums[0] += fx
            sums[1] += fy
            sums[2] += fz
        if (row := get(pair.id_A)) is not None:
            sums = forces[row]
            sums[0] -= fx
            sums[1] -= fy
            sums[2] -= fz
    return np.array(forces).reshape(n_pads, 3)


class ContactForceReporter(LeafSystem):
    """Contact results in, one 3-D world force per robot pad out (N).

    Output 'pad_forces_W' is [f_pad0; f_pad1; ...] in the order of pad_names.
    """

    def __init__(self, pad_names: list[str], pad_ids: list[GeometryId]):
        super().__init__()
        self.pad_names = list(pad_names)
        self._rows = {gid: i for i, gid in enumerate(pad_ids)}
        self._results = self.DeclareAbstractInputPort("contact_results", Value(ContactResults()))
        # The contact results alone: not recomputed at the loggers' and visualizers' times
        # between the plant's steps.
        self.DeclareVectorOutputPort(
            "pad_forces_W",
            3 * len(self.pad_names),
            self._CalcForces,
            prerequisites_of_calc={self._results.ticket()},
        )

    def _CalcForces(self, context: Context, output) -> None:
        results = self._results.Eval(context)
        forces = pad_forces(results, self._rows, len(self.pad_names))
        output.SetFromVector(forces.reshape(-1))


class PadImpulses(LeafSystem):
    """The contact impulse on each pad so far, int f dt (N s), on the plant's steps.

    Input pad_forces_W (3 per pad: ContactForceReporter's): the discrete plant holds the
    force of each step from the update that computed it to the next (its sampled output
    ports), so the integral is exact: at each update, the force held since the last one
    times the time since; between updates (a logger's instant), the same for the step in
    progress. Output pad_impulses_Ns (3 per pad, world frame). Differenced between two
    logged samples it gives the pads' mean force over that interval, what a force sensor
    whose filter averages over the interval reads, whatever the plant's step. A force
    sampled at the loggers' period instead aliases a slap one plant step long: it shows
    whole or not at all (docs/decisions/017-sole-force-measured.md)."""

    def __init__(self, n_pads: int, step_s: float):
        super().__init__()
        self._n = 3 * n_pads
        self._forces = self.DeclareVectorInputPort("pad_forces_W", self._n)
        # [the impulse up to the last update, that update's time].
        self._memory = self.DeclareDiscreteState(self._n + 1)
        self.DeclareVectorOutputPort(
            "pad_impulses_Ns",
            self._n,
            self._CalcImpulses,
            prerequisites_of_calc={
                self.discrete_state_ticket(self._memory),
                self._forces.ticket(),
                self.time_ticket(),
            },
        )
        # On the plant's own updates, offset 0 as its own: another offset splits no
        # integrator step, yet it moved psi by 1e-11 (measured).
        self.DeclarePeriodicDiscreteUpdateEvent(step_s, 0.0, self._Update)

    def _since_update(self, context: Context, memory: np.ndarray) -> np.ndarray:
        """The impulse of the force held since the last update, up to now."""
        return (context.get_time() - memory[self._n]) * self._forces.Eval(context)

    def _CalcImpulses(self, context: Context, output) -> None:
        memory = context.get_discrete_state(self._memory).value()
        output.SetFromVector(memory[: self._n] + self._since_update(context, memory))

    def _Update(self, context: Context, discrete_state) -> None:
        memory = discrete_state.get_mutable_value(self._memory)
        memory[: self._n] += self._since_update(context, memory)
        memory[self._n] = context.get_time()
