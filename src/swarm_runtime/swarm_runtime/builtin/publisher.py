"""``rclpy.publisher``: publishing into the in-process graph.

``publish(msg)`` puts the message into the queue of every connected subscription (dropping
the oldest one when a KEEP_LAST queue is full) and tells the executor that owns each
subscription's node. With the CDR round trip on (``SWARM_RUNTIME_CDR_ROUNDTRIP=1``, read
when the publisher is created), the message is serialized at publish, so a value a robot
could not serialize fails right here, and every subscriber later decodes its own copy.
Without it, subscribers receive the very object that was published: do not modify a message
after publishing it (on real ROS the middleware copies it).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ._graph import CLOCK_TOPIC, CLOCK_TYPE, effective_publisher_qos, queue_depth
from ._messages import cdr_codec, cdr_roundtrip_enabled
from .clock import SYSTEM_EPOCH_NS
from .duration import Duration
from .errors import RCLError
from .exceptions import InvalidHandle
from .qos import DurabilityPolicy, QoSProfile

if TYPE_CHECKING:
    from .node import Node
    from .subscription import Subscription

__all__ = ['Publisher', 'PublisherImpl']


@dataclass(frozen=True)
class PublisherImpl:
    """What the node resolved for a new publisher (rclpy's ``_rclpy.Publisher`` stand-in)."""

    node: Node
    topic_name: str
    typename: str


class Publisher:
    """A publisher created by :meth:`Node.create_publisher`; do not construct it directly."""

    def __init__(
        self,
        publisher_impl: PublisherImpl,
        msg_type: type,
        topic: str,
        qos_profile: QoSProfile,
        event_callbacks: Any,
        callback_group: Any,
    ) -> None:
        self.msg_type = msg_type
        self.topic = topic
        self.qos_profile = qos_profile
        self.event_handlers: list[Any] = []
        self.callback_group = callback_group
        self._event_callbacks = event_callbacks
        self._node = publisher_impl.node
        self._topic_name = publisher_impl.topic_name
        self._typename = publisher_impl.typename
        self._context = self._node.context
        self._graph = self._context._graph
        self._effective_qos = effective_publisher_qos(qos_profile)
        self._roundtrip = cdr_roundtrip_enabled()
        self._codec = cdr_codec(self._typename)
        self._connected: tuple[Subscription, ...] = ()
        # Per connected subscription: (subscription, its queue, its depth, wants CDR bytes,
        # wants MessageInfo), so that publish() reads everything from one tuple.
        self._targets: tuple[tuple[Subscription, deque[Any], int, bool, bool], ...] = ()
        self._needs_bytes = self._roundtrip
        self._is_clock = self._topic_name == CLOCK_TOPIC and self._typename == CLOCK_TYPE
        self._sequence = 0
        # Set by the graph when the publisher is registered.
        self._gid: tuple[int, ...] = ()
        self._alive = True
        self._history: deque[Any] | None = None
        if self._effective_qos.durability == DurabilityPolicy.TRANSIENT_LOCAL:
            self._history = deque(maxlen=queue_depth(self._effective_qos))

    @property
    def handle(self) -> Publisher:
        """The underlying publisher (the publisher itself in the built-in runtime)."""
        self._check_alive()
        return self

    @property
    def topic_name(self) -> str:
        """The fully qualified (expanded and remapped) topic name."""
        return self._topic_name

    def _check_alive(self) -> None:
        if not self._alive:
            raise InvalidHandle('Tried to use a handle that has been destroyed.')

    def _set_connected(self, subscriptions: list[Subscription]) -> None:
        """Called by the graph when the set of connected subscriptions changes."""
        self._connected = tuple(subscriptions)
        self._targets = tuple(
            (sub, sub._queue, sub._depth, self._roundtrip or sub.raw, sub._with_info)
            for sub in subscriptions
        )
        self._needs_bytes = self._roundtrip or any(sub.raw for sub in subscriptions)

    def publish(self, msg: Any) -> None:
        """Send a message (or its CDR bytes) to every connected subscription.

        Raises:
            TypeError: ``msg`` is neither a ``msg_type`` instance nor bytes.
            InvalidHandle: the publisher was destroyed.
            RCLError: the context was shut down.
            swarm_runtime.messages.errors.SerializationError: with the CDR round trip on, a
                field holds a value that cannot be serialized.
        """
        if isinstance(msg, self.msg_type):
            raw = False
        elif isinstance(msg, bytes):
            raw = True
        else:
            msg_text = f'Expected {self.msg_type}, got {type(msg)}'
            raise TypeError(msg_text)
        if not self._alive:
            raise InvalidHandle('Tried to use a handle that has been destroyed.')
        if not self._context._ok:
            raise RCLError("Failed to publish: publisher's context is invalid")
        if raw:
            payload = msg
        elif self._needs_bytes:
            payload = self._codec.serialize(msg)
        else:
            payload = None
        self._sequence += 1
        next_seq = self._graph.next_seq
        for sub, queue, depth, wants_bytes, wants_info in self._targets:
            seq = next_seq()
            if len(queue) >= depth:
                queue.popleft()
            data = payload if (raw or wants_bytes) else msg
            if wants_info:
                stamp_ns = SYSTEM_EPOCH_NS + self._context._elapsed_ns
                queue.append((seq, data, stamp_ns, self._sequence))
            else:
                queue.append((seq, data))
            owner = sub._owner
            if owner is not None:
                owner._inbox.append((seq, sub))
        if self._history is not None:
            self._history.append(payload if raw else msg)
        if self._is_clock:
            clock_msg = self._codec.deserialize(msg) if raw else msg
            self._graph.clock_ns = clock_msg.clock.sec * 1_000_000_000 + clock_msg.clock.nanosec

    def _latched_data_for(self, data: Any, subscription: Subscription) -> Any:
        """Data from the TRANSIENT_LOCAL history, as ``subscription`` should receive it."""
        if isinstance(data, bytes) or not (self._roundtrip or subscription.raw):
            return data
        return self._codec.serialize(data)

    def get_subscription_count(self) -> int:
        """Number of subscriptions this publisher is connected to."""
        self._check_alive()
        return len(self._connected)

    def assert_liveliness(self) -> None:
        """No-op: liveliness is not simulated."""
        self._check_alive()

    def wait_for_all_acked(self, timeout: Duration = Duration(seconds=-1)) -> bool:  # noqa: B008
        """Return True: in-process delivery leaves nothing unacknowledged."""
        self._check_alive()
        return True

    def destroy(self) -> None:
        """Destroy the publisher (use :meth:`Node.destroy_publisher` from node code)."""
        if not self._alive:
            return
        self._alive = False
        self._graph.remove_publisher(self)
        self._connected = ()
        self._targets = ()

    def __enter__(self) -> Publisher:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.destroy()
