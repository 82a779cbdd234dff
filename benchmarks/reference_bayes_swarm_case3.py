"""Whole Case 3 missions (Table 4) in the Bayes-Swarm-P authors' released simulator.

Runs under an interpreter that has the authors' package stack (numpy < 1.25, scikit-learn,
pyswarm, matplotlib; see ``reference_bayes_swarm_decision.py``), never under this suite's.
``--reference`` is a checkout of github.com/adamslab-ub/Bayes-Swarm-P. Each seed runs their
``Simulator`` with ``depot_mode='four-depot'`` (robots split into four blocks at the arena
corners, each block fanning over its inward quarter), COBYLA / L-BFGS-B, mode
``local-penalty``, full observation, 1 Hz samples, and prints one JSON line: the finder, its
start, the authors' own completion metric (their ``mission_time``, Eq. 12 with the finder's
straight-line time from its start to their ``source_location``), the time found, and the
closest any robot came to the source point.

What their release holds for Case 3 (read from their ``BayesSwarm/source.py``):

* ``source_11_init`` / ``source_11_measure`` are the paper's Eq. 21 exactly (c1 = (55, 45),
  divisors 6500 and 1600, the six weaker bumps), arena [-120, 120]^2, V = 1 m/s,
  eps = 0.2 m, T_max = 1000 s; but first leg 50 s, T = 30 s and L = 100, not Table 4's
  T = 100 s and L = 480; its ``source_location`` (the point whose reach ends the mission) is
  c1 = (55, 45), 10.5 m from the field's maximum (65.52, 44.31). Their ``Source`` does not
  dispatch id 11 (an unknown id falls back to Case 1's source), so this script selects it.
* ``source_10`` is another field on the same arena (main bump at (-45, -45), divisor 1400,
  nine weaker bumps) with Table 4's L = 480 and a 100 s first leg, then T = 10 s.

Options override the source's settings: ``--horizon-s`` (T), ``--first-horizon-s`` (the
first leg's duration), ``--lipschitz``, ``--t-max-s`` and ``--source-point X Y`` (the point
to reach; the field is unchanged). Example, the paper's Table 4 settings on Eq. 21::

    ../authors-venv/bin/python benchmarks/reference_bayes_swarm_case3.py \\
        --reference ../Bayes-Swarm-P --robots 48 --seeds 0 1 2 \\
        --horizon-s 100 --first-horizon-s 100 --lipschitz 480

This file only drives the authors' code; none of it is copied here.
"""

import argparse
import json
import os
import sys
import tempfile
import time
import types


def _select_source(source_class, args):
    """Make the authors' ``Source`` build ids 10 and 11 with the requested overrides."""
    original_init, original_measure = source_class.__init__, source_class.measure

    def init(self, source_id):
        if source_id not in (10, 11):
            original_init(self, source_id)
            return
        self.id = source_id
        self.source_dim = 2
        getattr(self, f'source_{source_id}_init')()
        if args.source_point is not None:
            import numpy as np

            self.source_location = np.array(args.source_point, dtype=float)
        if args.horizon_s is not None:
            self.decision_horizon = args.horizon_s
        if args.first_horizon_s is not None:
            self.decision_horizon_init = args.first_horizon_s
        if args.lipschitz is not None:
            self.local_penalizing_coef = {'M': 1.2, 'L': args.lipschitz}
        if args.t_max_s is not None:
            self.time_max = args.t_max_s

    def measure(self, location):
        if self.id == 11:
            return self.source_11_measure(location)
        return original_measure(self, location)

    source_class.__init__ = init
    source_class.measure = measure


def run(args, seed):
    """One mission; returns the JSON-ready result."""
    import numpy as np
    from BayesSwarm.simulator import Simulator
    from BayesSwarm.types import SimulationConfigs

    np.random.seed(seed)
    start_cpu = time.process_time()
    sim = Simulator(
        n_robots=args.robots,
        source_id=args.source_id,
        decision_making_mode='bayes-swarm',
        bayes_swarm_mode='local-penalty',
        filtering_mode='none',
        observation_frequency=1,
        optimizers=[None, None],
        enable_full_observation=True,
        depot_mode='four-depot',
        enable_log_simulation=False,
        simulation_configs=SimulationConfigs(),
    )
    sim.enable_plot = False
    sim.run()
    metric = sim.get_mission_metrics()['mission_time']
    point = np.asarray(sim.source_location, dtype=float)
    closest = min(
        float(np.min(np.linalg.norm(robot.get_robot_trajectory() - point, axis=1)))
        for robot in sim.robots.values()
    )
    result = {
        'seed': seed,
        'robots': args.robots,
        'source_id': args.source_id,
        'source_point': [float(v) for v in point],
        'horizon_s': float(sim.decision_horizon),
        'first_horizon_s': float(sim.decision_horizon_init),
        'found': bool(np.isfinite(metric)),
        'tau_authors': float(metric),
        'closest_m': closest,
        'cpu_s': time.process_time() - start_cpu,
    }
    finders = [name for name, found in sim.found_source.items() if found[0]]
    if finders:
        robot = sim.robots[finders[0]]
        ideal = float(robot.get_ideal_time())
        result.update(
            finder=finders[0],
            finder_start=[float(v) for v in robot.trajectory_history[0, :]],
            ideal_s=ideal,
            found_time_s=ideal * (1.0 + float(metric)),
        )
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--reference', required=True, help="checkout of the authors' code")
    parser.add_argument('--source-id', type=int, default=11, choices=(10, 11))
    parser.add_argument('--robots', type=int, default=48)
    parser.add_argument('--seeds', type=int, nargs='+', default=[0])
    parser.add_argument('--horizon-s', type=float)
    parser.add_argument('--first-horizon-s', type=float)
    parser.add_argument('--lipschitz', type=float)
    parser.add_argument('--t-max-s', type=float)
    parser.add_argument('--source-point', type=float, nargs=2, metavar=('X', 'Y'))
    args = parser.parse_args()
    sys.path.insert(0, os.path.abspath(args.reference))
    # Imported by the authors' modules but unused in this mode (their GPy GP, pybullet view).
    for name in ('GPy', 'pybullet', 'pybullet_data'):
        sys.modules.setdefault(name, types.ModuleType(name))
    try:
        import matplotlib

        matplotlib.use('Agg')
        from BayesSwarm.source import Source
    except ImportError as err:
        parser.exit(2, f"{parser.prog}: cannot import the authors' code here: {err}\n")

    _select_source(Source, args)
    answers = sys.stdout
    with tempfile.TemporaryDirectory() as scratch, open(os.devnull, 'w') as quiet:
        os.chdir(scratch)  # their simulator writes logs under the working directory
        for seed in args.seeds:
            sys.stdout = quiet  # their code prints every step
            try:
                result = run(args, seed)
            finally:
                sys.stdout = answers
            answers.write(json.dumps(result) + '\n')
            answers.flush()


if __name__ == '__main__':
    main()
