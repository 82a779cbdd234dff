"""A manual monotonic clock for deterministic device tests."""

from __future__ import annotations

__all__ = ['FakeClock']


class FakeClock:
    """Time that only moves when told: ``clock()`` reads it, ``sleep(dt)`` advances it [s]."""

    def __init__(self, start_s: float = 0.0) -> None:
        self.now_s = start_s

    def __call__(self) -> float:
        return self.now_s

    def sleep(self, duration_s: float) -> None:
        """Advance the clock instead of waiting."""
        self.now_s += max(duration_s, 0.0)

    advance = sleep
