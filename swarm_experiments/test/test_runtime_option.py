"""The spawners' --runtime and --time-scale options."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bouncer import WallBouncer
from swarm_experiments.mission import MissionSpec, RobotNodeSpec, run_mission
from swarm_experiments.runtime_option import chosen_runtime
from swarm_runtime.ros import using_real_rclpy
from swarm_sim.errors import ConfigurationError
from swarm_sim.site_loading import load_site

from swarm_experiments import spawn, spawn_bayes_swarm, spawn_msc_pf

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
IN_USE = 'rclpy' if using_real_rclpy() else 'builtin'
OTHER = 'builtin' if using_real_rclpy() else 'rclpy'


def test_the_option_wins_then_the_environment_then_builtin():
    assert chosen_runtime(['--runtime', 'rclpy'], {'SWARM_RUNTIME': 'builtin'}) == 'rclpy'
    assert chosen_runtime(['--seed', '1', '--runtime=builtin'], {}) == 'builtin'
    assert chosen_runtime(['--seed', '1'], {'SWARM_RUNTIME': 'rclpy'}) == 'rclpy'
    assert chosen_runtime(['--seed', '1'], {}) == 'builtin'  # even where rclpy is installed


@pytest.mark.parametrize('main', [spawn.main, spawn_bayes_swarm.main, spawn_msc_pf.main])
def test_a_runtime_other_than_the_one_in_use_is_a_one_line_error(main, capsys):
    assert main(['--runtime', OTHER, '--no-plots']) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert f'--runtime {OTHER}: this process already runs on the {IN_USE} runtime' in err


CHILD = textwrap.dedent(
    """
    import sys
    from swarm_experiments import runtime_option

    sys.argv = ['spawn', *sys.argv[1:], '--robots', '0']
    status = runtime_option.spawn_main()
    from swarm_runtime.ros import using_real_rclpy

    print('RUNTIME', 'rclpy' if using_real_rclpy() else 'builtin', status)
    """
)


def _child_runtime(*args):
    env = {k: v for k, v in os.environ.items() if k != 'SWARM_RUNTIME'}
    done = subprocess.run(
        [sys.executable, '-c', CHILD, *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    lines = [line for line in done.stdout.splitlines() if line.startswith('RUNTIME')]
    assert lines, done.stderr
    # --robots 0 is refused with a one-line error after the runtime was chosen.
    assert 'spawn: ' in done.stderr
    return lines[-1].split()[1:]


def test_the_console_entry_chooses_the_runtime_before_ros_is_imported():
    assert _child_runtime() == ['builtin', '2']
    assert _child_runtime('--runtime', 'builtin') == ['builtin', '2']
    if IN_USE == 'rclpy':
        assert _child_runtime('--runtime', 'rclpy') == ['rclpy', '2']


class RateProbe:
    """An extension that reads the bridge's real_time_factor when it is attached."""

    def __init__(self):
        self.real_time_factor = None

    def attach(self, node, robot_names):
        self.real_time_factor = node.get_parameter('real_time_factor').value

    def on_step(self, sim_time_s, states):
        pass

    def is_done(self):
        return False


def _bouncers(time_scale, extensions=()):
    return MissionSpec(
        site=load_site(str(FIVE_ROOMS)),
        initial_poses=np.array([[2.8, 1.73, 1.2], [3.4, 1.73, -1.9]]),
        robots=[RobotNodeSpec(WallBouncer), RobotNodeSpec(WallBouncer)],
        max_sim_time_s=2.0,
        stop_when_all_rooms_covered=False,
        time_scale=time_scale,
        extensions=extensions,
    )


def test_the_time_scale_is_the_bridge_clocks_real_time_factor():
    probe = RateProbe()
    result = run_mission(_bouncers(8.0, [probe]))
    assert probe.real_time_factor == 8.0
    assert result.sim_time_s == pytest.approx(2.0, abs=0.11)
    assert result.distance_travelled_m.min() > 0.1
    default = RateProbe()
    run_mission(_bouncers(1.0, [default]))
    assert default.real_time_factor == 1.0


@pytest.mark.parametrize('scale', [0.0, -1.0, float('inf')])
def test_an_impossible_time_scale_is_refused(scale):
    with pytest.raises(ConfigurationError, match='time_scale'):
        _bouncers(scale)
