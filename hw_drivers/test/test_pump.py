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
    Parameter,
    message_module,
    rclpy,
    using_real_rclpy,
)
from swarm_runtime.testing import NodeTestBed

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


# How late a timed output may be: one control tick on the built-in runtime's virtual clock;
# on real DDS a loaded 2-core host also delays the executor's timers and deliveries.
LATE_S = 0.2 if using_real_rclpy() else 0.03


@pytest.fixture
def pump_bed():
    with NodeTestBed() as bed:
        output = FakePumpOutput(bed.now_s)
        node = bed.add_node(
            PumpNode,
            output=output,
            parameter_overrides=[
                Parameter('max_on_s', value=0.5),
                Parameter('min_off_s', value=0.5),
            ],
        )
        command = bed.probe.player('/pump', std_msgs.Bool, period_s=0.1)
        bed.wait_for_graph()
        yield bed, node, output, command


def _command_for(bed, command, level, duration_s):
    """Republish a level every 0.1 s for a duration (a controller's heartbeat), then stop."""
    command.play(std_msgs.Bool(data=level))
    bed.spin_for(duration_s)
    command.play(None)


def test_node_follows_commands_within_limits_and_fails_safe_when_they_stop(pump_bed):
    bed, _node, output, command = pump_bed
    _command_for(bed, command, True, 0.3)
    assert bed.spin_until(lambda: output.level is True, timeout_s=LATE_S)
    _command_for(bed, command, True, 0.5 + LATE_S)
    assert output.level is False  # max_on_s = 0.5 cut the pulse
    _command_for(bed, command, False, 0.6)
    _command_for(bed, command, True, 0.2)
    assert bed.spin_until(lambda: output.level is True, timeout_s=LATE_S)
    # The controller goes silent: off within command_timeout_s (0.5 s) of the last command.
    start = bed.now_s()
    assert bed.spin_until(lambda: not output.level, timeout_s=2.0)
    assert bed.now_s() - start <= 0.5 + LATE_S
    on_times = [t for t, level in output.transitions if level]
    off_times = [t for t, level in output.transitions if not level]
    assert len(on_times) == len(off_times) == 2
    assert all(off - on <= 0.5 + LATE_S for on, off in zip(on_times, off_times, strict=True))


def test_destroying_the_node_turns_the_pump_off(pump_bed):
    bed, node, output, command = pump_bed
    command.play(std_msgs.Bool(data=True))
    assert bed.spin_until(lambda: output.level is True, timeout_s=2.0)
    node.shutdown_pump()
    assert output.level is False
    assert output.closed


def test_exception_in_a_callback_leaves_the_pump_off(pump_bed):
    bed, node, output, command = pump_bed
    command.play(std_msgs.Bool(data=True))
    assert bed.spin_until(lambda: output.level is True, timeout_s=2.0)

    def broken(now_s):
        raise RuntimeError('controller bug')

    node._controller.update = broken
    with pytest.raises(RuntimeError, match='controller bug'):
        bed.spin_for(0.5)
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

    def __init__(self, clock, failures, error=None):
        self.clock = clock
        self.failures = failures
        self.error = error or DeviceUnavailableError('no GPIO chip /dev/gpiochip0')
        self.attempts = []
        self.outputs = []

    def __call__(self):
        self.attempts.append(self.clock())
        if len(self.attempts) <= self.failures:
            raise self.error
        self.outputs.append(FakePumpOutput(self.clock))
        return self.outputs[-1]


@pytest.fixture
def flaky_pump():
    with NodeTestBed() as bed:
        command = bed.probe.player('/pump', std_msgs.Bool, period_s=0.1)
        diagnostics = bed.probe.collect('/diagnostics', diagnostic_msgs.DiagnosticArray, 10)

        def make(failures, error=None):
            opener = FlakyLine(bed.wall_time_s, failures, error)
            node = bed.add_node(PumpNode, open_output=opener, retry_clock=bed.wall_time_s)
            bed.wait_for_graph()
            return node, opener

        yield bed, make, command, diagnostics


def test_a_missing_gpio_backs_off_keeps_the_pump_off_and_recovers(flaky_pump):
    bed, make, command, diagnostics = flaky_pump
    node, opener = make(failures=3)
    # Commands while the line is missing change nothing (and no exception).
    _command_for(bed, command, True, 2.5)
    assert not node.line_available
    assert diagnostics
    status = diagnostics[-1].status[0]
    assert status.level == diagnostic_msgs.DiagnosticStatus.ERROR
    assert status.message.startswith('pump line unavailable (error): no GPIO chip')
    assert 'retrying in' in status.message
    assert bed.spin_until(lambda: node.line_available, timeout_s=10.0)
    # Back-off 1, 2, 4 s between the four attempts, checked at the 1 Hz diagnostics tick: on
    # the virtual clock exactly on it; in real time a late tick defers an attempt to the next.
    gaps = [b - a for a, b in zip(opener.attempts, opener.attempts[1:], strict=False)]
    slack_s = 1.0 + LATE_S if using_real_rclpy() else LATE_S
    assert len(gaps) == 3
    for gap, backoff in zip(gaps, [1.0, 2.0, 4.0], strict=True):
        assert backoff - LATE_S <= gap <= backoff + slack_s
    output = opener.outputs[0]
    assert output.transitions == []  # came up off, stayed off without a fresh "on"
    _command_for(bed, command, True, 0.3)
    assert bed.spin_until(lambda: output.level is True, timeout_s=LATE_S)
    bed.spin_for(1.2)
    assert output.level is False  # stale commands
    assert bed.spin_until(
        lambda: diagnostics[-1].status[0].level == diagnostic_msgs.DiagnosticStatus.OK,
        timeout_s=2.0,
    )


def test_a_line_that_fails_in_use_goes_off_is_released_and_is_requested_again(flaky_pump):
    bed, make, command, _ = flaky_pump
    node, opener = make(failures=0)
    _command_for(bed, command, True, 0.2)
    first, line = opener.outputs[0], node.line
    assert bed.spin_until(lambda: first.level is True, timeout_s=LATE_S)
    first.fail_on_set = False  # the line can no longer be driven (e.g. chip gone)
    _command_for(bed, command, False, 0.1)
    assert bed.spin_until(lambda: not node.line_available, timeout_s=LATE_S)
    assert node.line_failures == 1
    assert line.closed  # released (its off failed and was counted, nothing raised)
    assert line.off_failures >= 1
    assert bed.spin_until(lambda: node.line_available, timeout_s=3.0)
    assert len(opener.outputs) == 2
    assert opener.outputs[1].level is False


@pytest.mark.builtin_only(reason='virtual wall time: waits 35 s for the fatal back-off')
def test_a_busy_line_is_retried_slowly(flaky_pump):
    bed, make, _, diagnostics = flaky_pump
    _, opener = make(failures=100, error=FatalDeviceError('cannot request line 17: busy'))
    bed.spin_for(35.0)
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
