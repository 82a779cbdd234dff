"""A node that records topics of the running graph into a rosbag2 MCAP bag.

It works like ``ros2 bag record -s mcap`` and runs on both runtimes (the built-in one and
real rclpy on DDS). It polls the graph (``get_topic_names_and_types()``) when it starts and
then every ``discovery_period_s`` of *steady* time, so topics that DDS discovery reports late
(or that are created later) are picked up whether or not ``/clock`` runs yet. Messages arrive
through ``raw=True`` subscriptions and are written as the CDR bytes the publisher sent,
stamped with the node's clock (sim time under ``use_sim_time``).

What is recorded: the topics the caller names (names or glob patterns). ``/rosout`` and
``/parameter_events`` are recorded only when named exactly, never through a pattern or by
default; hidden topics (a name part starting with ``_``) only with ``include_hidden``.

QoS: a topic is subscribed once a publisher of it is visible, with a profile that matches
every publisher's offered one (reliable only if all are, transient-local only if all are), so
a latched message published before the recorder started is delivered from the publisher's
history. Each publisher's offered profile (``get_publishers_info_by_topic``) is recorded as
``offered_qos_profiles``, including publishers that appear later. A topic that has no
publisher yet is subscribed with the profile declared in ``offered_qos`` if there is one,
else it waits for a publisher.

Types: the definition stored for a type is this workspace's; where the publishers' type hash
(from the graph) differs from it, or the workspace does not know the type, the definition
installed on this machine (``share/<pkg>/msg``, as rosbag2 stores it) is used when its hash
matches. As with ``ros2 bag record``, a volatile message published before its topic was
subscribed is not recorded.
"""

from __future__ import annotations

import fnmatch
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

from ..ros import (
    Node,
    Parameter,
    QoSDurabilityPolicy,
    QoSProfile,
    ReliabilityPolicy,
    message_module,
    rclpy,
)
from .conversions import matching_profile, qos_to_rosbags
from .errors import BagError
from .writer import BagWriter

__all__ = ['RECORDER_QUEUE_DEPTH', 'SYSTEM_TOPICS', 'BagRecorder', 'is_hidden_topic']

#: Depth of the recorder's subscriptions: a burst of this many messages on one topic between
#: two executor turns is recorded without loss.
RECORDER_QUEUE_DEPTH = 1000
#: Topics every ROS node has; recorded only when named exactly in ``topics``.
SYSTEM_TOPICS = frozenset({'/rosout', '/parameter_events'})


def is_hidden_topic(topic: str) -> bool:
    """ROS hides topics with a name part starting with '_' (rosbag2 skips them by default)."""
    return any(part.startswith('_') for part in topic.split('/'))


def _matches(topic: str, patterns: Iterable[str]) -> bool:
    return any(fnmatch.fnmatchcase(topic, pattern) for pattern in patterns)


def type_hash_text(type_hash: Any) -> str:
    """rclpy's ``TypeHash`` as rosbag2 writes it ('RIHS01_<hex>'); '' when unknown."""
    version = getattr(type_hash, 'version', -1)
    value = bytes(getattr(type_hash, 'value', b''))
    if version != 1 or not any(value):
        return ''
    return f'RIHS01_{value.hex()}'


@dataclass
class _Topic:
    """State of one recorded topic."""

    typename: str
    subscription: Any
    publisher_gids: set[bytes] = field(default_factory=set)
    publisher_count: int = 0
    subscribed_qos: Any = None
    #: The recorded offered QoS is the declared stand-in (no publisher was visible).
    declared: bool = False


class BagRecorder(Node):
    """Record topics into a new bag at ``output`` until the node is destroyed.

    Args:
        output: Bag directory to create (must not exist).
        topics: Topic names or glob patterns ('/r*/scan') to record: on real DDS, the
            mission's topics (other nodes in the domain are visible too). None records every
            topic except the system topics.
        exclude: Names or patterns never recorded.
        include_hidden: Also record hidden topics (a name part starting with '_').
        offered_qos: Topic name or pattern -> QoS profile to record as offered (and to
            subscribe for) when no publisher of the topic can be seen.
        node_name: Name of the recorder node.
        discovery_period_s: How often the graph is polled for new topics and publishers
            [s, steady time] (rosbag2's default polling interval).
        flush_period_s: How often buffered messages are pushed to disk [s, steady time],
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
        self._patterns = tuple(topics) if topics is not None else None
        self._exclude = tuple(exclude)
        self._include_hidden = include_hidden
        self._offered_qos = dict(offered_qos or {})
        self._recording: dict[str, _Topic] = {}
        self._skipped: set[str] = set()
        self._failed_topics: set[str] = set()
        self._message_count = 0
        try:
            self._writer.open()
        except BagError:
            super().destroy_node()
            raise
        steady = rclpy.clock.Clock(clock_type=rclpy.clock.ClockType.STEADY_TIME)
        self._discover()
        self._discovery_timer = self.create_timer(discovery_period_s, self._discover, clock=steady)
        self._flush_timer = self.create_timer(flush_period_s, self._flush, clock=steady)

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

    def subscription_qos(self, topic: str) -> QoSProfile | None:
        """The QoS profile the recorder subscribed ``topic`` with (None if not recorded)."""
        state = self._recording.get(topic)
        return state.subscribed_qos if state is not None else None

    def _wanted(self, topic: str) -> bool:
        if not self._include_hidden and is_hidden_topic(topic):
            return False
        if _matches(topic, self._exclude):
            return False
        if topic in SYSTEM_TOPICS:
            return self._patterns is not None and topic in self._patterns
        return self._patterns is None or _matches(topic, self._patterns)

    def _discover(self) -> None:
        """Subscribe to every wanted topic not recorded yet; note publishers seen later."""
        for topic, types in self.get_topic_names_and_types():
            state = self._recording.get(topic)
            if state is not None:
                self._update_publishers(topic, state)
                continue
            if topic in self._skipped:
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

    def _publisher_endpoints(self, topic: str) -> list[Any] | None:
        """Endpoint info of the topic's publishers; None if the runtime cannot report it."""
        try:
            return list(self.get_publishers_info_by_topic(topic))
        except (AttributeError, NotImplementedError, RuntimeError):
            return None

    def _start_recording(self, topic: str, typename: str) -> None:
        endpoints = self._publisher_endpoints(topic)
        offered = [e.qos_profile for e in endpoints or ()]
        declared = not offered
        if declared:
            offered = self._fallback_qos(topic)
            if not offered and endpoints is not None:
                return  # no publisher yet: the next poll looks again
        package, _, name = typename.split('/')
        try:
            msg_type = getattr(message_module(package), name)
        except (ImportError, AttributeError, LookupError) as err:
            self.get_logger().warning(f'not recording {topic}: no message class for {typename}')
            self.get_logger().debug(str(err))
            self._skipped.add(topic)
            return
        hashes = {type_hash_text(e.topic_type_hash) for e in endpoints or ()} - {''}
        try:
            self._add_topic(topic, typename, offered, hashes)
        except BagError as err:
            self.get_logger().error(f'not recording {topic}: {err}')
            self._skipped.add(topic)
            return
        qos = self._subscription_qos(offered)
        subscription = self.create_subscription(
            msg_type, topic, partial(self._record, topic), qos, raw=True
        )
        state = _Topic(typename, subscription, subscribed_qos=qos, declared=declared)
        state.publisher_gids = {bytes(e.endpoint_gid) for e in endpoints or ()}
        state.publisher_count = len(state.publisher_gids)
        self._recording[topic] = state
        self.get_logger().info(f'recording {topic} ({typename})')

    def _add_topic(
        self, topic: str, typename: str, offered: list[QoSProfile], hashes: set[str]
    ) -> None:
        from .decoding import installed_definition

        profiles = [qos_to_rosbags(q) for q in offered]
        known = typename in self._writer_typestore_types()
        ours = self._writer_type_hash(typename) if known else None
        if known and (not hashes or ours in hashes):
            self._writer.add_topic(topic, typename, offered_qos_profiles=profiles)
            return
        installed = installed_definition(typename)
        if installed is not None and (not hashes or installed[1] in hashes):
            self._writer.add_topic(
                topic,
                typename,
                offered_qos_profiles=profiles,
                definition=installed[0],
                type_hash=installed[1],
            )
            return
        if known:
            self.get_logger().warning(
                f"{topic}: the publishers' {typename} (hash {', '.join(sorted(hashes))}) "
                'differs from the definition known here; recording it with that definition'
            )
            self._writer.add_topic(topic, typename, offered_qos_profiles=profiles)
            return
        msg = f'no definition of {typename} is known here or installed'
        raise BagError(msg)

    def _writer_typestore_types(self) -> Any:
        from swarm_runtime.messages import default_registry

        return default_registry().typestore.fielddefs

    @staticmethod
    def _writer_type_hash(typename: str) -> str:
        from swarm_runtime.messages import default_registry

        return str(default_registry().typestore.hash_rihs01(typename))

    def _update_publishers(self, topic: str, state: _Topic) -> None:
        """Record the offered QoS of publishers that appeared after the topic was added."""
        try:
            count = self.count_publishers(topic)
        except (AttributeError, NotImplementedError, RuntimeError):
            return
        if count == state.publisher_count:
            return
        state.publisher_count = count
        endpoints = self._publisher_endpoints(topic) or []
        new = [e for e in endpoints if bytes(e.endpoint_gid) not in state.publisher_gids]
        if not new:
            return
        state.publisher_gids |= {bytes(e.endpoint_gid) for e in new}
        try:
            self._writer.add_offered_qos(
                topic, [qos_to_rosbags(e.qos_profile) for e in new], replace=state.declared
            )
            state.declared = False
        except BagError as err:
            self.get_logger().error(str(err))
        subscribed = state.subscribed_qos
        for endpoint in new:
            offered = endpoint.qos_profile
            if (
                subscribed.reliability == ReliabilityPolicy.RELIABLE
                and offered.reliability != ReliabilityPolicy.RELIABLE
            ) or (
                subscribed.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL
                and offered.durability != QoSDurabilityPolicy.TRANSIENT_LOCAL
            ):
                self.get_logger().warning(
                    f'{topic}: a publisher that appeared later offers a QoS the recording '
                    'subscription does not match; its messages are not recorded'
                )

    def _fallback_qos(self, topic: str) -> list[QoSProfile]:
        """The profile declared in ``offered_qos`` for ``topic``, if any."""
        for pattern, profile in self._offered_qos.items():
            if fnmatch.fnmatchcase(topic, pattern):
                return [profile]
        return []

    @staticmethod
    def _subscription_qos(offered: list[QoSProfile]) -> QoSProfile:
        """A profile that matches every offered one (best effort/volatile when none is known)."""
        return matching_profile(
            rclpy,
            all_reliable=bool(offered)
            and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered),
            all_latched=bool(offered)
            and all(q.durability == QoSDurabilityPolicy.TRANSIENT_LOCAL for q in offered),
            depth=RECORDER_QUEUE_DEPTH,
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
