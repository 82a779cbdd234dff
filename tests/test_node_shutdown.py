"""Every node executable stops cleanly on SIGINT and SIGTERM: status 0, no traceback.

Each node runs as a child process from its console script on real rclpy, publishing fast
(so that a timer callback is running when the signal arrives: the race in which rclpy's
signal handler shuts the context down under a callback that then fails to publish). Once its
first output has arrived, it gets SIGINT or SIGTERM after a random delay, 20 times per node.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from swarm_runtime.ros import message_module, qos_profile_sensor_data, using_real_rclpy
from swarm_runtime.testing import NodeTestBed

pytestmark = pytest.mark.skipif(
    not using_real_rclpy(),
    reason="rclpy's signal handlers (the built-in runtime installs none: docs/runtime.md)",
)

STOPS_PER_NODE = 20

REPO = Path(__file__).resolve().parents[1]
# A site shipped with the simulator package, wherever that package lives in the workspace.
SITE_FILES = sorted(REPO.glob('*/config/sites/small_seed1.yaml'))

geometry = message_module('geometry_msgs')
rosgraph = message_module('rosgraph_msgs')

# Console script, ROS arguments (a fast publisher), the output that shows it is spinning
# (relative: in the child's namespace), and how many children run at once (one bridge at a
# time: every bridge publishes the same /clock).
NODES = {
    'oabug': (['-p', 'control_rate_hz:=200.0'], 'cmd_vel', geometry.Twist, 2),
    'bayes_swarm_node': (['-p', 'control_rate_hz:=200.0'], 'cmd_vel', geometry.Twist, 2),
    'msc_pf_node': (['-p', 'drive_rate_hz:=200.0'], 'cmd_vel', geometry.Twist, 2),
    'sim_bridge': (
        ['-p', f'site_file:={SITE_FILES[0] if SITE_FILES else ""}', '-p', 'robot_count:=2'],
        '/clock',
        rosgraph.Clock,
        1,
    ),
}


def console_script(name: str) -> Path:
    script = Path(sys.executable).parent / name
    if not script.exists():
        pytest.skip(f'console script {name} is not installed next to {sys.executable}')
    return script


def start(script: Path, namespace: str, ros_args: list[str]) -> subprocess.Popen[str]:
    command = [str(script), '--ros-args', '-r', f'__ns:={namespace}', *ros_args]
    return subprocess.Popen(
        command,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, 'PYTHONUNBUFFERED': '1'},
    )


def stop_children(children: list[tuple[subprocess.Popen[str], signal.Signals]]) -> list[str]:
    """Wait for signalled children; describe each that failed, hung or printed a traceback."""
    failures = []
    for child, signum in children:
        try:
            _, stderr = child.communicate(timeout=30.0)
        except subprocess.TimeoutExpired:
            child.kill()
            _, stderr = child.communicate()
            failures.append(f'{signum.name}: did not exit within 30 s\n{stderr}')
            continue
        if child.returncode != 0 or 'Traceback' in stderr:
            failures.append(f'{signum.name}: exit status {child.returncode}\n{stderr}')
    return failures


@pytest.mark.parametrize('executable', sorted(NODES))
def test_a_signal_stops_the_node_with_status_0_and_no_traceback(executable: str) -> None:
    script = console_script(executable)
    ros_args, output, msg_type, at_once = NODES[executable]
    qos = qos_profile_sensor_data if output == '/clock' else 10
    rng = random.Random(executable)
    signals = [signal.SIGINT, signal.SIGTERM] * (STOPS_PER_NODE // 2)
    failures = []
    with NodeTestBed() as bed:
        for first in range(0, STOPS_PER_NODE, at_once):
            batch = []
            for stop in range(first, min(first + at_once, STOPS_PER_NODE)):
                namespace = f'/r{900 + stop}'  # msc_pf takes its robot id from it
                topic = output if output.startswith('/') else f'{namespace}/{output}'
                received = bed.probe.collect(topic, msg_type, qos, expect_publishers=0)
                batch.append((start(script, namespace, ros_args), signals[stop], received))
            for child, signum, received in batch:
                up = bed.spin_until(lambda r=received: bool(r), timeout_s=60.0)
                assert up, f'{executable} published nothing on {output} within 60 s'
                time.sleep(rng.uniform(0.0, 0.3))
                child.send_signal(signum)
            failures += stop_children([(child, signum) for child, signum, _ in batch])
    assert not failures, f'{len(failures)} of {STOPS_PER_NODE} stops failed:\n' + '\n'.join(
        failures
    )
