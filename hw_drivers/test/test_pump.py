"""Pump safety: controller limits, fail-safe line, node behaviour, signals and exits."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest
from hw_drivers.errors import ConfigurationError, DeviceUnavailableError, FatalDeviceError
from hw_drivers.fakes.gpio import FakePumpOutput
from hw_drivers.pump_control import PumpController, PumpLimits
from hw_drivers.pump_node import PumpNode
from hw_drivers.pump_output import GpiodPumpOutput, SafePumpLine, parse_line_id
from swarm_runtime.ros import (
    Node,
    Parameter,
    SingleThreadedExecutor,
    message_module,
    rclpy,
    using_real_rclpy,
)
from swarm_runtime.simulation import spin_until, wall_time_s

std_msgs = message_module('std_msgs')
diagnostic_msgs = message_module('diagnostic_msgs')


def _run(controller, commands, until_s, step_s=0.01):
    """Feed commands {time: level} and tick every step; return the output transitions."""
    transitions = []
    last = False
    t = 0.0
    pending = dict(commands)
    while t <= until_s + 1e-9:
        for when in [w for w in pending if w <= t + 1e-9]:
            controller.command(pending.pop(when), t)
        out = controller.update(t)
        if out != last:
            transitions.append((round(t, 3), out))
            last = out
        t += step_s
    return transitions


def _heartbeat(level_at, until_s, period_s=0.1):
    """A controller republishing level_at(t) every period."""
    return {round(k * period_s, 3): level_at(k * period_s) for k in range(int(until_s / period_s))}


def test_commanded_pulse_passes_through():
    controller = PumpController(PumpLimits(max_on_s=1.0, min_off_s=1.0))
    commands = _heartbeat(lambda t: 1.0 <= t < 1.5, 3.0)
    assert _run(controller, commands, 3.0) == [(1.0, True), (1.5, False)]


def test_max_on_time_cuts_a_stuck_on_command_and_does_not_refire():
    controller = PumpController(PumpLimits(max_on_s=0.5, min_off_s=0.2))
    commands = _heartbeat(lambda t: t >= 1.0, 4.0)
    assert _run(controller, commands, 4.0) == [(1.0, True), (1.5, False)]
    assert controller.forced_stops == 1


def test_a_new_pulse_after_an_off_command_is_allowed_again():
    controller = PumpController(PumpLimits(max_on_s=0.5, min_off_s=0.2))
    commands = _heartbeat(lambda t: t < 1.0 or t >= 1.3, 3.0)
    assert _run(controller, commands, 3.0) == [(0.0, True), (0.5, False), (1.3, True), (1.8, False)]


def test_min_off_time_delays_the_next_pulse():
    controller = PumpController(PumpLimits(max_on_s=1.0, min_off_s=1.0))
    commands = _heartbeat(lambda t: t < 0.3 or 0.5 <= t < 2.0, 3.0)
    # Off at 0.3; the request at 0.5 has to wait until 1.3.
    assert _run(controller, commands, 3.0) == [(0.0, True), (0.3, False), (1.3, True), (2.0, False)]


def test_stale_commands_turn_the_pump_off():
    controller = PumpController(PumpLimits(max_on_s=5.0, command_timeout_s=0.5))
    commands = {0.0: True}  # the controller dies after one "on"
    transitions = _run(controller, commands, 2.0)
    assert [level for _, level in transitions] == [True, False]
    assert transitions[1][0] == pytest.approx(0.5, abs=0.011)
    assert controller.stale_stops == 1


def test_no_command_at_all_keeps_the_pump_off():
    assert _run(PumpController(), {}, 2.0) == []


@pytest.mark.parametrize(
    'kwargs', [{'max_on_s': 0.0}, {'min_off_s': -1.0}, {'command_timeout_s': 0}]
)
def test_impossible_limits_are_refused(kwargs):
    with pytest.raises(ConfigurationError):
        PumpLimits(**kwargs)


def test_safe_line_off_never_raises_and_counts_failures():
    output = FakePumpOutput()
    line = SafePumpLine(output)
    line.set(True)
    output.fail_on_set = False
    line.off()
    assert line.off_failures == 1
    line.close()
    assert line.closed


def test_line_ids_parse_as_offsets_or_names():
    assert parse_line_id('17') == 17
    assert parse_line_id(' GPIO17 ') == 'GPIO17'


def test_a_missing_gpio_chip_is_a_recoverable_error():
    with pytest.raises(DeviceUnavailableError, match='gpiochip99'):
        GpiodPumpOutput('/dev/gpiochip99', 17)


@pytest.fixture
def pump_setup():
    rclpy.init()
    output = FakePumpOutput(lambda: wall_time_s())
    node = PumpNode(
        output=output,
        parameter_overrides=[Parameter('max_on_s', value=0.5), Parameter('min_off_s', value=0.5)],
    )
    controller = Node('controller')
    pub = controller.create_publisher(std_msgs.Bool, 'pump', 10)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    executor.add_node(controller)
    yield node, output, pub, controller, executor
    node.destroy_node()
    controller.destroy_node()
    rclpy.try_shutdown()


def _publish_for(executor, controller, pub, level, duration_s, period_s=0.1):
    """Republish a level every period for a duration (a controller's heartbeat)."""
    start = wall_time_s()
    timer = controller.create_timer(period_s, lambda: pub.publish(std_msgs.Bool(data=level)))
    pub.publish(std_msgs.Bool(data=level))
    spin_until(executor, lambda: wall_time_s() - start >= duration_s, max_wall_time_s=duration_s)
    controller.destroy_timer(timer)


def test_node_follows_commands_within_limits_and_fails_safe_when_they_stop(pump_setup):
    _node, output, pub, controller, executor = pump_setup
    _publish_for(executor, controller, pub, True, 0.3)
    assert output.level is True
    _publish_for(executor, controller, pub, True, 0.5)
    assert output.level is False  # max_on_s = 0.5 cut the pulse
    _publish_for(executor, controller, pub, False, 0.6)
    _publish_for(executor, controller, pub, True, 0.2)
    assert output.level is True
    # The controller goes silent: off within command_timeout_s (0.5 s) + one tick.
    start = wall_time_s()
    spin_until(executor, lambda: not output.level, max_wall_time_s=2.0)
    assert wall_time_s() - start <= 0.5 + 0.03
    on_times = [t for t, level in output.transitions if level]
    off_times = [t for t, level in output.transitions if not level]
    assert all(off - on <= 0.5 + 0.03 for on, off in zip(on_times, off_times, strict=False))


def test_destroying_the_node_turns_the_pump_off(pump_setup):
    node, output, pub, controller, executor = pump_setup
    _publish_for(executor, controller, pub, True, 0.2)
    assert output.level is True
    node.shutdown_pump()
    assert output.level is False
    assert output.closed


def test_exception_in_a_callback_leaves_the_pump_off(pump_setup):
    node, output, pub, controller, executor = pump_setup
    _publish_for(executor, controller, pub, True, 0.2)
    assert output.level is True

    def broken(now_s):
        raise RuntimeError('controller bug')

    node._controller.update = broken
    with pytest.raises(RuntimeError, match='controller bug'):
        spin_until(executor, lambda: False, max_wall_time_s=0.1)
    assert output.level is False


def test_guard_thread_cuts_a_pulse_when_the_executor_stalls():
    output = FakePumpOutput()
    rclpy.init()
    try:
        node = PumpNode(output=output, parameter_overrides=[Parameter('max_on_s', value=0.05)])
        node._controller.command(True, 0.0)
        node._apply(lambda now_s: True)  # on, guard armed; then nothing runs the executor
        assert output.level is True
        deadline = 100
        while output.level and deadline:
            time.sleep(0.01)
            deadline -= 1
        assert output.level is False
        assert node.guard_trips == 1
        node._apply(lambda now_s: True)  # a stale "on" decision cannot re-fire it
        assert output.level is False
        node.destroy_node()
    finally:
        rclpy.try_shutdown()


class FlakyLine:
    """Opens a FakePumpOutput only after ``failures`` failed attempts; records them."""

    def __init__(self, failures, error=None):
        self.failures = failures
        self.error = error or DeviceUnavailableError('no GPIO chip /dev/gpiochip0')
        self.attempts = []
        self.outputs = []

    def __call__(self):
        self.attempts.append(wall_time_s())
        if len(self.attempts) <= self.failures:
            raise self.error
        self.outputs.append(FakePumpOutput(lambda: wall_time_s()))
        return self.outputs[-1]


@pytest.fixture
def flaky_pump():
    rclpy.init()
    nodes = []
    executor = SingleThreadedExecutor()
    controller = Node('controller')
    executor.add_node(controller)
    pub = controller.create_publisher(std_msgs.Bool, 'pump', 10)
    diagnostics = []
    controller.create_subscription(
        diagnostic_msgs.DiagnosticArray, '/diagnostics', diagnostics.append, 10
    )

    def make(opener):
        node = PumpNode(open_output=opener, retry_clock=wall_time_s)
        nodes.append(node)
        executor.add_node(node)
        return node

    yield make, executor, controller, pub, diagnostics
    for node in nodes:
        node.destroy_node()
    controller.destroy_node()
    rclpy.try_shutdown()


def test_a_missing_gpio_backs_off_keeps_the_pump_off_and_recovers(flaky_pump):
    make, executor, controller, pub, diagnostics = flaky_pump
    opener = FlakyLine(failures=3)
    node = make(opener)
    # Commands while the line is missing change nothing (and no exception).
    _publish_for(executor, controller, pub, True, 2.5)
    assert not node.line_available
    status = diagnostics[-1].status[0]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    assert status.message.startswith('pump line unavailable (error): no GPIO chip')
    assert 'retrying in' in status.message
    spin_until(executor, lambda: node.line_available, max_wall_time_s=10.0)
    # Back-off 1, 2, 4 s between the four attempts (checked at the 1 Hz diagnostics tick).
    gaps = [b - a for a, b in zip(opener.attempts, opener.attempts[1:], strict=False)]
    assert [round(g) for g in gaps] == [1, 2, 4]
    output = opener.outputs[0]
    assert output.transitions == []  # came up off, stayed off without a fresh "on"
    _publish_for(executor, controller, pub, True, 0.3)
    assert output.level is True
    spin_until(executor, lambda: False, max_wall_time_s=1.2)
    assert output.level is False  # stale commands
    assert diagnostics[-1].status[0].level == diagnostic_msgs.DiagnosticStatus.OK


def test_a_line_that_fails_in_use_goes_off_is_released_and_is_requested_again(flaky_pump):
    make, executor, controller, pub, _ = flaky_pump
    opener = FlakyLine(failures=0)
    node = make(opener)
    _publish_for(executor, controller, pub, True, 0.2)
    first, line = opener.outputs[0], node.line
    assert first.level is True
    first.fail_on_set = False  # the line can no longer be driven (e.g. chip gone)
    _publish_for(executor, controller, pub, False, 0.1)
    assert not node.line_available
    assert node.line_failures == 1
    assert line.closed  # released (its off failed and was counted, nothing raised)
    assert line.off_failures >= 1
    spin_until(executor, lambda: node.line_available, max_wall_time_s=3.0)
    assert len(opener.outputs) == 2
    assert opener.outputs[1].level is False


def test_a_busy_line_is_retried_slowly(flaky_pump):
    make, executor, _, _, diagnostics = flaky_pump
    opener = FlakyLine(failures=100, error=FatalDeviceError('cannot request line 17: busy'))
    make(opener)
    spin_until(executor, lambda: False, max_wall_time_s=35.0)
    assert len(opener.attempts) == 2  # at start, then after the 30 s fatal back-off
    assert 'fatal error' in diagnostics[-1].status[0].message


_CHILD = textwrap.dedent(
    """
    import sys
    from hw_drivers import pump_node
    from hw_drivers.fakes.gpio import FakePumpOutput

    class Reporting(FakePumpOutput):
        def set(self, on):
            super().set(on)
            print('LEVEL', int(on), flush=True)

    class OnAtStart(pump_node.PumpNode):
        # The pump_node executable with a line that reports its level, commanded on.
        def __init__(self, **kwargs):
            super().__init__(output=Reporting(), **kwargs)
            self._controller.command(True, self._now_s())
            self._apply(self._controller.update)
            print('READY', flush=True)

    mode = sys.argv[1]
    if mode == 'signal':
        pump_node.PumpNode = OnAtStart
        # Long limits: only the signal may turn the pump off.
        limits = ['-p', 'max_on_s:=60.0', '-p', 'command_timeout_s:=60.0']
        status = pump_node.main(['--ros-args', *limits])
        print('EXIT', status, flush=True)
    elif mode == 'atexit':
        from swarm_runtime.ros import rclpy
        rclpy.init()
        node = OnAtStart()
        sys.exit(3)
    """
)


def _child(mode, tmp_path):
    script = tmp_path / 'pump_child.py'
    script.write_text(_CHILD)
    runtime = 'rclpy' if using_real_rclpy() else 'builtin'
    env = {**os.environ, 'PYTHONUNBUFFERED': '1', 'SWARM_RUNTIME': runtime}
    return subprocess.Popen(
        [sys.executable, str(script), mode],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


@pytest.mark.slow
@pytest.mark.parametrize('signum', [signal.SIGTERM, signal.SIGINT])
def test_signals_turn_the_pump_off_before_the_process_exits(tmp_path, signum):
    child = _child('signal', tmp_path)
    lines = []
    for line in child.stdout:
        lines.append(line.strip())
        if line.startswith('READY'):
            time.sleep(0.3)  # spinning
            child.send_signal(signum)
    stderr = child.stderr.read()
    assert child.wait(30) == 0, stderr
    assert 'Traceback' not in stderr, stderr
    assert lines[:2] == ['LEVEL 1', 'READY']
    assert lines[-1] == 'EXIT 0'
    assert lines[2:-1], 'the pump went off'
    assert set(lines[2:-1]) == {'LEVEL 0'}, 'and never on again'


@pytest.mark.slow
def test_atexit_turns_the_pump_off_on_an_unplanned_exit(tmp_path):
    child = _child('atexit', tmp_path)
    out, _ = child.communicate(timeout=30)
    assert child.returncode == 3
    lines = out.splitlines()
    assert lines[:2] == ['LEVEL 1', 'READY']
    assert lines[2:]
    assert set(lines[2:]) == {'LEVEL 0'}
