# ruff: noqa: T201  (the --dry-run runner prints the command lines)
"""A mission as one OS process per node on real DDS: the spawners' ``--processes`` mode.

The sim bridge and every robot node run in processes of their own, started with the
command line a robot uses (``ros2 run <package> <executable> --ros-args -r __ns:=/r<i>
-p name:=value ...``), on sim time from the bridge's ``/clock``. What is not a ROS
parameter (the site, the start poses, the sensor set, the mission extensions) goes into a
mission file for the bridge (:mod:`sim_bridge.mission_file`); the bridge ends the mission at
the spawner's end condition, writes the outcome file and exits 0.

The spawner process is the supervisor (:func:`run_mission_processes`): it starts the
children, each in a process group of its own, shows progress from ``/clock`` and
``/sim/coverage``, hosts the bag recorder with ``--record``, and at the mission's end stops
the robots (SIGINT, then SIGKILL after a timeout), reads the outcome and returns the same
:class:`~swarm_experiments.mission.MissionResult` as the in-process runner, so the spawners
print it with the same code. Ctrl-C stops the bridge, which writes the outcome so far
(``StopReason.INTERRUPTED``); a child that exits before the mission's end stops every other
child and raises :class:`~swarm_experiments.errors.MissionError` naming it (exit 1).

:func:`mission_commands` builds the command lines; ``--dry-run`` prints them
(:func:`format_command`) and the launch file ``swarm_experiments/launch/swarm_sim.launch.py``
starts the same nodes from the same lists (:func:`launch_entries`).
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import IO, Any

import numpy as np
import yaml
from sim_bridge.bridge_parameters import BRIDGE_PARAMETERS, BridgeNodeConfig
from sim_bridge.mission_file import MissionFileError, read_outcome, write_mission
from swarm_common.params import render_value
from swarm_sim.errors import ConfigurationError
from swarm_sim.ground_truth import RoomEntry

from swarm_experiments.cli_args import NODE_CRASH_PREFIX
from swarm_experiments.errors import ExperimentError, MissionError
from swarm_experiments.mission import (
    MissionProgress,
    MissionResult,
    MissionSpec,
    StopReason,
    _make_recorder,
)

__all__ = [
    'BRIDGE_EXECUTABLE',
    'NodeCommand',
    'NodeCrash',
    'ProcessOptions',
    'format_command',
    'launch_entries',
    'mission_commands',
    'parse_command',
    'run_mission_processes',
    'spawner_commands',
    'split_crash_faults',
]

#: (package, executable) of the sim bridge.
BRIDGE_EXECUTABLE = ('sim_bridge', 'sim_bridge')
#: Seconds a child gets to exit after SIGINT before it is killed.
STOP_TIMEOUT_S = 10.0
_POLL_PERIOD_S = 0.05


@dataclass(frozen=True)
class NodeCommand:
    """One node process.

    Attributes:
        name: what errors call it ('sim_bridge', 'r0', ...).
        package: its ROS package.
        executable: its executable (console script).
        namespace: its namespace ('/r0'), or '' for the root.
        parameters: its ``-p`` parameters, in order.
    """

    name: str
    package: str
    executable: str
    namespace: str
    parameters: Mapping[str, Any]

    def ros_arguments(self) -> list[str]:
        """``--ros-args [-r __ns:=NS] -p name:=value ...``."""
        args = ['--ros-args']
        if self.namespace:
            args += ['-r', f'__ns:={self.namespace}']
        for name, value in self.parameters.items():
            args += ['-p', f'{name}:={render_value(value)}']
        return args

    def ros2_run(self) -> list[str]:
        """The ``ros2 run`` command line."""
        return ['ros2', 'run', self.package, self.executable, *self.ros_arguments()]

    def argv(self) -> list[str]:
        """The command line the supervisor starts: the executable as installed here."""
        return [*resolve_executable(self.package, self.executable), *self.ros_arguments()]


def resolve_executable(package: str, executable: str) -> list[str]:
    """How to start ``executable`` of ``package`` here: the console script next to this
    Python (a virtualenv), in ``<prefix>/lib/<package>/`` of an ament prefix (colcon), on
    PATH, else through ``ros2 run``.

    Raises:
        MissionError: none of these exists.
    """
    beside = Path(sys.executable).parent / executable
    if beside.is_file():
        return [str(beside)]
    for prefix in filter(None, os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)):
        candidate = Path(prefix) / 'lib' / package / executable
        if candidate.is_file():
            return [str(candidate)]
    found = shutil.which(executable)
    if found:
        return [found]
    if shutil.which('ros2'):
        return ['ros2', 'run', package, executable]
    msg = f'cannot find the executable {executable!r} of package {package!r} (is it installed?)'
    raise MissionError(msg)


def format_command(command: NodeCommand) -> str:
    """The ``ros2 run`` command line of ``command`` as one shell line."""
    return shlex.join(command.ros2_run())


def parse_command(line: str) -> NodeCommand:
    """The node command of a line printed by :func:`format_command` (values read as YAML,
    as rcl reads them).

    Raises:
        ValueError: not a ``ros2 run PACKAGE EXECUTABLE --ros-args ...`` line.
    """
    words = shlex.split(line)
    if words[:2] != ['ros2', 'run'] or len(words) < 5 or words[4] != '--ros-args':
        raise ValueError(f'not a ros2 run line with --ros-args: {line!r}')
    package, executable = words[2], words[3]
    namespace = ''
    parameters: dict[str, Any] = {}
    rest = words[5:]
    for flag, value in zip(rest[::2], rest[1::2], strict=True):
        name, _, text = value.partition(':=')
        if flag == '-r' and name == '__ns':
            namespace = text
        elif flag == '-p':
            parameters[name] = yaml.safe_load(text)
        else:
            raise ValueError(f'unexpected argument {flag} {value} in {line!r}')
    name = namespace.strip('/') or executable
    return NodeCommand(name, package, executable, namespace, parameters)


@dataclass(frozen=True)
class NodeCrash:
    """A node-crash fault: robot ``robot`` is killed (SIGKILL) when ``/clock`` reaches
    ``time_s`` and, unless ``restart_after_s`` is None, started again with the same command
    line that much sim time later."""

    robot: int
    time_s: float
    restart_after_s: float | None = None

    @property
    def name(self) -> str:
        """The robot's name (r<i>)."""
        return f'r{self.robot}'


_CRASH = re.compile(r'crash:r(\d+)@([0-9.]+)(?:\+([0-9.]+))?')


def split_crash_faults(items: Sequence[str]) -> tuple[list[str], tuple[NodeCrash, ...]]:
    """Split ``--fault`` items into the world's ``NAME=VALUE`` faults and node crashes
    ``crash:r<i>@<time_s>[+<restart_after_s>]``.

    Raises:
        ExperimentError: a malformed crash item.
    """
    rest: list[str] = []
    crashes: list[NodeCrash] = []
    for item in items:
        if not item.startswith(NODE_CRASH_PREFIX):
            rest.append(item)
            continue
        match = _CRASH.fullmatch(item.strip())
        if match is None:
            msg = (
                f'--fault {item}: a node crash is crash:r<i>@<time_s>[+<restart_after_s>], '
                'e.g. crash:r1@60 or crash:r1@60+10'
            )
            raise ExperimentError(msg)
        try:
            time_s = float(match.group(2))
            restart = None if match.group(3) is None else float(match.group(3))
        except ValueError as err:
            raise ExperimentError(f'--fault {item}: {err}') from err
        crashes.append(NodeCrash(int(match.group(1)), time_s, restart))
    return rest, tuple(crashes)


@dataclass(frozen=True)
class ProcessOptions:
    """How to run a mission in processes.

    Attributes:
        run_dir: directory for the mission file, the outcome file and the children's logs;
            None: a new temporary directory, removed after a run that ended normally.
        stop_timeout_s: seconds a child gets after SIGINT before it is killed.
        startup_timeout_s: wall seconds the bridge may wait for the nodes before the first
            step; exceeded, the run fails.
        crashes: node-crash faults to inject.
    """

    run_dir: Path | None = None
    stop_timeout_s: float = STOP_TIMEOUT_S
    startup_timeout_s: float = 120.0
    crashes: tuple[NodeCrash, ...] = ()


def _bridge_parameters(spec: MissionSpec, run_dir: Path) -> dict[str, Any]:
    """The bridge's ``-p`` parameters: the engine's values that differ from the defaults,
    the mission's bridge parameters, the pace, the end condition and the files."""
    engine = spec.engine_config
    if engine.render.mode != 'none':
        raise ConfigurationError('--render cannot be used with --processes')
    values = BRIDGE_PARAMETERS.values_of(BridgeNodeConfig(engine=engine))
    defaults = BRIDGE_PARAMETERS.defaults()
    params: dict[str, Any] = {}
    for name, value in values.items():
        if value != defaults[name] and not (
            isinstance(value, float) and math.isnan(value) and math.isnan(defaults[name])
        ):
            params[name] = value
    params['real_time_factor'] = float(spec.time_scale)
    params.update(spec.bridge_parameters)
    params['mission_file'] = str(run_dir / 'mission.json')
    params['outcome_file'] = str(run_dir / 'outcome.json')
    params['max_sim_time_s'] = float(spec.max_sim_time_s)
    params['stop_when_all_rooms_covered'] = bool(spec.stop_when_all_rooms_covered)
    params['trajectory_period_s'] = float(spec.trajectory_period_s)
    # The robots' time sources and the supervisor's monitor subscribe /clock.
    params['start_after_clock_subscribers'] = len(spec.robots) + 1
    return params


def mission_commands(spec: MissionSpec, run_dir: Path) -> list[NodeCommand]:
    """Write the bridge's mission file into ``run_dir`` and return the node commands:
    the bridge first, then robot ``r0``, ``r1``, ...

    Raises:
        ConfigurationError: a robot spec without an executable, or an option the processes
            cannot have (``--render``).
    """
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    engine = spec.engine_config
    from swarm_sim.engine import SENSORS

    sensors = None if engine.sensors == SENSORS else engine.sensors
    write_mission(
        run_dir / 'mission.json',
        site=spec.site,
        initial_poses=spec.initial_poses,
        sensors=sensors,
        extensions=spec.extension_entries,
    )
    package, executable = BRIDGE_EXECUTABLE
    commands = [
        NodeCommand('sim_bridge', package, executable, '', _bridge_parameters(spec, run_dir))
    ]
    for i, robot in enumerate(spec.robots):
        if robot.executable is None:
            msg = f'robot r{i}: its node spec names no executable, so it cannot run as a process'
            raise ConfigurationError(msg)
        package, executable = robot.executable
        params = {'use_sim_time': True, **robot.parameters}
        commands.append(NodeCommand(f'r{i}', package, executable, f'/r{i}', params))
    return commands


def launch_entries(commands: Sequence[NodeCommand]) -> list[dict[str, Any]]:
    """The commands as launch ``Node`` arguments (package, executable, namespace,
    parameters): what ``swarm_sim.launch.py`` builds its nodes from."""
    return [
        {
            'package': c.package,
            'executable': c.executable,
            'namespace': c.namespace.strip('/'),
            'parameters': [dict(c.parameters)],
        }
        for c in commands
    ]


# The supervisor ------------------------------------------------------------------------


def _parent_death_signal() -> None:
    """In a child, before exec: SIGTERM when the supervisor dies (Linux), so no orphans."""
    with contextlib.suppress(OSError, AttributeError):  # no libc, or no prctl: not Linux
        libc = ctypes.CDLL(None, use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGTERM)


@dataclass
class _Child:
    command: NodeCommand
    process: subprocess.Popen[bytes]
    log_path: Path
    log: IO[bytes]
    crashed: bool = False  # its crash fault has been injected

    def last_line(self) -> str:
        with contextlib.suppress(OSError):
            lines = self.log_path.read_text(encoding='utf-8', errors='replace').splitlines()
            for line in reversed(lines):
                if line.strip():
                    return line.strip()
        return ''


def _signal_group(child: _Child, signum: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(child.process.pid, signum)


def _stop_children(children: Sequence[_Child], timeout_s: float) -> None:
    """SIGINT to every child's process group, SIGKILL to those still there after
    ``timeout_s``; wait for all and close their logs."""
    for child in children:
        if child.process.poll() is None:
            _signal_group(child, signal.SIGINT)
    deadline = time.monotonic() + timeout_s
    for child in children:
        remaining = max(0.0, deadline - time.monotonic())
        try:
            child.process.wait(timeout=remaining)
        except subprocess.TimeoutExpired:
            _signal_group(child, signal.SIGKILL)
            child.process.wait()
        # Whatever the node left in its group (it started none) goes too.
        _signal_group(child, signal.SIGKILL)
        child.log.close()


@dataclass
class _Monitor:
    """The supervisor's node: sim time from /clock, coverage from /sim/coverage."""

    node: Any
    sim_time_s: float = 0.0
    rooms_covered: int = 0
    rooms_total: int = 0
    clocks: int = field(default=0)

    @classmethod
    def create(cls) -> _Monitor:
        from swarm_runtime.ros import (
            Node,
            QoSDurabilityPolicy,
            QoSProfile,
            message_module,
        )

        node = Node('spawn_supervisor')
        monitor = cls(node)
        rosgraph = message_module('rosgraph_msgs')
        swarm = message_module('swarm_interfaces')
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(rosgraph.Clock, '/clock', monitor._on_clock, 10)
        node.create_subscription(swarm.Coverage, '/sim/coverage', monitor._on_coverage, latched)
        return monitor

    def _on_clock(self, msg: Any) -> None:
        self.sim_time_s = msg.clock.sec + msg.clock.nanosec * 1e-9
        self.clocks += 1

    def _on_coverage(self, msg: Any) -> None:
        self.rooms_total = int(msg.rooms_total)
        self.rooms_covered = len(msg.visits)


class _Interrupt:
    """SIGINT (and SIGTERM) while entered: note it; a second one raises KeyboardInterrupt."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: dict[int, Any] = {}

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> _Interrupt:
        for signum in (signal.SIGINT, signal.SIGTERM):
            self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)


def _result_from_outcome(
    spec: MissionSpec, outcome: Mapping[str, Any], wall_time_s: float
) -> MissionResult:
    entries = tuple(
        RoomEntry(int(room), int(robot), float(t)) for room, robot, t in outcome['room_entries']
    )
    n = len(spec.robots)
    trajectories = np.asarray(outcome['trajectories'], dtype=float).reshape(-1, n, 3)
    return MissionResult(
        robot_names=tuple(outcome['robot_names']),
        site=spec.site,
        stop_reason=str(outcome['stop_reason']),
        sim_time_s=float(outcome['sim_time_s']),
        wall_time_s=wall_time_s,
        rooms_total=int(outcome['rooms_total']),
        room_entries=entries,
        trajectory_times_s=np.asarray(outcome['trajectory_times_s'], dtype=float),
        trajectories=trajectories,
        distance_travelled_m=np.asarray(outcome['distance_travelled_m'], dtype=float),
        bag_path=spec.recording.path if spec.recording is not None else None,
        extension_outcomes=tuple(outcome.get('extensions', ())),
    )


def _start(command: NodeCommand, run_dir: Path, *, restart: bool = False) -> _Child:
    log_path = run_dir / f'{command.name}.log'
    log = log_path.open('ab' if restart else 'wb')
    env = dict(os.environ, SWARM_RUNTIME='rclpy', PYTHONUNBUFFERED='1')
    try:
        process = subprocess.Popen(
            command.argv(),
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            env=env,
            start_new_session=True,
            preexec_fn=_parent_death_signal if sys.platform.startswith('linux') else None,
        )
    except OSError as err:
        log.close()
        msg = f'{command.name}: cannot start {command.executable}: {err.strerror or err}'
        raise MissionError(msg) from err
    return _Child(command, process, log_path, log)


def run_mission_processes(
    spec: MissionSpec,
    *,
    progress: Callable[[MissionProgress], None] | None = None,
    options: ProcessOptions | None = None,
) -> MissionResult:
    """Run ``spec`` with one process per node on real DDS; return its result.

    Needs real rclpy in this process (the supervisor is a ROS node: progress, recorder).

    Raises:
        MissionError: a child could not start, exited before the mission's end, or the
            bridge wrote no outcome.
        ExperimentError: this process is not on real rclpy.
    """
    from swarm_runtime.ros import SingleThreadedExecutor, rclpy, using_real_rclpy

    if not using_real_rclpy():
        raise ExperimentError('--processes needs real rclpy (ROS 2 Jazzy or its PyPI wheels)')
    options = options or ProcessOptions()
    for crash in options.crashes:
        if not 0 <= crash.robot < len(spec.robots):
            msg = f'--fault crash:{crash.name}: the mission has robots r0..r{len(spec.robots) - 1}'
            raise ExperimentError(msg)
    temporary = options.run_dir is None
    run_dir = Path(tempfile.mkdtemp(prefix='swarm-processes-')) if temporary else options.run_dir
    assert run_dir is not None
    commands = mission_commands(spec, run_dir)
    outcome_path = Path(commands[0].parameters['outcome_file'])
    from rclpy.signals import SignalHandlerOptions

    owns_context = not rclpy.ok()
    if owns_context:
        rclpy.init(args=[], signal_handler_options=SignalHandlerOptions.NO)
    executor = SingleThreadedExecutor()
    nodes: list[Any] = []
    children: list[_Child] = []
    failed = True
    wall_start = time.perf_counter()
    try:
        monitor = _Monitor.create()
        nodes.append(monitor.node)
        if spec.recording is not None:
            nodes.append(_make_recorder(spec.recording))
        for node in nodes:
            executor.add_node(node)
        with _Interrupt() as interrupt:
            for command in commands:
                children.append(_start(command, run_dir))
            bridge = children[0]
            pending: dict[str, NodeCrash] = {}  # killed on purpose, maybe to be restarted
            next_report_s = 0.0
            started_wall = time.monotonic()
            stopping = False
            while True:
                executor.spin_once(timeout_sec=_POLL_PERIOD_S)
                if interrupt.requested and not stopping:
                    stopping = True
                    _signal_group(bridge, signal.SIGINT)
                status = bridge.process.poll()
                if status is not None:
                    if status != 0:
                        _raise_crash(bridge, status)
                    break
                _inject_crashes(options.crashes, monitor.sim_time_s, children, run_dir, pending)
                for child in children[1:]:
                    status = child.process.poll()
                    if status is not None and child.command.name not in pending:
                        _raise_crash(child, status)
                if monitor.clocks == 0:
                    if time.monotonic() - started_wall > options.startup_timeout_s:
                        msg = (
                            f'the nodes did not come up within {options.startup_timeout_s:g} s '
                            f'(logs in {run_dir})'
                        )
                        raise MissionError(msg)
                    continue
                if progress is not None and monitor.sim_time_s + 1e-9 >= next_report_s:
                    next_report_s += spec.progress_period_s
                    progress(_progress(monitor, wall_start))
            # Let the recorder take the last messages, then stop the robots.
            drain_until = time.monotonic() + 0.5
            while time.monotonic() < drain_until:
                executor.spin_once(timeout_sec=_POLL_PERIOD_S)
            _stop_children(children, options.stop_timeout_s)
        try:
            outcome = read_outcome(outcome_path)
        except MissionFileError as err:
            msg = f'the sim bridge ended without an outcome: {err} (logs in {run_dir})'
            raise MissionError(msg) from err
        result = _result_from_outcome(spec, outcome, time.perf_counter() - wall_start)
        if interrupt.requested:
            result = _replace_reason(result, StopReason.INTERRUPTED)
        if progress is not None:
            progress(
                MissionProgress(
                    result.sim_time_s,
                    result.wall_time_s,
                    result.rooms_covered,
                    result.rooms_total,
                )
            )
        failed = False
        return result
    finally:
        if any(c.process.poll() is None for c in children):
            _stop_children(children, options.stop_timeout_s)
        for child in children:
            if not child.log.closed:
                child.log.close()
        for node in reversed(nodes):
            executor.remove_node(node)
            node.destroy_node()
        executor.shutdown()
        if owns_context:
            rclpy.try_shutdown()
        if temporary and not failed:
            shutil.rmtree(run_dir, ignore_errors=True)


def _inject_crashes(
    crashes: Sequence[NodeCrash],
    sim_time_s: float,
    children: list[_Child],
    run_dir: Path,
    pending: dict[str, NodeCrash],
) -> None:
    """Kill the robots whose crash time has come; restart those whose time has come.
    ``pending`` holds the robots killed on purpose and not (yet) restarted."""
    for crash in crashes:
        index = crash.robot + 1  # children[0] is the bridge
        child = children[index]
        due = sim_time_s + 1e-9 >= crash.time_s
        if not child.crashed and due and child.process.poll() is None:
            _signal_group(child, signal.SIGKILL)
            child.process.wait()
            child.log.close()
            child.crashed = True
            pending[crash.name] = crash
            continue
        restart_s = None if crash.restart_after_s is None else crash.time_s + crash.restart_after_s
        if crash.name in pending and restart_s is not None and sim_time_s + 1e-9 >= restart_s:
            restarted = _start(child.command, run_dir, restart=True)
            restarted.crashed = True
            children[index] = restarted
            del pending[crash.name]


def _replace_reason(result: MissionResult, reason: str) -> MissionResult:
    import dataclasses

    return dataclasses.replace(result, stop_reason=reason)


def _progress(monitor: _Monitor, wall_start: float) -> MissionProgress:
    return MissionProgress(
        sim_time_s=monitor.sim_time_s,
        wall_time_s=time.perf_counter() - wall_start,
        rooms_covered=monitor.rooms_covered,
        rooms_total=monitor.rooms_total,
    )


def _raise_crash(child: _Child, status: int) -> None:
    how = f'was killed by signal {-status}' if status < 0 else f'exited with status {status}'
    last = child.last_line()
    detail = f'; its last log line: {last}' if last else ''
    msg = (
        f'{child.command.name} ({child.command.executable}) {how} before the mission ended'
        f'{detail} (log: {child.log_path})'
    )
    raise MissionError(msg)


# The spawners' options -------------------------------------------------------------------


class DryRunDone(Exception):  # noqa: N818  (a control-flow signal, not an error)
    """Raised by the ``--dry-run`` runner once the command lines are printed."""


def _dry_run(run_dir: Path | None, out: IO[str]) -> Callable[..., MissionResult]:
    def runner(spec: MissionSpec, **_: Any) -> MissionResult:
        directory = run_dir or Path(tempfile.mkdtemp(prefix='swarm-processes-'))
        for command in mission_commands(spec, directory):
            print(format_command(command), file=out, flush=True)
        print(f'# the mission file is in {directory}', file=sys.stderr, flush=True)
        raise DryRunDone

    return runner


def process_runner(args: Any, out: IO[str] | None = None) -> Callable[..., MissionResult] | None:
    """The mission runner the spawner options ``--processes``, ``--dry-run`` and
    ``--run-dir`` ask for; None for the in-process runner.

    Raises:
        ExperimentError: ``--dry-run`` or ``--run-dir`` without ``--processes``, or
            ``--processes`` with ``--runtime builtin``.
    """
    if not args.processes:
        if args.dry_run or args.run_dir is not None:
            raise ExperimentError('--dry-run and --run-dir need --processes')
        if split_crash_faults(args.fault)[1]:
            raise ExperimentError('--fault crash:... kills a node process: it needs --processes')
        return None
    if args.runtime == 'builtin':
        msg = '--processes runs every node on real rclpy; leave out --runtime builtin'
        raise ExperimentError(msg)
    _, crashes = split_crash_faults(args.fault)
    if args.dry_run:
        return _dry_run(args.run_dir, out or sys.stdout)
    options = ProcessOptions(run_dir=args.run_dir, crashes=crashes)

    def runner(spec: MissionSpec, **kwargs: Any) -> MissionResult:
        return run_mission_processes(spec, options=options, **kwargs)

    return runner


#: The spawners' console scripts and their modules.
SPAWNERS = {
    'spawn': 'swarm_experiments.spawn',
    'spawn_bayes_swarm': 'swarm_experiments.spawn_bayes_swarm',
    'spawn_msc_pf': 'swarm_experiments.spawn_msc_pf',
}


def spawner_commands(spawner: str, argv: Sequence[str], run_dir: Path) -> list[NodeCommand]:
    """The node commands ``<spawner> --processes --dry-run --run-dir RUN_DIR ARGV`` prints
    (the mission file is written into ``run_dir``).

    Raises:
        ExperimentError: an unknown spawner, or options it rejects.
    """
    import importlib
    import io

    if spawner not in SPAWNERS:
        msg = f'unknown spawner {spawner!r}; choose one of {", ".join(SPAWNERS)}'
        raise ExperimentError(msg)
    main = importlib.import_module(SPAWNERS[spawner]).main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(['--processes', '--dry-run', '--run-dir', str(run_dir), *argv])
    if status != 0:
        lines = err.getvalue().strip().splitlines()
        raise ExperimentError(lines[0] if lines else f'{spawner} exited with status {status}')
    return [parse_command(line) for line in out.getvalue().splitlines()]
