"""human.recorded: a person's hand forces replayed from a CSV file (human.mode: recorded,
helper/recorded.py replays them; the file's format: docs/helpers.md).

The file is read and checked here, when the scenario is validated (rules.validate), so a
bad recording is one ScenarioError line before anything simulates; the replay reads the
same cached samples.

The CSV: a header row, then one row per sample. Columns (by name, in any order; others
are ignored): time_s (s, strictly increasing), left_fx_N ... right_fz_N (N, required),
left_tx_Nm ... right_tz_Nm (N m, optional: absent, zero). Each row is the wrench the
person applies ON the robot's hand at the hand frame's origin, in human.recorded.frame.
"""

import csv
import functools
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drake_standup.config.errors import ScenarioError
from drake_standup.config.inputs import read_text_file
from drake_standup.config.resources import own_or_shipped

# human.recorded.frame's settings: the frame the file's samples are written in.
FRAMES = ("world", "hand")
HANDS = ("left", "right")
# The 12 columns of a sample as the replay orders them, the hand_wrenches_W layout
# [torque_l, force_l, torque_r, force_r]; torques N m, forces N.
WRENCH_COLUMNS = tuple(
    f"{hand}_{kind}{axis}_{unit}"
    for hand in HANDS
    for kind, unit in (("t", "Nm"), ("f", "N"))
    for axis in "xyz"
)
REQUIRED = ("time_s", *(c for c in WRENCH_COLUMNS if c.endswith("_N")))
OPTIONAL = tuple(c for c in WRENCH_COLUMNS if c.endswith("_Nm"))
SHIPPED = "recordings/default_pull.csv"
FILES = (
    "a CSV file path (absolute or relative to the current directory) or a shipped "
    f"recording such as {SHIPPED}"
)
CONTENT = (
    "a CSV file: a header row naming time_s and left_fx_N ... right_fz_N (optional: "
    "left_tx_Nm ... right_tz_Nm), then at least 2 rows of finite numbers, time_s strictly "
    "increasing (the header is row 1; docs/helpers.md)"
)


@dataclass
class RecordedHelperConfig:
    """The recorded helper (human.mode: recorded): each hand's wrench read from a file."""

    # The recording: a CSV file (absolute, relative to the current directory, or a
    # shipped one such as recordings/default_pull.csv) of time_s (s), each hand's force
    # (N) and, optionally, torque (N m) ON the robot's hand at the hand frame's origin;
    # replayed by linear interpolation, zero before its first sample and after its last.
    file: str = ""
    # The frame the samples are in: world (a force plate's lab frame, as the scene's
    # world: x forward, the way the robot faces, z up) | hand (the arm F/T sensor's frame
    # as the robot logs it; the iCub's sensor sits in the upper arm (the URDF's
    # l_arm_ft_sensor), and the hand frame l_hand / r_hand stands in for its frame:
    # each sample is rotated by that frame's orientation in the world when replayed).
    frame: str = "world"


@dataclass(frozen=True)
class Recording:
    """A checked recording: times_s (n,), strictly increasing, s; wrenches (n, 12) in
    WRENCH_COLUMNS' order, in the file's frame (N m, N). Both read-only."""

    times_s: np.ndarray
    wrenches: np.ndarray


class _RecordingError(Exception):
    """What is wrong with a recording's text (the message's middle)."""


def recording_file(name: str) -> Path:
    """human.recorded.file as a path: the user's own file, else a shipped one such as
    recordings/default_pull.csv (under the data root), else the name as given."""
    return own_or_shipped(name)


def load_recording(name: str) -> Recording:
    """The recording human.recorded.file names, checked; raises ScenarioError (one line,
    `human.recorded.file: '<name>' <problem>; accepted: ...`)."""
    key = "human.recorded.file"
    path = recording_file(name)
    if not name or not path.exists():
        what = "names no file" if not name else "not found"
        raise ScenarioError(f"{key}: '{name}' {what}; accepted: {FILES}")
    read_text_file(path, key, FILES)  # a folder, unreadable, not UTF-8: its one line
    stat = path.stat()
    try:
        return _parsed(str(path.resolve()), stat.st_mtime_ns, stat.st_size)
    except _RecordingError as bad:
        raise ScenarioError(f"{key}: '{name}' {bad}; accepted: {CONTENT}") from None


@functools.lru_cache(maxsize=8)
def _parsed(path: str, mtime_ns: int, size: int) -> Recording:
    """The recording at path, cached per file version (mtime_ns, size): validation and
    the replay read it, and a sweep validates every run."""
    rows = _rows(read_text_file(path, "human.recorded.file", FILES))
    if not rows:
        raise _RecordingError("has no header row")
    (_, header), samples = rows[0], rows[1:]
    columns = _columns(header)
    if len(samples) < 2:
        raise _RecordingError(
            f"has {len(samples)} row{'s' * (len(samples) != 1)} of samples, fewer than 2"
        )
    values = np.array([[_number(line, row, columns, c) for c in REQUIRED] for line, row in samples])
    _check_increasing(values[:, 0], [line for line, _ in samples])
    wrenches = np.zeros((len(samples), len(WRENCH_COLUMNS)))
    for j, name in enumerate(WRENCH_COLUMNS):
        if name in REQUIRED:
            wrenches[:, j] = values[:, REQUIRED.index(name)]
        elif name in columns:
            wrenches[:, j] = [_number(line, row, columns, name) for line, row in samples]
    times = values[:, 0].copy()
    times.flags.writeable = wrenches.flags.writeable = False
    return Recording(times, wrenches)


def _rows(text: str) -> list[tuple[int, list[str]]]:
    """(the row's line number, its cells stripped) of each row that is not blank."""
    reader = csv.reader(io.StringIO(text))
    try:
        rows = [(reader.line_num, [cell.strip() for cell in row]) for row in reader]
    except csv.Error as err:
        raise _RecordingError(f"is not CSV (line {reader.line_num}: {err})") from None
    return [(line, row) for line, row in rows if any(row)]


def _columns(header: list[str]) -> dict[str, int]:
    """Each column name of the header -> its index; the required ones all there, none of
    the names this module reads twice."""
    columns: dict[str, int] = {}
    for index, name in enumerate(header):
        if name in columns and name in (*REQUIRED, *OPTIONAL):
            raise _RecordingError(f"names column {name} twice")
        columns.setdefault(name, index)
    missing = [name for name in REQUIRED if name not in columns]
    if missing:
        raise _RecordingError(f"misses column(s) {', '.join(missing)}")
    return columns


def _number(line: int, row: list[str], columns: dict[str, int], name: str) -> float:
    """The finite number in row's column name (row `line` of the file)."""
    index = columns[name]
    cell = row[index] if index < len(row) else ""
    where = f"row {line}, column {name}"
    if not cell:
        raise _RecordingError(f"{where}: empty")
    try:
        value = float(cell)
    except ValueError:
        raise _RecordingError(f"{where}: {cell[:40]!r} is not a number") from None
    if not math.isfinite(value):
        raise _RecordingError(f"{where}: {cell!r} is not finite")
    return value


def _check_increasing(times: np.ndarray, lines: list[int]) -> None:
    """time_s strictly increasing; else the first row that is not after the one before."""
    stalled = np.flatnonzero(np.diff(times) <= 0.0)
    if stalled.size:
        k = stalled[0] + 1
        raise _RecordingError(
            f"row {lines[k]}: time_s {float(times[k])!r} is not after the row before's "
            f"({float(times[k - 1])!r})"
        )


def write_recording(path: Path | str, times_s: np.ndarray, forces: np.ndarray) -> None:
    """A recording of forces alone (no torque columns): times_s (n,) s, forces (n, 6)
    [left xyz, right xyz] N, one row per sample, each number written exactly (the
    shortest text that reads back as the same float)."""
    lines = [",".join(REQUIRED)]
    for t, f in zip(times_s, forces):
        lines.append(",".join(_exact(x) for x in (t, *f)))
    Path(path).write_text("\n".join(lines) + "\n")


def _exact(x: float) -> str:
    """The shortest text of x that reads back as x: 15.0 -> '15', 3.001 -> '3.001'."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text
