"""Exceptions raised by the OA-Bug core; the node logs them through its logger."""

from __future__ import annotations

from swarm_common import params

__all__ = ['ConfigError', 'OABugError', 'ParameterError', 'ScanError']


class OABugError(Exception):
    """Base class of every error the oabug_robot package raises."""


class ConfigError(OABugError, ValueError):
    """A configuration value is out of range or inconsistent with another one."""


class ParameterError(ConfigError, params.ParameterError):
    """A node parameter is unknown, of the wrong type, out of range or not one of its choices."""


class ScanError(OABugError, ValueError):
    """A laser scan cannot be interpreted (wrong geometry, empty, non-finite angles)."""
