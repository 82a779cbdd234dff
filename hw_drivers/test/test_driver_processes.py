"""Driver and bringup processes as a user starts them: help, runtime check, logs, CPU, stopping.

Every test runs real processes. Where a test needs ROS 2 it runs on the real rclpy and is
skipped when rclpy is not installed; the same checks also run on the built-in runtime,
which the processes get only by asking for it (``SWARM_RUNTIME=builtin``). A "no ROS"
machine is simulated by an import hook that hides rclpy. DDS traffic stays on this machine
(``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, the domain id of the test process).

Whether a bringup leaves processes behind is checked by a token in the environment that
every descendant inherits: once the bringup has exited, no live process may carry it.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest
from hw_drivers.robot_bringup import cli

pytestmark = pytest.mark.runtime_independent(
    reason='every driver process is started with the runtime it asks for'
)

DRIVER_MODULES = {
    'rplidar_node': 'hw_drivers.rplidar_node',
    'gas_adc_node': 'hw_drivers.gas_node',
    'mpu6050_node': 'hw_drivers.mpu6050_node',
    'aoa_receiver_node': 'hw_drivers.aoa_receiver_node',
    'pump_node': 'hw_drivers.pump_node',
}
NEEDS_SWARM_MESSAGES = {'gas_adc_node', 'aoa_receiver_node'}
RCLPY_INSTALLED = importlib.util.find_spec('rclpy') is not None
needs_rclpy = pytest.mark.skipif(
    not RCLPY_INSTALLED,
    reason="rclpy is not installed (pip install 'ros-jazzy-rclpy[fastrtps]' or source Jazzy)",
)
TOKEN_VAR = 'HW_DRIVERS_TEST_TOKEN'

_HIDE_RCLPY = textwrap.dedent(
    """
    import sys

    class _NoRclpy:
        def find_spec(self, name, path=None, target=None):
            if name == 'rclpy' or name.startswith('rclpy.'):
                raise ModuleNotFoundError(f'No module named {name!r}', name=name)
            return None

    sys.meta_path.insert(0, _NoRclpy())
    """
)

_FAKE_ROS2 = textwrap.dedent(
    """
    # Behaves like `ros2 run`: starts the node as a child and waits for it; Ctrl-C is left to
    # the child (which gets it from the terminal), SIGTERM ends only this wrapper.
    import subprocess, sys
    MODULES = {modules!r}
    _, verb, package, executable, *args = sys.argv
    child = subprocess.Popen([sys.executable, '-m', MODULES[executable], *args])
    while child.returncode is None:
        try:
            child.communicate()
        except KeyboardInterrupt:
            pass
    sys.exit(child.returncode)
    """
)


def _env(tmp_path: Path, runtime: str, *, hide_rclpy: bool = False, **extra: str) -> dict:
    # ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE come from the root conftest.py.
    env = {**os.environ, TOKEN_VAR: uuid.uuid4().hex, **extra}
    env.pop('PYTHONUNBUFFERED', None)  # the drivers must line-buffer by themselves
    if runtime:
        env['SWARM_RUNTIME'] = runtime
    else:
        env.pop('SWARM_RUNTIME', None)
    if hide_rclpy:
        hook = tmp_path / 'hide_rclpy'
        hook.mkdir(exist_ok=True)
        (hook / 'sitecustomize.py').write_text(_HIDE_RCLPY)
        env['PYTHONPATH'] = os.pathsep.join(filter(None, [str(hook), env.get('PYTHONPATH')]))
    return env


@functools.cache
def _swarm_messages_on_rclpy() -> bool:
    """True when swarm_interfaces' generated messages import with the real rclpy."""
    if not RCLPY_INSTALLED:
        return False
    code = 'import swarm_interfaces.msg as m; m.GasReading; m.PeerBearingArray'
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, timeout=60)
    return result.returncode == 0


def _drivers_for(runtime: str) -> list[str]:
    if runtime == 'rclpy' and not _swarm_messages_on_rclpy():
        return [d for d in DRIVER_MODULES if d not in NEEDS_SWARM_MESSAGES]
    return list(DRIVER_MODULES)


class Output:
    """Collects a process's output lines in a thread, so reads never block the test."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.lines: list[tuple[float, str]] = []
        self._thread = threading.Thread(target=self._read, args=(process,), daemon=True)
        self._thread.start()

    def _read(self, process: subprocess.Popen) -> None:
        for line in process.stdout:
            self.lines.append((time.monotonic(), line.rstrip('\n')))

    def wait_for(self, text: str, timeout_s: float) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if any(text in line for _, line in self.lines):
                return True
            time.sleep(0.05)
        return False

    def text(self) -> str:
        self._thread.join(5.0)
        return '\n'.join(line for _, line in self.lines)


def _spawn(args: list[str], env: dict) -> tuple[subprocess.Popen, Output]:
    process = subprocess.Popen(
        args,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # a stray process of a failed test can be killed as a group
    )
    return process, Output(process)


def _processes_with_token(token: str) -> list[str]:
    """Live processes whose environment carries ``token`` (cmdline of each)."""
    found = []
    needle = f'{TOKEN_VAR}={token}'.encode()
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            if needle not in Path(f'/proc/{entry}/environ').read_bytes():
                continue
            stat = Path(f'/proc/{entry}/stat').read_text()
            cmdline = Path(f'/proc/{entry}/cmdline').read_bytes()
        except OSError:
            continue
        if stat[stat.rindex(')') + 2] not in 'ZX':
            found.append(cmdline.replace(b'\0', b' ').decode(errors='replace'))
    return found


def _kill_leftovers(token: str) -> None:
    needle = f'{TOKEN_VAR}={token}'.encode()
    for entry in os.listdir('/proc'):
        if entry.isdigit():
            try:
                if needle in Path(f'/proc/{entry}/environ').read_bytes():
                    os.kill(int(entry), signal.SIGKILL)
            except OSError:
                continue


def _cpu_s(pid: int) -> float:
    stat = Path(f'/proc/{pid}/stat').read_text()
    fields = stat[stat.rindex(')') + 2 :].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


# --- driver processes ----------------------------------------------------------------------


@pytest.mark.parametrize('driver', list(DRIVER_MODULES))
def test_help_prints_usage_and_exits_without_starting_ros(tmp_path, driver):
    env = _env(tmp_path, '', hide_rclpy=True)
    result = subprocess.run(
        [sys.executable, '-m', DRIVER_MODULES[driver], '--help'],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f'usage: {driver} [--help]')
    assert 'parameters (-p name:=value' in result.stdout
    assert result.stderr == ''  # no log line: no node was started


@pytest.mark.parametrize('driver', list(DRIVER_MODULES))
def test_without_ros_a_driver_refuses_the_builtin_runtime_in_one_line(tmp_path, driver):
    env = _env(tmp_path, '', hide_rclpy=True)
    result = subprocess.run(
        [sys.executable, '-m', DRIVER_MODULES[driver]],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    lines = result.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f'{driver}: ROS 2 (rclpy) is not importable')
    assert 'SWARM_RUNTIME=builtin' in lines[0]


def _log_is_line_buffered_and_sigterm_stops(tmp_path, runtime, driver):
    env = _env(tmp_path, runtime, hide_rclpy=runtime == 'builtin')
    process, output = _spawn([sys.executable, '-m', DRIVER_MODULES[driver]], env)
    try:
        # The first log line (the missing device) reaches the pipe while the driver runs.
        assert output.wait_for('[ERROR]', 30.0), output.text()
        assert process.poll() is None
        process.send_signal(signal.SIGTERM)
        assert process.wait(15.0) == 0
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    assert 'Traceback' not in output.text()


@pytest.mark.parametrize('driver', ['rplidar_node', 'mpu6050_node', 'pump_node'])
def test_builtin_logs_reach_a_pipe_at_once_and_sigterm_stops_cleanly(tmp_path, driver):
    _log_is_line_buffered_and_sigterm_stops(tmp_path, 'builtin', driver)


@needs_rclpy
@pytest.mark.parametrize('driver', ['rplidar_node', 'mpu6050_node', 'pump_node'])
def test_rclpy_logs_reach_a_pipe_at_once_and_sigterm_stops_cleanly(tmp_path, driver):
    _log_is_line_buffered_and_sigterm_stops(tmp_path, 'rclpy', driver)


def _idle_drivers(tmp_path, runtime: str) -> dict[str, tuple[float, list[str]]]:
    """Run every driver without its device for 10 s; CPU seconds and log lines of each."""
    env = _env(tmp_path, runtime, hide_rclpy=runtime == 'builtin')
    running = {}
    for driver in _drivers_for(runtime):
        args = [sys.executable, '-m', DRIVER_MODULES[driver]]
        if driver == 'aoa_receiver_node':
            args += ['--ros-args', '-p', 'listen_port:=0']
        running[driver] = _spawn(args, env)
    try:
        # Start-up (imports, DDS discovery) ends with each driver's first report of its
        # missing device; on a loaded machine that can take well over 5 s.
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and not all(out.lines for _, out in running.values()):
            time.sleep(0.2)
        time.sleep(1.0)
        start = {d: (_cpu_s(p.pid), len(out.lines)) for d, (p, out) in running.items()}
        time.sleep(10.0)
        result = {}
        for driver, (process, out) in running.items():
            assert process.poll() is None, out.text()
            cpu0, lines0 = start[driver]
            result[driver] = (_cpu_s(process.pid) - cpu0, [line for _, line in out.lines[lines0:]])
    finally:
        for process, _ in running.values():
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
        for process, _ in running.values():
            try:
                process.wait(15.0)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
    return result


def _check_idle(result):
    for driver, (cpu_s, lines) in result.items():
        # Budget 2 % of a core over 10 s; measured 0.2-1.4 % (bench_driver_idle.py).
        assert cpu_s < 0.2, f'{driver} used {cpu_s:.2f} CPU s in 10 s'
        # A missing device is logged once, then every 30 s: at most one line in 10 s.
        assert len(lines) <= 1, f'{driver} logged {lines}'


@pytest.mark.slow
@needs_rclpy
def test_drivers_without_devices_idle_on_rclpy(tmp_path):
    _check_idle(_idle_drivers(tmp_path, 'rclpy'))


@pytest.mark.slow
def test_drivers_without_devices_idle_on_the_builtin_runtime(tmp_path):
    _check_idle(_idle_drivers(tmp_path, 'builtin'))


# --- bringup --------------------------------------------------------------------------------


def _bringup(tmp_path, runtime, *args, hide_rclpy=False, **env_extra):
    env = _env(tmp_path, runtime, hide_rclpy=hide_rclpy, **env_extra)
    command = [sys.executable, '-m', 'hw_drivers.robot_bringup.cli', *args]
    process, output = _spawn(command, env)
    return process, output, env[TOKEN_VAR]


def _finish(process, output, token, timeout_s=60.0):
    try:
        code = process.wait(timeout_s)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    leftovers = _processes_with_token(token)
    _kill_leftovers(token)
    return code, output.text(), leftovers


def test_bringup_with_a_missing_parameter_file_prints_one_line_and_exits_2(tmp_path):
    process, output, token = _bringup(
        tmp_path, 'builtin', '--fake', '--params-file', str(tmp_path / 'nope.yaml')
    )
    code, text, leftovers = _finish(process, output, token)
    assert code == cli.EXIT_NOT_STARTED
    assert text.splitlines() == [
        f'robot_bringup: parameter file {tmp_path / "nope.yaml"}: no such file'
    ]
    assert leftovers == []


def test_bringup_names_each_missing_device_and_starts_nothing(tmp_path):
    params = tmp_path / 'r0.yaml'
    params.write_text(
        '/**/rplidar_node:\n  ros__parameters:\n    port: /dev/no_such_lidar\n'
        '/r0/mpu6050_node:\n  ros__parameters:\n    i2c_bus: 77\n'
    )
    process, output, token = _bringup(tmp_path, 'builtin', '--params-file', str(params))
    code, text, leftovers = _finish(process, output, token)
    assert code == cli.EXIT_NOT_STARTED
    lines = text.splitlines()
    assert lines[0].startswith('robot_bringup: pump_node: /dev/gpiochip0 does not exist')
    assert any('rplidar_node: /dev/no_such_lidar does not exist' in line for line in lines)
    assert any('mpu6050_node: /dev/i2c-77 does not exist' in line for line in lines)
    assert not any('started' in line for line in lines)
    assert leftovers == []


def test_bringup_without_ros_and_without_opt_in_exits_2(tmp_path):
    process, output, token = _bringup(tmp_path, '', '--fake', '--no-oabug', hide_rclpy=True)
    code, text, _ = _finish(process, output, token)
    assert code == cli.EXIT_NOT_STARTED
    assert text.splitlines() == ['robot_bringup: ' + cli.runtime_missing_reason()]


_SUBSET = textwrap.dedent(
    """
    import sys
    from hw_drivers.robot_bringup import cli
    names, launcher, crash = sys.argv[1].split(','), sys.argv[2], sys.argv[3] == 'crash'
    options = cli.BringupOptions(fake=True, with_oabug=False, launcher=launcher)
    plan = [spec for spec in cli.build_plan(options) if spec.name in names]
    if crash:  # a driver that dies once everything runs
        code = 'import time; time.sleep(4); raise SystemExit(3)'
        plan.append(cli.ChildSpec('crashing_node', (sys.executable, '-c', code)))
    sys.exit(cli.Supervisor(plan, grace_s=5.0).run())
    """
)


def _supervised(tmp_path, runtime, launcher, ending):
    """Start the drivers with fake devices, end the bringup by ``ending``; check leftovers."""
    extra = {}
    if launcher == 'ros2':
        bin_dir = tmp_path / 'bin'
        bin_dir.mkdir()
        ros2 = bin_dir / 'ros2'
        modules = {name: module for name, (_, module) in cli.EXECUTABLES.items()}
        ros2.write_text(f'#!{sys.executable}\n' + _FAKE_ROS2.format(modules=modules))
        ros2.chmod(0o755)
        extra['PATH'] = f'{bin_dir}{os.pathsep}{os.environ.get("PATH", "")}'
    drivers = _drivers_for(runtime)
    script = tmp_path / 'subset.py'
    script.write_text(_SUBSET)
    env = _env(tmp_path, runtime, hide_rclpy=runtime == 'builtin', **extra)
    args = [sys.executable, str(script), ','.join(drivers), launcher, ending]
    process, output = _spawn(args, env)
    token = env[TOKEN_VAR]
    try:
        assert output.wait_for(f'started {drivers[-1]}', 60.0), output.text()
        if ending != 'crash':
            time.sleep(3.0)  # every node initialised and spinning
            assert len(_processes_with_token(token)) >= len(drivers) + 1
            process.send_signal(signal.SIGINT if ending == 'sigint' else signal.SIGTERM)
    except BaseException:
        os.killpg(process.pid, signal.SIGKILL)
        _kill_leftovers(token)
        raise
    code, text, leftovers = _finish(process, output, token)
    assert leftovers == [], text
    assert 'Traceback' not in text, text
    if ending == 'crash':
        assert code == cli.EXIT_CHILD_FAILED
        assert 'crashing_node exited with status 3; stopping the other' in text
    else:
        assert code == cli.EXIT_STOPPED
        name = 'SIGINT' if ending == 'sigint' else 'SIGTERM'
        assert f'robot_bringup: {name} received; stopping' in text
    return text


@pytest.mark.slow
@needs_rclpy
@pytest.mark.parametrize('ending', ['crash', 'sigint', 'sigterm'])
def test_no_process_outlives_the_bringup_on_rclpy(tmp_path, ending):
    _supervised(tmp_path, 'rclpy', 'python', ending)


@pytest.mark.slow
@needs_rclpy
def test_no_node_outlives_the_bringup_behind_ros2_run_wrappers_on_rclpy(tmp_path):
    # The wrapper dies on SIGTERM at once; its node must be stopped all the same.
    _supervised(tmp_path, 'rclpy', 'ros2', 'crash')


@pytest.mark.slow
@pytest.mark.parametrize('ending', ['crash', 'sigint', 'sigterm'])
def test_no_process_outlives_the_bringup_on_the_builtin_runtime(tmp_path, ending):
    _supervised(tmp_path, 'builtin', 'python', ending)


@pytest.mark.slow
def test_no_node_outlives_the_bringup_behind_ros2_run_wrappers_on_builtin(tmp_path):
    _supervised(tmp_path, 'builtin', 'ros2', 'sigterm')


@pytest.mark.slow
def test_the_bringup_command_stops_everything_when_a_driver_fails_at_start(tmp_path):
    # An impossible calibration value makes the IMU driver exit 2 at start.
    params = tmp_path / 'r0.yaml'
    params.write_text('/**/mpu6050_node:\n  ros__parameters:\n    mounting: sideways\n')
    process, output, token = _bringup(
        tmp_path,
        'builtin',
        '--fake',
        '--no-oabug',
        '--params-file',
        str(params),
        hide_rclpy=True,
    )
    code, text, leftovers = _finish(process, output, token)
    assert code == cli.EXIT_CHILD_FAILED
    assert 'mpu6050_node exited with status 2; stopping the other' in text
    assert leftovers == []
    assert 'Traceback' not in text
