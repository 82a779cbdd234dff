"""Exceptions raised by the study machinery."""

from __future__ import annotations

__all__ = ['EngineError', 'ResultsError', 'StudyDefinitionError', 'StudyError', 'UsageError']


class StudyError(Exception):
    """Base class of every error the study machinery raises on purpose."""


class StudyDefinitionError(StudyError, ValueError):
    """A study definition, a parameter override or a run's returned row is not valid."""


class UsageError(StudyError, ValueError):
    """A request names something that does not exist (a study, a parameter, a directory)."""


class ResultsError(StudyError, RuntimeError):
    """A results directory cannot be read or written (locked, corrupt, wrong study)."""


class EngineError(StudyError, RuntimeError):
    """An engine cannot start, reach its cluster, or keep its workers alive."""
