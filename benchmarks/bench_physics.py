"""CPU time per simulated robot-second of each physics backend, on whole OA-Bug missions.

Runs the same OA-Bug missions (batch path, gas_sound, generated Small sites) on every backend
named, interleaved site by site, and prints, per backend and robot count, the CPU seconds of
the whole run and of the backend's own calls (the physics step, the lidar scan) divided by
robots x simulated seconds, then the ratio of each backend's whole-run figure to the first
backend's, measured in the same run. The backend's calls are timed by wrapping the backend
the registry builds (``swarm_sim.physics.PHYSICS_BACKENDS``). One short warm-up mission per
backend first loads the compiled kernels. CPU time is ``time.process_time``, one process::

    nice -n 10 python benchmarks/bench_physics.py --robots 4 10 --sites 2 --seconds 60
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

CALLS = ('step', 'scan')


class TimedBackend:
    """A physics backend whose step and scan add their CPU time to ``spent``."""

    def __init__(self, backend: Any, spent: dict[str, float]) -> None:
        self._backend = backend
        self._spent = spent
        self.walls = backend.walls
        self.num_bins = backend.num_bins
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


def run_mission(
    physics: str, robots: int, site_seed: int, seconds: float, spent: dict[str, float]
) -> tuple[float, float, int]:
    """Run one gas_sound mission; return (CPU s of the run, robot-seconds simulated, rooms
    covered), adding the CPU s of the backend's calls to ``spent``."""
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings
    from swarm_sim.engine import EngineConfig

    from swarm_sim import physics as physics_module

    factory = physics_module.PHYSICS_BACKENDS[physics]
    physics_module.PHYSICS_BACKENDS[physics] = lambda setup: TimedBackend(factory(setup), spent)
    try:
        settings = SpawnSettings(
            site='small',
            site_seed=site_seed,
            seed=site_seed,
            variant='gas_sound',
            robots=robots,
            actions=max(1, round(seconds * 0.3 / 0.1)),
            engine=EngineConfig(physics=physics),
        )
        start = time.process_time()
        result = run_spawn_batch(settings)
        cpu = time.process_time() - start
    finally:
        physics_module.PHYSICS_BACKENDS[physics] = factory
    return cpu, robots * result.mission.sim_time_s, result.mission.rooms_covered


@dataclass
class Tally:
    """What the missions of one backend and robot count added up to."""

    cpu_s: float = 0.0
    robot_s: float = 0.0
    spent: dict[str, float] = field(default_factory=lambda: defaultdict(float))
    covered: list[int] = field(default_factory=list)

    def per_robot_s_ms(self, seconds: float) -> float:
        """``seconds`` of CPU in milliseconds per simulated robot-second."""
        return 1e3 * seconds / self.robot_s


def measure(
    backends: Sequence[str], robots: int, site_seeds: Sequence[int], seconds: float
) -> dict[str, Tally]:
    """The same missions on every backend, interleaved (site by site, the order of the
    backends alternating) so that a change of the machine's load hits all of them alike."""
    tallies = {name: Tally() for name in backends}
    for k, seed in enumerate(site_seeds):
        order = list(backends) if k % 2 == 0 else list(reversed(backends))
        for name in order:
            tally = tallies[name]
            cpu, robot_s, covered = run_mission(name, robots, seed, seconds, tally.spent)
            tally.cpu_s += cpu
            tally.robot_s += robot_s
            tally.covered.append(covered)
    return tallies


def main(argv: Sequence[str] | None = None) -> int:
    """Command line entry point."""
    from swarm_common.cli import fail
    from swarm_common.errors import SwarmError
    from swarm_sim.physics import require_backend

    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--physics', nargs='+', default=['numpy', 'pybullet'])
    parser.add_argument('--robots', nargs='+', type=int, default=[4, 10])
    parser.add_argument('--sites', type=int, default=2, help='generated Small sites 0..n-1')
    parser.add_argument('--seconds', type=float, default=60.0, help='sim time per mission [s]')
    args = parser.parse_args(argv)
    try:
        for name in args.physics:
            require_backend(name)
    except SwarmError as err:
        return fail('bench_physics', err)
    for name in args.physics:
        run_mission(name, 2, 0, 5.0, defaultdict(float))  # warm-up: imports, compiled kernels
    print(
        '| physics | robots | missions | rooms covered | CPU ms per robot-s (whole run) '
        '| backend ms per robot-s | of which step / scan |'
    )
    print('|---|---|---|---|---|---|---|')
    ratios = []
    for robots in args.robots:
        tallies = measure(args.physics, robots, range(args.sites), args.seconds)
        for name, tally in tallies.items():
            parts = ' / '.join(f'{tally.per_robot_s_ms(tally.spent[c]):.2f}' for c in CALLS)
            print(
                f'| {name} | {robots} | {len(tally.covered)} | {np.mean(tally.covered):.1f} '
                f'| {tally.per_robot_s_ms(tally.cpu_s):.2f} '
                f'| {tally.per_robot_s_ms(sum(tally.spent.values())):.2f} | {parts} |',
                flush=True,
            )
        base_name = args.physics[0]
        base = tallies[base_name]
        for name in args.physics[1:]:
            ratio = tallies[name].per_robot_s_ms(tallies[name].cpu_s) / base.per_robot_s_ms(
                base.cpu_s
            )
            ratios.append(f'{name} / {base_name} at {robots} robots: {ratio:.1f} x')
    if ratios:
        print('\nCPU time per robot-second, whole runs, measured in this run: ' + '; '.join(ratios))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
