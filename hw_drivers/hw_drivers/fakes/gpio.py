"""A fake GPIO output that records its transitions."""

from __future__ import annotations

from collections.abc import Callable

__all__ = ['FakePumpOutput']


class FakePumpOutput:
    """Records (time, level) transitions; can be told to fail."""

    def __init__(self, clock: Callable[[], float] = lambda: 0.0) -> None:
        self._clock = clock
        self.level = False
        self.transitions: list[tuple[float, bool]] = []
        self.closed = False
        self.fail_on_set: bool | None = None

    def set(self, on: bool) -> None:
        if self.fail_on_set is not None and on == self.fail_on_set:
            raise OSError(5, 'Input/output error')
        if on != self.level:
            self.transitions.append((self._clock(), on))
        self.level = on

    def close(self) -> None:
        self.set(False)
        self.closed = True
