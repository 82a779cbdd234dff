"""Exceptions raised by the simulation bridge's ROS-free modules."""

from __future__ import annotations

__all__ = ['ConfigurationError', 'MissionError', 'SimBridgeError', 'WorldGeometryError']


class SimBridgeError(Exception):
    """Base class of every error the simulation bridge raises on purpose."""


class ConfigurationError(SimBridgeError, ValueError):
    """A configuration value is out of range or inconsistent with another one."""


class WorldGeometryError(SimBridgeError, ValueError):
    """Wall segments, rooms or robot poses that the world cannot be built from."""


class MissionError(SimBridgeError, RuntimeError):
    """A mission run cannot start or continue (e.g. a node failed to come up)."""
