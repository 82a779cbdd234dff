"""Studies: named sets of runs, executed on one machine or a cluster, stored as rows.

A :class:`Study` names its parameter axes, fixed parameters, seeds and a run function
``run(spec) -> row``; :func:`make_specs` expands it into :class:`RunSpec` objects with
stable run ids; :func:`run_study` executes the runs on an engine (``serial``, ``pool`` or
``dask``) and stores one Parquet row per run, resuming where an earlier call stopped;
:func:`write_reports` turns stored rows into markdown pages with tables and plots.
"""

from __future__ import annotations

from .definition import Smoke, Study, StudyRegistry, load_registry
from .engines import ENGINES, make_engine
from .errors import (
    EngineError,
    ResultsError,
    StudyDefinitionError,
    StudyError,
    UsageError,
)
from .projection import Projection, project_wall_time
from .report import ReportPage, paired_differences, reference_table, write_reports
from .results import VOLATILE_COLUMNS, read_rows
from .runner import RunSummary, run_study
from .spec import RunSpec, make_specs, parse_overrides, run_id

__all__ = [
    'ENGINES',
    'VOLATILE_COLUMNS',
    'EngineError',
    'Projection',
    'ReportPage',
    'ResultsError',
    'RunSpec',
    'RunSummary',
    'Smoke',
    'Study',
    'StudyDefinitionError',
    'StudyError',
    'StudyRegistry',
    'UsageError',
    'load_registry',
    'make_engine',
    'make_specs',
    'paired_differences',
    'parse_overrides',
    'project_wall_time',
    'read_rows',
    'reference_table',
    'run_id',
    'run_study',
    'write_reports',
]
