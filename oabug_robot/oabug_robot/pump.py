"""The scent pump's duty cycle (paper Sec. IV-A: 75 % ethanol, 0.5 s every 5 s).

The paper places pump and sensor "so that a robot's ethanol cannot interfere with its own
sensor". That holds while the robot drives away from its puff; a robot that pumps while
turning on the spot sits in its own cloud and later reads its own trail as a revisit. So a
burst only starts while the robot drives at ``min_speed_mps`` or faster, and the next burst
is due ``period_s`` after the previous one started. ``min_speed_mps = 0`` gives the plain
0.5 s / 5 s clock of the paper.
"""

from __future__ import annotations

import math

__all__ = ['PumpScheduler']


class PumpScheduler:
    """Decides, step by step, whether the pump runs."""

    def __init__(
        self, on_s: float = 0.5, period_s: float = 5.0, min_speed_mps: float = 0.0
    ) -> None:
        """Pump for ``on_s`` [s] at most every ``period_s`` [s], starting only at speed."""
        self._on_s = on_s
        self._period_s = period_s
        self._min_speed_mps = min_speed_mps
        self._burst_start_s = -math.inf

    def update(self, time_s: float, speed_mps: float) -> bool:
        """Return True when the pump should run at ``time_s`` with forward speed ``speed_mps``."""
        if not math.isfinite(time_s):
            return False
        elapsed = time_s - self._burst_start_s
        if 0.0 <= elapsed < self._on_s:
            return True
        if (elapsed >= self._period_s or elapsed < 0.0) and speed_mps >= self._min_speed_mps:
            self._burst_start_s = time_s
            return self._on_s > 0.0
        return False
