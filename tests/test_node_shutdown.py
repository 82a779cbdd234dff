"""Node executables stop cleanly on SIGINT and SIGTERM: status 0, no traceback, pump off.

Each node runs as a child process on real rclpy, publishing fast (so that a timer callback
is running when the signal arrives: the race in which rclpy's signal handler shuts the
context down under a callback that then fails to publish). Once its first output has
arrived over DDS, it gets SIGINT or SIGTERM after a random delay: 24 stops in all, four per
executable, half of each signal. The pump driver is commanded on first and must have
switched its (fake) line off by the time it exits.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest
from swarm_runtime.ros import message_module, qos_profile_sensor_data, using_real_rclpy
from swarm_runtime.testing import NodeTestBed

pytestmark = pytest.mark.skipif(
    not using_real_rclpy(),
    reason="rclpy's signal handlers (the built-in runtime installs none: docs/runtime.md)",
)

STOPS_PER_EXECUTABLE = 4
START_TIMEOUT_S = 90.0

REPO = Path(__file__).resolve().parents[1]
SITE_FILE = REPO / 'swarm_sim' / 'config' / 'sites' / 'small_seed1.yaml'

geometry = message_module('geometry_msgs')
rosgraph = message_module('rosgraph_msgs')
std = message_module('std_msgs')

# The pump driver with a fake line that prints every level it is set to.
PUMP_CHILD = textwrap.dedent(
    """
    import sys
    from hw_drivers.fakes.gpio import FakePumpOutput

    plain_set = FakePumpOutput.set

    def reporting_set(self, on):
        plain_set(self, on)
        print('LEVEL', int(on), flush=True)

    FakePumpOutput.set = reporting_set
    from hw_drivers import pump_node

    sys.exit(pump_node.main(sys.argv[1:]))
    """
)


@dataclass(frozen=True)
class Executable:
    """How to start one node executable and what shows it is up."""

    command: tuple[str, ...]
    ros_args: tuple[str, ...]
    output: str  # relative: in the child's namespace
    output_type: type
    at_once: int  # children at a time (one bridge at a time: each publishes /clock)
    command_topic: str = ''  # a Bool played to the child (the pump command)


def _script(name: str) -> tuple[str, ...]:
    return (str(Path(sys.executable).parent / name),)


EXECUTABLES = {
    'oabug': Executable(
        _script('oabug'), ('-p', 'control_rate_hz:=200.0'), 'cmd_vel', geometry.Twist, 2
    ),
    'sgba': Executable(
        _script('sgba'), ('-p', 'control_rate_hz:=200.0'), 'cmd_vel', geometry.Twist, 2
    ),
    'bayes_swarm_node': Executable(
        _script('bayes_swarm_node'), ('-p', 'control_rate_hz:=200.0'), 'cmd_vel', geometry.Twist, 2
    ),
    'msc_pf_node': Executable(
        _script('msc_pf_node'), ('-p', 'drive_rate_hz:=200.0'), 'cmd_vel', geometry.Twist, 2
    ),
    'sim_bridge': Executable(
        _script('sim_bridge'),
        ('-p', f'site_file:={SITE_FILE}', '-p', 'robot_count:=2'),
        '/clock',
        rosgraph.Clock,
        1,
    ),
    'pump_node': Executable(
        (sys.executable, '-c', PUMP_CHILD),
        ('-p', 'fake_device:=true', '-p', 'control_rate_hz:=200.0'),
        'pump/state',
        std.Bool,
        2,
        command_topic='pump',
    ),
}


def _start(executable: Executable, namespace: str) -> subprocess.Popen[str]:
    command = [*executable.command, '--ros-args', '-r', f'__ns:={namespace}']
    return subprocess.Popen(
        [*command, *executable.ros_args],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # faulthandler dumps every thread's stack on SIGABRT: what a hung stop waits for.
        env={**os.environ, 'PYTHONUNBUFFERED': '1', 'PYTHONFAULTHANDLER': '1'},
    )


def _failure(executable: Executable, child: subprocess.Popen[str], signum: signal.Signals) -> str:
    """Wait for a signalled child; '' if it stopped cleanly, else what went wrong."""
    try:
        stdout, stderr = child.communicate(timeout=30.0)
    except subprocess.TimeoutExpired:
        child.send_signal(signal.SIGABRT)  # the stacks of its threads, then the end
        try:
            stdout, stderr = child.communicate(timeout=10.0)
        except subprocess.TimeoutExpired:
            child.kill()
            stdout, stderr = child.communicate()
        return f'{signum.name}: did not exit within 30 s\n{stderr}'
    if child.returncode != 0 or 'Traceback' in stderr or 'Exception ignored' in stderr:
        return f'{signum.name}: exit status {child.returncode}\n{stderr}'
    if executable.command_topic:
        levels = [line for line in stdout.splitlines() if line.startswith('LEVEL')]
        if 'LEVEL 1' not in levels or levels[-1] != 'LEVEL 0':
            return f'{signum.name}: the pump line was left on ({levels})'
    return ''


@pytest.mark.slow
@pytest.mark.parametrize('name', sorted(EXECUTABLES))
def test_a_signal_stops_the_node_with_status_0_and_no_traceback(name: str) -> None:
    executable = EXECUTABLES[name]
    if not Path(executable.command[0]).exists():
        pytest.skip(f'{executable.command[0]} is not installed')
    if not SITE_FILE.is_file():
        pytest.fail(f'missing site file {SITE_FILE}')
    rng = random.Random(name)
    signals = [signal.SIGINT, signal.SIGTERM] * (STOPS_PER_EXECUTABLE // 2)
    qos = qos_profile_sensor_data if executable.output == '/clock' else 10
    failures = []
    with NodeTestBed() as bed:
        for first in range(0, STOPS_PER_EXECUTABLE, executable.at_once):
            batch = []
            for stop in range(first, min(first + executable.at_once, STOPS_PER_EXECUTABLE)):
                namespace = f'/r{900 + stop}'  # msc_pf takes its robot id from it
                topic = executable.output
                if not topic.startswith('/'):
                    topic = f'{namespace}/{topic}'
                received = bed.probe.collect(
                    topic, executable.output_type, qos, expect_publishers=0
                )
                if executable.command_topic:
                    player = bed.probe.player(
                        f'{namespace}/{executable.command_topic}', std.Bool, expect_subscriptions=0
                    )
                    player.play(std.Bool(data=True))
                batch.append((_start(executable, namespace), signals[stop], received))
            for child, signum, received in batch:

                def up(received: list = received) -> bool:
                    if executable.command_topic:  # the pump has been switched on
                        return any(msg.data for msg in received)
                    return bool(received)

                assert bed.spin_until(up, timeout_s=START_TIMEOUT_S), (
                    f'{name} published nothing on {executable.output} within {START_TIMEOUT_S} s'
                )
                bed.spin_for(rng.uniform(0.0, 0.3))
                child.send_signal(signum)
            failures += [_failure(executable, child, signum) for child, signum, _ in batch]
    failures = [failure for failure in failures if failure]
    assert not failures, f'{len(failures)} of {STOPS_PER_EXECUTABLE} stops failed:\n' + '\n'.join(
        failures
    )
