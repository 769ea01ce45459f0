"""human.body: the helper as a body (human.mode: body, helper/body.py).

The person's intent is human.reactive's (the guide, its pace, its force, its reaction
time); this section says who they are and how they hold the robot's hands.
"""

from dataclasses import dataclass

# human.body.tone's settings: a relaxed arm, or one made firm by co-contraction. (Older
# files' soft and stiff still load as relaxed and firm: config/legacy.py.)
TONES = ("relaxed", "firm")


@dataclass
class BodyHelperConfig:
    # The person's stature and mass: any adult within the anthropometric table's reach
    # (de Leva 1996, male; helper/anthropometry.py). m, kg.
    height_m: float = 1.75
    mass_kg: float = 75.0
    # relaxed (the default): a relaxed arm (Shadmehr & Mussa-Ivaldi 1994), the trunk at
    # 20 % effort (Gardner-Morse & Stokes 2001); firm: the arms co-contracted, 3 times
    # stiffer, the trunk at 40 % effort; also how soon they give way (world/
    # helper/body.py, JOINT_IMPEDANCE, YIELD_TIME_S). A firm person reaches their back's
    # strength and pulls up to 170 N at moments (docs/design.md).
    tone: str = "relaxed"
    # Hand in hand, the grip's translational spring and damper (a force element between
    # the person's grip and the robot's hand frame; no torque: a hand-hold transmits a
    # force). A fingertip is ~50 N/m at its lightest touch and stiffens with force
    # (Hajian & Howe 1997); no whole-hand grip measurement was found: 1000 N/m stretches
    # 2.5 cm under the authors' 25 N pull, critically damped on the person's hand
    # (damping ratio ~1 as Hajian & Howe's finger). N/m, N s/m.
    grip_stiffness_N_per_m: float = 1000.0
    grip_damping_Ns_per_m: float = 40.0
