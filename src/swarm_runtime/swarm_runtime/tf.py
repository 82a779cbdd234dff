"""Transforms on ``/tf`` and ``/tf_static`` with plain tf2_msgs/TFMessage publishers.

No tf2 library is needed (there is no wheel of it): a node that owns a moving frame
publishes :class:`TransformPublisher` messages on ``/tf``; fixed frames (sensor mounts)
go to ``/tf_static`` through :class:`StaticTransformPublisher`, which keeps every static
transform it was given and republishes the whole set, latched, whenever one is added or
changed, as tf2_ros' static broadcaster and ``static_transform_publisher`` do. The QoS
profiles are tf2_ros': ``/tf`` reliable, volatile, depth 100; ``/tf_static`` reliable,
transient local, depth 1 (a late subscriber gets the latest set of each publisher).

Transforms here are planar poses lifted to 3D: a translation x, y, z [m] and a rotation
``yaw_rad`` about +z (REP 103). Message classes come through :mod:`swarm_runtime.ros`;
:func:`tf_message_class` raises :class:`TfUnavailableError` where tf2_msgs is not installed
(real rclpy from pip), so callers can turn transforms off with one log line.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from swarm_common.angles import yaw_to_quaternion
from swarm_common.stamps import stamp_from_seconds

from swarm_runtime.ros import QoSDurabilityPolicy, QoSProfile, message_module

__all__ = [
    'TF_STATIC_TOPIC',
    'TF_TOPIC',
    'PlanarTransform',
    'StaticTransformPublisher',
    'TfUnavailableError',
    'TransformPublisher',
    'tf_message',
    'tf_message_class',
    'tf_qos',
    'tf_static_qos',
    'transform_stamped',
]

TF_TOPIC = '/tf'
TF_STATIC_TOPIC = '/tf_static'


class TfUnavailableError(ImportError):
    """tf2_msgs cannot be imported, so no transform can be published."""


@dataclass(frozen=True)
class PlanarTransform:
    """The pose of ``child`` in ``parent``: a translation and a rotation about +z.

    Attributes:
        parent: frame id of the parent (the header's frame_id).
        child: frame id of the child (child_frame_id).
        x_m, y_m, z_m: position of the child's origin in the parent frame [m].
        yaw_rad: rotation of the child's axes about the parent's +z [rad].
    """

    parent: str
    child: str
    x_m: float = 0.0
    y_m: float = 0.0
    z_m: float = 0.0
    yaw_rad: float = 0.0


def tf_qos() -> QoSProfile:
    """QoS of ``/tf`` (tf2_ros' dynamic broadcaster: reliable, volatile, depth 100)."""
    return QoSProfile(depth=100)


def tf_static_qos() -> QoSProfile:
    """QoS of ``/tf_static`` (tf2_ros' static broadcaster: reliable, transient local, depth 1)."""
    return QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)


def tf_message_class() -> type:
    """The tf2_msgs/TFMessage class of the runtime in use.

    Raises:
        TfUnavailableError: tf2_msgs is not installed (no transforms can be published).
    """
    try:
        return message_module('tf2_msgs').TFMessage
    except (ImportError, AttributeError, LookupError) as err:
        msg = f'tf2_msgs is not available, so /tf and /tf_static are off: {err}'
        raise TfUnavailableError(msg) from err


def transform_stamped(transform: PlanarTransform, time_s: float) -> Any:
    """The geometry_msgs/TransformStamped of ``transform``, stamped ``time_s`` [s]."""
    geometry_msgs = message_module('geometry_msgs')
    builtin_interfaces = message_module('builtin_interfaces')
    msg = geometry_msgs.TransformStamped()
    msg.header.stamp = stamp_from_seconds(time_s, builtin_interfaces.Time)
    msg.header.frame_id = transform.parent
    msg.child_frame_id = transform.child
    translation = msg.transform.translation
    translation.x, translation.y, translation.z = (
        float(transform.x_m),
        float(transform.y_m),
        float(transform.z_m),
    )
    rotation = msg.transform.rotation
    rotation.x, rotation.y, rotation.z, rotation.w = yaw_to_quaternion(transform.yaw_rad)
    return msg


def tf_message(transforms: Iterable[PlanarTransform], time_s: float) -> Any:
    """A tf2_msgs/TFMessage holding ``transforms``, each stamped ``time_s`` [s].

    Raises:
        TfUnavailableError: tf2_msgs is not installed.
    """
    cls = tf_message_class()
    return cls(transforms=[transform_stamped(t, time_s) for t in transforms])


class TransformPublisher:
    """Publishes moving frames on ``/tf``, one TFMessage per call.

    Raises:
        TfUnavailableError: tf2_msgs is not installed (raised by the constructor).
    """

    def __init__(self, node: Any) -> None:
        self._publisher = node.create_publisher(tf_message_class(), TF_TOPIC, tf_qos())

    def wanted(self) -> bool:
        """True when somebody subscribes to ``/tf`` (messages are worth building)."""
        return self._publisher.get_subscription_count() > 0

    def send(self, transforms: Sequence[PlanarTransform], time_s: float) -> None:
        """Publish ``transforms`` stamped ``time_s`` [s] in one message."""
        self._publisher.publish(tf_message(transforms, time_s))


class StaticTransformPublisher:
    """Latches fixed frames on ``/tf_static``: the whole set, again at every change.

    Raises:
        TfUnavailableError: tf2_msgs is not installed (raised by the constructor).
    """

    def __init__(self, node: Any) -> None:
        self._publisher = node.create_publisher(
            tf_message_class(), TF_STATIC_TOPIC, tf_static_qos()
        )
        self._transforms: dict[str, Any] = {}

    @property
    def child_frames(self) -> tuple[str, ...]:
        """The child frame ids published so far, in the order they were first given."""
        return tuple(self._transforms)

    def send(self, transforms: Iterable[PlanarTransform], time_s: float) -> None:
        """Add or replace ``transforms`` (by child frame), stamped ``time_s`` [s], and
        publish every static transform of this publisher in one latched message."""
        for transform in transforms:
            self._transforms[transform.child] = transform_stamped(transform, time_s)
        self._publisher.publish(tf_message_class()(transforms=list(self._transforms.values())))
