"""The scent pump's duty cycle (paper Sec. IV-A: 75 % ethanol, 0.5 s every 5 s)."""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ['PumpSchedule']


@dataclass(frozen=True)
class PumpSchedule:
    """Pump on for ``on_s`` at the start of every ``period_s`` [s]."""

    on_s: float = 0.5
    period_s: float = 5.0

    def is_on(self, elapsed_s: float) -> bool:
        """Return True when the pump should run ``elapsed_s`` seconds after the start."""
        if elapsed_s < 0.0 or not math.isfinite(elapsed_s):
            return False
        return math.fmod(elapsed_s, self.period_s) < self.on_s
