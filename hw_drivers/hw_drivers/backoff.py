"""Reconnect back-off: wait longer after each failed attempt, up to a ceiling."""

from __future__ import annotations

from dataclasses import dataclass

from hw_drivers.errors import ConfigurationError

__all__ = ['Backoff', 'BackoffConfig']


@dataclass(frozen=True)
class BackoffConfig:
    """Delays between reconnect attempts.

    Attributes:
        initial_s: delay after the first failure [s] (1 s).
        max_s: ceiling of the delay [s] (5 s).
        factor: growth of the delay after each further failure.
        fatal_s: delay after a fatal error (wrong chip, permissions) [s].
    """

    initial_s: float = 1.0
    max_s: float = 5.0
    factor: float = 2.0
    fatal_s: float = 30.0

    def __post_init__(self) -> None:
        if not 0.0 < self.initial_s <= self.max_s:
            msg = f'backoff needs 0 < initial_s <= max_s, got {self.initial_s} and {self.max_s}'
            raise ConfigurationError(msg)
        if self.factor < 1.0:
            raise ConfigurationError(f'backoff factor must be >= 1, got {self.factor}')
        if self.fatal_s <= 0.0:
            raise ConfigurationError(f'backoff fatal_s must be > 0, got {self.fatal_s}')


class Backoff:
    """Delay sequence initial, initial*factor, ... capped at max; reset on success."""

    def __init__(self, config: BackoffConfig | None = None) -> None:
        self._config = config or BackoffConfig()
        self._next_s = self._config.initial_s
        self.failures = 0

    def next_delay_s(self, *, fatal: bool = False) -> float:
        """Record one failure and return how long to wait before the next attempt [s]."""
        self.failures += 1
        if fatal:
            return self._config.fatal_s
        delay = self._next_s
        self._next_s = min(self._next_s * self._config.factor, self._config.max_s)
        return delay

    def reset(self) -> None:
        """Forget past failures after a successful connection."""
        self._next_s = self._config.initial_s
        self.failures = 0
