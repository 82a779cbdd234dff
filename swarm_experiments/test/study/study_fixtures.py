"""TEST FIXTURES ONLY: synthetic studies for the study machinery's tests (not shipped).

The run function is deterministic from its spec: a noisy "coverage" that grows with the
robot count, a time series, and a few other metrics. Parameters used by the tests:

* ``sleep_s``: wall time each run takes (for interruption and worker-death tests);
* ``fail_seeds``: seeds whose run raises;
* ``die_once_seeds``: seeds whose first execution kills its own process (worker death).

The studies' check (:func:`check_synthetic`) refuses ``sim.steps`` < 1 and ``sleep_s`` < 0.

With ``STUDY_TEST_MARKERS`` set to a directory, each execution leaves a marker file there
named ``<run_id>.<node>.<pid>.<ns>`` (``STUDY_TEST_NODE`` names the node), so a test can
see which runs started where and how often. With ``STUDY_TEST_HANG_NODE`` naming a node,
every run after that node's first one hangs there, so a test that kills the node always
cuts a run short.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from swarm_experiments.study import RunSpec, Smoke, Study
from swarm_experiments.study.checks import check_number, check_whole

VARIANT_GAIN = {'gas': 1.0, 'sound': 0.8, 'random': 0.5}


def _marker(spec: RunSpec) -> Path | None:
    directory = os.environ.get('STUDY_TEST_MARKERS')
    if not directory:
        return None
    node = _node()
    path = Path(directory, f'{spec.run_id}.{node}.{os.getpid()}.{time.monotonic_ns()}')
    path.touch()
    return path


def _node() -> str:
    return os.environ.get('STUDY_TEST_NODE', 'main')


def synthetic_run(spec: RunSpec) -> Mapping[str, Any]:
    """A fake search mission: coverage from robots and variant plus seeded noise."""
    config = spec.config
    marker = _marker(spec)
    if spec.seed in config.get('die_once_seeds', []) and marker is not None:
        earlier = [p for p in marker.parent.glob(f'{spec.run_id}.*') if p != marker]
        if not earlier:
            os._exit(17)
    if marker is not None and os.environ.get('STUDY_TEST_HANG_NODE') == _node():
        earlier_here = [p for p in marker.parent.glob(f'*.{_node()}.*') if p != marker]
        if earlier_here:
            time.sleep(3600.0)  # until the test kills this node
    if config.get('sleep_s', 0.0):
        time.sleep(config['sleep_s'])
    if spec.seed in config.get('fail_seeds', []):
        raise ValueError(f'seed {spec.seed} fails on purpose')
    rng = np.random.default_rng([spec.seed, config['robots']])
    gain = VARIANT_GAIN[config['variant']] * config['sim']['speed_scale']
    steps = config['sim']['steps']
    rates = gain * config['robots'] * rng.uniform(0.5, 1.5, size=steps) / 100.0
    coverage = 1.0 - np.exp(-np.cumsum(rates))
    return {
        'coverage': coverage[-1],
        'found': bool(coverage[-1] > 0.9),
        'actions': int(steps * config['robots']),
        'first_90_step': int(np.argmax(coverage > 0.9)) if coverage[-1] > 0.9 else None,
        'coverage_every_10': coverage[::10],
        'energy': {'total_j': float(rng.gamma(2.0, 10.0))},
    }


def check_synthetic(config: Mapping[str, Any]) -> None:
    """The synthetic studies' check: at least one step, no negative sleep."""
    check_whole(config, 'sim.steps', minimum=1)
    check_number(config, 'sleep_s', minimum=0.0)


def blas_threads_run(spec: RunSpec) -> Mapping[str, Any]:
    """The BLAS thread variables the worker that runs ``spec`` sees (0: unset)."""
    return {
        name.lower(): int(os.environ.get(name, '0'))
        for name in ('OMP_NUM_THREADS', 'OPENBLAS_NUM_THREADS', 'MKL_NUM_THREADS')
    }


def dying_run(spec: RunSpec) -> Mapping[str, Any]:
    """Kills the process running it, every time."""
    os._exit(13)


def search_study(**changes: Any) -> Study:
    fields: dict[str, Any] = {
        'name': 'synthetic-search',
        'run': synthetic_run,
        'axes': {'variant': ('gas', 'sound', 'random'), 'robots': (2, 4, 6)},
        'params': {
            'sim': {'steps': 60, 'speed_scale': 1.0},
            'sleep_s': 0.0,
            'fail_seeds': [],
            'die_once_seeds': [],
        },
        'runs': 4,
        'seed_label': 'site',
        'description': 'Synthetic search (test fixture).',
        'smoke': Smoke(runs=2, axes={'robots': (2,)}, params={'sim': {'steps': 20}}),
        'check': check_synthetic,
    }
    fields.update(changes)
    return Study(**fields)


def studies() -> list[Study]:
    """Entry for ``--studies study_fixtures:studies``."""
    return [
        search_study(),
        search_study(
            name='synthetic-slow',
            axes={'variant': ('gas', 'sound'), 'robots': (2, 4)},
            params={
                'sim': {'steps': 30, 'speed_scale': 1.0},
                'sleep_s': 0.15,
                'fail_seeds': [],
                'die_once_seeds': [],
            },
            runs=6,
        ),
    ]
