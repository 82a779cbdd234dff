"""CPU time per simulated robot-second of each physics backend, on whole OA-Bug missions.

Runs the same OA-Bug missions (batch path, generated Small sites) on every backend named, and
prints, per backend and robot count, the CPU seconds of the whole run and of the backend's own
calls (the physics step, the lidar scan, the wall counts of bearings and scent) divided by
robots x simulated seconds. The backend's calls are timed by wrapping the backend the
registry builds (``swarm_sim.physics.PHYSICS_BACKENDS``); one short warm-up mission per
backend first loads the compiled kernels. CPU time is ``time.process_time``, one process::

    nice -n 10 python benchmarks/bench_physics.py --robots 4 10 --sites 2 --seconds 60
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

CALLS = ('step', 'scan', 'wall_crossings')


class TimedBackend:
    """A physics backend whose step, scan and wall counts add their CPU time to ``spent``."""

    def __init__(self, backend: Any, spent: dict[str, float]) -> None:
        self._backend = backend
        self._spent = spent
        self.walls = backend.walls
        self.num_bins = backend.num_bins
        counter = backend.wall_crossings
        self.wall_crossings = None if counter is None else self._timed('wall_crossings', counter)
        self.step = self._timed('step', backend.step)
        self.scan = self._timed('scan', backend.scan)

    def _timed(self, name: str, call: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any) -> Any:
            start = time.process_time()
            try:
                return call(*args)
            finally:
                self._spent[name] += time.process_time() - start

        return timed

    def __getattr__(self, name: str) -> Any:
        return getattr(self._backend, name)


def run_missions(
    physics: str, robots: int, site_seeds: Sequence[int], seconds: float
) -> tuple[float, dict[str, float], float, list[int]]:
    """Run one gas_sound mission per site seed; return (CPU s of the runs, CPU s per backend
    call, robot-seconds simulated, rooms covered per run)."""
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings
    from swarm_sim.engine import EngineConfig

    from swarm_sim import physics as physics_module

    spent: dict[str, float] = defaultdict(float)
    factory = physics_module.PHYSICS_BACKENDS[physics]
    physics_module.PHYSICS_BACKENDS[physics] = lambda setup: TimedBackend(factory(setup), spent)
    try:
        cpu = 0.0
        robot_s = 0.0
        covered = []
        for seed in site_seeds:
            settings = SpawnSettings(
                site='small',
                site_seed=seed,
                seed=seed,
                variant='gas_sound',
                robots=robots,
                actions=max(1, round(seconds * 0.3 / 0.1)),
                engine=EngineConfig(physics=physics),
            )
            start = time.process_time()
            result = run_spawn_batch(settings)
            cpu += time.process_time() - start
            robot_s += robots * result.mission.sim_time_s
            covered.append(result.mission.rooms_covered)
    finally:
        physics_module.PHYSICS_BACKENDS[physics] = factory
    return cpu, dict(spent), robot_s, covered


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--physics', nargs='+', default=['numpy', 'pybullet'])
    parser.add_argument('--robots', nargs='+', type=int, default=[4, 10])
    parser.add_argument('--sites', type=int, default=2, help='generated Small sites 0..n-1')
    parser.add_argument('--seconds', type=float, default=60.0, help='sim time per mission [s]')
    args = parser.parse_args(argv)
    print(
        '| physics | robots | missions | rooms covered | CPU ms per robot-s (whole run) '
        '| backend ms per robot-s | of which step / scan / wall counts |'
    )
    print('|---|---|---|---|---|---|---|')
    for physics in args.physics:
        run_missions(physics, 2, [0], 5.0)  # warm-up: imports, compiled kernels
        for robots in args.robots:
            cpu, spent, robot_s, covered = run_missions(
                physics, robots, range(args.sites), args.seconds
            )
            per = 1e3 / robot_s
            parts = ' / '.join(f'{spent.get(name, 0.0) * per:.2f}' for name in CALLS)
            print(
                f'| {physics} | {robots} | {len(covered)} | {np.mean(covered):.1f} '
                f'| {cpu * per:.2f} | {sum(spent.values()) * per:.2f} | {parts} |',
                flush=True,
            )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
