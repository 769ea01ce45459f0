"""The CoM at the last robot state the controller's model computed, for the sensed CoM.

The controller's tick computes the CoM and its velocity with its model (control/terms.py:
from the mass matrix's base rows); the advancement and the state machine read the same
state's CoM through the sensing (world/sensing.py) between ticks. LastCoM hands the one
to the other, so the CoM is computed once a state (issue 48).
"""

from __future__ import annotations

import numpy as np


class LastCoM:
    """(p_WCom, v_WCom) of the last state put, keyed by the state's bytes."""

    def __init__(self):
        self._key: bytes | None = None
        self._com: tuple[np.ndarray, np.ndarray] | None = None
        self.hits = 0  # reads served (the sharing's test reads it)

    def put(self, x: np.ndarray, p_WCom: np.ndarray, v_WCom: np.ndarray) -> None:
        self._key, self._com = x.tobytes(), (p_WCom, v_WCom)

    def get(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The CoM and its velocity at x if x is the last state put, else None."""
        if self._key is None or x.tobytes() != self._key:
            return None
        self.hits += 1
        p_WCom, v_WCom = self._com
        return p_WCom.copy(), v_WCom.copy()
