"""JointMuscles: the iCub's joints between the controller's torques and the plant (hardware: icub).

Between the controller and the plant, at the plant's step:

    torque loop   the joint's torque follows the command through a first-order lag of
                  hw.torque_time_constant_s (the boards' torque loop), clipped to the
                  joint's motor limit (hw limits)
    compensation  the boards add the friction they believe in: the viscous part at the
                  estimated joint velocity (the estimator's); no Coulomb part, which nobody
                  identified (iCubGenova04's leg boards compensate none: kbemf 0), and
                  which on the delayed, quantized velocity made the light joints chatter
                  (measured: wrists 2-4 rad/s rms while seated)
    position mode the joints iCub's whole-body torque control leaves to their boards'
                  position loops (hw.position_mode: neck and wrists) hold their seated
                  angles; the controller's torque for them goes unused
    friction      the joint's true friction, the identified times hw.friction_scale (the
                  physics, not a sensor): its viscous part as the plant's joint damping
                  (wiring.joint_damping, beyond the URDF's), which the plant integrates
                  implicitly; its Coulomb part here, at the true velocity, into the
                  plant's applied generalized force. Applied explicitly, the viscous
                  part's 0.2 N m s/rad took 1.97 of the 2 an explicit step allows
                  (b h / I) on iCubGenova04's wrist pronosupination (5e-4 kg m^2): with
                  the position loop's 0.5 it spun at 20-140 rad/s and the robot fell
                  (iCubGenova04 and iCubErzelli02, measured).

Coulomb friction is tanh-smoothed over a velocity v_s per joint, the smallest the explicit
step keeps stable: the friction's slope Fc / v_s times the step over the joint's own
inertia (1 / (M^-1)_jj at the seated pose, motors included) at most 1/2.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector, Context, DiscreteValues, LeafSystem

from drake_standup.robot.icub import velocity_start
from drake_standup.senses.hardware import ICubHardware


class JointMuscles(LeafSystem):
    """Inputs command (n_u, actuator order, N m), robot_state (the true [q; v]) and
    estimated_state (the estimator's); outputs actuation (n_u, N m) and
    generalized_friction (the plant's n_v, N m)."""

    def __init__(self, plant, instance, joints, hw: ICubHardware, step_s: float, *, inertia, q0):
        """joints: the instance's ActuatedJoints; inertia: each actuated joint's own
        inertia (n_u, kg m^2); q0: the robot's seated [q] (the position-mode joints hold
        their seated angles)."""
        super().__init__()
        names = joints.names
        nu = len(names)
        # The position-mode joints' boards: a PD at the plant's step, critically damped at
        # the fastest rate one explicit step keeps well damped (kd h / I = 1/2).
        self._held = np.array([any(k in n for k in hw.position_mode) for n in names])
        inertia = np.asarray(inertia)
        wn = 1.0 / (4.0 * step_s)
        self._kp = inertia * wn**2
        self._kd = 2.0 * inertia * wn
        self._q_hold = np.asarray(q0)[np.asarray(joints.q_index)]
        self._q_state = np.asarray(joints.q_index)
        friction = [hw.friction_of(n) for n in names]
        self._fc = np.array([f.coulomb_Nm for f in friction])
        self._fv = np.array([f.viscous_Nms for f in friction])
        # The slope Fc / v_s at most half of what one explicit step can carry (inertia / h).
        self._vs = np.maximum(2.0 * self._fc * step_s / np.asarray(inertia), 1e-4)
        self._scale = hw.friction_scale
        self._limit = np.array(
            [
                plant.get_joint_actuator(a).effort_limit()
                for a in plant.GetJointActuatorIndices(instance)
            ]
        )
        self._gain = 1.0 - math.exp(-step_s / hw.torque_time_constant_s)
        nv0 = velocity_start(plant, instance)
        nq = plant.num_positions(instance)
        self._v_state = nq + np.asarray(joints.v_index)  # in the instance's [q; v]
        self._v_plant = nv0 + np.asarray(joints.v_index)  # in the plant's v
        self._nv = plant.num_velocities()
        nx = plant.num_multibody_states(instance)
        self._command = self.DeclareVectorInputPort("command", nu)
        self._true = self.DeclareVectorInputPort("robot_state", nx)
        self._estimate = self.DeclareVectorInputPort("estimated_state", nx)
        # [started, lagged torque (n_u)]
        self._lag = self.DeclareDiscreteState(np.zeros(1 + nu))
        self.DeclareVectorOutputPort(
            "actuation",
            nu,
            self._CalcActuation,
            prerequisites_of_calc={
                self.xd_ticket(),
                self._command.ticket(),
                self._estimate.ticket(),
                self._true.ticket(),
            },
        )
        self.DeclareVectorOutputPort(
            "generalized_friction",
            self._nv,
            self._CalcFriction,
            prerequisites_of_calc={self._true.ticket()},
        )
        self.DeclarePeriodicDiscreteUpdateEvent(step_s, 0.0, self._Update)

    def coulomb(self, v: np.ndarray) -> np.ndarray:
        """The identified Coulomb friction (n_u) at joint velocities v, smoothed."""
        return self._fc * np.tanh(v / self._vs)

    def _Update(self, context: Context, out: DiscreteValues) -> None:
        state = context.get_discrete_state(self._lag).value()
        command = self._command.Eval(context)
        lagged = state[1:] + self._gain * (command - state[1:]) if state[0] > 0.5 else command
        out.set_value(self._lag, np.r_[1.0, lagged])

    def _CalcActuation(self, context: Context, output: BasicVector) -> None:
        state = context.get_discrete_state(self._lag).value()
        torque = state[1:] if state[0] > 0.5 else self._command.Eval(context)
        v_hat = self._estimate.Eval(context)[self._v_state]
        torque = torque + self._fv * v_hat
        x = self._true.Eval(context)  # the boards' own encoders, at their 1 kHz
        hold = self._kp * (self._q_hold - x[self._q_state]) - self._kd * x[self._v_state]
        torque = np.where(self._held, hold, torque)
        output.SetFromVector(np.clip(torque, -self._limit, self._limit))

    def _CalcFriction(self, context: Context, output: BasicVector) -> None:
        v = self._true.Eval(context)[self._v_state]
        tau = np.zeros(self._nv)
        tau[self._v_plant] = -self._scale * self.coulomb(v)
        output.SetFromVector(tau)
