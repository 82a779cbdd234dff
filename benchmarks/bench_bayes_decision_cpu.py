"""CPU per Bayes-Swarm-P decision: this suite's planner against the authors' code, interleaved.

Decision states come from this suite's batch runs (``swarm_experiments.bayes_batch``, the
``paper`` profile: COBYLA / L-BFGS-B, the case's L, M and T_max; Case 1 with 5 robots and
Case 2 with 10, the paper's fields): every Bayes decision after the first of every robot is
recorded as the planner just before it (a deep copy: data set, peers' plans, GP state) with
the robot's position and the mission time. Each state is then decided again by both codes,
alternately (ours first on even states, theirs first on odd ones), so that both see the same
machine load:

* ours: ``BayesSwarmPlanner.decide`` on a fresh copy of the recorded planner, in this process;
* the authors': their ``BayesSwarm.get_next_point`` fed the same samples, position, time and
  peers' plans (``reference_bayes_swarm_decision.py``, a worker process under an interpreter
  with the authors' package stack, given with ``--authors-python``; ``--authors`` is a
  checkout of github.com/adamslab-ub/Bayes-Swarm-P).

Each time is ``time.process_time`` around the one call in its own process (one BLAS thread
in both). Printed per case: decisions, median and p90 CPU ms of each code, and the ratios
ours / authors' of the medians and of the p90s. Example (seeds 101-103)::

    python benchmarks/bench_bayes_decision_cpu.py --authors ../Bayes-Swarm-P \\
        --authors-python ../authors-venv/bin/python --seeds 3 --first-seed 101

``--ours-only`` skips the authors' code, ``--profile FILE`` writes a cProfile of our
decisions to FILE (a separate replay after the timed one).
"""

from __future__ import annotations

import os

for _var in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import argparse  # noqa: E402
import copy  # noqa: E402
import cProfile  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Sequence  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
from bayes_swarm.planner import BayesSwarmPlanner  # noqa: E402
from swarm_experiments.bayes_batch import run_mission  # noqa: E402
from swarm_experiments.spawn_bayes_swarm import batch_mission_spec  # noqa: E402
from swarm_sim.signal_fields import get_case  # noqa: E402

# This suite's case name -> (the authors' source id, robots).
CASES = {'case1': (7, 5), 'case2': (2, 10)}
_WORKER = Path(__file__).resolve().parent / 'reference_bayes_swarm_decision.py'


@dataclass
class State:
    """One recorded decision: the planner just before it, the robot's position and the time."""

    planner: BayesSwarmPlanner
    position_m: np.ndarray
    time_s: float


def record_states(case: str, seed: int, profile: str) -> list[State]:
    """Every decision after the first of every robot in one batch run of ``case``."""
    states: list[State] = []
    original = BayesSwarmPlanner.decide

    def recording(self: BayesSwarmPlanner, position_m: np.ndarray, time_s: float) -> Any:
        if self.decision_index > 0 and self.n_observations > 0:
            states.append(State(copy.deepcopy(self), np.array(position_m, float), float(time_s)))
        return original(self, position_m, time_s)

    _, n_robots = CASES[case]
    spec = batch_mission_spec(get_case(case), profile=profile)
    BayesSwarmPlanner.decide = recording  # type: ignore[method-assign]
    try:
        run_mission(spec, 'bayes_swarm_p', n_robots, seed)
    finally:
        BayesSwarmPlanner.decide = original  # type: ignore[method-assign]
    return states


def authors_request(case: str, state: State, seed: int) -> str:
    """The worker's JSON line for ``state``: the same samples, position, time and plans."""
    planner = state.planner
    points, values = planner._data.arrays()
    # The authors' plan rows are [start x, start y, waypoint x, waypoint y].
    peers = {
        name: [*map(float, start), *map(float, waypoint)]
        for name, (start, waypoint) in planner._peer_plans.items()
    }
    source_id, n_robots = CASES[case]
    return json.dumps(
        {
            'case': source_id,
            'robot': planner.config.robot_index,
            'n_robots': n_robots,
            'position': [float(v) for v in state.position_m],
            'time_s': state.time_s,
            'points': points.tolist(),
            'values': values.tolist(),
            'peers': peers,
            'seed': seed,
        }
    )


class AuthorsWorker:
    """The authors' decision maker in a worker process, one decision per request."""

    def __init__(self, python: Path, checkout: Path) -> None:
        self._proc = subprocess.Popen(
            [str(python), str(_WORKER), str(checkout)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, 'OMP_NUM_THREADS': '1', 'OPENBLAS_NUM_THREADS': '1'},
        )

    def decide(self, request: str) -> float:
        if self._proc.stdin is None or self._proc.stdout is None:
            msg = "the authors' worker has no pipes"
            raise RuntimeError(msg)
        self._proc.stdin.write(request + '\n')
        self._proc.stdin.flush()
        line = self._proc.stdout.readline()
        if not line:
            msg = "the authors' worker stopped (check --authors and --authors-python)"
            raise RuntimeError(msg)
        return float(json.loads(line)['cpu_s'])

    def close(self) -> None:
        if self._proc.stdin is not None:
            self._proc.stdin.close()
        self._proc.wait(timeout=30)


def ours(state: State) -> float:
    planner = copy.deepcopy(state.planner)
    start = time.process_time()
    planner.decide(state.position_m, state.time_s)
    return time.process_time() - start


def profile_ours(states: Sequence[State], profiler: cProfile.Profile) -> None:
    """The states decided once more under the profiler (after, never during, the timing)."""
    for state in states:
        planner = copy.deepcopy(state.planner)
        profiler.enable()
        planner.decide(state.position_m, state.time_s)
        profiler.disable()


def _row(case: str, mine: list[float], theirs: list[float]) -> str:
    m50, m90 = np.percentile(mine, [50, 90]) * 1e3
    cells = [case, str(len(mine)), f'{m50:.1f}', f'{m90:.1f}']
    if theirs:
        a50, a90 = np.percentile(theirs, [50, 90]) * 1e3
        cells += [f'{a50:.1f}', f'{a90:.1f}', f'{m50 / a50:.3f}', f'{m90 / a90:.3f}']
    else:
        cells += ['-'] * 4
    return '| ' + ' | '.join(cells) + ' |'


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--authors', type=Path, help="checkout of the authors' code")
    parser.add_argument('--authors-python', type=Path, help="interpreter for the authors' code")
    parser.add_argument('--ours-only', action='store_true', help="skip the authors' code")
    parser.add_argument('--cases', nargs='+', choices=tuple(CASES), default=list(CASES))
    parser.add_argument('--seeds', type=int, default=3, help='batch runs per case')
    parser.add_argument('--first-seed', type=int, default=101)
    parser.add_argument('--max-states', type=int, default=60, help='decisions per case at most')
    parser.add_argument('--planner-profile', default='paper', help='settings profile of ours')
    parser.add_argument('--profile', type=Path, help='write a cProfile of our decisions here')
    args = parser.parse_args(argv)
    if not args.ours_only and (args.authors is None or args.authors_python is None):
        parser.error('give --authors DIR and --authors-python PYTHON, or --ours-only')
    worker = None
    if not args.ours_only:
        worker = AuthorsWorker(args.authors_python, args.authors.resolve())
    profiler = cProfile.Profile() if args.profile else None
    rows = []
    try:
        for case in args.cases:
            states: list[State] = []
            for seed in range(args.first_seed, args.first_seed + args.seeds):
                states += record_states(case, seed, args.planner_profile)
            if len(states) > args.max_states:
                keep = np.linspace(0, len(states) - 1, args.max_states).round().astype(int)
                states = [states[i] for i in keep]
            # Warm-up of both (imports, first calls), not counted.
            ours(states[0])
            if worker is not None:
                worker.decide(authors_request(case, states[0], 0))
            mine: list[float] = []
            theirs: list[float] = []
            for i, state in enumerate(states):
                request = authors_request(case, state, i)
                if worker is not None and i % 2:
                    theirs.append(worker.decide(request))
                mine.append(ours(state))
                if worker is not None and not i % 2:
                    theirs.append(worker.decide(request))
            rows.append(_row(case, mine, theirs))
            if profiler is not None:
                profile_ours(states, profiler)
    finally:
        if worker is not None:
            worker.close()
    print(
        f'load average {os.getloadavg()[0]:.1f}; seeds {args.first_seed}-'
        f'{args.first_seed + args.seeds - 1}; profile {args.planner_profile}'
    )
    print(
        '| case | decisions | ours median ms | ours p90 ms | authors median ms '
        '| authors p90 ms | ratio median | ratio p90 |'
    )
    print('|---|---|---|---|---|---|---|---|')
    for row in rows:
        print(row)
    if profiler is not None:
        profiler.dump_stats(str(args.profile))
    return 0


if __name__ == '__main__':
    sys.exit(main())
