"""``rclpy.time_source``: drives a node's ROS clock from ``/clock`` when use_sim_time is set.

As in rclpy, every node declares the ``use_sim_time`` parameter (default False). While it is
True the node subscribes to ``/clock`` (rosgraph_msgs/Clock, BEST_EFFORT, depth 1) and its
clock reports the last received time, 0 before the first message.
"""

from __future__ import annotations

import struct
import weakref
from typing import TYPE_CHECKING, Any

from ._messages import cdr_codec, cdr_roundtrip_enabled, interface_class, interface_module
from .clock import ROSClock
from .clock_type import ClockType
from .parameter import Parameter
from .qos import QoSProfile, ReliabilityPolicy
from .time import Time

if TYPE_CHECKING:
    from .node import Node
    from .subscription import Subscription

__all__ = ['CLOCK_TOPIC', 'USE_SIM_TIME_NAME', 'TimeSource']

CLOCK_TOPIC = '/clock'
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
USE_SIM_TIME_NAME = 'use_sim_time'
_CLOCK_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
# A rosgraph_msgs/Clock in CDR: the encapsulation header (byte 1: 1 little-endian, 0 big-endian),
# then builtin_interfaces/Time as int32 sec and uint32 nanosec.
_CLOCK_CDR = {1: struct.Struct('<iI'), 0: struct.Struct('>iI')}
_CLOCK_CDR_SIZE = 12


class TimeSource:
    """Keeps the attached ROS clocks on ``/clock`` time while ROS time is active."""

    def __init__(self, *, node: Node | None = None) -> None:
        self._clock_sub: Subscription | None = None
        self._node_weak_ref: weakref.ref[Node] | None = None
        self._associated_clocks: list[ROSClock] = []
        self._last_ns = 0
        self._ros_time_is_active = False
        if node is not None:
            self.attach_node(node)

    @property
    def ros_time_is_active(self) -> bool:
        """True while the attached clocks follow ``/clock``."""
        return self._ros_time_is_active

    @ros_time_is_active.setter
    def ros_time_is_active(self, enabled: bool) -> None:
        if self._ros_time_is_active == enabled:
            return
        self._ros_time_is_active = enabled
        for clock in self._associated_clocks:
            clock._set_ros_time_is_active(enabled)
        if enabled:
            self._subscribe_to_clock_topic()
        elif self._clock_sub is not None:
            node = self._get_node()
            if node is not None:
                node.destroy_subscription(self._clock_sub)
            self._clock_sub = None

    def _get_node(self) -> Node | None:
        return None if self._node_weak_ref is None else self._node_weak_ref()

    def _subscribe_to_clock_topic(self) -> None:
        """Subscribe to /clock; with the CDR round trip on, take the bytes and read the time.

        Decoding a whole Clock message per node and step would be the costliest part of a
        simulation's clock ticks, and nothing but the time is used.
        """
        node = self._get_node()
        if self._clock_sub is None and node is not None:
            raw = cdr_roundtrip_enabled()
            self._clock_sub = node.create_subscription(
                interface_class('rosgraph_msgs', 'Clock'),
                CLOCK_TOPIC,
                self._clock_cdr_callback if raw else self.clock_callback,
                _CLOCK_QOS,
                raw=raw,
            )

    def attach_node(self, node: Node) -> None:
        """Read ``use_sim_time`` from ``node`` (declaring it) and follow its changes."""
        from .node import Node

        if not isinstance(node, Node):
            raise TypeError('Node must be of type rclpy.node.Node')
        if self._node_weak_ref is not None:
            self.detach_node()
        self._node_weak_ref = weakref.ref(node)
        if not node.has_parameter(USE_SIM_TIME_NAME):
            node.declare_parameter(USE_SIM_TIME_NAME, False)
        use_sim_time = node.get_parameter(USE_SIM_TIME_NAME)
        if use_sim_time.type_ == Parameter.Type.BOOL:
            self.ros_time_is_active = use_sim_time.value
        elif use_sim_time.type_ != Parameter.Type.NOT_SET:
            node.get_logger().error(
                f"Invalid type for parameter '{USE_SIM_TIME_NAME}' {use_sim_time.type_!r} "
                'should be bool'
            )
        node.add_on_set_parameters_callback(self._on_parameter_event)

    def detach_node(self) -> None:
        """Stop following the node (and its ``/clock`` subscription)."""
        node = self._get_node()
        if node is not None and self._clock_sub is not None:
            node.destroy_subscription(self._clock_sub)
        self._clock_sub = None
        if node is not None:
            node.remove_on_set_parameters_callback(self._on_parameter_event)
        self._node_weak_ref = None

    def attach_clock(self, clock: ROSClock) -> None:
        """Drive ``clock`` (which must be a ROS_TIME clock) from this time source."""
        if not isinstance(clock, ROSClock):
            raise ValueError('Only clocks with type ROS_TIME can be attached.')
        clock.set_ros_time_override(Time._from_ns(self._last_ns, ClockType.ROS_TIME))
        clock._set_ros_time_is_active(self._ros_time_is_active)
        self._associated_clocks.append(clock)

    def clock_callback(self, msg: Any) -> None:
        """Take a rosgraph_msgs/Clock message as the new ROS time."""
        stamp = msg.clock
        nanoseconds = stamp.sec * 1_000_000_000 + stamp.nanosec
        self._last_ns = nanoseconds
        for clock in self._associated_clocks:
            clock._set_ros_ns(nanoseconds)

    def _clock_cdr_callback(self, data: bytes) -> None:
        """Take a rosgraph_msgs/Clock in CDR as the new ROS time.

        Raises:
            swarm_runtime.messages.DeserializationError: the bytes are not a Clock message.
        """
        layout = _CLOCK_CDR.get(data[1]) if len(data) >= _CLOCK_CDR_SIZE else None
        if layout is None:
            self.clock_callback(cdr_codec(CLOCK_TYPE).deserialize(data))
            return
        sec, nanosec = layout.unpack_from(data, 4)
        nanoseconds = sec * 1_000_000_000 + nanosec
        self._last_ns = nanoseconds
        for clock in self._associated_clocks:
            clock._set_ros_ns(nanoseconds)

    def _on_parameter_event(self, parameter_list: list[Parameter]) -> Any:
        result = interface_module('rcl_interfaces').SetParametersResult(successful=True)
        for parameter in parameter_list:
            if parameter.name != USE_SIM_TIME_NAME:
                continue
            if parameter.type_ == Parameter.Type.BOOL:
                self.ros_time_is_active = parameter.value
            else:
                result.successful = False
                result.reason = f'{USE_SIM_TIME_NAME} parameter set to something besides a bool'
                node = self._get_node()
                if node is not None:
                    node.get_logger().error(result.reason)
        return result
