"""A node that replays a bag into the running graph and drives sim time from it.

Nodes under test are started with ``use_sim_time`` and a :class:`BagPlayer` is added to the
same executor. The player publishes the recorded messages (as CDR bytes, with the recorded
QoS) and ``/clock`` with the bag's log times, so the nodes see the recording's time: for every
instant of the bag (messages sharing a log time) ``/clock`` is published first, then the
messages, in the bag's order.

Pacing runs on the player's own clock, which must not be sim time: each instant is scheduled
at ``start + (log_time - bag_start) / rate``. On real ROS that is real time; the built-in
runtime's executor jumps its virtual wall clock from one instant to the next, so a replay runs
as fast as the callbacks allow and always the same way. :meth:`BagPlayer.step` publishes the
next instant at once, for callers that drive the replay themselves.

Within an instant, a recording shows which messages its node received only after it had acted:
those recorded after the node's own output of that instant (a peer's message relayed after
the node's decision). With ``outputs`` naming the node's output topics, the player holds those
messages back and publishes them just before the next instant's ``/clock``, after the node's
callbacks of the instant, so a deterministic node on the built-in runtime receives its inputs
in the recorded order and acts exactly as it did.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosReliability

from ..ros import (
    Node,
    QoSProfile,
    message_module,
    rclpy,
)
from .conversions import matching_profile, qos_from_rosbags
from .reader import BagMessage, TopicSummary, read_bag_info, read_messages

__all__ = ['CLOCK_TOPIC', 'BagPlayer', 'replay_qos']

CLOCK_TOPIC = '/clock'
_DEFAULT_QOS_DEPTH = 10


def _selector(topics: Iterable[str] | None) -> Callable[[str], bool]:
    if topics is None:
        return lambda _topic: True
    patterns = [topics] if isinstance(topics, str) else list(topics)
    return lambda topic: any(fnmatch.fnmatchcase(topic, p) for p in patterns)


def replay_qos(offered: Sequence[Qos]) -> QoSProfile:
    """The QoS a replay publisher offers, from a topic's recorded offered profiles.

    As ``ros2 bag play`` adapts them: reliable only if every recorded publisher was,
    transient-local only if every one was; otherwise the most permissive choice, so every
    subscription that matched one of the recorded publishers matches the replay. History is
    the recorded KEEP_LAST depth where the middleware reported one; where it reported none
    (history UNKNOWN, depth 0: DDS discovery does not carry it) a latched topic keeps its last
    message and any other topic gets rclpy's default depth of 10.
    """
    if not offered:
        return QoSProfile(depth=_DEFAULT_QOS_DEPTH)
    latched = all(q.durability == QosDurability.TRANSIENT_LOCAL for q in offered)
    depths = [q.depth for q in offered if q.history == QosHistory.KEEP_LAST and q.depth > 0]
    base = qos_from_rosbags(offered[0], rclpy)
    return matching_profile(
        rclpy,
        all_reliable=all(q.reliability == QosReliability.RELIABLE for q in offered),
        all_latched=latched,
        depth=max(depths) if depths else (1 if latched else _DEFAULT_QOS_DEPTH),
        deadline=base.deadline,
        lifespan=base.lifespan,
        liveliness=base.liveliness,
        liveliness_lease_duration=base.liveliness_lease_duration,
    )


class BagPlayer(Node):
    """Publish the messages of ``bag`` and ``/clock`` from its log times.

    Args:
        bag: Bag directory (or .mcap file) to replay.
        topics: Topic names or glob patterns to replay; None replays all (except ``/clock``,
            which the player publishes itself when ``publish_clock`` is set).
        rate: Playback speed factor (2.0 replays twice as fast).
        publish_clock: Publish ``/clock`` (rosgraph_msgs/Clock) with the bag's time.
        start_paused: Do not schedule playback; call :meth:`play` or :meth:`step`.
        allow_truncated: Replay a damaged bag as far as it can be read.
        outputs: Topic names or patterns the nodes under test publish (recorded, never
            replayed). At an instant where the bag holds one of them, the replayed messages
            recorded after it are held back and published just before the next instant's
            ``/clock`` (module docstring). None: every message goes out at its instant.
        node_name: Name of the player node.
        **node_kwargs: Passed to ``Node`` (namespace, context ...).

    Raises:
        BagError: the bag cannot be read.
        ValueError: ``rate`` is not positive, or the node runs on sim time.
    """

    def __init__(
        self,
        bag: str | Path,
        *,
        topics: Iterable[str] | None = None,
        rate: float = 1.0,
        publish_clock: bool = True,
        start_paused: bool = False,
        allow_truncated: bool = False,
        outputs: Iterable[str] | None = None,
        node_name: str = 'bag_player',
        **node_kwargs: Any,
    ) -> None:
        if rate <= 0.0:
            msg = f'rate must be positive, got {rate}'
            raise ValueError(msg)
        info = read_bag_info(bag, allow_truncated=allow_truncated)
        super().__init__(node_name, **node_kwargs)
        if self.get_parameter('use_sim_time').value:
            self.destroy_node()
            msg = 'the bag player paces itself and publishes /clock: it cannot run on sim time'
            raise ValueError(msg)
        self._rate = rate
        self._publish_clock = publish_clock
        selected = _selector(topics)
        self._publishers_by_topic: dict[str, Any] = {}
        for topic, summary in sorted(info.topics.items()):
            if (publish_clock and topic == CLOCK_TOPIC) or not selected(topic):
                continue
            publisher = self._create_replay_publisher(topic, summary)
            if publisher is not None:
                self._publishers_by_topic[topic] = publisher
        replayed = set(self._publishers_by_topic)
        is_output = _selector(outputs) if outputs is not None else (lambda _topic: False)
        self._anchors = {t for t in info.topics if t not in replayed and is_output(t)}
        self._messages: Iterator[BagMessage] = read_messages(
            bag, sorted(replayed | self._anchors), allow_truncated=allow_truncated, raw=True
        )
        self._held: list[BagMessage] = []
        self._clock_publisher = (
            self.create_publisher(
                message_module('rosgraph_msgs').Clock, CLOCK_TOPIC, QoSProfile(depth=1)
            )
            if publish_clock
            else None
        )
        self._pending: BagMessage | None = next(self._messages, None)
        self._bag_start_ns = self._pending.log_time_ns if self._pending else 0
        self._last_clock_ns = -1
        self._published = 0
        self._timer: Any = None
        self._wall_start_ns: int | None = None
        if not start_paused:
            self.play()

    @property
    def finished(self) -> bool:
        """True once every message has been published."""
        return self._pending is None and not self._held

    @property
    def published_count(self) -> int:
        """Number of bag messages published so far (``/clock`` not counted)."""
        return self._published

    @property
    def bag_time_ns(self) -> int:
        """Log time of the last published instant (the bag's current time) [ns]."""
        return max(self._last_clock_ns, 0)

    def play(self) -> None:
        """Schedule playback on the player's clock from the next pending instant."""
        if self.finished or self._timer is not None:
            return
        if self._pending is None:
            self._wall_start_ns = self.get_clock().now().nanoseconds
            self._schedule()
            return
        now = self.get_clock().now().nanoseconds
        self._wall_start_ns = now - int(
            (self._pending.log_time_ns - self._bag_start_ns) / self._rate
        )
        self._schedule()

    def pause(self) -> None:
        """Stop scheduled playback; :meth:`play` resumes it."""
        if self._timer is not None:
            self.destroy_timer(self._timer)
            self._timer = None

    def step(self) -> int | None:
        """Publish the next instant now; return its log time [ns], or None when finished.

        Messages held back from the previous instant (``outputs``) go out first; after the
        last instant, one more step publishes those of the last and returns its time.
        """
        for held in self._held:
            self._publisher_for(held).publish(held.message)
            self._published += 1
        flushed = bool(self._held)
        self._held = []
        pending = self._pending
        if pending is None:
            return self._last_clock_ns if flushed else None
        log_time = pending.log_time_ns
        if self._clock_publisher is not None and log_time > self._last_clock_ns:
            stamp = message_module('builtin_interfaces').Time(
                sec=log_time // 1_000_000_000, nanosec=log_time % 1_000_000_000
            )
            self._clock_publisher.publish(message_module('rosgraph_msgs').Clock(clock=stamp))
        self._last_clock_ns = max(self._last_clock_ns, log_time)
        after_output = False
        while pending is not None and pending.log_time_ns == log_time:
            if pending.topic in self._anchors:
                after_output = True
            elif after_output:
                self._held.append(pending)
            else:
                self._publisher_for(pending).publish(pending.message)
                self._published += 1
            pending = next(self._messages, None)
        self._pending = pending
        return log_time

    def _create_replay_publisher(self, topic: str, summary: TopicSummary) -> Any:
        """A publisher of ``topic`` with the recorded QoS; None if its type is not available."""
        package, _, name = summary.typename.split('/')
        try:
            msg_type = getattr(message_module(package), name)
        except (ImportError, AttributeError, LookupError):
            self.get_logger().warning(
                f'not replaying {topic}: message type {summary.typename} is not available here'
            )
            return None
        return self.create_publisher(msg_type, topic, replay_qos(summary.offered_qos_profiles))

    def subscription_counts(self) -> dict[str, int]:
        """Topic -> number of subscriptions matched by its replay publisher.

        On real DDS, wait until the nodes under test are matched (discovery takes time)
        before :meth:`play` or :meth:`step`; create the player with ``start_paused=True``.
        """
        return {
            topic: publisher.get_subscription_count()
            for topic, publisher in self._publishers_by_topic.items()
        }

    def _publisher_for(self, message: BagMessage) -> Any:
        return self._publishers_by_topic[message.topic]

    def _schedule(self) -> None:
        """(Re)arm the one-shot timer for the pending instant."""
        if self._timer is not None:
            self.destroy_timer(self._timer)
            self._timer = None
        if self.finished or self._wall_start_ns is None:
            return
        if self._pending is None:  # only held-back messages of the last instant are left
            due = self.get_clock().now().nanoseconds
        else:
            due = self._wall_start_ns + int(
                (self._pending.log_time_ns - self._bag_start_ns) / self._rate
            )
        delay_ns = max(due - self.get_clock().now().nanoseconds, 1)
        self._timer = self.create_timer(delay_ns / 1e9, self._on_timer)

    def _on_timer(self) -> None:
        self.step()
        self._schedule()
