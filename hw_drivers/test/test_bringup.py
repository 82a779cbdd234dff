"""robot_bringup: what it starts, in which order, and how it stops."""

import io
import signal
import sys
from pathlib import Path

import pytest
import yaml
from hw_drivers.parameters import NODE_SPECS
from hw_drivers.robot_bringup import cli
from hw_drivers.robot_bringup.cli import (
    BringupOptions,
    ChildSpec,
    Supervisor,
    build_plan,
    driver_parameters,
)


def test_pump_starts_first_and_oabug_last_after_the_locator():
    plan = build_plan(BringupOptions(robot='r3', locator_command='locator -s 127.0.0.1:8080'))
    names = [spec.name for spec in plan]
    assert names[0] == 'pump_node'
    assert names[-1] == 'oabug'
    assert names.index('aoa_receiver_node') < names.index('aoa_locator')


def test_every_child_runs_in_the_robot_namespace_with_the_simulator_frames():
    plan = build_plan(BringupOptions(robot='r3', own_tag_id='C3', launcher='ros2'))
    commands = {spec.name: ' '.join(spec.command) for spec in plan}
    assert all('__ns:=/r3' in command for command in commands.values())
    assert commands['rplidar_node'].startswith('ros2 run hw_drivers rplidar_node')
    assert 'frame_id:=r3/laser' in commands['rplidar_node']
    assert 'frame_id:=r3/imu_link' in commands['mpu6050_node']
    assert 'own_tag_id:=C3' in commands['aoa_receiver_node']
    assert 'own_tag_id:=C3' in commands['oabug']


def test_fake_mode_switches_every_device_driver_to_its_simulated_device():
    params = driver_parameters('r0', fake=True)
    assert all(params[name]['fake_device'] for name in ('pump_node', 'rplidar_node'))
    assert 'fake_device' not in params['aoa_receiver_node']  # it has no device to fake


def test_dry_run_prints_the_commands(capsys):
    assert cli.run(BringupOptions(launcher='python'), dry_run=True) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 7
    assert lines[0].split()[1:3] == ['-m', 'hw_drivers.pump_node']


def test_a_dying_child_stops_the_others_and_fails_the_bringup(tmp_path):
    marker = tmp_path / 'stopped'
    sleeper = (
        'import signal, sys, time\n'
        f'signal.signal(signal.SIGTERM, lambda *a: (open({str(marker)!r}, "w").close(), '
        'sys.exit(0)))\n'
        'time.sleep(30)\n'
    )
    plan = [
        ChildSpec('long_running', (sys.executable, '-c', sleeper), settle_s=0.5),
        ChildSpec('crashing', (sys.executable, '-c', 'raise SystemExit(4)')),
    ]
    handler_before = signal.getsignal(signal.SIGINT)
    out = io.StringIO()
    assert Supervisor(plan, grace_s=5.0, out=out).run() == cli.EXIT_CHILD_FAILED
    assert marker.exists()  # the survivor got SIGTERM and shut down cleanly
    assert signal.getsignal(signal.SIGINT) is handler_before
    assert 'crashing exited with status 4; stopping the other 1 process(es)' in out.getvalue()


def test_example_parameter_file_names_real_parameters():
    path = Path(__file__).resolve().parents[1] / 'bringup' / 'r0.params.example.yaml'
    document = yaml.safe_load(path.read_text())
    for key, section in document.items():
        node = key.removeprefix('/**/')
        spec = NODE_SPECS[node]
        for name, value in section['ros__parameters'].items():
            spec.check(name, value, strict=True)


@pytest.mark.slow
def test_the_locator_is_respawned_alone(tmp_path):
    runs = tmp_path / 'runs'
    runs.mkdir()
    locator = f'import pathlib, uuid; (pathlib.Path({str(runs)!r}) / uuid.uuid4().hex).touch()'
    plan = [
        ChildSpec('aoa_locator', (sys.executable, '-c', locator), respawn=True),
        ChildSpec('crashing_later', (sys.executable, '-c', 'import time; time.sleep(1)')),
    ]
    supervisor = Supervisor(plan, grace_s=2.0, respawn_delay_s=0.1, out=io.StringIO())
    assert supervisor.run() == cli.EXIT_CHILD_FAILED
    assert len(list(runs.iterdir())) >= 2


def test_numeric_looking_strings_are_quoted_so_ros_keeps_them_strings():
    plan = build_plan(BringupOptions(robot='r0', own_tag_id='42', launcher='ros2'))
    command = next(spec.command for spec in plan if spec.name == 'aoa_receiver_node')
    assert "own_tag_id:='42'" in command
