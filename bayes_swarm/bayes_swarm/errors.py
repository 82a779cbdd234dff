"""Exceptions raised by the bayes_swarm algorithm modules.

Library code raises these; nodes and scripts catch them and log or print the message.
"""

from __future__ import annotations

from swarm_common import params

__all__ = [
    'BayesSwarmError',
    'ConfigError',
    'GpFitError',
    'ObservationError',
    'ParameterError',
    'PlanningError',
]


class BayesSwarmError(Exception):
    """Base class of every error raised by this package."""


class ConfigError(BayesSwarmError, ValueError):
    """A configuration value is invalid (negative range, N_max < 1, unknown case, ...)."""


class ParameterError(ConfigError, params.ParameterError):
    """A node parameter is unknown, of the wrong type, out of range or not one of its choices."""


class ObservationError(BayesSwarmError, ValueError):
    """Observations have the wrong shape or contain no finite sample."""


class GpFitError(BayesSwarmError, RuntimeError):
    """The Gaussian process could not be conditioned on the data even with added jitter."""


class PlanningError(BayesSwarmError, RuntimeError):
    """A waypoint decision could not be made (e.g. decide() called before any observation)."""
