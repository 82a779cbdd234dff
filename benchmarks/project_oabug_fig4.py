"""Projected wall time of the full OA-Bug Fig. 4 study from a few measured configurations.

``swarm_study project`` needs a measured row for every configuration of the plan. This
script needs fewer: the measured ``cpu_s`` per site configuration and variant at two robot
counts (``swarm_study run oabug-fig4 --set variant=random,gas_sound --set robots=2,10
--set departure=center --sites 1 --out DIR``). Every run of the 15,000-run plan gets the
cost of its site configuration, the measured variant of its class (random for the three
variants without scent, gas_sound for the two with it) and its robot count by linear
interpolation between the measured counts; the departure is assumed not to change the
cost. The runs are then scheduled as ``swarm_study project`` does (Dask's per-task overhead,
dispatch rate and startup: the figures of ``swarm_experiments.study.projection`` unless
``--overhead-ms``, ``--dispatch-ms`` and ``--startup-s`` give others, e.g. measured again
with ``benchmarks/bench_study_engine.py --measure dask``). Example::

    python benchmarks/project_oabug_fig4.py --from DIR/oabug-fig4 --cores 2 32 256
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

CLASS_OF = {
    'random': 'random',
    'minimum': 'random',
    'sound': 'random',
    'gas': 'gas_sound',
    'gas_sound': 'gas_sound',
}


def main(argv: Sequence[str] | None = None) -> int:
    from swarm_experiments.oabug_study import studies
    from swarm_experiments.study import make_specs, read_rows
    from swarm_experiments.study.projection import (
        DASK_DISPATCH_S,
        DASK_OVERHEAD_S,
        DASK_STARTUP_S,
        project_wall_time,
    )

    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--from', dest='measured', type=Path, required=True)
    parser.add_argument('--cores', type=int, nargs='+', default=[2, 32, 256])
    parser.add_argument('--cpu-scale', type=float, default=1.0)
    parser.add_argument(
        '--overhead-ms',
        type=float,
        default=1000 * DASK_OVERHEAD_S,
        help="the engine's core time per task (bench_study_engine.py's core_overhead_per_task_ms)",
    )
    parser.add_argument(
        '--dispatch-ms',
        type=float,
        default=1000 * DASK_DISPATCH_S,
        help="the engine's wall time per task (bench_study_engine.py's overhead_per_task_ms)",
    )
    parser.add_argument('--startup-s', type=float, default=DASK_STARTUP_S)
    args = parser.parse_args(argv)
    rows = read_rows(args.measured)
    rows = rows[rows['status'] == 'ok']
    means = rows.groupby(['config.site', 'config.variant', 'config.robots'])['cpu_s'].mean()
    (study,) = studies()
    plan = make_specs(study)
    costs = []
    for spec in plan.specs:
        config = spec.config
        measured = means.loc[(config['site'], CLASS_OF[config['variant']])]
        counts = np.array(measured.index, dtype=float)
        costs.append(float(np.interp(config['robots'], counts, measured.to_numpy())))
    print(f'{len(costs)} runs, {sum(costs) / 3600:.2f} CPU-hours (measured rows: {len(rows)})')
    for site in ('small', 'medium', 'big'):
        part = [c for c, s in zip(costs, plan.specs, strict=True) if s.config['site'] == site]
        print(f'  {site}: {len(part)} runs, mean {np.mean(part):.2f} CPU s per run')
    for cores in args.cores:
        projection = project_wall_time(
            costs,
            cores,
            per_task_overhead_s=args.overhead_ms / 1000,
            dispatch_s=args.dispatch_ms / 1000,
            startup_s=args.startup_s,
            cpu_scale=args.cpu_scale,
        )
        print(f'{cores} cores: {projection.summary()}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
