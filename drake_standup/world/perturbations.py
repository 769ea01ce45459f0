"""Perturbations for robustness studies (scenario key perturbation:, all off by default).

- PushSource: constant world forces on named robot bodies over time windows,
  applied to the plant only (the wrist sensors do not measure them).
- NoisyWrenchSensor: Gaussian noise on the force rows of the measured hand
  wrenches, held over each sample period; the plant keeps the true pull.
- apply_model_errors: the simulated robot's masses (and rotational inertias)
  scaled, in the simulation's plant context only; the controller, sensing and
  human keep the nominal model in their own contexts.
- scale_friction: every proximity geometry's Coulomb friction scaled in the
  scene graph's model, so every pair's combined coefficient scales alike.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from pydrake.common.value import Value
from pydrake.geometry import ProximityProperties, Role, RoleAssign, SceneGraph
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import CoulombFriction, ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import BasicVector, Context, LeafSystem

from drake_standup.config import Push, Scenario
from drake_standup.ports.caching import declare_cached
from drake_standup.robot.icub import Robot

# Time tolerance of window and period boundaries: Drake's sample times
# (n * 1 ms) land within rounding of them, and must fall on the later side.
TIME_EPS_S = 1e-9

# Rows of the force components in hand_wrenches_W ([tau_l, f_l, tau_r, f_r]).
FORCE_ROWS = np.r_[3:6, 9:12]


def robot_body_names(plant: MultibodyPlant, robot: Robot) -> list[str]:
    """Names of the robot's bodies, in body index order."""
    return [plant.get_body(i).name() for i in plant.GetBodyIndices(robot.model_instance)]


def push_active(push: Push, t: float) -> bool:
    """True over [start_s, start_s + duration_s) (boundaries within TIME_EPS_S)."""
    local = t + TIME_EPS_S - push.start_s
    return 0.0 <= local < push.duration_s


class PushSource(LeafSystem):
    """Outputs spatial_forces (the active pushes, for the plant's
    applied_spatial_force input: a world force at the origin of each pushed
    body) and push_force_W (3: the sum of the active pushes' forces, N). The
    bodies are the robot's (config.validate checks their names).
    """

    def __init__(self, plant: MultibodyPlant, robot: Robot, pushes: list[Push]):
        super().__init__()
        self._pushes = list(pushes)
        # One preallocated force per push; only its force changes (never, here).
        self._applied = []
        for push in self._pushes:
            applied = ExternallyAppliedSpatialForce()
            applied.body_index = plant.GetBodyByName(push.body, robot.model_instance).index()
            applied.p_BoBq_B = np.zeros(3)
            applied.F_Bq_W = SpatialForce(np.zeros(3), np.asarray(push.force_N, dtype=float))
            self._applied.append(applied)
        time_only = {self.time_ticket()}
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
            self._CalcSpatialForces,
            prerequisites_of_calc=time_only,
        )
        self.DeclareVectorOutputPort(
            "push_force_W", 3, self._CalcTotalForce, prerequisites_of_calc=time_only
        )

    def _active(self, t: float) -> list[int]:
        return [i for i, push in enumerate(self._pushes) if push_active(push, t)]

    def _CalcSpatialForces(self, context: Context, output) -> None:
        output.set_value([self._applied[i] for i in self._active(context.get_time())])

    def _CalcTotalForce(self, context: Context, output: BasicVector) -> None:
        total = np.zeros(3)
        for i in self._active(context.get_time()):
            total += self._pushes[i].force_N
        output.SetFromVector(total)


def noise_period_index(t: float, period_s: float) -> int:
    """The sample period k that time t falls in: floor(t / period + 1e-9)."""
    return math.floor(t / period_s + TIME_EPS_S)


@lru_cache(maxsize=8)
def _unit_noise(seed: int, k: int) -> np.ndarray:
    """Six standard normal samples of period k: a pure function of (seed, k)
    (memoised: ~16 us a draw, and every period is read at many times)."""
    sample = np.random.default_rng([seed, k]).standard_normal(6)
    sample.flags.writeable = False
    return sample


def force_noise(t: float, sigma_N: float, period_s: float, seed: int) -> np.ndarray:
    """(6,) the noise on [f_l, f_r] at time t: N(0, sigma_N^2) per component,
    constant within each period, independent across periods and seeds. N."""
    return sigma_N * _unit_noise(seed, noise_period_index(t, period_s))


class NoisyWrenchSensor(LeafSystem):
    """Input hand_wrenches_W (12, true), output hand_wrenches_W (12, measured):
    the input plus force_noise on the six force rows; torques pass unchanged.

    Stateless: the noise is a function of time and seed alone. It is a cache
    entry that depends on time only, so consumers and integrator stages share
    one evaluation per time.
    """

    def __init__(self, sigma_N: float, period_s: float, seed: int):
        super().__init__()
        self._sigma, self._period, self._seed = float(sigma_N), float(period_s), int(seed)
        self._true = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        self._noise = declare_cached(self, "force noise", self._calc_noise, {self.time_ticket()})
        self.DeclareVectorOutputPort(
            "hand_wrenches_W",
            12,
            self._CalcMeasured,
            prerequisites_of_calc={self._true.ticket(), self._noise.ticket()},
        )

    def _calc_noise(self, context: Context) -> np.ndarray:
        return force_noise(context.get_time(), self._sigma, self._period, self._seed)

    def _CalcMeasured(self, context: Context, output: BasicVector) -> None:
        w = self._true.Eval(context).copy()
        w[FORCE_ROWS] += self._noise.Eval(context)
        output.SetFromVector(w)


def apply_model_errors(scene, plant_context: Context, scenario: Scenario) -> None:
    """Scales every robot body's mass by perturbation.mass_scale in plant_context
    (the simulation's; CoM and unit inertia kept, so the rotational inertia
    scales too). From the default masses: calling it twice scales once."""
    s = scenario.perturbation.mass_scale
    if s == 1.0:
        return
    plant = scene.plant
    for index in plant.GetBodyIndices(scene.robot.model_instance):
        body = plant.get_body(index)
        body.SetMass(plant_context, s * body.default_mass())


def scale_friction(plant: MultibodyPlant, scene_graph: SceneGraph, scale: float) -> None:
    """Replaces each proximity geometry's ('material', 'coulomb_friction') by
    itself times scale, in scene_graph's model (call after plant.Finalize(),
    before any context exists)."""
    if scale == 1.0:
        return
    inspector = scene_graph.model_inspector()
    source_id = plant.get_source_id()
    for geometry_id in inspector.GetAllGeometryIds(Role.kProximity):
        props = inspector.GetProximityProperties(geometry_id)
        if not props.HasProperty("material", "coulomb_friction"):
            raise ValueError(
                f"geometry '{inspector.GetName(geometry_id)}' has no Coulomb friction to scale"
            )
        mu = props.GetProperty("material", "coulomb_friction")
        new = ProximityProperties(props)
        new.UpdateProperty(
            "material",
            "coulomb_friction",
            CoulombFriction(scale * mu.static_friction(), scale * mu.dynamic_friction()),
        )
        scene_graph.AssignRole(source_id, geometry_id, new, RoleAssign.kReplace)
