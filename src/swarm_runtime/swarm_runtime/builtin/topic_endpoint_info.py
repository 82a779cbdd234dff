"""``rclpy.topic_endpoint_info``: what the graph reports about one publisher or subscription.

``Node.get_publishers_info_by_topic()`` and ``get_subscriptions_info_by_topic()`` return these.
As with a DDS middleware, the QoS profile is the one the endpoint announces in discovery: the
policies the middleware resolved (reliability, durability, liveliness; unspecified durations as
infinite) and no history (``UNKNOWN``, depth 0), which DDS discovery does not carry.
"""

from __future__ import annotations

from enum import IntEnum
from typing import Any

from .qos import HistoryPolicy, QoSPresetProfiles, QoSProfile
from .type_hash import TypeHash

__all__ = ['TopicEndpointInfo', 'TopicEndpointTypeEnum']


class TopicEndpointTypeEnum(IntEnum):
    """Kind of a topic endpoint (rmw's ``rmw_endpoint_type_t``)."""

    INVALID = 0
    PUBLISHER = 1
    SUBSCRIPTION = 2


def _require(condition: bool, text: str) -> None:
    if not condition:
        raise AssertionError(text)


class TopicEndpointInfo:
    """Node, type, kind, GID and QoS of one endpoint on a topic."""

    __slots__ = (
        '_endpoint_gid',
        '_endpoint_type',
        '_node_name',
        '_node_namespace',
        '_qos_profile',
        '_topic_type',
        '_topic_type_hash',
    )

    def __init__(
        self,
        *,
        node_name: str = '',
        node_namespace: str = '',
        topic_type: str = '',
        topic_type_hash: TypeHash | dict[str, Any] | None = None,
        endpoint_type: TopicEndpointTypeEnum | int = TopicEndpointTypeEnum.INVALID,
        endpoint_gid: list[int] | None = None,
        qos_profile: QoSProfile | dict[str, Any] | None = None,
    ) -> None:
        self.node_name = node_name
        self.node_namespace = node_namespace
        self.topic_type = topic_type
        self.topic_type_hash = TypeHash() if topic_type_hash is None else topic_type_hash
        self.endpoint_type = endpoint_type
        self.endpoint_gid = [] if endpoint_gid is None else endpoint_gid
        self.qos_profile = QoSPresetProfiles.UNKNOWN.value if qos_profile is None else qos_profile

    @property
    def node_name(self) -> str:
        """Name of the node that owns the endpoint."""
        return self._node_name

    @node_name.setter
    def node_name(self, value: str) -> None:
        _require(isinstance(value, str), f'node_name must be a str, got {value!r}')
        self._node_name = value

    @property
    def node_namespace(self) -> str:
        """Namespace of the node that owns the endpoint."""
        return self._node_namespace

    @node_namespace.setter
    def node_namespace(self, value: str) -> None:
        _require(isinstance(value, str), f'node_namespace must be a str, got {value!r}')
        self._node_namespace = value

    @property
    def topic_type(self) -> str:
        """Message type name, e.g. ``'sensor_msgs/msg/LaserScan'``."""
        return self._topic_type

    @topic_type.setter
    def topic_type(self, value: str) -> None:
        _require(isinstance(value, str), f'topic_type must be a str, got {value!r}')
        self._topic_type = value

    @property
    def topic_type_hash(self) -> Any:
        """The :class:`~.type_hash.TypeHash` of the message type (RIHS01)."""
        return self._topic_type_hash

    @topic_type_hash.setter
    def topic_type_hash(self, value: TypeHash | dict[str, Any]) -> None:
        if isinstance(value, TypeHash):
            self._topic_type_hash = value
        elif isinstance(value, dict):
            self._topic_type_hash = TypeHash(**value)
        else:
            raise AssertionError(f'topic_type_hash must be a TypeHash or dict, got {value!r}')

    @property
    def endpoint_type(self) -> Any:
        """:class:`TopicEndpointTypeEnum` of the endpoint."""
        return self._endpoint_type

    @endpoint_type.setter
    def endpoint_type(self, value: TopicEndpointTypeEnum | int) -> None:
        _require(isinstance(value, int), f'endpoint_type must be an int, got {value!r}')
        self._endpoint_type = TopicEndpointTypeEnum(value)

    @property
    def endpoint_gid(self) -> list[int]:
        """Globally unique id of the endpoint (16 byte values)."""
        return self._endpoint_gid

    @endpoint_gid.setter
    def endpoint_gid(self, value: list[int]) -> None:
        _require(
            all(isinstance(byte, int) for byte in value),
            f'endpoint_gid must be a list of int, got {value!r}',
        )
        self._endpoint_gid = value

    @property
    def qos_profile(self) -> Any:
        """The :class:`~.qos.QoSProfile` the endpoint announces."""
        return self._qos_profile

    @qos_profile.setter
    def qos_profile(self, value: QoSProfile | dict[str, Any]) -> None:
        if isinstance(value, QoSProfile):
            self._qos_profile = value
        elif isinstance(value, dict):
            self._qos_profile = QoSProfile(**value)
        else:
            raise AssertionError(f'qos_profile must be a QoSProfile or dict, got {value!r}')

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TopicEndpointInfo):
            return False
        return all(getattr(self, slot) == getattr(other, slot) for slot in self.__slots__)

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        qos = self.qos_profile
        history = qos.history.name
        if qos.history == HistoryPolicy.KEEP_LAST:
            history = f'{history} ({qos.depth})'
        gid = '.'.join(f'{byte:02x}' for byte in self.endpoint_gid)
        return '\n'.join(
            [
                f'Node name: {self.node_name}',
                f'Node namespace: {self.node_namespace}',
                f'Topic type: {self.topic_type}',
                f'Topic type hash: {self.topic_type_hash}',
                f'Endpoint type: {self.endpoint_type.name}',
                f'GID: {gid}',
                'QoS profile:',
                f'  Reliability: {qos.reliability.name}',
                f'  History (Depth): {history}',
                f'  Durability: {qos.durability.name}',
                f'  Lifespan: {qos.lifespan}',
                f'  Deadline: {qos.deadline}',
                f'  Liveliness: {qos.liveliness.name}',
                f'  Liveliness lease duration: {qos.liveliness_lease_duration}',
            ]
        )
