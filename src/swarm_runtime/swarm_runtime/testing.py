"""Testing nodes through their topics, the same way on the built-in runtime and real rclpy.

A :class:`NodeTestBed` owns a context of its own, an executor, the nodes under test and a
:class:`Probe` node that stands in for the rest of the graph: it plays input messages at a
fixed period, can publish ``/clock`` for nodes on sim time, and collects what the nodes
publish::

    from swarm_runtime.testing import NodeTestBed

    with NodeTestBed() as bed:
        node = bed.add_node(OABugNode, namespace='/r0')
        commands = bed.probe.collect('/r0/cmd_vel', geometry_msgs.Twist)
        scan = bed.probe.player('/r0/scan', sensor_msgs.LaserScan)
        bed.wait_for_graph()            # every probe endpoint matched by the node's
        scan.play(scan_msg)             # published every 0.1 s from now on
        assert bed.spin_until(lambda: commands and commands[-1].linear.x > 0.0)

On the built-in runtime the executor is the deterministic one and time is its virtual wall
clock (or the probe's ``/clock``): ``spin_for(2.0)`` takes milliseconds and gives the same
result every run. On real rclpy the executor is rclpy's, the messages go through DDS
(between nodes of one process, as between processes), discovery takes time (hence
:meth:`NodeTestBed.wait_for_graph`) and ``spin_for(2.0)`` takes two seconds. Tests written
against this module therefore assert what holds on a robot too: that an output arrives,
its content, rates within a margin, never exact timings.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from swarm_runtime.ros import message_module, rclpy, using_real_rclpy

__all__ = ['GraphNotMatchedError', 'NodeTestBed', 'Player', 'Probe', 'cdr_roundtrip']

NodeT = TypeVar('NodeT')

# The probe's tick: players and the /clock publisher run on it.
DEFAULT_TICK_S = 0.01


class GraphNotMatchedError(AssertionError):
    """Endpoints of the probe did not match the nodes' within the timeout (names them)."""


def cdr_roundtrip(message: Any) -> Any:
    """Return what a subscriber in another process receives when ``message`` is published.

    Serializes with the runtime in use: rclpy's ``serialize_message`` / ``deserialize_message``
    (the rmw's type support), or the built-in runtime's CDR codec.
    """
    if using_real_rclpy():
        serialization = importlib.import_module('rclpy.serialization')
        data = serialization.serialize_message(message)
        return serialization.deserialize_message(data, type(message))
    from swarm_runtime.messages import cdr_roundtrip as builtin_roundtrip

    return builtin_roundtrip(message)


class Player:
    """A probe publisher; optionally re-publishes one message at a fixed period."""

    def __init__(self, probe: Probe, publisher: Any, period_s: float, expected: int) -> None:
        self._probe = probe
        self.publisher = publisher
        self.period_s = period_s
        self.expected_subscriptions = expected
        self.message: Any = None
        self._next_s: float | None = None

    @property
    def topic_name(self) -> str:
        """The resolved topic name."""
        return str(self.publisher.topic_name)

    def publish(self, message: Any) -> None:
        """Publish ``message`` once, now."""
        self.publisher.publish(message)

    def play(self, message: Any) -> None:
        """Publish ``message`` at the next probe tick and then every ``period_s``; None stops."""
        self.message = message
        self._next_s = None

    def _tick(self, now_s: float) -> None:
        if self.message is None:
            return
        if self._next_s is None or now_s >= self._next_s - 1e-9:
            self.publisher.publish(self.message)
            base = now_s if self._next_s is None else self._next_s
            self._next_s = max(base + self.period_s, now_s)


class Probe:
    """The node that plays inputs, publishes ``/clock`` and collects outputs in a test bed."""

    def __init__(self, node: Any, *, clock_step_s: float | None, clock_start_s: float) -> None:
        self.node = node
        self._players: list[Player] = []
        self._collectors: list[tuple[Any, int]] = []
        self._clock_step_ns = None if clock_step_s is None else round(clock_step_s * 1e9)
        self._clock_ns = round(clock_start_s * 1e9)
        self._clock_pub: Any = None
        if self._clock_step_ns is not None:
            rosgraph_msgs = message_module('rosgraph_msgs')
            clock_qos = rclpy.qos.QoSProfile(
                depth=1, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT
            )
            self._clock_pub = node.create_publisher(rosgraph_msgs.Clock, '/clock', clock_qos)
            self._clock_msg = rosgraph_msgs.Clock()

    @property
    def clock_running(self) -> bool:
        """Whether this probe publishes ``/clock``."""
        return self._clock_pub is not None

    def sim_time_s(self) -> float:
        """The time last published on ``/clock`` (the start time before the first tick)."""
        return self._clock_ns / 1e9

    def now_s(self) -> float:
        """The nodes' time: the probe's ``/clock`` when it runs one, else the ROS clock."""
        if self.clock_running:
            return self.sim_time_s()
        return self.node.get_clock().now().nanoseconds / 1e9

    def collect(
        self, topic: str, msg_type: type, qos: Any = 10, *, expect_publishers: int = 1
    ) -> list[Any]:
        """Subscribe to ``topic`` and return the list every received message is appended to.

        ``expect_publishers`` is how many publishers :meth:`NodeTestBed.wait_for_graph`
        waits for (0: none).
        """
        received: list[Any] = []
        subscription = self.node.create_subscription(msg_type, topic, received.append, qos)
        self._collectors.append((subscription, expect_publishers))
        return received

    def player(
        self,
        topic: str,
        msg_type: type,
        qos: Any = 10,
        *,
        period_s: float = 0.1,
        expect_subscriptions: int = 1,
    ) -> Player:
        """A publisher on ``topic`` whose :meth:`Player.play` repeats a message every ``period_s``.

        ``expect_subscriptions`` is how many subscriptions :meth:`NodeTestBed.wait_for_graph`
        waits for (0: none).
        """
        publisher = self.node.create_publisher(msg_type, topic, qos)
        player = Player(self, publisher, period_s, expect_subscriptions)
        self._players.append(player)
        return player

    def unmatched(self, clock_subscriptions: int) -> list[str]:
        """Endpoints of the probe with fewer matches than expected, described for an error."""
        missing = []
        for player in self._players:
            count = player.publisher.get_subscription_count()
            if count < player.expected_subscriptions:
                missing.append(
                    f'{player.topic_name}: {count} of {player.expected_subscriptions} subscriptions'
                )
        for subscription, expected in self._collectors:
            count = subscription.get_publisher_count()
            if count < expected:
                missing.append(f'{subscription.topic_name}: {count} of {expected} publishers')
        if self._clock_pub is not None:
            count = self._clock_pub.get_subscription_count()
            if count < clock_subscriptions:
                missing.append(f'/clock: {count} of {clock_subscriptions} subscriptions')
        return missing

    def _tick(self) -> None:
        if self._clock_step_ns is not None:
            self._clock_ns += self._clock_step_ns
        now_s = self.now_s()
        for player in self._players:
            player._tick(now_s)
        if self._clock_pub is not None:
            stamp = self._clock_msg.clock
            stamp.sec, stamp.nanosec = divmod(self._clock_ns, 1_000_000_000)
            self._clock_pub.publish(self._clock_msg)


class NodeTestBed:
    """Nodes under test and a probe in a fresh context, driven by one executor.

    Args:
        args: the context's command-line arguments (``['--ros-args', '-p', 'x:=1.0']``),
            which reach every node as in ``rclpy.init(args=...)``.
        tick_s: period of the probe's wall timer, on which players and ``/clock`` run.
        clock_step_s: if given, the probe publishes ``/clock`` advancing this much per tick
            (so simulated time runs ``clock_step_s / tick_s`` times faster than the wall
            clock). Nodes follow it when added with ``use_sim_time`` true.
        clock_start_s: the sim time before the first tick.
    """

    def __init__(
        self,
        args: Sequence[str] | None = None,
        *,
        tick_s: float = DEFAULT_TICK_S,
        clock_step_s: float | None = None,
        clock_start_s: float = 0.0,
    ) -> None:
        self.context = rclpy.context.Context()
        rclpy.init(args=list(args) if args is not None else [], context=self.context)
        self._nodes: list[Any] = []
        try:
            self.executor = rclpy.executors.SingleThreadedExecutor(context=self.context)
            probe_node = rclpy.create_node('probe', context=self.context)
            self._nodes.append(probe_node)
            self.probe = Probe(probe_node, clock_step_s=clock_step_s, clock_start_s=clock_start_s)
            probe_node.create_timer(tick_s, self.probe._tick)
            self.executor.add_node(probe_node)
        except BaseException:
            self.close()
            raise
        self._closed = False

    def __enter__(self) -> NodeTestBed:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def add_node(self, factory: Callable[..., NodeT], /, **kwargs: Any) -> NodeT:
        """Build a node in the bed's context (``factory(context=..., **kwargs)``) and spin it."""
        node = factory(context=self.context, **kwargs)
        self._nodes.append(node)
        self.executor.add_node(node)
        return node

    def create_node(self, node_name: str, **kwargs: Any) -> Any:
        """A plain node in the bed's context, spun with the others (for extra endpoints)."""
        return self.add_node(rclpy.node.Node, node_name=node_name, **kwargs)

    def _sim_time_nodes(self) -> int:
        return sum(
            1
            for node in self._nodes[1:]
            if node.has_parameter('use_sim_time') and node.get_parameter('use_sim_time').value
        )

    def wait_for_graph(self, timeout_s: float = 20.0) -> None:
        """Wait until every probe endpoint is matched as expected, without spinning.

        Publishers count matched subscriptions, subscriptions matched publishers, and the
        ``/clock`` publisher one subscription per node on sim time. On the built-in runtime
        endpoints match at creation; on real DDS this waits for discovery (wall time).

        Raises:
            GraphNotMatchedError: after ``timeout_s``, naming what is still unmatched.
        """
        deadline = time.monotonic() + timeout_s
        while True:
            missing = self.probe.unmatched(self._sim_time_nodes())
            if not missing:
                return
            if not using_real_rclpy() or time.monotonic() >= deadline:
                msg = f'graph not matched after {timeout_s} s: {"; ".join(missing)}'
                raise GraphNotMatchedError(msg)
            time.sleep(0.01)

    def now_s(self) -> float:
        """The nodes' time in seconds: the probe's ``/clock`` if it runs one, else wall time."""
        return self.probe.now_s()

    def wall_time_s(self) -> float:
        """Wall time in seconds: the built-in runtime's virtual wall clock, or the host's."""
        if using_real_rclpy():
            return time.monotonic()
        from swarm_runtime.simulation import wall_time_s

        return wall_time_s(self.context)

    def spin_until(self, predicate: Callable[[], bool], timeout_s: float = 10.0) -> bool:
        """Run callbacks until ``predicate()`` holds; False after ``timeout_s`` of wall time.

        The timeout is virtual wall time on the built-in runtime, real time on rclpy.
        Exceptions raised by callbacks propagate.
        """
        if using_real_rclpy():
            deadline = time.monotonic() + timeout_s
            while not predicate():
                remaining = deadline - time.monotonic()
                if remaining <= 0.0 or not self.context.ok():
                    return False
                self.executor.spin_once(timeout_sec=min(remaining, 0.05))
            return True
        from swarm_runtime.simulation import spin_until

        return spin_until(self.executor, predicate, max_wall_time_s=timeout_s)

    def spin_for(self, seconds: float) -> None:
        """Run the graph for ``seconds`` of the nodes' time (sim time when the probe runs a clock).

        Raises:
            TimeoutError: the probe's clock did not advance that far within a generous wall
                time (the executor is starved).
        """
        if self.probe.clock_running:
            end = self.probe.sim_time_s() + seconds
            reached = self.spin_until(
                lambda: self.probe.sim_time_s() >= end - 1e-9, timeout_s=10.0 + 20.0 * seconds
            )
        else:
            end = self.wall_time_s() + seconds
            reached = self.spin_until(
                lambda: self.wall_time_s() >= end - 1e-9, timeout_s=seconds + 1.0
            )
        if not reached:
            msg = f'spin_for({seconds}) did not get that far'
            raise TimeoutError(msg)

    def close(self) -> None:
        """Destroy the nodes and shut the context down (safe to call twice)."""
        if getattr(self, '_closed', False):
            return
        self._closed = True
        executor = getattr(self, 'executor', None)
        if executor is not None:
            executor.shutdown()
        for node in reversed(self._nodes):
            node.destroy_node()
        self._nodes.clear()
        rclpy.try_shutdown(context=self.context)
