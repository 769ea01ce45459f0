"""Writes the example's data: a pull logged as a force plate would (bring_your_own/data/
lab_pull.csv) and the lab's chair as a closed mesh (bring_your_own/data/lab_chair.obj).

    python make_data.py

The pull is shaped after the real iCub's trained helper, whose peak hand force was 13.3 N
left and 9.9 N right during the rise (the authors' robot logs, read from their repository
Yeshasvitvs/whole-body-controllers): here those peaks, 45 degrees forward and up, from 3 s
over a 0.6 s onset, held 5 s, let go over 0.5 s, logged at 200 Hz with 0.3 N of sensor noise
(seeded). It is made up in that shape, not a measurement of a person.
"""

import math
from pathlib import Path

import numpy as np

DATA = Path(__file__).parent / "bring_your_own" / "data"
RATE_HZ, DURATION_S, NOISE_N = 200.0, 12.0, 0.3
PEAK_N = {"left": 13.3, "right": 9.9}
START_S, ONSET_S, HOLD_S, RELEASE_S = 3.0, 0.6, 5.0, 0.5


def envelope(t: np.ndarray) -> np.ndarray:
    """0 -> 1 over the onset (smooth), held, 1 -> 0 over the release."""
    rise = np.clip((t - START_S) / ONSET_S, 0.0, 1.0)
    fall = np.clip((START_S + ONSET_S + HOLD_S + RELEASE_S - t) / RELEASE_S, 0.0, 1.0)
    return (0.5 - 0.5 * np.cos(math.pi * rise)) * fall


def write_pull(path: Path) -> None:
    t = np.arange(0.0, DURATION_S, 1.0 / RATE_HZ)
    rng = np.random.default_rng(2019)
    columns = {"time_s": t}
    for hand, peak in PEAK_N.items():
        along = peak * envelope(t) / math.sqrt(2.0)  # 45 degrees forward and up
        for axis, mean in (("x", along), ("y", 0.0 * t), ("z", along)):
            columns[f"{hand}_f{axis}_N"] = mean + rng.normal(0.0, NOISE_N, t.size)
    rows = [",".join(columns)]
    rows += [",".join(f"{v:.6g}" for v in values) for values in zip(*columns.values())]
    path.write_text("\n".join(rows) + "\n")


def box(lo, hi):
    """The 8 corners and 12 outward triangles of an axis-aligned box."""
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    faces = [
        (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),  # x low, x high
        (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),  # y low, y high
        (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),  # z low, z high
    ]  # fmt: skip
    return corners, faces


def write_chair(path: Path, seat_m=0.23, depth_m=0.42, width_m=0.46, board_m=0.03) -> None:
    """A seat board (its top seat_m above the floor, its front edge at x = 0), four legs
    and a backrest, each a closed box."""
    leg, half = 0.04, width_m / 2
    boxes = [((-depth_m, -half, seat_m - board_m), (0.0, half, seat_m))]
    for x in (-depth_m, -leg):
        for y in (-half, half - leg):
            boxes.append(((x, y, 0.0), (x + leg, y + leg, seat_m - board_m)))
    boxes.append(((-depth_m - 0.03, -half, seat_m + 0.02), (-depth_m, half, seat_m + 0.45)))
    lines, offset = [], 1
    for lo, hi in boxes:
        corners, faces = box(lo, hi)
        lines += [f"v {x:.4f} {y:.4f} {z:.4f}" for x, y, z in corners]
        lines += [f"f {a + offset} {b + offset} {c + offset}" for a, b, c in faces]
        offset += len(corners)
    path.write_text(
        "# The lab's chair (make_data.py), m, z up, x forward\n" + "\n".join(lines) + "\n"
    )


if __name__ == "__main__":
    DATA.mkdir(parents=True, exist_ok=True)
    write_pull(DATA / "lab_pull.csv")
    write_chair(DATA / "lab_chair.obj")
