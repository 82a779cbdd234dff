"""``rclpy.subscription``: a subscription's queue and callback.

Each subscription keeps the messages delivered to it but not yet taken by its executor, at
most ``depth`` of them (KEEP_LAST drops the oldest). Entries are ``(seq, data)``, plus
``(stamp_ns, publication_sequence_number)`` for callbacks that take a MessageInfo; ``seq`` is
the context-wide publish order, which executors use to run callbacks in publish order across
all subscriptions.
"""

from __future__ import annotations

import inspect
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from typing import TYPE_CHECKING, Any, TypedDict

from ._graph import queue_depth
from ._messages import cdr_codec
from .clock import SYSTEM_EPOCH_NS
from .exceptions import InvalidHandle
from .qos import QoSProfile

if TYPE_CHECKING:
    from .executors import Executor
    from .node import Node

__all__ = ['MessageInfo', 'Subscription', 'SubscriptionImpl']


class MessageInfo(TypedDict):
    """What a two-argument subscription callback receives besides the message."""

    source_timestamp: int
    received_timestamp: int
    publication_sequence_number: int
    reception_sequence_number: int


@dataclass(frozen=True)
class SubscriptionImpl:
    """What the node resolved for a new subscription (rclpy's ``_rclpy.Subscription``)."""

    node: Node
    topic_name: str
    typename: str


class Subscription:
    """A subscription created by :meth:`Node.create_subscription`; do not construct it."""

    class CallbackType(Enum):
        """Whether the callback takes the message only, or the message and a MessageInfo."""

        MessageOnly = 0
        WithMessageInfo = 1

    def __init__(
        self,
        subscription_impl: SubscriptionImpl,
        msg_type: type,
        topic: str,
        callback: Callable[..., Any],
        callback_group: Any,
        qos_profile: QoSProfile,
        raw: bool,
        event_callbacks: Any,
    ) -> None:
        self.msg_type = msg_type
        self.topic = topic
        self.callback_group = callback_group
        self.qos_profile = qos_profile
        self.raw = raw
        # CDR bytes in the queue are decoded for the callback unless it asked for them.
        self._decode_bytes = not raw
        self.event_handlers: list[Any] = []
        self._with_info = False
        self._event_callbacks = event_callbacks
        self.callback = callback
        self._node = subscription_impl.node
        self._topic_name = subscription_impl.topic_name
        self._typename = subscription_impl.typename
        self._context = self._node.context
        self._effective_qos = qos_profile
        self._queue: deque[tuple[Any, ...]] = deque()
        self._depth = queue_depth(qos_profile)
        self._owner: Executor | None = None
        # Set by the graph when the subscription is registered.
        self._gid: tuple[int, ...] = ()
        self._alive = True
        self._received = 0
        self._codec = cdr_codec(self._typename)

    @property
    def handle(self) -> Subscription:
        """The underlying subscription (the subscription itself in the built-in runtime)."""
        if not self._alive:
            raise InvalidHandle('Tried to use a handle that has been destroyed.')
        return self

    @property
    def topic_name(self) -> str:
        """The fully qualified (expanded and remapped) topic name."""
        return self._topic_name

    @property
    def callback(self) -> Callable[..., Any]:
        """The user callback: ``f(msg)`` or ``f(msg, message_info)``."""
        return self._callback

    @callback.setter
    def callback(self, value: Callable[..., Any]) -> None:
        signature = inspect.signature(value)
        for arity, callback_type in (
            (1, Subscription.CallbackType.MessageOnly),
            (2, Subscription.CallbackType.WithMessageInfo),
        ):
            try:
                signature.bind(*([object()] * arity))
            except TypeError:
                continue
            self._callback = value
            self._callback_type = callback_type
            self._with_info = callback_type is Subscription.CallbackType.WithMessageInfo
            self._update_plain()
            return
        raise RuntimeError(
            'Subscription.__init__(): callback should be either be callable with one argument'
            '(to get only the message) or two (to get message and message info)'
        )

    def _update_plain(self) -> None:
        """Whether the executor hands a message straight to ``callback(msg)`` (no MessageInfo)."""
        self._plain = not self._with_info

    def _set_effective_qos(self, qos: QoSProfile) -> None:
        self._effective_qos = qos
        self._depth = queue_depth(qos)

    def _enqueue(self, seq: int, data: Any) -> None:
        """Queue one message (latched data); the publisher inlines this on its hot path."""
        queue = self._queue
        if len(queue) >= self._depth:
            queue.popleft()
        if self._with_info:
            queue.append((seq, data, SYSTEM_EPOCH_NS + self._context._elapsed_ns, 0))
        else:
            queue.append((seq, data))
        if self._owner is not None:
            self._owner._inbox.append((seq, self))

    def _deliver(self, entry: tuple[Any, ...]) -> None:
        """Run the callback with one queued message (decoding CDR bytes unless raw)."""
        data = entry[1]
        if not self.raw and type(data) is bytes:
            data = self._codec.deserialize(data)
        self._received += 1
        if self._with_info:
            now_ns = SYSTEM_EPOCH_NS + self._context._elapsed_ns
            # Entries queued before the callback changed to take a MessageInfo lack its data.
            stamp_ns, publication = entry[2:4] if len(entry) == 4 else (now_ns, 0)
            info: MessageInfo = {
                'source_timestamp': stamp_ns,
                'received_timestamp': now_ns,
                'publication_sequence_number': publication,
                'reception_sequence_number': self._received,
            }
            self._callback(data, info)
        else:
            self._callback(data)

    def get_publisher_count(self) -> int:
        """Number of publishers connected to this subscription."""
        publishers = self._context._graph.publishers_on(self._topic_name)
        return sum(1 for publisher in publishers if self in publisher._connected)

    def destroy(self) -> None:
        """Destroy the subscription (use :meth:`Node.destroy_subscription` from node code)."""
        if not self._alive:
            return
        self._alive = False
        self._queue.clear()
        self._owner = None
        self._context._graph.remove_subscription(self)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.destroy()
