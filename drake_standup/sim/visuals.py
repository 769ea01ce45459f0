"""StandupVisuals: what the helper should see, drawn into Meshcat and its recording.

- an arrow at each hand along the helper's pull, its length proportional to the force
  (PULL_N_PER_M);
- the CoM (red) and its reference x_d (green, translucent) as small spheres, drawn
  COM_SIDE_OFFSET_M to the robot's right (toward the default camera): at the CoM itself
  the torso hides them, and the stand-up moves the CoM in the sagittal plane only;
- the stand-up state as the colour of a lamp beside the robot: grey seated (1),
  orange CoM forward (2), yellow thighs unloading (3), green rising (4);
- two bars beside the lamp: psi_dot (tick marks at 1 and at the scenario's upper bound)
  and psi's lead over time since the stand-up's clock started (psi - (t - t_1), s).

Bars and not Meshcat sliders or a plot: the recording (recording.html) replays only
transforms and properties of objects in the scene, so a bar whose height is a scale
is the one read-out that is the same live and in every recording; it also sits where
the eye already is, next to the robot.

A publish-only system at the recording's rate: every property is set with the
context's time, so it lands in the recording's frame of the visualizer's publish.
A scaled shape's scale sits on a node of its own ('scaled') below the node that moves:
the live viewer decomposes a transform into position, rotation and scale, so a
transform sent to the same node would undo its scale.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.geometry import Box, Cylinder, Meshcat, MeshcatCone, Rgba, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context, EventStatus, LeafSystem

from drake_standup.config.scenario import VisualizationConfig
from drake_standup.helper.hands import TASK_FRAMES
from drake_standup.robot.icub import Robot

PREFIX = "/standup"
# Arrow length per newton: the largest pull a slider allows (25 N, [authors-code]'s
# strongest helper) draws 0.25 m, about the forearm's length. m/N.
PULL_M_PER_N = 0.01
# Below this a hand is not pulled and its arrow is hidden. N.
PULL_VISIBLE_N = 0.25
ARROW_RADIUS_M = 0.008
ARROW_HEAD_M = (0.05, 0.022)  # length, radius
# Cyan: Drake's contact force arrows are blue, the robot red, the chair brown.
PULL_RGBA = Rgba(0.0, 0.85, 0.95, 1.0)
# The state lamp's colour per state 1-4: seated, forward, unloading, rising.
STATE_RGBA = (
    Rgba(0.6, 0.6, 0.6, 1.0),
    Rgba(1.0, 0.55, 0.0, 1.0),
    Rgba(1.0, 0.9, 0.0, 1.0),
    Rgba(0.1, 0.8, 0.2, 1.0),
)
# Where the lamp and the bars stand: behind the chair on the camera's side,
# clear of the robot in the default view. m.
GAUGE_XYZ_M = (-0.3, -0.35, 0.0)
BAR_WIDTH_M = 0.04
# Bar heights: psi_dot 1 -> 0.2 m (2.5 -> 0.5 m); 1 s of lead -> 0.25 m.
PSI_DOT_M = 0.2
PSI_LEAD_M_PER_S = 0.25
LAMP_RADIUS_M = 0.04
# The CoM spheres' offset along world y (the robot's right): clear of the body. m.
COM_SIDE_OFFSET_M = -0.3


def camera_pose(vis: VisualizationConfig, helper_X_WP: RigidTransform | None = None):
    """The recording's camera position and target (m, world): the scenario's. With a
    person's body kneeling at helper_X_WP in front of the robot and both keys at their
    defaults, the default camera would look at the robot through the person: it moves to
    the robot's right side, nearly side-on, aimed at the middle between the robot's
    target and the person, and back by the distance between them, so both are in view."""
    default = VisualizationConfig()
    xyz, target = np.array(vis.camera_xyz_m), np.array(vis.target_xyz_m)
    if helper_X_WP is None or not (
        vis.camera_xyz_m == default.camera_xyz_m and vis.target_xyz_m == default.target_xyz_m
    ):
        return xyz, target
    person = helper_X_WP.translation()
    gap = max(person[0] - target[0], 0.0)
    middle = np.array([target[0] + 0.5 * gap, target[1], target[2]])
    # Nearly side-on (the person leans over the robot's hands), at the default view's
    # height over its target and a distance that grows with the gap.
    distance = 0.75 * np.linalg.norm(xyz[:2] - target[:2]) + gap
    return middle + np.array([0.1 * distance, -distance, xyz[2] - target[2]]), middle


def arrow_pose(p_W: np.ndarray, f_W: np.ndarray) -> RigidTransform:
    """The arrow's frame: origin at the hand, +z along the force."""
    return RigidTransform(RotationMatrix.MakeFromOneVector(f_W, 2), p_W)


class StandupVisuals(LeafSystem):
    """Inputs robot_state ([q; v] of the robot), hand_wrenches_W (12: the
    helper's pull), com_W, x_d_W (3), standup_state, psi, psi_dot (1) and
    entry_times_s (n_states: the state machine's). No outputs: it publishes to meshcat
    every period_s."""

    def __init__(
        self,
        plant: MultibodyPlant,
        robot: Robot,
        meshcat: Meshcat,
        period_s: float,
        psi_dot_upper: float,
        n_states: int,
    ):
        super().__init__()
        self._meshcat = meshcat
        self._plant = plant
        self._instance = robot.model_instance
        self._plant_context = plant.CreateDefaultContext()
        self._frames = [robot.frame(plant, name) for name in TASK_FRAMES]
        self._state = self.DeclareVectorInputPort(
            "robot_state", plant.num_multibody_states(self._instance)
        )
        self._wrenches = self.DeclareVectorInputPort("hand_wrenches_W", 12)
        self._com = self.DeclareVectorInputPort("com_W", 3)
        self._x_d = self.DeclareVectorInputPort("x_d_W", 3)
        self._standup_state = self.DeclareVectorInputPort("standup_state", 1)
        self._psi = self.DeclareVectorInputPort("psi", 1)
        self._psi_dot = self.DeclareVectorInputPort("psi_dot", 1)
        self._entry = self.DeclareVectorInputPort("entry_times_s", n_states)
        self._add_objects(psi_dot_upper)
        self.DeclareInitializationPublishEvent(self._Publish)
        self.DeclarePeriodicPublishEvent(period_s, 0.0, self._Publish)

    def _add_objects(self, psi_dot_upper: float) -> None:
        m = self._meshcat
        length, radius = ARROW_HEAD_M
        for hand in ("left", "right"):
            m.SetObject(
                f"{PREFIX}/pull/{hand}/shaft/scaled", Cylinder(ARROW_RADIUS_M, 1.0), PULL_RGBA
            )
            # The cone's point at the arrow's tip (head), its base toward the hand.
            cone = f"{PREFIX}/pull/{hand}/head/cone"
            m.SetObject(cone, MeshcatCone(length, radius, radius), PULL_RGBA)
            m.SetTransform(cone, RigidTransform(RotationMatrix.MakeXRotation(math.pi)))
        m.SetObject(f"{PREFIX}/com", Sphere(0.03), Rgba(0.9, 0.1, 0.1, 1.0))
        m.SetObject(f"{PREFIX}/com_reference", Sphere(0.03), Rgba(0.1, 0.8, 0.2, 0.5))
        x, y, z = GAUGE_XYZ_M
        top = PSI_DOT_M * psi_dot_upper + 0.15
        for k, rgba in enumerate(STATE_RGBA):
            m.SetObject(f"{PREFIX}/state/{k + 1}", Sphere(LAMP_RADIUS_M), rgba)
            m.SetTransform(f"{PREFIX}/state/{k + 1}", RigidTransform([x, y, z + top]))
        bars = {"psi_dot": y, "psi_lead": y - 2 * BAR_WIDTH_M}
        for name, bar_y in bars.items():
            base = RigidTransform([x, bar_y, z])
            m.SetTransform(f"{PREFIX}/{name}", base)
            m.SetObject(
                f"{PREFIX}/{name}/bar/scaled",
                Box(BAR_WIDTH_M, BAR_WIDTH_M, 1.0),
                Rgba(0.1, 0.45, 1.0, 1.0) if name == "psi_dot" else Rgba(0.55, 0.2, 0.9, 1.0),
            )
        # psi_dot's scale: a thin rail up to the bound, ticks at 1 and at the bound.
        rail = Rgba(0.2, 0.2, 0.2, 0.35)
        height = PSI_DOT_M * psi_dot_upper
        m.SetObject(f"{PREFIX}/psi_dot/rail", Box(0.006, 0.006, height), rail)
        m.SetTransform(f"{PREFIX}/psi_dot/rail", RigidTransform([-BAR_WIDTH_M, 0.0, height / 2]))
        for name, value in (("one", 1.0), ("upper", psi_dot_upper)):
            m.SetObject(f"{PREFIX}/psi_dot/tick_{name}", Box(0.08, 0.08, 0.004), rail)
            m.SetTransform(
                f"{PREFIX}/psi_dot/tick_{name}", RigidTransform([0, 0, PSI_DOT_M * value])
            )

    def _hands_W(self, context: Context) -> list[np.ndarray]:
        plant, c = self._plant, self._plant_context
        plant.SetPositionsAndVelocities(c, self._instance, self._state.Eval(context))
        return [f.CalcPoseInWorld(c).translation() for f in self._frames]

    def _Publish(self, context: Context) -> EventStatus:
        m, t = self._meshcat, context.get_time()
        forces = self._wrenches.Eval(context).reshape(2, 6)[:, 3:]
        hands = None
        for hand, f in zip(("left", "right"), forces):
            path = f"{PREFIX}/pull/{hand}"
            norm = float(np.linalg.norm(f))
            visible = norm >= PULL_VISIBLE_N
            m.SetProperty(path, "visible", visible, t)
            if not visible:
                continue
            if hands is None:
                hands = self._hands_W(context)
            p = hands[0 if hand == "left" else 1]
            length = norm * PULL_M_PER_N
            shaft = max(length - ARROW_HEAD_M[0], 1e-3)
            m.SetTransform(path, arrow_pose(p, f), t)
            m.SetTransform(f"{path}/shaft", RigidTransform([0.0, 0.0, shaft / 2]), t)
            m.SetProperty(f"{path}/shaft/scaled", "scale", [1.0, 1.0, shaft], t)
            m.SetTransform(f"{path}/head", RigidTransform([0.0, 0.0, length]), t)
        side = np.array([0.0, COM_SIDE_OFFSET_M, 0.0])
        m.SetTransform(f"{PREFIX}/com", RigidTransform(self._com.Eval(context) + side), t)
        m.SetTransform(f"{PREFIX}/com_reference", RigidTransform(self._x_d.Eval(context) + side), t)
        state = int(round(self._standup_state.Eval(context)[0]))
        for k in range(1, len(STATE_RGBA) + 1):
            m.SetProperty(f"{PREFIX}/state/{k}", "visible", k == state, t)
        psi_dot = float(self._psi_dot.Eval(context)[0])
        lead_s = float(self._psi.Eval(context)[0]) - (t - float(self._entry.Eval(context)[0]))
        for name, height in (
            ("psi_dot", PSI_DOT_M * psi_dot),
            ("psi_lead", PSI_LEAD_M_PER_S * lead_s),
        ):
            height = max(height, 1e-3)
            m.SetTransform(f"{PREFIX}/{name}/bar", RigidTransform([0.0, 0.0, height / 2]), t)
            m.SetProperty(f"{PREFIX}/{name}/bar/scaled", "scale", [1.0, 1.0, height], t)
        return EventStatus.Succeeded()
