"""Exceptions raised by the msc_pf library (nodes catch them and log)."""

from __future__ import annotations

from swarm_common import params

__all__ = ['ConfigError', 'MscPfError', 'ObservationError', 'ParameterError']


class MscPfError(Exception):
    """Base class of every error the msc_pf package raises."""


class ConfigError(MscPfError, ValueError):
    """A configuration value is out of range or inconsistent with another one."""


class ParameterError(ConfigError, params.ParameterError):
    """A node parameter is unknown, of the wrong type, out of range or not one of its choices."""


class ObservationError(MscPfError, ValueError):
    """An observation handed to the core is malformed (wrong shape, not finite)."""
