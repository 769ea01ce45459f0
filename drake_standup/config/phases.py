"""The phase table: what each stand-up state does, declared once ([authors-code],
[early-probe]; the postures: the authors' state 2, 3 and 4).

A scenario's `phases:` section holds one Phase per state; the defaults below are the
table every consumer reads: the state machine (segments, guards, the answer to a
hindering pull), the CoM reference (segments), the advancement (psi advances or not),
the contact schedule (how the seat supports the robot) and the task references (gains,
posture, base orientation, lean, stance).

    state  phase     CoM K_P       posture        base   seat              lean  stance  psi
    1      seated    [60, 40, 5]   as it sits     0.0    held              -     -       = t
    2      forward   [60, 40, 5]*  authors' st. 2 0.4    buttocks unload   -     -       advances
    3      lift_off  [60, 40, 30]  authors' st. 3 0.3    thighs unload     yes   -       advances
    4      rise      [60, 40, 30]  authors' st. 4 0.0    off the chair     yes   yes     advances

    * forward's CoM height is not tracked (com_height_follows): its reference height is
      the measured CoM's, so the z gain only damps; state 3 starts its height there.

    leaves when (Guard, all of them, and no hindering pull for standup.resume_after_s):
    1 -> 2   3 s balanced, the stand-up asked for (standup.trigger)
    2 -> 3   segment done, the buttocks unloaded (their release waits for the CoM 1.5 cm
             ahead of the thigh pads), the feet carry > 150 N together, the CoM 3 cm
             ahead of the heels
    3 -> 4   the thighs unloaded, segment done, each foot carries > 95 N
    a pull against the stand-up: 1 waits, 2 sits back, 3 steps back, 4 stands (leans)

Why these values: docs/design.md, "The phase table". Older scenario files spelled parts
of this table as separate keys of standup: and controller: (config/legacy.py reads them).
"""

import copy
import math
from dataclasses import dataclass, field

# The phases in the order of the stand-up states 1-4.
PHASES = ("seated", "forward", "lift_off", "rise")
# The sit-down's phases, states 5-7 (entered only where sit_down.trigger asks for one):
# each the reverse of a stand-up phase, back to `seated` (state 1).
DESCENT = ("lower", "land", "settle")
EVERY_PHASE = PHASES + DESCENT
# Pad groups of the chair whose load a phase can release (models/icub_contact.yaml).
SEAT_PADS = ("buttocks", "thighs")
# The seat's pads in the one order every consumer keeps (the station's
# seat_pad_normal_forces_N, the seat loads, the controller's chair contacts): each pad's
# frame (robot.TASK_FRAMES' key) and the group a phase releases it with.
SEAT_PAD_ROWS = (("buttocks", "buttocks"), ("l_thigh", "thighs"), ("r_thigh", "thighs"))
SEAT_HOLDS = ("held", "hinged")
# What a phase does under a pull against the stand-up (standup/transitions.py); a
# sit-down phase under a pull against the sit-down: stand (back up, state 4) or hold.
WHEN_HINDERED = ("wait", "sit_back", "step_back", "stand", "hold")
# Where a sit-down phase's segment ends: where that stand-up phase's segment started
# (the robot's own path on this chair, reversed), or at the seated CoM (x, y; its
# height follows the CoM).
RETURNS_TO = ("rise", "lift_off", "seated")

_LEGS = ("hip_pitch", "hip_roll", "knee", "ankle_pitch")
_ARMS = ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")


def posture(values: list[float]) -> dict[str, float]:
    """A [authors-code] posture row [hip pitch, roll, knee, ankle pitch | shoulder pitch, roll, yaw,
    elbow | torso pitch], both sides alike, as joint name -> rad."""
    table = {
        f"{side}_{joint}": value
        for side in "lr"
        for joint, value in zip(_LEGS + _ARMS, values[:8], strict=True)
    }
    table["torso_pitch"] = values[8]
    return table


@dataclass
class Guard:
    """What leaves a phase: every condition set here holds, and no pull against the
    stand-up has been felt for standup.resume_after_s (standup/transitions.py)."""

    # At least this long in the phase. s.
    min_time_s: float = 0.0
    # The stand-up was asked for: standup.trigger (the hands' pull, or time), or the live
    # page's Stand up button.
    asked: bool = False
    # The phase's CoM segment is done: psi past its end (a segment that does not move is
    # done at once). It keeps the reference's slope continuous across the switch.
    segment_done: bool = True
    # The pads this phase unloads have finished unloading (unload_s after their release
    # began: at entry, or once unload_when holds); in a sit-down phase, the pads it
    # lands have finished landing (load_s after their touch).
    unloaded: bool = False
    # Both soles together carry more than this (filtered, Schmitt trigger). N.
    feet_force_N: float | None = None
    # Each sole carries more than this. N.
    each_foot_force_N: float | None = None
    # The CoM at least this far in front of the soles' heel edge ([early-probe]: the feet's
    # forces alone fired with the CoM behind the heels). m.
    com_ahead_of_heels_m: float | None = None
    # A sit-down phase ends early (its segment not yet done) once the thigh pads'
    # undersides are this near the seat's top (the measured thigh_gap_m). m.
    thighs_within_m: float | None = None


@dataclass
class Phase:
    """One stand-up state's behaviour."""

    # The CoM segment the phase follows from its entry (com_path.py: min jerk): its
    # length in psi (= s at psi = t), its displacement, optionally an absolute end height
    # (replacing the displacement's z) and a start at the CoM's measured height instead of
    # the previous segment's end. In `seated` the length is that of the return to the
    # seat after a sit-back (the phase itself holds the CoM where it sits).
    segment_psi: float = 1.0
    com_delta_m: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    # An absolute end x (replacing the displacement's x), or one this far in front of the
    # soles' frames (under the ankles) where the robot sits, which the plan makes absolute
    # (standup/plan.py): the feet's place, not the chair's, says how far forward. m.
    com_x_m: float | None = None
    com_x_over_soles_m: float | None = None
    com_height_m: float | None = None
    # Without com_height_m: end at the erect CoM height of this phase's posture on the
    # scenario's robot (scene.standing, resolved by resolve_com_heights), so
    # that each model stands at its own height.
    com_height_erect: bool = False
    start_at_com_height: bool = False
    # The reference's height is the measured CoM's all through the phase (its rate and
    # acceleration 0: the z gain only damps the vertical motion), not the segment's: a
    # phase that moves the CoM forward and lets its height go where the posture takes
    # it (the pelvis' pitch dips the CoM ~5 cm in `forward`). The next segment starts at
    # that height, where the reference is: no jump (com_path.py). Phases 2-4 (the
    # seated phase and a sit-back's return hold the segment's height).
    com_height_follows: bool = False
    # CoM stiffness K_P (x, y, z); K_D = 2 zeta sqrt(K_P) (controller.com_damping_ratio).
    # 1/s^2.
    com_kp_per_s2: list[float] = field(default_factory=lambda: [60.0, 40.0, 5.0])
    # Posture target by joint name; a joint not named holds the posture of the first
    # tick. rad.
    posture_rad: dict[str, float] = field(default_factory=dict)
    # The posture's seated leg joints (hip pitch, knee, ankle pitch: those the seating
    # solves) move with the seated pose: posture_rad holds their targets for the shipped
    # seated pose (config.chair.SEATED_JOINTS), and the plan adds how far the robot's own
    # seated pose differs from it (resolve_postures), so a phase keeps [authors-code]'s motion
    # from the seat wherever the robot sits. False: posture_rad as it is.
    posture_from_seated: bool = False
    # Forward pitch of the base's (root_link's) target orientation. rad.
    base_pitch_rad: float = 0.0
    # How the seat contact holds the pelvis while the buttocks are seated: held (all six
    # rows) or hinged (free to pitch about the hip axis); and after a sit-back.
    seat_hold: str = "held"
    seat_hold_sat_back: str = "hinged"
    # Pad groups (SEAT_PADS) whose load is released from this phase's entry, over
    # unload_s (smoothstep); released pads stay so in the later phases. s.
    unload: list[str] = field(default_factory=list)
    unload_s: float = 0.0
    # The release begins once the CoM is at least this far in front of the thigh pads'
    # centres (the seat's support line: released behind it, the robot tips back onto
    # the chair, docs/design.md, "Leaving the seat"); None: at entry. m.
    unload_when: float | None = None
    # The CoM target leans against the hands' pull (the feet alone carry the robot).
    lean: bool = False
    # The legs' posture, not the CoM height, ends the segment (controller.stance_*); or
    # sets the height all along it (stance_throughout).
    stance: bool = False
    stance_throughout: bool = False
    # psi may run ahead of time here (advancement.py).
    advances: bool = True
    # Sit-down phases: the segment ends where the stand-up phase named here started
    # (RETURNS_TO); the posture is that phase's, as the plan resolved it (empty: the
    # seated pose held). Pad groups landed here: from the measured touch
    # (sit_down.touch_force_N), the load the QP may ask of them rises from 0 to what they
    # carried before their release, over load_s (smoothstep). s.
    returns_to: str | None = None
    posture_as: str | None = None
    # ... the trunk (the torso's joints, the hips' pitch, the pelvis' pitch) this many times
    # as fast (all the way once it is that far along).
    trunk_leads_by: float = 1.0
    # The posture leads, the CoM goes where it puts it (controller.posture_led_*): held to
    # the settle's path, which ends 3.6 cm ahead of the seated pose's CoM, the torso folded
    # onto its stop (docs/results.md, "The settle led by its posture").
    posture_leads: bool = False
    # Its path done with a pad it lands not yet touching the seat, the reference creeps
    # this much lower (over load_s) until the touch; from the touch the reference's
    # height follows the CoM (the seat takes it). m.
    sink_m: float = 0.0
    load: list[str] = field(default_factory=list)
    load_s: float = 0.0
    # The answer to a pull against the stand-up (WHEN_HINDERED).
    when_hindered: str = "wait"
    exit: Guard = field(default_factory=Guard)


@dataclass
class PhaseTable:
    """The four phases, in the order of the stand-up states (PHASES). The last is final:
    its exit is never taken."""

    # 1: balance on the chair ([authors-code]), the initial posture held.
    seated: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.5,
            advances=False,
            exit=Guard(min_time_s=3.0, asked=True),
        )
    )
    # 2: the CoM forward over the feet ([authors-code]: [0.1277, -0.0295, 0]; the lateral part
    # belonged to the authors' asymmetric posture, ours is symmetric), the pelvis pitched
    # forward; the buttocks lift off the seat. [authors-code]'s 0.1277 m, measured from the
    # shipped seated pose, ends 8.1 mm behind the soles' frames: kept there on any seat.
    # Its height follows the CoM: the path's z (0 displacement, K_P 5) pulled back toward
    # the seated height while the pitch dipped the CoM, and state 3 restarted 37-66 mm
    # lower in one step.
    forward: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.5,
            com_delta_m=[0.1277, 0.0, 0.0],
            com_x_over_soles_m=-0.0081,
            posture_rad=posture(
                [1.5402, 0.1594, -1.7365, -0.2814, -1.6455, 0.4363, 0.5862, 0.2473, 1.0]
            ),
            posture_from_seated=True,
            com_height_follows=True,
            base_pitch_rad=0.4,
            seat_hold="hinged",
            unload=["buttocks"],
            unload_s=0.2,
            unload_when=0.015,
            when_hindered="sit_back",
            exit=Guard(unloaded=True, feet_force_N=150.0, com_ahead_of_heels_m=0.03),
        )
    )
    # 3: the CoM further forward ([authors-code]), its height stiffened from where it is; the
    # thighs lift off the seat. Over 0.7 s, not [authors-code]'s 0.5 s: the min-jerk path's
    # 0.92 m/s^2 forward needs the CoP 3 cm behind the CoM at its 0.32 m height, at the
    # soles' heel edge, past their pads' middle third; the toes lifted and slapped (up to
    # 76 N of sole chatter). 0.7 s needs 0.47 m/s^2 (issue 30, docs/design.md).
    lift_off: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=0.7,
            com_delta_m=[0.04, 0.0, 0.0],
            start_at_com_height=True,
            com_kp_per_s2=[60.0, 40.0, 30.0],
            posture_rad=posture(
                [1.1097, 0.0122, -0.8365, -0.0714, -1.4615, 0.4363, 0.1545, 0.2018, 0.0611]
            ),
            posture_from_seated=True,
            base_pitch_rad=0.3,
            seat_hold="hinged",
            unload=["thighs"],
            # Over the whole phase, as [authors-code]'s 0.5 s of both: released earlier, the free
            # thighs brushed the seat again while the CoM still moved forward at its height.
            unload_s=0.7,
            lean=True,
            when_hindered="step_back",
            exit=Guard(unloaded=True, each_foot_force_N=95.0),
        )
    )
    # 4: up to the erect CoM height (scene.standing of this posture: 0.5753 m
    # on iCubGazeboV2_5, 0.553 m on iCubGenova01), the legs' posture ending the rise; the
    # final state.
    rise: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.8,
            com_height_erect=True,
            com_kp_per_s2=[60.0, 40.0, 30.0],
            posture_rad=posture(
                [0.2094, 0.1047, -0.1745, -0.0349, -1.6455, 0.4363, 0.5862, 0.2473, 0.0]
            ),
            seat_hold="hinged",
            lean=True,
            stance=True,
            when_hindered="stand",
        )
    )

    # 5: lower over the feet to where the rise started: the rise reversed, the feet
    # carrying the robot (the lift-off's posture and gains, the CoM leaning against the
    # pull). A pull against the sit-down stands the robot back up.
    lower: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.8,
            returns_to="rise",
            posture_as="lift_off",
            com_kp_per_s2=[60.0, 40.0, 30.0],
            base_pitch_rad=0.3,
            seat_hold="hinged",
            # Led by the legs' posture (the height row at stance_vertical_weight_scale),
            # the trunk and the hips three times as far along: a person leans forward,
            # then lowers. Led by the CoM, or with the trunk keeping pace, the knees bent
            # first and the ankles hit their stops (-0.611 rad: 62-132 N on the soles).
            stance=True,
            stance_throughout=True,
            trunk_leads_by=3.0,
            when_hindered="stand",
        )
    )
    # 6: back to where the lift-off started, the thighs landing: their load planned from
    # the touch over the lift-off's own 0.7 s (its release reversed), the forward's
    # posture. Longer than the lift-off (1.0 psi): the CoM goes back over the heels.
    land: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.0,
            returns_to="lift_off",
            sink_m=0.03,
            posture_as="forward",
            com_kp_per_s2=[60.0, 40.0, 30.0],
            base_pitch_rad=0.4,
            seat_hold="hinged",
            load=["thighs"],
            load_s=0.7,
            lean=True,
            stance=True,
            stance_throughout=True,
            when_hindered="hold",
            exit=Guard(unloaded=True),
        )
    )
    # 7: back to the seated CoM, the pelvis upright, the buttocks landing, the arms
    # back in the lap (the seated pose held: the helper's hands let go); its height
    # follows the CoM as the forward's did. Then state 1, seated.
    settle: Phase = field(
        default_factory=lambda: Phase(
            segment_psi=1.5,
            returns_to="seated",
            com_height_follows=True,
            seat_hold="hinged",
            posture_leads=True,
            load=["buttocks"],
            load_s=0.5,
            when_hindered="hold",
            exit=Guard(unloaded=True),
        )
    )

    def phase(self, state: int) -> Phase:
        """The phase of state 1-7 (stand-up 1-4, sit-down 5-7)."""
        return getattr(self, EVERY_PHASE[state - 1])

    def __iter__(self):
        """The stand-up's phases, states 1-4."""
        return (getattr(self, name) for name in PHASES)

    def every(self) -> list[Phase]:
        """Every phase, states 1-7: the stand-up's, then the sit-down's."""
        return [getattr(self, name) for name in EVERY_PHASE]

    def unresolved_heights(self) -> list[str]:
        """The phases whose end height waits for the robot (com_height_erect, no
        com_height_m)."""
        return [
            name
            for name, phase in zip(PHASES, self, strict=True)
            if phase.com_height_erect and phase.com_height_m is None
        ]

    def landing_phase(self, pads: str) -> int | None:
        """The sit-down state (5-7) that lands a pad group, None if none."""
        for state, phase in enumerate(self.every()[len(PHASES) :], start=len(PHASES) + 1):
            if pads in phase.load:
                return state
        return None

    def unloading_phase(self, pads: str) -> int | None:
        """The state (1-4) whose entry starts the release of a pad group, None if none."""
        for state, phase in enumerate(self, start=1):
            if pads in phase.unload:
                return state
        return None


def resolve_com_x(table: PhaseTable, soles_x_m: float) -> PhaseTable:
    """A copy of table whose com_x_over_soles_m phases without a com_x_m end that far in
    front of soles_x_m (the soles' frames' x where the robot sits, m)."""
    resolved = copy.deepcopy(table)
    for phase in resolved:
        if phase.com_x_over_soles_m is not None and phase.com_x_m is None:
            phase.com_x_m = soles_x_m + phase.com_x_over_soles_m
    return resolved


def resolve_com_heights(table: PhaseTable, erect_height_m) -> PhaseTable:
    """A copy of table whose com_height_erect phases without a com_height_m end at
    erect_height_m(phase.posture_rad) (m)."""
    resolved = copy.deepcopy(table)
    for name in table.unresolved_heights():
        phase = getattr(resolved, name)
        phase.com_height_m = float(erect_height_m(phase.posture_rad))
    return resolved


def resolve_descent(table: PhaseTable) -> PhaseTable:
    """A copy of table whose sit-down phases with a posture_as and no posture of their own
    take that (resolved) phase's posture."""
    resolved = copy.deepcopy(table)
    for name in DESCENT:
        phase = getattr(resolved, name)
        if phase.posture_as is not None and not phase.posture_rad:
            phase.posture_rad = dict(getattr(resolved, phase.posture_as).posture_rad)
    return resolved


def resolve_postures(
    table: PhaseTable,
    shift_rad: dict[str, float],
    limits_rad: dict[str, tuple[float, float]],
    margin_rad: float,
) -> PhaseTable:
    """A copy of table whose posture_from_seated phases have each joint of shift_rad (the
    robot's seated pose minus the shipped one, by joint name) moved by that much, kept
    margin_rad inside limits_rad (joint name -> (lower, upper)) where those allow it."""
    resolved = copy.deepcopy(table)
    for phase in resolved:
        if not phase.posture_from_seated:
            continue
        for name, shift in shift_rad.items():
            if name not in phase.posture_rad:
                continue
            target = phase.posture_rad[name] + shift
            low, high = limits_rad.get(name, (-math.inf, math.inf))
            if high - low > 2.0 * margin_rad:
                target = min(max(target, low + margin_rad), high - margin_rad)
            phase.posture_rad[name] = target
    return resolved
