"""The chair and the robot's place on it: the scenario's chair: and initial: sections.

world/chair.py builds the chair from ChairConfig's numbers (or loads a user's SDF);
world/seating.py solves the seated pose InitialPose leaves out from the chair's geometry.
"""

import math
from dataclasses import dataclass, field
from pathlib import Path

from drake_standup.config.resources import own_or_shipped


def _seated_joints() -> dict[str, float]:
    # [authors-code] (authors' seated pose), with the feasibility probe's knee
    # (-1.7365 rad) and the ankle pitch that puts the soles flat on the floor
    # for that knee ([early-probe]: the window for feet on the floor is narrow).
    legs = {
        "hip_pitch": 1.5908,
        "hip_roll": 0.2141,
        "hip_yaw": 0.0,
        "knee": -1.7365,
        "ankle_pitch": -0.1452,
        "ankle_roll": 0.0,
    }
    arms = {
        "shoulder_pitch": -0.6981,
        "shoulder_roll": 0.2094,
        "shoulder_yaw": 1.3963,
        "elbow": 0.5585,
    }
    joints = {f"{side}_{name}": q for side in "lr" for name, q in {**legs, **arms}.items()}
    joints.update(torso_pitch=0.0, torso_roll=0.0, torso_yaw=0.0)
    return joints


@dataclass
class InitialPose:
    """The seated pose. Left out, it is solved from the chair's geometry (world/seating.py:
    thighs on the seat, soles flat on the floor, the pelvis upright); base_xyz_m and
    joints_rad, where given, are taken as they are."""

    # The root_link's position; None: solved (its height from the seat, x from the
    # hips' place on it). m.
    base_xyz_m: list[float] | None = None
    # The iCub's root_link x axis points backwards: yaw pi faces the robot to +x.
    base_rpy_rad: list[float] = field(default_factory=lambda: [0.0, 0.0, math.pi])
    # Joint angles by name; None: solved from SEATED_JOINTS (the joints the seat does
    # not decide keep those values); given: the pose as it is (with base_xyz_m, or
    # SEATED_BASE_XYZ_M).
    joints_rad: dict[str, float] | None = None
    # The hip-pitch axes this far behind the seat's front edge; None: as deep as the seat
    # lets the thigh pads lie wholly on it (world/seating.py). m.
    hips_behind_seat_edge_m: float | None = None
    # The soles' frames (under the ankles) this far in front of the seat's front edge;
    # None: where the legs reach the floor closest to SEATED_JOINTS. m.
    feet_ahead_of_seat_edge_m: float | None = None


# Where the seated pose is solved from, and the base of files that give only the joints
# (0.39 m: the pads on the shipped seat).
SEATED_JOINTS = _seated_joints()
SEATED_BASE_XYZ_M = [0.0, 0.0, 0.39]


@dataclass
class Cushion:
    """A soft seat: a compliant hydroelastic layer on the seat board. Upholstery foams'
    Young's modulus is of order 10-100 kPa (flexible polyurethane foams: [gibson-ashby]);
    Drake's hydroelastic modulus is taken as about E ([elandt2019])."""

    # Hydroelastic modulus. Pa.
    modulus_Pa: float = 1.0e5
    # The layer's thickness, part of chair.seat_height_m. m.
    thickness_m: float = 0.04


# The seat board's thickness (under a cushion), the shipped chair's. m.
SEAT_BOARD_M = 0.04


@dataclass
class ChairConfig:
    """The chair, described by what matters to sitting on it (world/chair.py builds it),
    or an SDF file of your own."""

    # The seat's top above the chair's frame (on the floor): 0.2195 m is where the
    # iCubGazeboV2_5's pads rest in the authors' seated pose ([authors-code]; their Gazebo chair
    # had about 0.2075 m). With `file`, say where your chair's seat top is. m.
    seat_height_m: float = 0.2195
    # None: a rigid seat; else a soft layer on top of the board (Cushion).
    cushion: Cushion | None = None
    # Coulomb friction of the seat (static = dynamic): the shipped chair's 1.0.
    friction: float = 1.0
    # "": the chair made from these numbers; else an SDF file of your own (absolute, or
    # relative to the current directory; models/chair.sdf is the shipped chair as a
    # file) with a frame 'chair' on the floor below the seat's front edge, x forward.
    file: str = ""
    # What makes the chair from this section (drake_standup/plugins, docs/extending.md):
    # standard, the chair of these numbers or of `file`; or a chair of your own, by name or
    # module:attribute, a function chair(config) -> ChairModel. Its seat height is the
    # model's: seat_height_m is set from it when the scenario loads.
    kind: str = "standard"
    # Where the chair's frame (floor, below the seat's front edge) stands. m.
    xyz_m: list[float] = field(default_factory=lambda: [0.16, 0.0, 0.0])

    def seat_top_z_m(self) -> float:
        """The seat's top in the world: its frame's height plus seat_height_m. m."""
        return self.xyz_m[2] + self.seat_height_m

    def seat_edge_x_m(self) -> float:
        """The seat's front edge in the world. m."""
        return self.xyz_m[0]


def chair_file(name: str) -> Path:
    """chair.file as a path: the user's own file (or folder: config.inputs names it), else a
    shipped one such as models/chair.sdf, else the name as given (config.inputs: missing)."""
    return own_or_shipped(name)


@dataclass(frozen=True)
class ChairModel:
    """What a chair plug-in makes of the scenario's chair: section: an SDF model (its text,
    or a file: relative <uri>s resolve from the file's folder) with one model holding a
    frame 'chair' on the floor below the seat's front edge, x pointing the way the seated
    robot faces; and the seat's top above that frame, which the seating and the stand-up
    plan read. m."""

    seat_height_m: float
    sdf: str = ""
    path: Path | None = None
