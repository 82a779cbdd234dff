"""Headless mission runner shared by every spawner: bridge + N robot nodes on sim time.

A mission is one simulated run: the sim bridge node (world, sensors, extensions), one
algorithm node per robot in its namespace (``/r0``, ``/r1``, ...) with ``use_sim_time`` on,
an optional rosbag2 recorder, all in one executor. :func:`run_mission` spins it until every
room is covered, an extension reports its mission done, a caller's predicate says stop, or
the sim-time budget ends, and returns a :class:`MissionResult` (coverage, trajectories,
timing). Ctrl-C (SIGINT, in the main thread) stops it at the next physics step like any other
stop condition (``StopReason.INTERRUPTED``): the result covers the run so far and the bag is
closed; a second Ctrl-C raises KeyboardInterrupt at once (the bag is still closed).

The runner is the only place that knows how the pieces are wired, so the OA-Bug,
Bayes-Swarm and MSC spawners are short scripts around it::

    spec = MissionSpec(
        site=site,
        initial_poses=poses,
        robots=[RobotNodeSpec(OABugNode, {'robot_index': i}) for i in range(n)],
        max_sim_time_s=300.0,
    )
    result = run_mission(spec, progress=print)
"""

from __future__ import annotations

import math
import signal
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
from sim_bridge.bridge_node import SimBridgeNode
from sim_bridge.extensions import SimExtension
from swarm_runtime.ros import (
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    SingleThreadedExecutor,
    rclpy,
    using_real_rclpy,
)
from swarm_sim.engine import EngineConfig, SimEngine, StepOutput
from swarm_sim.errors import ConfigurationError
from swarm_sim.ground_truth import RoomEntry
from swarm_sim.mission_rules import (
    ALL_ROOMS_COVERED,
    BUDGET,
    EXTENSION_DONE,
    TIME_TOLERANCE_S,
    TrajectorySampler,
    end_reason,
)

from swarm_experiments.errors import MissionError

__all__ = [
    'RECORD_TOPIC_SETS',
    'VIEWER_TOPICS',
    'MissionProgress',
    'MissionResult',
    'MissionSpec',
    'RecordingSpec',
    'RobotNodeSpec',
    'StopReason',
    'recorded_topics',
    'run_mission',
]

NodeFactory = Callable[..., Any]

#: What Foxglove and RViz need to show a recorded run: the transform tree and the site's
#: markers (sim_bridge.visualization). Every spawner records them by default.
VIEWER_TOPICS = ('/tf', '/tf_static', '/sim/markers/*')

#: What a spawner's ``--record`` writes (``--record-topics``): 'sensors' (the default) the
#: mission's topics plus every topic the robots' nodes subscribe to, so ``BagPlayer`` can feed
#: the recording back into a node; 'mission' only the mission's topics (ground truth, the
#: robots' states and commands, the viewer topics), for big studies; 'all' every topic the
#: graph shows (``/rosout`` and ``/parameter_events`` excepted, see docs/bags.md).
RECORD_TOPIC_SETS = ('sensors', 'mission', 'all')


def recorded_topics(
    which: str, *, mission: Sequence[str], sensors: Sequence[str]
) -> tuple[str, ...] | None:
    """The topics (names or patterns) of the record set ``which`` (one of
    :data:`RECORD_TOPIC_SETS`); None for 'all' (the recorder then takes every topic).

    Raises:
        ConfigurationError: ``which`` is not a record set.
    """
    if which == 'mission':
        return tuple(mission)
    if which == 'sensors':
        return (*mission, *(t for t in sensors if t not in mission))
    if which == 'all':
        return None
    msg = f'unknown record topic set {which!r}; choose one of {", ".join(RECORD_TOPIC_SETS)}'
    raise ConfigurationError(msg)


# Callbacks run per node after the stop, to deliver the messages of the last step.
_DRAIN_CALLBACKS_PER_NODE = 20


class StopReason:
    """Why a mission ended (string constants, also used in reports)."""

    ALL_ROOMS_COVERED = ALL_ROOMS_COVERED
    BUDGET = BUDGET
    EXTENSION_DONE = EXTENSION_DONE
    PREDICATE = 'predicate'
    INTERRUPTED = 'interrupted'


@dataclass(frozen=True)
class RobotNodeSpec:
    """How to build one robot's algorithm node.

    Attributes:
        factory: called as ``factory(namespace='/r0', parameter_overrides=[...])``; a Node
            subclass whose constructor forwards keyword arguments to rclpy's Node works.
        parameters: parameter overrides (name -> value); ``use_sim_time`` is set to True.
        executable: (package, executable) of the node's ``ros2 run`` command, for a run with
            one process per node (:mod:`swarm_experiments.processes`).
    """

    factory: NodeFactory
    parameters: Mapping[str, Any] = field(default_factory=dict)
    executable: tuple[str, str] | None = None


@dataclass(frozen=True)
class RecordingSpec:
    """What to record into a rosbag2 directory (MCAP storage).

    Attributes:
        path: the bag directory to create; it must not exist yet.
        topics: absolute topic names to record; None records every topic.
        latched_topics: topics (names or patterns) published with transient-local durability
            (the site, the coverage, the static transforms, the markers): the recorder
            subscribes to them transient-local so it gets what was published before it
            started.
        staging: record into a hidden sibling ``.<name>.<pid>.partial`` and rename it to
            ``path`` when the bag is closed, so a killed run leaves no bag under ``path``.
    """

    path: Path
    topics: tuple[str, ...] | None = None
    latched_topics: tuple[str, ...] = ('/sim/site', '/sim/coverage', '/tf_static', '/sim/markers/*')
    staging: bool = True


@dataclass(frozen=True)
class MissionSpec:
    """Everything a mission needs.

    Attributes:
        site: a :class:`swarm_sim.sites.model.Site` (or an engine ``SiteGeometry``).
        initial_poses: (N, 3) start poses x [m], y [m], yaw [rad]; robot i is ``r{i}``.
        robots: N node specs, one per robot, in robot order.
        max_sim_time_s: sim-time budget [s].
        engine_config: world configuration (seed, rates, noise).
        bridge_parameters: extra bridge parameters (e.g. peer relay: peer_msg_type,
            comm_range_m, peer_loss_probability).
        extensions: mission-specific world parts attached to the bridge.
        stop_when_all_rooms_covered: end the run once every room is covered.
        recording: optional bag recording.
        progress_period_s: sim-time interval between progress reports [s].
        trajectory_period_s: sim-time interval between stored true poses [s].
        time_scale: sim seconds per wall second of the bridge's physics timer (its
            ``real_time_factor``, unless ``bridge_parameters`` sets that). On real rclpy the
            mission runs this much faster than real time, as far as the nodes keep up; the
            built-in runtime runs as fast as it can whatever it is.
        extension_entries: the ``extensions`` as mission-file entries
            (:mod:`sim_bridge.mission_file`), for a bridge in a process of its own.
    """

    site: Any
    initial_poses: np.ndarray
    robots: Sequence[RobotNodeSpec]
    max_sim_time_s: float
    engine_config: EngineConfig = field(default_factory=EngineConfig)
    bridge_parameters: Mapping[str, Any] = field(default_factory=dict)
    extensions: Sequence[SimExtension] = ()
    stop_when_all_rooms_covered: bool = True
    recording: RecordingSpec | None = None
    progress_period_s: float = 10.0
    trajectory_period_s: float = 0.5
    time_scale: float = 1.0
    extension_entries: Sequence[Mapping[str, Any]] = ()

    def __post_init__(self) -> None:
        poses = np.asarray(self.initial_poses, dtype=float)
        if poses.ndim != 2 or poses.shape[1] != 3:
            msg = f'initial_poses must have shape (N, 3), got {poses.shape}'
            raise ConfigurationError(msg)
        if len(self.robots) != len(poses):
            msg = f'{len(self.robots)} robot node specs for {len(poses)} start poses'
            raise ConfigurationError(msg)
        if not (math.isfinite(self.max_sim_time_s) and self.max_sim_time_s > 0.0):
            msg = f'max_sim_time_s must be positive and finite, got {self.max_sim_time_s}'
            raise ConfigurationError(msg)
        if not (self.progress_period_s > 0.0 and self.trajectory_period_s > 0.0):
            raise ConfigurationError('progress_period_s and trajectory_period_s must be > 0')
        if not (math.isfinite(self.time_scale) and self.time_scale > 0.0):
            msg = f'time_scale must be positive and finite, got {self.time_scale}'
            raise ConfigurationError(msg)


@dataclass(frozen=True)
class MissionProgress:
    """A progress report.

    Attributes:
        sim_time_s: sim time [s].
        wall_time_s: wall time since the run started [s].
        rooms_covered: rooms entered so far.
        rooms_total: rooms of the site.
    """

    sim_time_s: float
    wall_time_s: float
    rooms_covered: int
    rooms_total: int

    @property
    def coverage(self) -> float:
        """Covered fraction of the rooms."""
        return self.rooms_covered / self.rooms_total if self.rooms_total else 1.0

    @classmethod
    def of_engine(cls, engine: SimEngine, wall_start_s: float) -> MissionProgress:
        """The progress of ``engine`` now, for a run that started at ``wall_start_s``
        (a :func:`time.perf_counter` reading)."""
        return cls(
            sim_time_s=engine.time_s,
            wall_time_s=time.perf_counter() - wall_start_s,
            rooms_covered=engine.coverage.rooms_covered,
            rooms_total=engine.coverage.rooms_total,
        )


@dataclass(frozen=True)
class MissionResult:
    """Outcome of one mission.

    Attributes:
        robot_names: r0..r{N-1}.
        site: the site simulated.
        stop_reason: one of the :class:`StopReason` constants.
        sim_time_s: sim time at the end [s].
        wall_time_s: wall time of the run [s].
        rooms_total: rooms of the site.
        room_entries: first entries, in order.
        trajectory_times_s: (T,) sim times of the stored poses [s].
        trajectories: (T, N, 3) true poses at those times.
        distance_travelled_m: (N,) path length of each robot [m].
        bag_path: the recorded bag directory, if any.
        extension_outcomes: with one process per node, each extension's outcome as the
            bridge reported it (:func:`sim_bridge.mission_file.extension_outcome`); empty
            in process, where the caller holds the extensions themselves.
    """

    robot_names: tuple[str, ...]
    site: Any
    stop_reason: str
    sim_time_s: float
    wall_time_s: float
    rooms_total: int
    room_entries: tuple[RoomEntry, ...]
    trajectory_times_s: np.ndarray
    trajectories: np.ndarray
    distance_travelled_m: np.ndarray
    bag_path: Path | None = None
    extension_outcomes: tuple[Mapping[str, Any], ...] = ()

    @classmethod
    def of_engine(
        cls,
        engine: SimEngine,
        *,
        robot_names: Sequence[str],
        site: Any,
        stop_reason: str,
        wall_time_s: float,
        times: list[float],
        poses: list[np.ndarray],
        bag_path: Path | None = None,
    ) -> MissionResult:
        """The outcome of a run that ended on ``engine``, with the poses stored at ``times``
        (the final pose is appended when the last sample is older than the engine's time)."""
        if times[-1] < engine.time_s:
            times.append(engine.time_s)
            poses.append(engine.world.poses)
        return cls(
            robot_names=tuple(robot_names),
            site=site,
            stop_reason=stop_reason,
            sim_time_s=engine.time_s,
            wall_time_s=wall_time_s,
            rooms_total=engine.coverage.rooms_total,
            room_entries=engine.coverage.entries,
            trajectory_times_s=np.array(times),
            trajectories=np.stack(poses),
            distance_travelled_m=engine.distance_travelled_m.copy(),
            bag_path=bag_path,
        )

    @property
    def rooms_covered(self) -> int:
        """Rooms entered by the end."""
        return len(self.room_entries)

    @property
    def coverage(self) -> float:
        """Covered fraction of the rooms at the end."""
        return self.rooms_covered / self.rooms_total if self.rooms_total else 1.0

    def coverage_curve(self) -> tuple[np.ndarray, np.ndarray]:
        """(times [s], covered fraction) step curve from t = 0 to the end of the run."""
        times = [0.0, *(e.time_s for e in self.room_entries), self.sim_time_s]
        counts = [0, *range(1, self.rooms_covered + 1), self.rooms_covered]
        total = max(self.rooms_total, 1)
        return np.array(times), np.array(counts, dtype=float) / total


class _Observer:
    """Collects progress and trajectories from the bridge's step listener."""

    def __init__(self, bridge: SimBridgeNode, spec: MissionSpec) -> None:
        self.bridge = bridge
        self.spec = spec
        self.trajectory = TrajectorySampler.starting_at(
            bridge.engine.world.poses, spec.trajectory_period_s
        )
        bridge.step_listeners.append(self.on_step)

    def on_step(self, out: StepOutput) -> None:
        self.trajectory.offer(out.time_s, out.poses)


def _spin_until(executor: Any, predicate: Callable[[], bool]) -> None:
    """Spin until ``predicate()``; sim-time aware with the built-in runtime."""
    if not using_real_rclpy():
        try:
            from swarm_runtime.simulation import spin_until
        except ImportError:
            spin_until = None
        if spin_until is not None:
            spin_until(executor, predicate)
            return
    while not predicate():
        executor.spin_once(timeout_sec=0.1)


def _make_recorder(recording: RecordingSpec) -> Any:
    """A bag recorder on sim time; built last, so it discovers every topic at once."""
    try:
        from swarm_runtime.bag import BagRecorder
    except ImportError as err:
        msg = f'bag recording needs swarm_runtime.bag: {err}'
        raise MissionError(msg) from err
    topics = list(recording.topics) if recording.topics is not None else None
    latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
    return BagRecorder(
        recording.path,
        topics=topics,
        offered_qos=dict.fromkeys(recording.latched_topics, latched),
        use_sim_time=True,
        staging=recording.staging,
    )


class _InterruptRequest:
    """While entered (in the main thread): the first SIGINT asks the mission to stop at the
    next step, a second one raises KeyboardInterrupt."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: Any = None
        self._installed = False

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> _InterruptRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handle)
            self._installed = True
        return self

    def __exit__(self, *exc: object) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)
            self._installed = False


def run_mission(
    spec: MissionSpec,
    *,
    progress: Callable[[MissionProgress], None] | None = None,
    stop: Callable[[MissionProgress], bool] | None = None,
) -> MissionResult:
    """Run one mission to its stop condition.

    Args:
        spec: the mission.
        progress: called every ``spec.progress_period_s`` of sim time and at the end.
        stop: optional extra stop predicate, checked at every progress period.

    Ctrl-C ends the run at the next physics step with ``StopReason.INTERRUPTED``.

    Raises:
        MissionError: a node could not be built or failed during the run.
        ConfigurationError: the spec or a parameter is invalid.
    """
    owns_context = not rclpy.ok()
    if owns_context:
        rclpy.init(args=[])
    nodes: list[Any] = []
    executor = SingleThreadedExecutor()
    wall_start = time.perf_counter()
    interrupt = _InterruptRequest()
    try:
        bridge_values = {'real_time_factor': float(spec.time_scale), **spec.bridge_parameters}
        bridge_overrides = [Parameter(k, value=v) for k, v in bridge_values.items()]
        bridge = SimBridgeNode(
            site=spec.site,
            initial_poses=np.asarray(spec.initial_poses, dtype=float),
            engine_config=spec.engine_config,
            extensions=spec.extensions,
            parameter_overrides=bridge_overrides,
        )
        nodes.append(bridge)
        for i, robot in enumerate(spec.robots):
            overrides = [Parameter('use_sim_time', value=True)]
            overrides += [Parameter(k, value=v) for k, v in robot.parameters.items()]
            try:
                node = robot.factory(namespace=f'/r{i}', parameter_overrides=overrides)
            except Exception as err:
                msg = f'robot r{i}: its node could not be built: {err}'
                raise MissionError(msg) from err
            nodes.append(node)
        if spec.recording is not None:
            nodes.append(_make_recorder(spec.recording))
        for node in nodes:
            executor.add_node(node)
        observer = _Observer(bridge, spec)
        engine = bridge.engine
        state: dict[str, Any] = {
            'reason': StopReason.BUDGET,
            'next_report_s': 0.0,
            'checked_step': -1,
        }

        def snapshot() -> MissionProgress:
            return MissionProgress.of_engine(engine, wall_start)

        def finished() -> bool:
            if interrupt.requested:
                state['reason'] = StopReason.INTERRUPTED
                return True
            # The state only changes at physics steps; skip the checks between them.
            if engine.step_index == state['checked_step']:
                return False
            state['checked_step'] = engine.step_index
            reason = end_reason(
                engine,
                stop_when_all_rooms_covered=spec.stop_when_all_rooms_covered,
                max_sim_time_s=spec.max_sim_time_s,
                extensions_done=bridge.extensions_done if bridge.extensions else None,
            )
            if reason:
                state['reason'] = reason
                return True
            if engine.time_s + TIME_TOLERANCE_S >= state['next_report_s']:
                state['next_report_s'] += spec.progress_period_s
                report = snapshot()
                if progress is not None:
                    progress(report)
                if stop is not None and stop(report):
                    state['reason'] = StopReason.PREDICATE
                    return True
            return False

        try:
            with interrupt:
                _spin_until(executor, finished)
        except (MissionError, ConfigurationError):
            raise
        except Exception as err:
            msg = f'the mission failed at sim time {engine.time_s:.2f} s: {err!r}'
            raise MissionError(msg) from err
        # Deliver what the last step published (e.g. to the bag) without stepping further.
        bridge.pause()
        for _ in range(_DRAIN_CALLBACKS_PER_NODE * len(nodes)):
            executor.spin_once(timeout_sec=0.0)
        final = snapshot()
        if progress is not None:
            progress(final)
        return MissionResult.of_engine(
            engine,
            robot_names=bridge.robot_names,
            site=spec.site,
            stop_reason=str(state['reason']),
            wall_time_s=final.wall_time_s,
            times=observer.trajectory.times_s,
            poses=observer.trajectory.poses,
            bag_path=spec.recording.path if spec.recording is not None else None,
        )
    finally:
        for node in reversed(nodes):
            executor.remove_node(node)
            node.destroy_node()
        executor.shutdown()
        if owns_context:
            rclpy.try_shutdown()
