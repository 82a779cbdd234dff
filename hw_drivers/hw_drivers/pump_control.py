"""Pump safety logic, independent of the GPIO.

The ``pump`` topic carries the level the controller wants (OA-Bug publishes its duty cycle
on every control tick). :class:`PumpController` decides the actual output and enforces, on
its own and whatever the commands say:

* off when the last command is older than ``command_timeout_s`` (stale controller);
* on for at most ``max_on_s`` at a time; after such a forced stop the pump stays off until
  the controller has commanded off once (a stuck "on" command cannot keep re-firing it);
* off for at least ``min_off_s`` between two pulses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from hw_drivers.errors import ConfigurationError

__all__ = ['PumpController', 'PumpLimits']


@dataclass(frozen=True)
class PumpLimits:
    """Limits the pump driver enforces.

    Attributes:
        max_on_s: longest continuous on-time [s] (paper pulse 0.5 s; authors 0.35 s).
        min_off_s: shortest off-time between pulses [s].
        command_timeout_s: commands older than this count as "off" [s].
    """

    max_on_s: float = 1.0
    min_off_s: float = 1.0
    command_timeout_s: float = 0.5

    def __post_init__(self) -> None:
        for name in ('max_on_s', 'command_timeout_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigurationError(f'{name} must be > 0, got {value}')
        if not (math.isfinite(self.min_off_s) and self.min_off_s >= 0.0):
            raise ConfigurationError(f'min_off_s must be >= 0, got {self.min_off_s}')


class PumpController:
    """Turns timed commands into a safe pump output.

    All times are seconds on one monotonic clock chosen by the caller.
    """

    def __init__(self, limits: PumpLimits | None = None) -> None:
        self.limits = limits or PumpLimits()
        self.output = False
        self._wanted = False
        self._command_time_s: float | None = None
        self._on_since_s = 0.0
        self._off_since_s = -math.inf
        self._locked_out = False
        self.pulses = 0
        self.forced_stops = 0
        self.stale_stops = 0

    def command(self, on: bool, now_s: float) -> bool:
        """Record a command and return the output to apply now."""
        self._wanted = on
        self._command_time_s = now_s
        if not on:
            self._locked_out = False
        return self.update(now_s)

    def _command_fresh(self, now_s: float) -> bool:
        if self._command_time_s is None:
            return False
        age_s = now_s - self._command_time_s
        return 0.0 <= age_s <= self.limits.command_timeout_s

    def update(self, now_s: float) -> bool:
        """Return the output to apply at ``now_s`` (call periodically and on each command)."""
        fresh = self._command_fresh(now_s)
        if self.output:
            if not fresh:
                self.stale_stops += 1
                self._turn_off(now_s)
            elif not self._wanted:
                self._turn_off(now_s)
            elif now_s - self._on_since_s >= self.limits.max_on_s:
                self.forced_stops += 1
                self._locked_out = True
                self._turn_off(now_s)
        elif (
            fresh
            and self._wanted
            and not self._locked_out
            and now_s - self._off_since_s >= self.limits.min_off_s
        ):
            self.output = True
            self._on_since_s = now_s
            self.pulses += 1
        return self.output

    def force_off(self, now_s: float) -> None:
        """Turn off now (shutdown, errors); a new "on" command is needed afterwards."""
        if self.output:
            self._turn_off(now_s)
        self._wanted = False

    def _turn_off(self, now_s: float) -> None:
        self.output = False
        self._off_since_s = now_s
