"""Named layouts of the vectors the systems pass each other, and that signals.npz logs.

A VectorLayout names the entries of a vector port once, for its producer and every
reader: `HAND_WRENCHES["f_l"]` is the slice of the left hand's force, and
`DIAGNOSTICS.unpack(row)` the named parts of a logged row. Payloads that are not logged
travel as abstract values of documented dataclasses (control/contacts.py:
ContactCommands, control/targets.py: TaskReferences, standup/transitions.py: StandupMode).
"""

from __future__ import annotations

import numpy as np


class VectorLayout:
    """Named, consecutive parts of a vector: (name, size) in order."""

    def __init__(self, *parts: tuple[str, int]):
        self.names = tuple(name for name, _ in parts)
        self._slices: dict[str, slice] = {}
        start = 0
        for name, size in parts:
            self._slices[name] = slice(start, start + size)
            start += size
        self.size = start

    def __getitem__(self, name: str) -> slice:
        return self._slices[name]

    def __len__(self) -> int:
        return self.size

    def index(self, name: str) -> int:
        """The entry of a part of size 1."""
        part = self._slices[name]
        if part.stop - part.start != 1:
            raise KeyError(f"{name} has {part.stop - part.start} entries")
        return part.start

    def unpack(self, data: np.ndarray) -> dict[str, np.ndarray]:
        """Each part of data (its last axis laid out by this layout), by name: a view."""
        return {name: data[..., part] for name, part in self._slices.items()}

    def pack(self, **parts) -> np.ndarray:
        """A vector from every part, by name."""
        out = np.empty(self.size)
        for name, part in self._slices.items():
            out[part] = parts[name]
        return out


# Measured hand wrenches in the world frame W, at the hand frames' origins: [torque;
# force] of the left hand, then of the right. N m, N.
HAND_WRENCHES = VectorLayout(("tau_l", 3), ("f_l", 3), ("tau_r", 3), ("f_r", 3))

# A CoM segment of the reference (com_path.py): psi at its start, its length in psi,
# where it starts and its displacement (world, m), and whether the reference's height
# follows the measured CoM's instead of the segment's (1/0; phases.com_height_follows).
SEGMENT = VectorLayout(
    ("psi_entry", 1), ("psi_length", 1), ("x_start", 3), ("delta", 3), ("height_follows", 1)
)

# The CoM reference [x_d, xd_dot, xd_ddot] (world; m, m/s, m/s^2).
COM_REFERENCE = VectorLayout(("x_d", 3), ("xd_dot", 3), ("xd_ddot", 3))
