"""Exceptions raised by the msc_pf library (nodes catch them and log)."""

from __future__ import annotations

from swarm_common.errors import SwarmError

__all__ = ['ConfigError', 'MscPfError', 'ObservationError']


class MscPfError(SwarmError):
    """Base class of every error the msc_pf package raises."""


class ConfigError(MscPfError, ValueError):
    """A configuration value is out of range or inconsistent with another one."""


class ObservationError(MscPfError, ValueError):
    """An observation handed to the core is malformed (wrong shape, not finite)."""
