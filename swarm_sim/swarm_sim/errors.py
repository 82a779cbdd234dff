"""Exceptions raised by the simulator."""

from __future__ import annotations

from swarm_common.errors import SwarmError

__all__ = ['ConfigurationError', 'SimulationError', 'WorldGeometryError']


class SimulationError(SwarmError):
    """Base class of every error the simulator raises on purpose."""


class ConfigurationError(SimulationError, ValueError):
    """A configuration value is out of range or inconsistent with another one."""


class WorldGeometryError(SimulationError, ValueError):
    """Wall segments, rooms or robot poses that the world cannot be built from."""
