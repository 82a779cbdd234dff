"""Exceptions raised by the experiment harness (spawners, mission loop, batch runners)."""

from __future__ import annotations

from swarm_common.cli import EXIT_UNFINISHED
from swarm_common.errors import SwarmError

__all__ = ['ExperimentError', 'MissionError']


class ExperimentError(SwarmError):
    """Settings an experiment cannot be run with (exit code 2 on the command line)."""


class MissionError(ExperimentError, RuntimeError):
    """A mission run cannot start or continue (e.g. a node failed to come up)."""

    exit_code = EXIT_UNFINISHED
