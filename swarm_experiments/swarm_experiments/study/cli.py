"""``swarm_study``: list, run, report and project studies.

Exit codes: 0 everything asked for is done; 1 some runs failed or were not run (a cluster
lost, a report of an unfinished study); 2 a usage or input error (one line on stderr;
``--debug`` shows the traceback); 130 interrupted by Ctrl-C, 143 stopped by SIGTERM (what
batch schedulers and ``timeout`` send): either way the finished runs are kept and the same
command resumes.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import shlex
import signal
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import FrameType

from swarm_common.cli import EXIT_INTERRUPTED, ToolParser, run_tool
from swarm_common.outputs import check_output_directory

from .definition import StudyRegistry, load_registry
from .engines import ENGINES, make_engine
from .errors import UsageError
from .projection import (
    DASK_DISPATCH_S,
    DASK_OVERHEAD_S,
    DASK_STARTUP_S,
    costs_for_plan,
    project_wall_time,
)
from .report import blas_setups, study_directories, write_reports
from .results import read_manifest, read_rows
from .runner import run_study
from .spec import StudyPlan, make_specs, parse_overrides

PROG = 'swarm_study'
EXIT_OK, EXIT_INCOMPLETE, EXIT_USAGE = 0, 1, 2
#: Stopped by SIGTERM: 128 + the signal number, as a shell reports a process it ended.
EXIT_TERMINATED = 128 + signal.SIGTERM
EXIT_CODES = (
    'exit codes: 0 everything asked for is done; 1 some runs failed or were not run; 2 a usage '
    'or input error (one line on stderr, --debug adds the traceback); 130 interrupted by '
    'Ctrl-C, 143 stopped by SIGTERM: finished runs are kept, the same command resumes'
)


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: raised where Ctrl-C raises KeyboardInterrupt, for the same clean stop
    (the rows received so far are stored, the engine is stopped)."""


@contextlib.contextmanager
def sigterm_stops() -> Iterator[list[int]]:
    """While entered, SIGTERM raises :class:`Terminated` in the main thread (once; a second
    SIGTERM while the rows are being stored is ignored). Yields the signals received."""
    received: list[int] = []

    def handle(signum: int, frame: FrameType | None) -> None:
        if received:
            return
        received.append(signum)
        raise Terminated

    try:
        previous = signal.signal(signal.SIGTERM, handle)
    except ValueError:  # not the main thread: the caller handles its own signals
        yield received
        return
    try:
        yield received
    finally:
        signal.signal(signal.SIGTERM, previous)


def _add_plan_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('name', help='study name (see: swarm_study list)')
    count = parser.add_mutually_exclusive_group()
    count.add_argument('--runs', type=int, help='seeds per configuration')
    count.add_argument('--sites', type=int, help='sites per configuration (site studies)')
    first = parser.add_mutually_exclusive_group()
    first.add_argument('--first-seed', type=int, help="first seed instead of the study's own")
    first.add_argument(
        '--first-site', type=int, help='first site index instead of 0 (site studies)'
    )
    parser.add_argument(
        '--set',
        dest='overrides',
        action='append',
        default=[],
        metavar='PARAM=VALUE',
        help='set a parameter (dotted names for nested ones) or restrict an axis '
        '(comma-separated values); repeatable',
    )
    parser.add_argument('--smoke', action='store_true', help="the study's small smoke variant")


def build_parser() -> argparse.ArgumentParser:
    parser = ToolParser(
        prog=PROG, description='Run parameter studies and report their results.', epilog=EXIT_CODES
    )
    parser.add_argument(
        '--studies',
        action='append',
        default=[],
        metavar='MODULE:FUNCTION',
        help='also load the studies FUNCTION() returns (repeatable)',
    )
    commands = parser.add_subparsers(dest='command', required=True)
    commands.add_parser('list', help='list the registered studies')

    run = commands.add_parser('run', help='run (or resume) a study')
    _add_plan_options(run)
    run.add_argument('--out', type=Path, default=Path('runs/studies'), help='results directory')
    run.add_argument('--engine', choices=ENGINES, default='pool')
    run.add_argument('--address', help='join the Dask cluster at this scheduler address')
    run.add_argument('--workers', type=int, help='local worker processes (default: all cores)')
    run.add_argument(
        '--connect-timeout-s', type=float, default=20.0, help='how long to try --address'
    )
    run.add_argument('--batch-rows', type=int, default=50, help='rows per stored part file')
    run.add_argument('--quiet', action='store_true', help='no progress bar')

    report = commands.add_parser('report', help='write markdown reports of stored results')
    report.add_argument('directory', type=Path, help='a results directory or one study in it')

    project = commands.add_parser(
        'project', help='project the wall time of a study on N cores from measured runs'
    )
    _add_plan_options(project)
    project.add_argument(
        '--from',
        dest='measured',
        type=Path,
        required=True,
        help='study directory with measured rows (e.g. a smaller run)',
    )
    project.add_argument('--cores', type=int, required=True)
    project.add_argument(
        '--overhead-ms',
        type=float,
        default=1000 * DASK_OVERHEAD_S,
        help='per-task core time of the engine',
    )
    project.add_argument(
        '--dispatch-ms',
        type=float,
        default=1000 * DASK_DISPATCH_S,
        help='scheduler time per task handed out',
    )
    project.add_argument('--startup-s', type=float, default=DASK_STARTUP_S)
    project.add_argument(
        '--cpu-scale', type=float, default=1.0, help="target core's time per measured CPU second"
    )
    project.add_argument(
        '--longest-first', action='store_true', help='hand out the most expensive runs first'
    )
    return parser


def _plan(registry: StudyRegistry, args: argparse.Namespace) -> StudyPlan:
    study = registry.get(args.name)
    if args.sites is not None and study.seed_label != 'site':
        raise UsageError(f'study {study.name} has seeds, not sites: use --runs')
    if args.first_site is not None and study.seed_label != 'site':
        raise UsageError(f'study {study.name} has seeds, not sites: use --first-seed')
    runs = args.sites if args.sites is not None else args.runs
    first = args.first_site if args.first_site is not None else args.first_seed
    return make_specs(
        study,
        runs=runs,
        overrides=parse_overrides(args.overrides),
        smoke=args.smoke,
        first_seed=first,
    )


def _cmd_list(registry: StudyRegistry) -> int:
    if not len(registry):
        print(
            'no studies registered (packages add them through the '
            "'swarm_experiments.studies' entry points; or use --studies MODULE:FUNCTION)"
        )
        return EXIT_OK
    for study in registry:
        plan = make_specs(study)
        configurations = len(plan.specs) // max(1, len(plan.seeds))
        summary = study.description.strip().splitlines()[0] if study.description else ''
        print(
            f'{study.name}: {configurations} configurations x {len(plan.seeds)} '
            f'{study.seed_label}s = {len(plan.specs)} runs  {summary}'.rstrip()
        )
    return EXIT_OK


def _command_line(argv: Sequence[str]) -> str:
    """The command as typed, for the study's history (where the rows came from)."""
    return shlex.join([PROG, *argv])


def _cmd_run(registry: StudyRegistry, args: argparse.Namespace) -> int:
    plan = _plan(registry, args)
    if args.workers is not None and args.workers < 1:
        raise UsageError(f'--workers must be >= 1, not {args.workers}')
    if args.batch_rows < 1:
        raise UsageError(f'--batch-rows must be >= 1, not {args.batch_rows}')
    check_output_directory(args.out, option='--out')
    if not args.debug:
        # Worker processes inherit this: no Dask log lines between the progress bar updates.
        os.environ.setdefault('DASK_LOGGING__DISTRIBUTED', 'error')
        logging.getLogger('distributed').setLevel(logging.ERROR)
    with sigterm_stops() as terminated:
        try:
            return _run_plan(plan, args, terminated)
        except Terminated:
            # Arrived outside the loop over the rows (starting or closing the engine): the
            # rows received so far are stored already.
            pass
    print(f'{PROG}: stopped by SIGTERM; run the same command again to resume', file=sys.stderr)
    return EXIT_TERMINATED


def _run_plan(plan: StudyPlan, args: argparse.Namespace, terminated: Sequence[int]) -> int:
    try:
        engine = make_engine(
            args.engine,
            workers=args.workers,
            address=args.address,
            connect_timeout_s=args.connect_timeout_s,
        )
    except Terminated:
        raise
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted while starting the engine', file=sys.stderr)
        return EXIT_INTERRUPTED
    with engine:
        summary = run_study(
            plan,
            args.out,
            engine,
            progress=not args.quiet,
            batch_rows=args.batch_rows,
            command=_command_line(args.argv),
        )
    print(
        f'{summary.study}: {summary.ok} ok, {summary.failed} failed, {summary.skipped} '
        f'already stored, {summary.unfinished} not run of {summary.planned}; '
        f'rows in {summary.directory}'
    )
    setups = blas_setups(read_rows(summary.directory))
    if len(setups) > 1:
        print(
            f'{PROG}: warning: the rows in {summary.directory} ran on {len(setups)} BLAS '
            f'setups ({" | ".join(setups)}); a run that hinges on a close decision can '
            'come out otherwise on another',
            file=sys.stderr,
        )
    if summary.interrupted and terminated:
        print(f'{PROG}: stopped by SIGTERM; run the same command again to resume', file=sys.stderr)
        return EXIT_TERMINATED
    if summary.interrupted:
        print(f'{PROG}: interrupted; run the same command again to resume', file=sys.stderr)
        return EXIT_INTERRUPTED
    return EXIT_OK if summary.complete else EXIT_INCOMPLETE


def _cmd_report(registry: StudyRegistry, args: argparse.Namespace) -> int:
    def hook_error(study: str, exc: Exception) -> None:
        print(f'{PROG}: {study}: report hook failed: {type(exc).__name__}: {exc}', file=sys.stderr)

    import matplotlib

    matplotlib.use('Agg')
    pages = write_reports(
        args.directory,
        registry,
        on_hook_error=hook_error,
        report_command=_command_line(args.argv),
    )
    incomplete = 0
    for page in pages:
        directory = page.parent
        rows = read_rows(directory)
        ok = int((rows['status'] == 'ok').sum()) if len(rows) else 0
        planned = max(int(read_manifest(directory).get('runs', 0)), len(rows))
        incomplete += ok < planned
        print(f'{page} ({ok} of {planned} runs ok)')
    return EXIT_INCOMPLETE if incomplete else EXIT_OK


def _cmd_project(registry: StudyRegistry, args: argparse.Namespace) -> int:
    plan = _plan(registry, args)
    (measured_dir,) = study_directories(args.measured)[:1]
    costs = costs_for_plan(plan, read_rows(measured_dir))
    try:
        projection = project_wall_time(
            costs,
            args.cores,
            per_task_overhead_s=args.overhead_ms / 1000,
            dispatch_s=args.dispatch_ms / 1000,
            startup_s=args.startup_s,
            cpu_scale=args.cpu_scale,
            order='longest_first' if args.longest_first else 'given',
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from exc
    print(f'{plan.directory_name}: {projection.summary()}')
    return EXIT_OK


def main(argv: Sequence[str] | None = None, *, registry: StudyRegistry | None = None) -> int:
    """Run the command line; ``registry`` replaces the installed studies (for tests)."""

    def body(args_list: list[str]) -> int:
        args = build_parser().parse_args(args_list)
        args.argv = list(args_list)
        studies = registry
        if studies is None:
            studies = load_registry(args.studies)
        elif args.studies:
            studies.extend(load_registry(args.studies, use_entry_points=False))
        if args.command == 'list':
            return _cmd_list(studies)
        if args.command == 'run':
            return _cmd_run(studies, args)
        if args.command == 'report':
            return _cmd_report(studies, args)
        return _cmd_project(studies, args)

    return run_tool(PROG, body, argv)


if __name__ == '__main__':
    sys.exit(main())
