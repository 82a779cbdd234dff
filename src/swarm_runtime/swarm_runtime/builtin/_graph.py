"""The simulated ROS graph of one context: topics, endpoints and who receives from whom.

A publisher is *connected* to a subscription on the same topic when both use the same
message type and their QoS profiles are compatible (:func:`.qos.qos_check_compatible`
on the effective profiles, see :mod:`.qos`). Each publisher keeps the tuple of its
connected subscriptions, recomputed when an endpoint appears or goes, so that publishing
is a loop over a ready-made tuple.

The graph also answers the introspection queries (topic names and types, endpoint info). Each
endpoint gets a 16-byte GID when it is registered: like a DDS GUID, a prefix shared by the
context (one DDS participant per context in Jazzy) and an entity id unique within it.
"""

from __future__ import annotations

import itertools
import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ._messages import type_hash_text
from .duration import Infinite
from .qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSCompatibility,
    QoSProfile,
    ReliabilityPolicy,
    qos_check_compatible,
)
from .topic_endpoint_info import TopicEndpointInfo, TopicEndpointTypeEnum
from .type_hash import TypeHash

if TYPE_CHECKING:
    from .node import Node
    from .publisher import Publisher
    from .subscription import Subscription

__all__ = [
    'Graph',
    'announced_qos',
    'effective_publisher_qos',
    'effective_subscription_qos',
    'queue_depth',
]

CLOCK_TOPIC = '/clock'
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'

# DDS entity kinds (last byte of a GUID) of user-defined writers and readers without a key.
_WRITER_KIND = 0x03
_READER_KIND = 0x04
# Contexts created so far in this process: the GID prefix of the next one (values only compared).
_context_numbers = itertools.count(1)


def _copy(qos: QoSProfile) -> QoSProfile:
    return QoSProfile(**{name: getattr(qos, name) for name in QoSProfile._FIELDS})


def effective_publisher_qos(qos: QoSProfile) -> QoSProfile:
    """Resolve SYSTEM_DEFAULT/BEST_AVAILABLE of a publisher as the middleware would."""
    resolved = _copy(qos)
    if qos.reliability in (ReliabilityPolicy.SYSTEM_DEFAULT, ReliabilityPolicy.BEST_AVAILABLE):
        resolved.reliability = ReliabilityPolicy.RELIABLE
    if qos.durability == DurabilityPolicy.SYSTEM_DEFAULT:
        resolved.durability = DurabilityPolicy.VOLATILE
    elif qos.durability == DurabilityPolicy.BEST_AVAILABLE:
        resolved.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return resolved


def effective_subscription_qos(
    qos: QoSProfile, publishers: list[Publisher] | tuple[Publisher, ...]
) -> QoSProfile:
    """Resolve SYSTEM_DEFAULT/BEST_AVAILABLE of a subscription, given the topic's publishers."""
    resolved = _copy(qos)
    offered = [publisher._effective_qos for publisher in publishers]
    if qos.reliability == ReliabilityPolicy.SYSTEM_DEFAULT:
        resolved.reliability = ReliabilityPolicy.BEST_EFFORT
    elif qos.reliability == ReliabilityPolicy.BEST_AVAILABLE:
        best_effort = any(o.reliability == ReliabilityPolicy.BEST_EFFORT for o in offered)
        resolved.reliability = (
            ReliabilityPolicy.BEST_EFFORT if best_effort else ReliabilityPolicy.RELIABLE
        )
    if qos.durability == DurabilityPolicy.SYSTEM_DEFAULT:
        resolved.durability = DurabilityPolicy.VOLATILE
    elif qos.durability == DurabilityPolicy.BEST_AVAILABLE:
        latched = bool(offered) and all(
            o.durability == DurabilityPolicy.TRANSIENT_LOCAL for o in offered
        )
        resolved.durability = (
            DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE
        )
    return resolved


def _announced_duration(duration: Any) -> Any:
    """rmw turns an unspecified (0) or best-available duration into the DDS default: infinite."""
    if duration.nanoseconds <= 0 or duration.nanoseconds >= Infinite.nanoseconds - 1:
        return Infinite
    return duration


def announced_qos(effective: QoSProfile, *, is_publisher: bool) -> QoSProfile:
    """The QoS an endpoint announces in discovery, as rmw reports it for endpoint info.

    Reliability and durability as resolved for the endpoint; liveliness left to the system as
    DDS resolves it (AUTOMATIC, or MANUAL_BY_TOPIC for a best-available publisher);
    unspecified durations as infinite; history UNKNOWN with depth 0 (history is local to an
    endpoint and not part of DDS discovery data).
    """
    liveliness = effective.liveliness
    if liveliness == LivelinessPolicy.BEST_AVAILABLE and is_publisher:
        liveliness = LivelinessPolicy.MANUAL_BY_TOPIC
    elif liveliness in (LivelinessPolicy.SYSTEM_DEFAULT, LivelinessPolicy.BEST_AVAILABLE):
        liveliness = LivelinessPolicy.AUTOMATIC
    return QoSProfile(
        history=HistoryPolicy.UNKNOWN,
        depth=0,
        reliability=effective.reliability,
        durability=effective.durability,
        lifespan=_announced_duration(effective.lifespan),
        deadline=_announced_duration(effective.deadline),
        liveliness=liveliness,
        liveliness_lease_duration=_announced_duration(effective.liveliness_lease_duration),
        avoid_ros_namespace_conventions=effective.avoid_ros_namespace_conventions,
    )


def queue_depth(qos: QoSProfile) -> int:
    """How many undelivered messages an endpoint keeps: KEEP_ALL unbounded, depth 0 means 1."""
    if qos.history == HistoryPolicy.KEEP_ALL:
        return sys.maxsize
    return max(qos.depth, 1)


def _incompatible_policy(reason: str) -> str:
    for keyword, policy in (
        ('reliab', 'RELIABILITY'),
        ('durab', 'DURABILITY'),
        ('transient', 'DURABILITY'),
        ('deadline', 'DEADLINE'),
        ('lease', 'LIVELINESS_LEASE_DURATION'),
        ('liveliness', 'LIVELINESS'),
    ):
        if keyword in reason.lower():
            return policy
    return 'INVALID'


@dataclass
class _Topic:
    name: str
    publishers: list[Publisher] = field(default_factory=list)
    subscriptions: list[Subscription] = field(default_factory=list)


class Graph:
    """Topics and endpoints of one context, and the message sequence counter."""

    def __init__(self) -> None:
        self._topics: dict[str, _Topic] = {}
        self._nodes: list[Node] = []
        # Global publish order: every queued message gets the next number.
        self.next_seq = itertools.count(1).__next__
        #: The last time published on /clock (ns), None before the first one.
        self.clock_ns: int | None = None
        self._warned_pairs: set[tuple[int, int]] = set()
        self._gid_prefix = next(_context_numbers).to_bytes(12, 'big')
        self._next_entity_id = itertools.count(1).__next__
        # topic_names_and_types() until an endpoint appears or goes.
        self._names_and_types: list[tuple[str, list[str]]] | None = None

    # Nodes

    def add_node(self, node: Node) -> None:
        """Register a node; warn when its fully qualified name is taken already."""
        name = node.get_fully_qualified_name()
        if any(other.get_fully_qualified_name() == name for other in self._nodes):
            node.get_logger().warning(
                f'A node named {name} exists already in this context; node names should be unique'
            )
        self._nodes.append(node)

    def remove_node(self, node: Node) -> None:
        """Forget a destroyed node."""
        if node in self._nodes:
            self._nodes.remove(node)

    def node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """``(name, namespace)`` of every live node, in creation order."""
        return [(node.get_name(), node.get_namespace()) for node in self._nodes]

    # Endpoints

    def _topic(self, name: str) -> _Topic:
        topic = self._topics.get(name)
        if topic is None:
            topic = self._topics[name] = _Topic(name)
        return topic

    def _new_gid(self, kind: int) -> tuple[int, ...]:
        entity = self._next_entity_id().to_bytes(3, 'big')
        return tuple(self._gid_prefix + entity + bytes((kind,)))

    def add_publisher(self, publisher: Publisher) -> None:
        """Register a publisher and connect it to the compatible subscriptions."""
        publisher._gid = self._new_gid(_WRITER_KIND)
        self._names_and_types = None
        topic = self._topic(publisher.topic_name)
        topic.publishers.append(publisher)
        self._reconnect(topic)

    def add_subscription(self, subscription: Subscription) -> None:
        """Register a subscription, connect it, and hand it latched (TRANSIENT_LOCAL) data."""
        subscription._gid = self._new_gid(_READER_KIND)
        self._names_and_types = None
        topic = self._topic(subscription.topic_name)
        subscription._set_effective_qos(
            effective_subscription_qos(subscription.qos_profile, topic.publishers)
        )
        topic.subscriptions.append(subscription)
        self._reconnect(topic)
        if subscription._effective_qos.durability != DurabilityPolicy.TRANSIENT_LOCAL:
            return
        for publisher in topic.publishers:
            if publisher._history is None or subscription not in publisher._connected:
                continue
            for data in publisher._history:
                latched = publisher._latched_data_for(data, subscription)
                subscription._enqueue(self.next_seq(), latched)

    def remove_publisher(self, publisher: Publisher) -> None:
        """Unregister a publisher."""
        topic = self._topics.get(publisher.topic_name)
        if topic is not None and publisher in topic.publishers:
            topic.publishers.remove(publisher)
            self._names_and_types = None
            self._reconnect(topic)

    def remove_subscription(self, subscription: Subscription) -> None:
        """Unregister a subscription."""
        topic = self._topics.get(subscription.topic_name)
        if topic is not None and subscription in topic.subscriptions:
            topic.subscriptions.remove(subscription)
            self._names_and_types = None
            self._reconnect(topic)

    def _reconnect(self, topic: _Topic) -> None:
        for publisher in topic.publishers:
            connected = [
                subscription
                for subscription in topic.subscriptions
                if self._connects(publisher, subscription)
            ]
            publisher._set_connected(connected)

    def _connects(self, publisher: Publisher, subscription: Subscription) -> bool:
        if publisher._typename != subscription._typename:
            self._warn_once(
                publisher,
                subscription,
                f"Topic '{publisher.topic_name}' has a publisher of {publisher._typename} and a "
                f'subscription of {subscription._typename}; they are not connected',
            )
            return False
        compatibility, reason = qos_check_compatible(
            publisher._effective_qos, subscription._effective_qos
        )
        if compatibility != QoSCompatibility.ERROR:
            return True
        policy = _incompatible_policy(reason)
        self._warn_once(
            publisher,
            subscription,
            f"New publisher discovered on topic '{publisher.topic_name}', offering incompatible "
            f'QoS. No messages will be received from it. Last incompatible policy: {policy} '
            f'({reason})',
        )
        return False

    def _warn_once(self, publisher: Publisher, subscription: Subscription, text: str) -> None:
        pair = (id(publisher), id(subscription))
        if pair not in self._warned_pairs:
            self._warned_pairs.add(pair)
            subscription._node.get_logger().warning(text)

    # Introspection

    def topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        """``(topic, [types])`` of every topic with at least one endpoint, sorted by name.

        The answer is kept until an endpoint appears or goes (discovery polls it often); the
        caller gets fresh lists each time.
        """
        if self._names_and_types is None:
            result = []
            for name in sorted(self._topics):
                topic = self._topics[name]
                types = {p._typename for p in topic.publishers}
                types.update(s._typename for s in topic.subscriptions)
                if types:
                    result.append((name, sorted(types)))
            self._names_and_types = result
        return [(name, list(types)) for name, types in self._names_and_types]

    def count_publishers(self, topic_name: str) -> int:
        """Number of publishers on a fully qualified topic."""
        topic = self._topics.get(topic_name)
        return 0 if topic is None else len(topic.publishers)

    def count_subscribers(self, topic_name: str) -> int:
        """Number of subscriptions on a fully qualified topic."""
        topic = self._topics.get(topic_name)
        return 0 if topic is None else len(topic.subscriptions)

    def publishers_on(self, topic_name: str) -> tuple[Publisher, ...]:
        """The publishers on a fully qualified topic."""
        topic = self._topics.get(topic_name)
        return () if topic is None else tuple(topic.publishers)

    def publishers_info(self, topic_name: str) -> list[TopicEndpointInfo]:
        """Endpoint info of the publishers on a topic, in creation order."""
        topic = self._topics.get(topic_name)
        if topic is None:
            return []
        return [
            _endpoint_info(p, p._effective_qos, TopicEndpointTypeEnum.PUBLISHER)
            for p in topic.publishers
        ]

    def subscriptions_info(self, topic_name: str) -> list[TopicEndpointInfo]:
        """Endpoint info of the subscriptions on a topic, in creation order."""
        topic = self._topics.get(topic_name)
        if topic is None:
            return []
        return [
            _endpoint_info(s, s._effective_qos, TopicEndpointTypeEnum.SUBSCRIPTION)
            for s in topic.subscriptions
        ]


def _endpoint_info(
    endpoint: Publisher | Subscription, effective: QoSProfile, kind: TopicEndpointTypeEnum
) -> TopicEndpointInfo:
    node = endpoint._node
    return TopicEndpointInfo(
        node_name=node._name,
        node_namespace=node._namespace,
        topic_type=endpoint._typename,
        topic_type_hash=TypeHash._from_text(type_hash_text(endpoint._typename)),
        endpoint_type=kind,
        endpoint_gid=list(endpoint._gid),
        qos_profile=announced_qos(effective, is_publisher=kind == TopicEndpointTypeEnum.PUBLISHER),
    )
