"""A dependency-free progress bar for long runs (simulated time, sweep runs)."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressBar:
    """Redraws one line on a terminal; elsewhere prints a line every 10%."""

    def __init__(self, total: float, label: str, unit: str = "s", stream: TextIO | None = None):
        self.total = max(float(total), 1e-12)
        self.label = label
        self.unit = unit
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty()
        self.start = time.perf_counter()
        self._last_decile = -1

    def update(self, done: float, note: str = "") -> None:
        frac = min(max(done / self.total, 0.0), 1.0)
        if self.tty:
            filled = int(30 * frac)
            bar = "#" * filled + "." * (30 - filled)
            self.stream.write(f"\r{self.label} [{bar}] {self._counts(done)} {note}  ")
            self.stream.flush()
        elif int(10 * frac) > self._last_decile:
            self._last_decile = int(10 * frac)
            counts = f"({self._counts(done)})"
            self.stream.write(f"{self.label}: {100 * frac:3.0f}% {counts} {note}\n")
            self.stream.flush()

    def _counts(self, done: float) -> str:
        if self.unit == "runs":
            return f"{int(done)}/{int(self.total)} {self.unit}"
        return f"{done:6.2f}/{self.total:.2f} {self.unit}"

    def close(self) -> None:
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
