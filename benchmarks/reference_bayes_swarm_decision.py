"""Worker that times single decisions of the Bayes-Swarm-P authors' released code.

Run by ``bench_bayes_decision_cpu.py`` under an interpreter that has the authors' package
stack (their code needs numpy < 1.25, scikit-learn and pyswarm; it does not run on this
suite's numpy), with the path of a checkout of github.com/adamslab-ub/Bayes-Swarm-P as the
only argument. It reads one JSON object per line on stdin, a decision state::

    {"case": 7, "robot": 1, "n_robots": 5, "position": [x, y], "time_s": t,
     "points": [[x, y], ...], "values": [...], "peers": {"r0": [x0, y0, x1, y1], ...},
     "seed": s}

(``case`` is the authors' source id: 7 is Case 1, 2 is Case 2), builds their decision maker
(``BayesSwarm.bayes_swarm.BayesSwarm``, COBYLA / L-BFGS-B, mode ``local-penalty``, their
``Source`` for the case's settings) around a minimal robot that reports the position and the
peers' plans, and calls its ``get_next_point`` once, past the trivial first decision. It
answers one JSON line: ``{"cpu_s": ..., "wall_s": ..., "waypoint": [x, y]}``, the process
CPU time of that call alone. The authors' robot de-duplicates its samples with
``np.unique`` before the call; so does this worker, outside the timed call.

This file only drives the authors' code; none of it is copied here.
"""

import argparse
import json
import os
import sys
import time
import types


class _Robot:
    """What the authors' decision maker asks of its robot."""

    def __init__(self, robot_id, n_robots, position, peers):
        import numpy as np

        self.id = robot_id
        self.n_robots = n_robots
        self.location = np.asarray(position, dtype=float)
        self.peers_plan = {name: np.asarray(plan, dtype=float) for name, plan in peers.items()}

    def get_robot_id(self):
        return self.id

    def get_n_robots(self):
        return self.n_robots

    def get_robot_position(self):
        return self.location, 0.0

    def get_sensor_info(self):
        return 0.0, 1.0  # noise-free, 1 Hz, as the cases' runs

    def get_peers_plan(self):
        return self.peers_plan


def main():
    # Plain argparse: this runs under the authors' interpreter, without this suite's packages.
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('checkout', help="checkout of the authors' Bayes-Swarm-P code")
    args = parser.parse_args()
    if not os.path.isdir(os.path.join(args.checkout, 'BayesSwarm')):
        parser.exit(2, f'{parser.prog}: {args.checkout}: no BayesSwarm package in it\n')
    sys.path.insert(0, args.checkout)
    # GPy is imported by the authors' decision module but only used by a GP mode that the
    # default configuration does not select.
    sys.modules.setdefault('GPy', types.ModuleType('GPy'))
    try:
        import numpy as np
        from BayesSwarm.bayes_swarm import BayesSwarm
        from BayesSwarm.source import Source
    except ImportError as err:
        parser.exit(2, f"{parser.prog}: cannot import the authors' code here: {err}\n")

    answers = sys.stdout
    sys.stdout = sys.stderr  # anything the authors' code prints stays off the answers
    sources = {}
    for line in sys.stdin:
        if not line.strip():
            continue
        state = json.loads(line)
        case = int(state['case'])
        if case not in sources:
            sources[case] = Source(case)
        source = sources[case]
        _, time_max = source.get_source_info_mission()
        robot = _Robot(state['robot'], state['n_robots'], state['position'], state['peers'])
        planner = BayesSwarm(
            robot,
            source,
            time_max,
            source.get_source_bayes_settings(),
            'local-penalty',
            optimizers=['COBYLA', 'L-BFGS-B'],
        )
        planner.decision_counter = 1
        rows = np.column_stack([np.asarray(state['points'], float), np.asarray(state['values'])])
        unique = np.unique(rows, axis=0)
        np.random.seed(int(state['seed']))
        start_cpu, start = time.process_time(), time.perf_counter()
        waypoint = planner.get_next_point(float(state['time_s']), unique[:, :2], unique[:, 2])
        cpu, wall = time.process_time() - start_cpu, time.perf_counter() - start
        answer = {'cpu_s': cpu, 'wall_s': wall, 'waypoint': [float(v) for v in waypoint]}
        answers.write(json.dumps(answer) + '\n')
        answers.flush()


if __name__ == '__main__':
    main()
