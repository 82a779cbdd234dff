"""Run the OA-Bug authors' own grid simulator on its sites, as the reference figures were measured.

The authors' simulator (github.com/kevintsq/SwarmSearchSimulation, commit 9d16ebb) is not part
of this project and none of its code is copied here: this script imports its modules from a
checkout the user provides (``--simulator DIR``; it needs pygame and numpy) and follows the
measurement protocol of docs/oabug_reference.md: site s is generated after
``random.seed(1000003 * (s + 1))``, each run seeds ``random.seed(site_seed * 100 +
algo_index * 2 + edge)``, all variants and departures run on the same sites, and coverage is
taken at the end of the search (every room covered, or the action budget spent).

``--robot-hit-turn left`` makes a robot that hits another turn left instead of right (the
grid's only change for the measurement in docs/notes/oabug.md, "Why Gas trails Gas+Sound from the
edge on the authors' grid"). The grid's Gas robot keeps walls on its right, so its right turn
at a robot hit points it into its own wall, and two robots can lock each other for the rest
of the run; the report counts the robots standing still over the last 50 actions of runs
that used the whole budget. Example::

    python benchmarks/reference_oabug_grid.py --simulator ../SwarmSearchSimulation \\
        --variants gas gas_sound --departures edge --sites 100 --workers 2 --out grid.csv
    python benchmarks/reference_oabug_grid.py --simulator ../SwarmSearchSimulation \\
        --variants gas gas_sound --departures edge --sites 100 --robot-hit-turn left
"""

from __future__ import annotations

import contextlib
import csv
import importlib
import io
import math
import multiprocessing
import os
import random
import signal
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import astuple, dataclass, fields
from pathlib import Path
from typing import Any

from swarm_common.cli import EXIT_INTERRUPTED, ToolParser, fail, run_tool
from swarm_common.outputs import atomic_output, check_output_file

VARIANTS = ('random', 'minimum', 'sound', 'gas', 'gas_sound')
"""In the simulator's algorithm order (its run seed uses the index)."""
ROBOT_CLASSES = {
    'random': ('robots.random_robot', 'RandomRobot'),
    'minimum': ('robots.robot', 'Robot'),
    'sound': ('robots.robot_using_sound', 'RobotUsingSound'),
    'gas': ('robots.robot_using_gas', 'RobotUsingGas'),
    'gas_sound': ('robots.robot_using_gas_and_sound', 'RobotUsingGasAndSound'),
}
DEPARTURES = ('center', 'edge')
LOCK_WINDOW_ACTIONS = 50


@dataclass(frozen=True)
class GridConfig:
    """One of the paper's Table II configurations on the grid."""

    width_cells: int
    height_cells: int
    rooms: int
    victims: int
    actions: int


CONFIGS = {
    'small': GridConfig(60, 30, 30, 10, 1000),
    'medium': GridConfig(80, 40, 60, 10, 2000),
    'big': GridConfig(120, 60, 120, 10, 4000),
}


@dataclass(frozen=True)
class GridRun:
    """One run's outcome."""

    site: int
    variant: str
    departure: str
    robot_hit_turn: str
    coverage_pct: float
    actions: int
    locked_robots: int
    wall_s: float


def site_seed(site: int, attempt: int = 0) -> int:
    """Seed set before generating site ``site`` (docs/oabug_reference.md, "Protocol")."""
    return 1000003 * (site + 1) + attempt


def run_seed(seed_of_site: int, variant: str, departure: str) -> int:
    """Seed set before a run: site seed x 100 + algorithm index x 2 + edge."""
    return seed_of_site * 100 + VARIANTS.index(variant) * 2 + int(departure == 'edge')


class SimulatorMissingError(RuntimeError):
    """The simulator checkout cannot be found or imported."""


class _QuietLogger:
    """Stands in for the simulator's database logger, which the search does not need."""

    def debug(self, *_args: Any, **_kwargs: Any) -> None:
        """Drop the message."""

    def log(self, *_args: Any, **_kwargs: Any) -> None:
        """Drop the row."""


class GridSimulator:
    """The authors' modules, imported from a checkout, and one-run execution."""

    def __init__(self, checkout: Path, config: GridConfig, robot_hit_turn: str) -> None:
        """Import the simulator from ``checkout``.

        Raises:
            SimulatorMissingError: the folder or one of its modules is missing.
        """
        if not (checkout / 'generator.py').is_file():
            msg = f'no SwarmSearchSimulation checkout at {checkout} (generator.py not found)'
            raise SimulatorMissingError(msg)
        os.environ.setdefault('SDL_VIDEODRIVER', 'dummy')
        sys.path.insert(0, str(checkout))
        os.chdir(checkout)  # the simulator opens its assets by relative path
        try:
            with contextlib.redirect_stdout(io.StringIO()):  # pygame's greeting
                importlib.import_module('pygame')
            self._generator = importlib.import_module('generator').SiteGenerator
            self._layout = importlib.import_module('layout').Layout
            managers = importlib.import_module('robot_manager')
            self._manager = managers.RandomSpreadingRobotManager
            self._robots = {
                name: getattr(importlib.import_module(module), cls)
                for name, (module, cls) in ROBOT_CLASSES.items()
            }
            state = importlib.import_module('state')
        except ImportError as error:
            msg = f'cannot import the simulator from {checkout}: {error}'
            raise SimulatorMissingError(msg) from error
        self.config = config
        self.robot_hit_turn = robot_hit_turn
        if robot_hit_turn == 'left':
            base = state.AbstractState
            base.transfer_when_colliding_another_robot = _turning_left(
                base.transfer_when_colliding_another_robot
            )
        self._sites: dict[int, tuple[int, Any]] = {}

    def _site(self, site: int) -> tuple[int, Any]:
        if site not in self._sites:
            cfg = self.config
            for attempt in range(100):
                seed = site_seed(site, attempt)
                random.seed(seed)
                try:
                    generated = self._generator(
                        cfg.width_cells, cfg.height_cells, cfg.rooms, cfg.victims
                    )
                except Exception:
                    continue
                self._sites[site] = (seed, generated)
                break
            else:
                msg = f'site {site}: the generator failed 100 times'
                raise RuntimeError(msg)
        return self._sites[site]

    def run(
        self, site: int, variant: str, departure: str, robots: int, *, full_budget: bool = False
    ) -> GridRun:
        """One search run; coverage in percent of the rooms generated.

        The run ends when every room is covered or the action budget is spent; with
        ``full_budget`` only the budget ends it.
        """
        start = time.perf_counter()
        seed, generated = self._site(site)
        edge = departure == 'edge'
        random.seed(run_seed(seed, variant, departure))
        layout = self._layout.from_generator(generated, enable_display=False, depart_from_edge=edge)
        manager = self._manager(
            self._robots[variant],
            _QuietLogger(),
            layout,
            robots,
            depart_from_edge=edge,
            act_after_finding_injury=False,
        )
        recent: list[list[tuple[int, int]]] = []
        while not ((not full_budget and layout) or manager.action_count >= self.config.actions):
            manager.update()
            recent.append([tuple(robot.position) for robot in manager.robots])
            del recent[:-LOCK_WINDOW_ACTIONS]
        locked = 0
        if manager.action_count >= self.config.actions and recent:
            locked = sum(
                all(step[i] == recent[0][i] for step in recent) for i in range(len(recent[0]))
            )
        coverage = 100.0 * layout.report()[0] / generated.room_cnt
        return GridRun(
            site,
            variant,
            departure,
            self.robot_hit_turn,
            coverage,
            int(manager.action_count),
            locked,
            time.perf_counter() - start,
        )


def _turning_left(transfer: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """Wrap the grid's robot-hit transition so that its 90 deg right turn turns left."""

    def transfer_turning_left(state: Any) -> Any:
        robot = state.get_robot()
        if 'turn_right' in vars(robot):  # a nested transition: already turning left
            return transfer(state)
        robot.turn_right = robot.turn_left
        try:
            return transfer(state)
        finally:
            del robot.turn_right

    return transfer_turning_left


_WORKER: GridSimulator | None = None


def _init_worker(checkout: str, config: GridConfig, robot_hit_turn: str) -> None:
    global _WORKER
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's: it keeps the runs
    _WORKER = GridSimulator(Path(checkout), config, robot_hit_turn)


def _run_job(job: tuple[int, str, str, int]) -> GridRun:
    assert _WORKER is not None
    return _WORKER.run(*job)


def summary(runs: Sequence[GridRun]) -> list[str]:
    """Markdown table per departure and variant, and Gas+Sound minus Gas paired by site."""
    lines = [
        '| departure | variant | runs | coverage % | median | full coverage runs | locked robots'
        ' per run | wall s per run |',
        '|---|---|---|---|---|---|---|---|',
    ]
    for departure in DEPARTURES:
        for variant in VARIANTS:
            rows = [r for r in runs if r.departure == departure and r.variant == variant]
            if not rows:
                continue
            values = [r.coverage_pct for r in rows]
            full = sum(v >= 100.0 - 1e-9 for v in values)
            locked = statistics.fmean(r.locked_robots for r in rows)
            wall = statistics.fmean(r.wall_s for r in rows)
            lines.append(
                f'| {departure} | {variant} | {len(rows)} | {statistics.fmean(values):.1f} +- '
                f'{statistics.pstdev(values):.1f} | {statistics.median(values):.1f} | {full} | '
                f'{locked:.2f} | {wall:.2f} |'
            )
    for departure in DEPARTURES:
        by_site = {
            variant: {
                r.site: r.coverage_pct
                for r in runs
                if r.departure == departure and r.variant == variant
            }
            for variant in ('gas', 'gas_sound')
        }
        sites = sorted(set(by_site['gas']) & set(by_site['gas_sound']))
        if len(sites) < 2:
            continue
        diffs = [by_site['gas_sound'][s] - by_site['gas'][s] for s in sites]
        mean = statistics.fmean(diffs)
        sd = statistics.stdev(diffs)
        better = sum(d > 0 for d in diffs)
        worse = sum(d < 0 for d in diffs)
        lines.append(
            f'\n{departure}: Gas+Sound minus Gas {mean:+.1f} +- {sd / math.sqrt(len(diffs)):.1f}'
            f' points (mean paired difference +- its standard error; {better} sites better,'
            f' {worse} worse)'
        )
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point; exit codes as every tool's (docs/conventions.md);
    130 after Ctrl-C with the finished runs written."""
    return run_tool('reference_oabug_grid', _main, argv)


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='reference_oabug_grid', description=__doc__.splitlines()[0])
    parser.add_argument(
        '--simulator', type=Path, required=True, help='SwarmSearchSimulation checkout'
    )
    parser.add_argument('--config', choices=sorted(CONFIGS), default='small')
    parser.add_argument('--variants', nargs='+', choices=VARIANTS, default=list(VARIANTS))
    parser.add_argument('--departures', nargs='+', choices=DEPARTURES, default=list(DEPARTURES))
    parser.add_argument('--sites', type=int, default=20)
    parser.add_argument('--first-site', type=int, default=0)
    parser.add_argument('--robots', type=int, default=10)
    parser.add_argument('--robot-hit-turn', choices=('right', 'left'), default='right')
    parser.add_argument('--workers', type=int, default=1)
    parser.add_argument('--out', type=Path, help='write every run to this CSV file')
    args = parser.parse_args(argv)
    if args.sites < 1 or args.robots < 1 or args.workers < 1:
        parser.error('--sites, --robots and --workers must be at least 1')
    checkout = args.simulator.resolve()
    out = args.out.resolve() if args.out is not None else None  # before the chdir below
    if out is not None:
        check_output_file(out, option='--out')
    config = CONFIGS[args.config]
    try:
        GridSimulator(checkout, config, args.robot_hit_turn)  # fail fast, in this process
    except SimulatorMissingError as error:
        parser.error(str(error))
    jobs = [
        (site, variant, departure, args.robots)
        for site in range(args.first_site, args.first_site + args.sites)
        for departure in args.departures
        for variant in args.variants
    ]
    runs: list[GridRun] = []
    init = (str(checkout), config, args.robot_hit_turn)
    interrupted = False
    with multiprocessing.Pool(args.workers, _init_worker, init) as pool:
        try:
            for run in pool.imap(_run_job, jobs):
                runs.append(run)
                print(
                    f'[{len(runs)}/{len(jobs)}] site {run.site} {run.departure} {run.variant}:'
                    f' {run.coverage_pct:.1f} %, {run.locked_robots} locked',
                    flush=True,
                )
        except KeyboardInterrupt:
            interrupted = True  # leaving the pool terminates the workers
    if out is not None:
        with atomic_output(out) as partial, partial.open('w', newline='') as stream:
            writer = csv.writer(stream)
            writer.writerow([f.name for f in fields(GridRun)])
            writer.writerows(astuple(run) for run in runs)
    if runs:
        print('\n'.join(summary(runs)))
    if interrupted:
        fail('reference_oabug_grid', f'interrupted after {len(runs)} of {len(jobs)} runs')
        return EXIT_INTERRUPTED
    return 0


if __name__ == '__main__':
    sys.exit(main())
