"""``--processes``: one OS process per node on real DDS, supervised by the spawner.

The command-line tests run the spawners' console scripts as a user does: each algorithm on
two robots for a short budget (the robots must move and the outcome must be the spawner's
usual report), a robot killed mid-run (every child stops, exit 1, no process left) and
Ctrl-C to the supervisor (exit 130, every child gone). ``--dry-run`` is checked on either
runtime: its lines parse back to the nodes' parameters the spawner builds.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bridge_parameters import BRIDGE_PARAMETERS
from sim_bridge.mission_file import load_mission
from swarm_experiments.processes import NodeCommand, format_command, parse_command
from swarm_experiments.reliability import first_move_s, path_length_m
from swarm_runtime.bag import read_messages
from swarm_runtime.ros import using_real_rclpy

from swarm_experiments import spawn, spawn_bayes_swarm, spawn_msc_pf

real_rclpy = pytest.mark.skipif(
    not using_real_rclpy(), reason='--processes runs the nodes on real rclpy over DDS'
)

BIN = Path(sys.executable).parent
RUN_TIMEOUT_S = 90.0


def _dry_run(main, argv: list[str], run_dir: Path) -> list[NodeCommand]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main(['--processes', '--dry-run', '--run-dir', str(run_dir), *argv])
    assert status == 0
    lines = out.getvalue().splitlines()
    commands = [parse_command(line) for line in lines]
    assert [format_command(c) for c in commands] == lines  # the parse is exact
    return commands


def _check_bridge(command: NodeCommand, poses: np.ndarray) -> None:
    assert (command.package, command.executable, command.namespace) == (
        'sim_bridge',
        'sim_bridge',
        '',
    )
    for name, value in command.parameters.items():
        BRIDGE_PARAMETERS.check(name, value, strict=True)  # a real parameter of the right type
    mission = load_mission(command.parameters['mission_file'])
    np.testing.assert_array_equal(mission.initial_poses, poses)


def test_dry_run_lines_are_the_oabug_nodes(tmp_path: Path) -> None:
    argv = ['--robots', '3', '--actions', '40', '--seed', '4', '--param', 'gas_threshold=300']
    commands = _dry_run(spawn.main, argv, tmp_path)
    config = spawn.SpawnSettings(
        robots=3,
        actions=40,
        seed=4,
        robot_parameters=spawn.oabug_parameter_overrides(['gas_threshold=300']),
    )
    spec, _ = spawn.build_mission(config)
    assert len(commands) == 4
    _check_bridge(commands[0], spec.initial_poses)
    assert commands[0].parameters['max_sim_time_s'] == pytest.approx(spec.max_sim_time_s)
    assert commands[0].parameters['stop_when_all_rooms_covered'] is True
    for i, (command, robot) in enumerate(zip(commands[1:], spec.robots, strict=True)):
        assert (command.package, command.executable) == ('oabug_robot', 'oabug')
        assert command.namespace == f'/r{i}'
        assert command.parameters == {'use_sim_time': True, **robot.parameters}
    assert commands[1].parameters['gas_threshold'] == 300


def test_dry_run_lines_are_the_bayes_swarm_nodes(tmp_path: Path) -> None:
    commands = _dry_run(spawn_bayes_swarm.main, ['--robots', '2', '--t-max', '30'], tmp_path)
    settings = spawn_bayes_swarm.SpawnSettings(robots=2, max_mission_time_s=30.0)
    case = spawn_bayes_swarm.check_settings(settings)
    assert [c.executable for c in commands] == [
        'sim_bridge',
        'bayes_swarm_node',
        'bayes_swarm_node',
    ]
    bridge = commands[0].parameters
    assert bridge['peer_msg_type'] == 'swarm_interfaces/msg/BayesSwarmPeer'
    assert bridge['physics_rate_hz'] == 20.0  # the point-robot engine, not the default
    mission = load_mission(bridge['mission_file'])
    assert type(mission.extensions[0]).__name__ == 'SignalExtension'
    for i, command in enumerate(commands[1:]):
        expected = spawn_bayes_swarm.node_parameters(case, settings, 2, i)
        assert command.parameters == {'use_sim_time': True, **expected}


def test_dry_run_lines_are_the_msc_pf_nodes(tmp_path: Path) -> None:
    argv = ['--robots', '2', '--targets', '3', '--seed', '2']
    commands = _dry_run(spawn_msc_pf.main, argv, tmp_path)
    settings = spawn_msc_pf.SpawnSettings(robots=2, targets=3, seed=2)
    targets, poses = spawn_msc_pf.scenario(settings)
    _check_bridge(commands[0], poses)
    mission = load_mission(commands[0].parameters['mission_file'])
    np.testing.assert_array_equal(mission.extensions[0].targets.positions_m, targets.positions_m)
    for i, command in enumerate(commands[1:]):
        assert (command.package, command.executable) == ('msc_pf', 'msc_pf_node')
        expected = spawn_msc_pf.node_parameters(settings, i)
        assert command.parameters == {'use_sim_time': True, **expected}


@pytest.mark.parametrize(
    'argv',
    [
        ['--dry-run'],
        ['--run-dir', 'x'],
        ['--processes', '--runtime', 'builtin'],
        ['--fault', 'crash:r1@5'],  # a node crash needs node processes
        ['--processes', '--dry-run', '--fault', 'crash:1@5'],
    ],
)
def test_process_options_that_do_not_fit_are_usage_errors(argv: list[str]) -> None:
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        status = spawn.main([*argv, '--robots', '2', '--no-plots'])
    assert status == 2
    assert len(err.getvalue().strip().splitlines()) == 1


# Real runs --------------------------------------------------------------------------------


def _children_of(pid: int) -> set[int]:
    """Process ids whose parent is ``pid`` (from /proc)."""
    found = set()
    for entry in Path('/proc').iterdir():
        if not entry.name.isdigit():
            continue
        with contextlib.suppress(OSError):
            stat = (entry / 'stat').read_text()
            ppid = int(stat.rsplit(')', 1)[1].split()[1])
            if ppid == pid:
                found.add(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        stat = Path(f'/proc/{pid}/stat').read_text()
    except OSError:
        return False
    return stat.rsplit(')', 1)[1].split()[0] != 'Z'


def _run(script: str, argv: list[str], run_dir: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [
            str(BIN / script),
            '--processes',
            '--run-dir',
            str(run_dir),
            '--no-plots',
            '--quiet',
            *argv,
        ],
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT_S,
        check=False,
    )


def _outcome(run_dir: Path) -> dict:
    return json.loads((run_dir / 'outcome.json').read_text())


@real_rclpy
def test_oabug_runs_in_processes_and_records_the_bag(tmp_path: Path) -> None:
    bag = tmp_path / 'bag'
    argv = ['--robots', '2', '--actions', '24', '--time-scale', '3', '--record', str(bag)]
    done = _run('spawn', argv, tmp_path / 'run')
    assert done.returncode in (0, 1), done.stderr
    assert 'stopped by budget after 8.0 s sim' in done.stdout
    assert 'Coverage:' in done.stdout
    outcome = _outcome(tmp_path / 'run')
    assert outcome['stop_reason'] == 'budget'
    assert min(outcome['distance_travelled_m']) > 0.3  # both robots drove on their scans
    topics = {m.topic for m in read_messages(bag, raw=True)}
    for topic in ('/clock', '/sim/site', '/sim/coverage', '/r1/cmd_vel', '/r0/state'):
        assert topic in topics  # the supervisor's recorder took the children's topics


@real_rclpy
def test_bayes_swarm_runs_in_processes(tmp_path: Path) -> None:
    argv = ['--robots', '2', '--t-max', '12', '--time-scale', '3']
    done = _run('spawn_bayes_swarm', argv, tmp_path)
    assert done.returncode in (0, 1), done.stderr
    assert 'case case1, bayes_swarm_p, seed 0' in done.stdout
    outcome = _outcome(tmp_path)
    assert outcome['extensions'][0]['kind'] == 'signal'
    assert min(outcome['distance_travelled_m']) > 0.3  # 0.1 m/s for most of 12 s


@real_rclpy
def test_msc_pf_runs_in_processes(tmp_path: Path) -> None:
    argv = ['--robots', '2', '--targets', '2', '--t-max', '40', '--time-scale', '8']
    done = _run('spawn_msc_pf', argv, tmp_path)
    assert done.returncode in (0, 1), done.stderr
    assert 'scheme proposed, 2 robots, 2 targets' in done.stdout
    outcome = _outcome(tmp_path)
    assert outcome['stop_reason'] == 'budget'
    assert len(outcome['extensions'][0]['capture_times_s']) == 2
    assert min(outcome['distance_travelled_m']) > 5.0


def _start_long_run(run_dir: Path) -> tuple[subprocess.Popen[str], set[int]]:
    """A long OA-Bug run; returns once the simulation steps, with the children's pids."""
    argv = ['--robots', '2', '--actions', '3000', '--no-plots', '--quiet']
    proc = subprocess.Popen(
        [str(BIN / 'spawn'), '--processes', '--run-dir', str(run_dir), *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    bridge_log = run_dir / 'sim_bridge.log'
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        if bridge_log.exists() and 'the simulation starts' in bridge_log.read_text():
            break
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.2)
    else:
        proc.kill()
        pytest.fail('the simulation did not start within 60 s')
    children = _children_of(proc.pid)
    assert len(children) == 3
    return proc, children


@real_rclpy
def test_a_crashed_robot_stops_every_child(tmp_path: Path) -> None:
    proc, children = _start_long_run(tmp_path)
    robot = next(pid for pid in children if '__ns:=/r1' in Path(f'/proc/{pid}/cmdline').read_text())
    os.kill(robot, signal.SIGKILL)
    _, err = proc.communicate(timeout=30.0)
    assert proc.returncode == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1
    assert 'r1 (oabug) was killed by signal 9' in lines[0]
    assert not [pid for pid in children if _alive(pid)]


@real_rclpy
def test_ctrl_c_stops_every_child_with_the_summary_so_far(tmp_path: Path) -> None:
    proc, children = _start_long_run(tmp_path)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30.0)
    assert proc.returncode == 130, err
    assert 'stopped by interrupted' in out
    assert 'Coverage:' in out
    assert not [pid for pid in children if _alive(pid)]


@real_rclpy
def test_a_crash_fault_kills_and_restarts_one_robot(tmp_path: Path) -> None:
    # Time scale 1: the restarted node's start-up (a few wall seconds) costs as much sim time.
    argv = ['--robots', '2', '--actions', '75', '--time-scale', '1', '--fault', 'crash:r1@3+2']
    done = _run('spawn', argv, tmp_path)
    assert done.returncode in (0, 1), done.stderr  # the mission goes on without r1
    assert 'stopped by budget after 25.0 s sim' in done.stdout
    starts = 'OA-Bug gas_sound: robot {} of 2'
    assert (tmp_path / 'r0.log').read_text().count(starts.format(0)) == 1
    assert (tmp_path / 'r1.log').read_text().count(starts.format(1)) == 2  # started again
    outcome = _outcome(tmp_path)
    times = np.asarray(outcome['trajectory_times_s'])
    paths = np.asarray(outcome['trajectories']).reshape(len(times), 2, 3)[..., :2]
    # Killed at 3 s: r1 stops within the bridge's cmd_vel timeout and stays down ...
    assert path_length_m(times, paths[:, 1], 0.0, 3.0) > 0.5
    assert path_length_m(times, paths[:, 1], 4.0, 5.0) == 0.0
    # ... while r0 drives on; from the restart at 5 s the new node drives r1 again.
    assert path_length_m(times, paths[:, 0], 3.0, 5.0) > 0.3
    moving_s = first_move_s(times, paths[:, 1], 5.0)
    assert moving_s < 20.0, 'the restarted node never drove its robot'
    assert path_length_m(times, paths[:, 1], moving_s, 25.0) > 1.0
