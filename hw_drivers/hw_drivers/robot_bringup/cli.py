"""robot_bringup: one robot's drivers and its OA-Bug node as supervised child processes.

``robot_bringup --robot r0 --own-tag D2 --variant gas_sound --robot-index 0 --robot-count 4``
first checks what it needs (the parameter file, the device files, ROS, the programs to run)
and stops with one line per problem and exit status 2 if anything is missing. It then
starts, in this order, the pump driver (first, so the line is held off), the static frames
node (the sensor mounts on ``/tf_static``), the lidar, gas, IMU and AoA receiver drivers,
optionally the locator host binary (after the AoA receiver is listening), and the OA-Bug
node, all in the robot's namespace with frame ids that match the simulator's (``r0/laser``,
``r0/imu_link``, ...).

Every child runs in a process group of its own. When one exits, or the bringup gets SIGINT,
SIGTERM or SIGHUP, every group is sent SIGTERM, and SIGKILL after ``--grace`` seconds, so no
process of the robot outlives the bringup (``ros2 run`` wrappers and their node processes
alike). Only the locator host, which exits by design whenever its connection ends, is
restarted alone. ``--dry-run`` prints the commands.

Exit status: 0 stopped by a signal (or ``--dry-run``), 1 a child exited or could not be
started (the others were stopped), 2 nothing was started (bad options, parameter file,
missing device or program).

Children are started with ``ros2 run`` on a ROS machine, or with ``python -m`` where ``ros2``
is missing (``--launcher`` chooses explicitly).
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import importlib.util
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any, TextIO

from swarm_common.cli import EXIT_SUCCESS, EXIT_UNFINISHED, EXIT_USAGE, ToolParser, run_tool
from swarm_common.errors import SwarmError
from swarm_runtime.standalone import (
    builtin_runtime_requested,
    rclpy_available,
    runtime_missing_reason,
)

from hw_drivers.parameters import NODE_SPECS

__all__ = [
    'DEVICE_PARAMETERS',
    'EXIT_CHILD_FAILED',
    'EXIT_NOT_STARTED',
    'EXIT_STOPPED',
    'BringupError',
    'BringupOptions',
    'ChildSpec',
    'Supervisor',
    'build_plan',
    'driver_parameters',
    'launch_nodes',
    'load_params_file',
    'main',
    'node_parameters',
    'plan_parameters',
    'preflight',
    'run',
]

# The suite's exit codes (swarm_common.cli), read for a robot that runs until stopped.
EXIT_STOPPED = EXIT_SUCCESS
EXIT_CHILD_FAILED = EXIT_UNFINISHED
EXIT_NOT_STARTED = EXIT_USAGE

# executable name -> module, as in setup.py's console_scripts.
EXECUTABLES = {
    'pump_node': ('hw_drivers', 'hw_drivers.pump_node'),
    'rplidar_node': ('hw_drivers', 'hw_drivers.rplidar_node'),
    'gas_adc_node': ('hw_drivers', 'hw_drivers.gas_node'),
    'mpu6050_node': ('hw_drivers', 'hw_drivers.mpu6050_node'),
    'aoa_receiver_node': ('hw_drivers', 'hw_drivers.aoa_receiver_node'),
    'static_frames_node': ('hw_drivers', 'hw_drivers.static_frames_node'),
    'oabug': ('oabug_robot', 'oabug_robot.node'),
}
DRIVERS = ('pump_node', 'rplidar_node', 'gas_adc_node', 'mpu6050_node', 'aoa_receiver_node')

#: Driver parameters that name a device, with the drivers' defaults (from their parameter
#: specs, which are ROS-free: importing them needs neither ROS nor the generated messages).
DEVICE_PARAMETERS: dict[str, dict[str, Any]] = {
    node: {name: NODE_SPECS[node][name].default for name in names}
    for node, names in {
        'pump_node': ('chip',),
        'rplidar_node': ('port',),
        'gas_adc_node': ('backend', 'i2c_bus', 'serial_port'),
        'mpu6050_node': ('i2c_bus',),
    }.items()
}


class BringupError(SwarmError):
    """Something the bringup needs is missing or wrong; nothing was started."""


@dataclass(frozen=True)
class ChildSpec:
    """One process of the bringup; ``respawn`` restarts it alone when it exits."""

    name: str
    command: tuple[str, ...]
    settle_s: float = 0.0
    respawn: bool = False


@dataclass(frozen=True)
class BringupOptions:
    """What to start for one robot."""

    robot: str = 'r0'
    own_tag_id: str = ''
    variant: str = 'gas_sound'
    robot_index: int = 0
    robot_count: int = 1
    fake: bool = False
    with_oabug: bool = True
    gas_backend: str = ''
    locator_command: str = ''
    params_file: str = ''
    launcher: str = 'auto'
    extra: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)


def driver_parameters(robot: str, *, own_tag_id: str = '', fake: bool = False) -> dict[str, dict]:
    """Per-driver parameters that make a real robot publish what the simulator publishes.

    Frame ids follow the sim bridge (``<robot>/laser``, ``<robot>/gas_sensor``,
    ``<robot>/imu_link``, ``<robot>/base_link`` for bearings); the static frames node
    prefixes its frames the same way.
    """
    params: dict[str, dict[str, Any]] = {
        'pump_node': {},
        'static_frames_node': {'frame_prefix': f'{robot}/'},
        'rplidar_node': {'frame_id': f'{robot}/laser'},
        'gas_adc_node': {'frame_id': f'{robot}/gas_sensor'},
        'mpu6050_node': {'frame_id': f'{robot}/imu_link'},
        'aoa_receiver_node': {'frame_id': f'{robot}/base_link', 'own_tag_id': own_tag_id},
    }
    if fake:
        for name in DRIVERS:
            params[name]['fake_device'] = True
        params['aoa_receiver_node'].pop('fake_device')
    return params


_YAML_NON_STRINGS = {'', 'true', 'false', 'yes', 'no', 'on', 'off', 'null', '~'}


def _looks_like_a_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _format_value(value: Any) -> str:
    """A ``-p name:=value`` value; strings that YAML would read as something else are quoted.

    ROS parses command-line parameter values as YAML, so a tag id such as ``42`` would become
    an integer and fail against the string parameter.
    """
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, str):
        if value.lower() in _YAML_NON_STRINGS or _looks_like_a_number(value):
            return f"'{value}'"
        return value
    return str(value)


def _launcher(options: BringupOptions) -> str:
    if options.launcher != 'auto':
        return options.launcher
    return 'ros2' if shutil.which('ros2') else 'python'


def _command(
    executable: str, namespace: str, params: Mapping[str, Any], options: BringupOptions
) -> tuple[str, ...]:
    package, module = EXECUTABLES[executable]
    head = (
        ('ros2', 'run', package, executable)
        if _launcher(options) == 'ros2'
        else (sys.executable, '-m', module)
    )
    args: list[str] = ['--ros-args', '-r', f'__ns:=/{namespace}']
    if options.params_file:
        args += ['--params-file', options.params_file]
    for key, value in params.items():
        args += ['-p', f'{key}:={_format_value(value)}']
    return (*head, *args)


def plan_parameters(options: BringupOptions) -> list[tuple[str, dict[str, Any]]]:
    """(executable, ``-p`` parameters) of each node the bringup starts, in start order: the
    pump first (its line is held off), then the static frames, the sensors and the OA-Bug
    node. :func:`build_plan` and the launch file ``robot.launch.py`` are built from it."""
    params = driver_parameters(options.robot, own_tag_id=options.own_tag_id, fake=options.fake)
    if options.gas_backend:
        params['gas_adc_node']['backend'] = options.gas_backend
    for name, extra in options.extra.items():
        params.setdefault(name, {}).update(extra)
    order = (DRIVERS[0], 'static_frames_node', *DRIVERS[1:])
    plan = [(name, params[name]) for name in order]
    if options.with_oabug:
        oabug_params = {
            'variant': options.variant,
            'robot_index': options.robot_index,
            'robot_count': options.robot_count,
            'own_tag_id': options.own_tag_id,
            **params.get('oabug', {}),
        }
        plan.append(('oabug', oabug_params))
    return plan


def launch_nodes(options: BringupOptions) -> list[dict[str, Any]]:
    """The nodes of :func:`plan_parameters` as launch ``Node`` arguments (package,
    executable, namespace, parameters: the parameter file first, then the values)."""
    files: list[Any] = [options.params_file] if options.params_file else []
    return [
        {
            'package': EXECUTABLES[name][0],
            'executable': name,
            'namespace': options.robot,
            'parameters': [*files, dict(params)],
        }
        for name, params in plan_parameters(options)
    ]


def build_plan(options: BringupOptions) -> list[ChildSpec]:
    """The processes to start, in order."""
    plan: list[ChildSpec] = []
    for name, params in plan_parameters(options):
        command = _command(name, options.robot, params, options)
        if name == 'oabug':
            if options.locator_command:
                # The authors' locator exits whenever its TCP connection ends: respawn it alone.
                locator = tuple(shlex.split(options.locator_command))
                plan.append(ChildSpec('aoa_locator', locator, settle_s=0.5, respawn=True))
            plan.append(ChildSpec(name, command))
        else:
            plan.append(ChildSpec(name, command, settle_s=0.5))
    if options.locator_command and not options.with_oabug:
        locator = tuple(shlex.split(options.locator_command))
        plan.append(ChildSpec('aoa_locator', locator, settle_s=0.5, respawn=True))
    return plan


# --- checks before anything starts ---------------------------------------------------------


def load_params_file(path: str) -> dict[str, dict[str, Any]]:
    """Read a ROS parameter file: ``{node pattern: {'ros__parameters': {...}}}``.

    Raises:
        BringupError: the file is missing, unreadable, not YAML or not shaped like one.
    """
    try:
        text = Path(path).read_text(encoding='utf-8')
    except FileNotFoundError:
        raise BringupError(f'parameter file {path}: no such file') from None
    except OSError as err:
        raise BringupError(f'parameter file {path}: {err.strerror or err}') from None
    try:
        import yaml
    except ImportError:  # pragma: no cover - PyYAML ships with ROS and with this package
        return {}
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        where = f' (line {mark.line + 1})' if mark is not None else ''
        raise BringupError(f'parameter file {path}: not valid YAML{where}') from None
    if document is None:
        return {}
    if not isinstance(document, dict):
        raise BringupError(f'parameter file {path}: expected node names at the top level')
    for node, section in document.items():
        inner = section.get('ros__parameters') if isinstance(section, dict) else None
        if not isinstance(inner, dict):
            msg = f'parameter file {path}: {node!r} needs a "ros__parameters" mapping'
            raise BringupError(msg)
    return document


def _pattern_matches(pattern: str, fully_qualified: str) -> bool:
    """ROS parameter-file node matching: ``/**`` any namespaces, ``*`` one name part."""
    pattern = '/' + str(pattern).lstrip('/')
    regex = ''
    for token in re.split(r'(/\*\*|\*)', pattern):
        if token == '/**':
            regex += r'(/[^/]+)*'
        elif token == '*':
            regex += r'[^/]*'
        else:
            regex += re.escape(token)
    return re.fullmatch(regex, fully_qualified) is not None


def node_parameters(
    document: Mapping[str, Mapping[str, Any]], namespace: str, node: str
) -> dict[str, Any]:
    """The parameters a parameter file gives node ``node`` in ``namespace`` (later keys win)."""
    fully_qualified = f'/{namespace.strip("/")}/{node}' if namespace.strip('/') else f'/{node}'
    values: dict[str, Any] = {}
    for pattern, section in document.items():
        if _pattern_matches(pattern, fully_qualified):
            values.update(section['ros__parameters'])
    return values


def _device_files(options: BringupOptions, document: Mapping[str, Any]) -> list[tuple[str, str]]:
    """(node, device path) pairs that must exist for a run with real devices."""
    needed: list[tuple[str, str]] = []
    settings = {
        name: {**defaults, **node_parameters(document, options.robot, name)}
        for name, defaults in DEVICE_PARAMETERS.items()
    }
    if options.gas_backend:
        settings['gas_adc_node']['backend'] = options.gas_backend
    needed.append(('pump_node', str(settings['pump_node']['chip'])))
    port = str(settings['rplidar_node']['port'])
    if '://' not in port:  # pyserial URLs (loop://, socket://) are not files
        needed.append(('rplidar_node', port))
    gas = settings['gas_adc_node']
    if gas['backend'] == 'xiao_serial':
        needed.append(('gas_adc_node', str(gas['serial_port'])))
    else:
        needed.append(('gas_adc_node', f'/dev/i2c-{gas["i2c_bus"]}'))
    needed.append(('mpu6050_node', f'/dev/i2c-{settings["mpu6050_node"]["i2c_bus"]}'))
    return needed


def preflight(options: BringupOptions, *, check_devices: bool = True) -> list[str]:
    """Everything that would stop the robot from starting, one line each (empty: go)."""
    problems: list[str] = []
    document: Mapping[str, Any] = {}
    if options.params_file:
        try:
            document = load_params_file(options.params_file)
        except BringupError as err:
            return [str(err)]  # the device checks below would read the same file
    launcher = _launcher(options)
    if launcher == 'ros2':
        if shutil.which('ros2') is None:
            problems.append('ros2 not found: source /opt/ros/jazzy/setup.bash or --launcher python')
    elif not rclpy_available() and not builtin_runtime_requested():
        problems.append(runtime_missing_reason())
    if launcher == 'python' and options.with_oabug and not importlib.util.find_spec('oabug_robot'):
        problems.append('oabug_robot is not installed: build the workspace, or --no-oabug')
    if options.locator_command:
        try:
            argv = shlex.split(options.locator_command)
        except ValueError as err:
            argv = []
            problems.append(f'--locator-command cannot be parsed: {err}')
        if argv and shutil.which(argv[0]) is None:
            problems.append(f'locator program {argv[0]} not found or not executable')
    if check_devices and not options.fake:
        for node, path in _device_files(options, document):
            if not os.path.exists(path):
                problems.append(
                    f'{node}: {path} does not exist (connect the device, fix the parameter'
                    ' file, or start with --fake)'
                )
    return problems


# --- supervision ---------------------------------------------------------------------------


def _set_parent_death_signal() -> None:
    """In a child, before exec: get SIGTERM if the bringup itself dies (Linux only)."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


def live_group_members(groups: Sequence[int]) -> dict[int, int]:
    """Processes still alive (not zombies) in the given process groups: pid -> group."""
    wanted = set(groups)
    found: dict[int, int] = {}
    try:
        entries = os.listdir('/proc')
    except OSError:  # no procfs: fall back to asking each group
        for group in wanted:
            try:
                os.killpg(group, 0)
            except (ProcessLookupError, PermissionError):
                continue
            found[group] = group
        return found
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            text = Path(f'/proc/{entry}/stat').read_text()
        except OSError:
            continue
        fields = text[text.rindex(')') + 2 :].split()
        state, group = fields[0], int(fields[2])
        if group in wanted and state not in ('Z', 'X'):
            found[int(entry)] = group
    return found


class Supervisor:
    """Start the plan, watch it, and stop every process group on the way out.

    Args:
        plan: the children, in start order.
        grace_s: time between SIGTERM and SIGKILL when stopping [s].
        respawn_delay_s: pause before a ``respawn`` child is started again [s].
        out: where the bringup's own lines go.
        env: environment of the children (default: this one, with line-buffered output).
    """

    def __init__(
        self,
        plan: Sequence[ChildSpec],
        *,
        grace_s: float = 5.0,
        respawn_delay_s: float = 2.0,
        out: TextIO | None = None,
        env: Mapping[str, str] | None = None,
    ) -> None:
        self.plan = list(plan)
        self.grace_s = grace_s
        self.respawn_delay_s = respawn_delay_s
        self._out = out or sys.stdout
        base = dict(os.environ if env is None else env)
        base.setdefault('PYTHONUNBUFFERED', '1')
        base.setdefault('RCUTILS_LOGGING_BUFFERED_STREAM', '1')
        self._env = base
        self.children: list[tuple[ChildSpec, subprocess.Popen]] = []
        self.groups: list[int] = []
        self.signal_received = 0
        self._signals = 0

    def say(self, message: str) -> None:
        """One line of the bringup's own output."""
        self._out.write(f'robot_bringup: {message}\n')
        self._out.flush()

    def _on_signal(self, signum: int, _frame: FrameType | None) -> None:
        self._signals += 1
        if not self.signal_received:
            self.signal_received = signum

    def _start(self, spec: ChildSpec) -> subprocess.Popen:
        process = subprocess.Popen(
            spec.command,
            env=self._env,
            start_new_session=True,
            preexec_fn=_set_parent_death_signal,
        )
        self.groups.append(process.pid)
        return process

    def _wait(self, seconds: float) -> tuple[ChildSpec, subprocess.Popen] | None:
        """Sleep up to ``seconds``; return the first non-respawn child that exited."""
        deadline = time.monotonic() + seconds
        while True:
            for index, (spec, process) in enumerate(self.children):
                if process.poll() is None:
                    continue
                if not spec.respawn:
                    return spec, process
                self.say(f'{spec.name} exited ({process.returncode}); restarting it')
                time.sleep(self.respawn_delay_s)
                self.children[index] = (spec, self._start(spec))
            if self.signal_received or time.monotonic() >= deadline:
                return None
            time.sleep(min(0.05, max(deadline - time.monotonic(), 0.0)))

    def run(self) -> int:
        """Supervise until a child fails or a signal arrives; return the exit status."""
        watched = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
        previous = {sig: signal.signal(sig, self._on_signal) for sig in watched}
        status = EXIT_STOPPED
        try:
            failed = None
            for spec in self.plan:
                if self.signal_received:
                    break
                try:
                    process = self._start(spec)
                except OSError as err:
                    self.say(f'cannot start {spec.name}: {err.strerror or err}; stopping')
                    status = EXIT_CHILD_FAILED
                    break
                self.children.append((spec, process))
                self.say(f'started {spec.name} (pid {process.pid}): {shlex.join(spec.command)}')
                failed = self._wait(spec.settle_s)
                if failed is not None:
                    break
            while status == EXIT_STOPPED and failed is None and not self.signal_received:
                failed = self._wait(3600.0)
            if failed is not None:
                spec, process = failed
                others = sum(1 for _, p in self.children if p.poll() is None)
                self.say(
                    f'{spec.name} exited with status {process.returncode};'
                    f' stopping the other {others} process(es)'
                )
                status = EXIT_CHILD_FAILED
            elif self.signal_received:
                name = signal.Signals(self.signal_received).name
                self.say(f'{name} received; stopping {len(self.children)} process(es)')
        finally:
            left = self.stop_all()
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        if left:
            self.say(f'{left} process(es) could not be stopped')
        return status

    def stop_all(self) -> int:
        """SIGTERM every process group, SIGKILL what is left after the grace time.

        Returns the number of processes still alive at the end (0 unless they are stuck in
        the kernel).
        """
        groups = list(reversed(self.groups))
        self._signal_groups(groups, signal.SIGTERM)
        signals_before = self._signals
        deadline = time.monotonic() + self.grace_s
        while live_group_members(groups) and time.monotonic() < deadline:
            if self._signals > signals_before:
                break  # a second Ctrl-C / SIGTERM: do not wait any longer
            self._reap()
            time.sleep(0.05)
        if live_group_members(groups):
            names = {p.pid: s.name for s, p in self.children}
            stuck = sorted({names.get(g, str(g)) for g in live_group_members(groups).values()})
            self.say(f'killing {", ".join(stuck)} (no exit {self.grace_s:g} s after SIGTERM)')
            self._signal_groups(groups, signal.SIGKILL)
            deadline = time.monotonic() + 2.0
            while live_group_members(groups) and time.monotonic() < deadline:
                self._reap()
                time.sleep(0.05)
        self._reap()
        for _, process in self.children:
            with contextlib.suppress(subprocess.TimeoutExpired):
                process.wait(1.0)
        return len(live_group_members(groups))

    def _reap(self) -> None:
        for _, process in self.children:
            process.poll()

    @staticmethod
    def _signal_groups(groups: Sequence[int], sig: signal.Signals) -> None:
        for group in groups:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(group, sig)


def run(
    options: BringupOptions,
    *,
    dry_run: bool = False,
    check_devices: bool = True,
    grace_s: float = 5.0,
    respawn_delay_s: float = 2.0,
    out: TextIO | None = None,
) -> int:
    """Check, start the plan and supervise it; return the exit status for the process."""
    out = out or sys.stdout
    plan = build_plan(options)
    if dry_run:
        for spec in plan:
            out.write(shlex.join(spec.command) + '\n')
        return EXIT_STOPPED
    problems = preflight(options, check_devices=check_devices)
    if problems:
        for problem in problems:
            sys.stderr.write(f'robot_bringup: {problem}\n')
        return EXIT_NOT_STARTED
    supervisor = Supervisor(plan, grace_s=grace_s, respawn_delay_s=respawn_delay_s, out=out)
    return supervisor.run()


def parse_args(argv: Sequence[str] | None = None) -> tuple[BringupOptions, argparse.Namespace]:
    """Command-line options."""
    parser = ToolParser(
        prog='robot_bringup',
        description=(__doc__ or '').split('\n\n')[0],
        epilog=(
            'exit status: 0 stopped by SIGINT/SIGTERM/SIGHUP or --dry-run; 1 a child exited'
            ' or could not start (all others stopped); 2 nothing started (bad options,'
            ' parameter file, missing device or program; one line on stderr per problem,'
            ' --debug adds the traceback of an error)'
        ),
    )
    parser.add_argument('--robot', default='r0', help='robot name = namespace (r0, r1, ...)')
    parser.add_argument('--own-tag', default='', help="this robot's AoA tag id, e.g. D2")
    parser.add_argument('--variant', default='gas_sound', help='OA-Bug variant (Table I)')
    parser.add_argument('--robot-index', type=int, default=0)
    parser.add_argument('--robot-count', type=int, default=1)
    parser.add_argument(
        '--gas-backend',
        default='',
        choices=('', 'ads1115', 'ads1015', 'grove_hat', 'xiao_serial'),
        help='gas ADC backend (default: the parameter file, else ads1115)',
    )
    parser.add_argument('--locator-command', default='', help='locator host command line')
    parser.add_argument('--params-file', default='', help='ROS parameter YAML for all nodes')
    parser.add_argument('--fake', action='store_true', help='drivers use simulated devices')
    parser.add_argument('--no-oabug', action='store_true', help='start the drivers only')
    parser.add_argument('--launcher', choices=('auto', 'ros2', 'python'), default='auto')
    parser.add_argument(
        '--skip-device-check',
        action='store_true',
        help='start even if device files are missing (the drivers wait for them)',
    )
    parser.add_argument(
        '--grace', type=float, default=5.0, help='seconds from SIGTERM to SIGKILL on stop'
    )
    parser.add_argument('--dry-run', action='store_true', help='print the commands only')
    args = parser.parse_args(argv)
    if args.robot_count < 1:
        raise BringupError(f'--robot-count must be >= 1, got {args.robot_count}')
    if not 0 <= args.robot_index < args.robot_count:
        msg = f'--robot-index must be in 0..{args.robot_count - 1}, got {args.robot_index}'
        raise BringupError(msg)
    if not args.grace >= 0.0:
        raise BringupError(f'--grace must be >= 0 s, got {args.grace}')
    options = BringupOptions(
        robot=args.robot,
        own_tag_id=args.own_tag,
        variant=args.variant,
        robot_index=args.robot_index,
        robot_count=args.robot_count,
        fake=args.fake,
        with_oabug=not args.no_oabug,
        gas_backend=args.gas_backend,
        locator_command=args.locator_command,
        params_file=args.params_file,
        launcher=args.launcher,
    )
    return options, args


def _main(argv: list[str]) -> int:
    options, args = parse_args(argv)
    try:
        return run(
            options,
            dry_run=args.dry_run,
            check_devices=not args.skip_device_check,
            grace_s=args.grace,
        )
    except KeyboardInterrupt:  # Ctrl-C before the supervisor took over: nothing runs
        return EXIT_STOPPED


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of ``robot_bringup``; exits with the status (module docstring)."""
    sys.exit(run_tool('robot_bringup', _main, argv))


if __name__ == '__main__':
    main()
