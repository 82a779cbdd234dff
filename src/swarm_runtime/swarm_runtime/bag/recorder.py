"""A node that records topics of the running graph into a rosbag2 MCAP bag.

It works like ``ros2 bag record -s mcap`` and runs on both runtimes: it discovers topics with
``get_topic_names_and_types()`` (at start and then every ``discovery_period_s``, by default
0.1 s like rosbag2's polling interval), subscribes to the chosen ones with ``raw=True`` so
messages arrive as CDR bytes and are written without decoding, and stamps each message with
the node's clock (sim time under ``use_sim_time``).

For each topic it records the QoS profiles its publishers announce
(``get_publishers_info_by_topic``) as ``offered_qos_profiles`` and subscribes with a profile
that matches all of them: reliable only if every publisher is, transient-local only if every
publisher is, so a latched message published before the recorder started or before its
discovery found the topic is recorded too. Where no publisher can be reported (the topic has
only subscriptions so far, or a runtime lacks endpoint info), the profile declared for the
topic in ``offered_qos`` is used in its place; a topic without one gets a best-effort,
volatile subscription, which matches any publisher but misses latched history.

As with ``ros2 bag record``, a volatile message published before discovery found its topic
is not recorded.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Iterable, Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import Any

from ..ros import (
    HistoryPolicy,
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    message_module,
)
from .conversions import qos_to_rosbags
from .errors import BagError
from .writer import BagWriter

__all__ = ['RECORDER_QUEUE_DEPTH', 'BagRecorder', 'is_hidden_topic']

#: Depth of the recorder's subscriptions: a burst of this many messages on one topic between
#: two executor turns is recorded without loss.
RECORDER_QUEUE_DEPTH = 1000


def is_hidden_topic(topic: str) -> bool:
    """ROS hides topics with a name part starting with '_' (rosbag2 skips them by default)."""
    return any(part.startswith('_') for part in topic.split('/'))


def _matches(topic: str, patterns: Iterable[str]) -> bool:
    return any(fnmatch.fnmatchcase(topic, pattern) for pattern in patterns)


class BagRecorder(Node):
    """Record topics into a new bag at ``output`` until the node is destroyed.

    Args:
        output: Bag directory to create (must not exist).
        topics: Topic names or glob patterns ('/r*/scan'); None records every topic.
        exclude: Names or patterns never recorded.
        include_hidden: Also record hidden topics (a name part starting with '_').
        offered_qos: Topic name or pattern -> QoS profile to record as offered (and to
            subscribe for) when no publisher of the topic can be reported.
        node_name: Name of the recorder node.
        discovery_period_s: How often new topics are looked for [s, node clock] (rosbag2's
            default polling interval).
        flush_period_s: How often buffered messages are pushed to disk [s, node clock],
            so a crash loses at most this much.
        use_sim_time: Set the node's ``use_sim_time`` parameter (timestamps in sim time).
        **node_kwargs: Passed to ``Node`` (namespace, context, parameter_overrides ...).
    """

    def __init__(
        self,
        output: str | Path,
        *,
        topics: Sequence[str] | None = None,
        exclude: Sequence[str] = (),
        include_hidden: bool = False,
        offered_qos: Mapping[str, QoSProfile] | None = None,
        node_name: str = 'bag_recorder',
        discovery_period_s: float = 0.1,
        flush_period_s: float = 5.0,
        use_sim_time: bool | None = None,
        **node_kwargs: Any,
    ) -> None:
        if discovery_period_s <= 0.0 or flush_period_s <= 0.0:
            msg = 'discovery_period_s and flush_period_s must be positive'
            raise ValueError(msg)
        if use_sim_time is not None:
            overrides = list(node_kwargs.pop('parameter_overrides', None) or [])
            overrides.append(Parameter('use_sim_time', value=use_sim_time))
            node_kwargs['parameter_overrides'] = overrides
        self._writer = BagWriter(output)
        super().__init__(node_name, **node_kwargs)
        self._patterns = tuple(topics) if topics else None
        self._exclude = tuple(exclude)
        self._include_hidden = include_hidden
        self._offered_qos = dict(offered_qos or {})
        self._subscriptions_by_topic: dict[str, Any] = {}
        self._skipped: set[str] = set()
        self._failed_topics: set[str] = set()
        self._message_count = 0
        try:
            self._writer.open()
        except BagError:
            super().destroy_node()
            raise
        self._discover()
        self._discovery_timer = self.create_timer(discovery_period_s, self._discover)
        self._flush_timer = self.create_timer(flush_period_s, self._flush)

    @property
    def path(self) -> Path:
        """The bag directory being written."""
        return self._writer.path

    @property
    def recorded_topics(self) -> dict[str, str]:
        """Topic -> type name of every topic being recorded."""
        return self._writer.topics

    @property
    def message_count(self) -> int:
        """Number of messages written so far."""
        return self._message_count

    def _wanted(self, topic: str) -> bool:
        if not self._include_hidden and is_hidden_topic(topic):
            return False
        if _matches(topic, self._exclude):
            return False
        return self._patterns is None or _matches(topic, self._patterns)

    def _discover(self) -> None:
        """Subscribe to every wanted topic not recorded yet."""
        for topic, types in self.get_topic_names_and_types():
            if topic in self._subscriptions_by_topic or topic in self._skipped:
                continue
            if not self._wanted(topic):
                self._skipped.add(topic)
                continue
            if len(types) != 1:
                self.get_logger().warning(
                    f'not recording {topic}: it carries several types ({", ".join(types)})'
                )
                self._skipped.add(topic)
                continue
            self._start_recording(topic, types[0])

    def _start_recording(self, topic: str, typename: str) -> None:
        package, _, name = typename.split('/')
        try:
            msg_type = getattr(message_module(package), name)
        except (ImportError, AttributeError, LookupError) as err:
            self.get_logger().warning(f'not recording {topic}: no message class for {typename}')
            self.get_logger().debug(str(err))
            self._skipped.add(topic)
            return
        offered = self._publisher_qos(topic) or self._fallback_qos(topic)
        try:
            self._writer.add_topic(
                topic, typename, offered_qos_profiles=[qos_to_rosbags(q) for q in offered]
            )
        except BagError as err:
            self.get_logger().error(f'not recording {topic}: {err}')
            self._skipped.add(topic)
            return
        self._subscriptions_by_topic[topic] = self.create_subscription(
            msg_type,
            topic,
            partial(self._record, topic),
            self._subscription_qos(offered),
            raw=True,
        )
        self.get_logger().info(f'recording {topic} ({typename})')

    def _publisher_qos(self, topic: str) -> list[QoSProfile]:
        """QoS announced by the topic's publishers; empty if none can be reported."""
        try:
            endpoints = self.get_publishers_info_by_topic(topic)
        except (AttributeError, NotImplementedError, RuntimeError):
            return []
        return [endpoint.qos_profile for endpoint in endpoints]

    def _fallback_qos(self, topic: str) -> list[QoSProfile]:
        """The profile declared in ``offered_qos`` for ``topic``, if any."""
        for pattern, profile in self._offered_qos.items():
            if fnmatch.fnmatchcase(topic, pattern):
                return [profile]
        return []

    @staticmethod
    def _subscription_qos(offered: list[QoSProfile]) -> QoSProfile:
        """A profile that matches every offered one (best effort/volatile when none is known)."""
        reliable = bool(offered) and all(
            q.reliability == ReliabilityPolicy.RELIABLE for q in offered
        )
        latched = bool(offered) and all(
            q.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL for q in offered
        )
        return QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=RECORDER_QUEUE_DEPTH,
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=(
                QoSDurabilityPolicy.TRANSIENT_LOCAL if latched else QoSDurabilityPolicy.VOLATILE
            ),
        )

    def _record(self, topic: str, data: bytes) -> None:
        try:
            self._writer.write(topic, self.get_clock().now().nanoseconds, data)
        except BagError as err:
            if topic not in self._failed_topics:
                self._failed_topics.add(topic)
                self.get_logger().error(f'cannot record a message of {topic}: {err}')
            return
        self._message_count += 1

    def _flush(self) -> None:
        try:
            self._writer.flush()
        except BagError as err:
            self.get_logger().error(str(err))

    def destroy_node(self) -> None:
        """Stop recording, finish the bag (MCAP summary and metadata.yaml), destroy the node."""
        try:
            if self._writer.is_open:
                self._writer.close()
                self.get_logger().info(
                    f'wrote {self._message_count} messages on '
                    f'{len(self._writer.topics)} topics to {self._writer.path}'
                )
        except BagError as err:
            self.get_logger().error(str(err))
        finally:
            super().destroy_node()
