"""``rclpy.node``: the Node class of the built-in runtime.

Names, parameters and entity creation follow rclpy 7.1 (Jazzy), including its exception
types; the parameter methods live in :mod:`._node_parameters`. What a Node of real rclpy
offers and this one does not (services, clients, actions, rates, guard conditions, names
and types by node) raises :class:`~.errors.BuiltinRuntimeUnsupported` naming the method.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from ._arguments import RosArguments, parameter_overrides_for, parse_ros_arguments, remap_name
from ._messages import interface_module, message_typename
from ._names import expand_name, logger_name_of
from ._node_parameters import NodeParameters
from .clock import Clock, ROSClock
from .constants import S_TO_NS
from .errors import BuiltinRuntimeUnsupported
from .exceptions import (
    InvalidHandle,
    NotInitializedException,
)
from .expand_topic_name import expand_topic_name
from .logging import RcutilsLogger, get_logger
from .parameter import Parameter
from .publisher import Publisher, PublisherImpl
from .qos import QoSProfile, qos_profile_parameter_events
from .subscription import Subscription, SubscriptionImpl
from .time_source import TimeSource
from .timer import Timer
from .topic_endpoint_info import TopicEndpointInfo
from .utilities import get_default_context
from .validate_full_topic_name import validate_full_topic_name
from .validate_namespace import validate_namespace
from .validate_node_name import validate_node_name
from .validate_topic_name import validate_topic_name

if TYPE_CHECKING:
    from .context import Context
    from .executors import Executor

__all__ = ['HIDDEN_NODE_PREFIX', 'Node']

HIDDEN_NODE_PREFIX = '_'

# rclpy Node methods that the built-in runtime does not provide, with what to do instead.
_UNSUPPORTED_METHODS = {
    'create_client': 'services are not simulated; use topics',
    'create_service': 'services are not simulated; use topics',
    'destroy_client': 'services are not simulated',
    'destroy_service': 'services are not simulated',
    'create_guard_condition': 'guard conditions are not simulated; use a timer',
    'destroy_guard_condition': 'guard conditions are not simulated',
    'create_rate': 'Rate.sleep() would block the single-threaded simulation; use a timer',
    'destroy_rate': 'rates are not simulated; use a timer',
    'add_waitable': 'waitables are not simulated',
    'remove_waitable': 'waitables are not simulated',
    'resolve_service_name': 'services are not simulated',
    'count_clients': 'services are not simulated',
    'count_services': 'services are not simulated',
    'get_service_names_and_types': 'services are not simulated',
    'get_service_names_and_types_by_node': 'services are not simulated',
    'get_client_names_and_types_by_node': 'services are not simulated',
    'get_publisher_names_and_types_by_node': 'use get_topic_names_and_types()',
    'get_subscriber_names_and_types_by_node': 'use get_topic_names_and_types()',
    'get_node_names_and_namespaces_with_enclaves': 'enclaves are not simulated',
    'wait_for_node': 'waiting would block the single-threaded simulation',
}


class _CallbackGroupPlaceholder:
    """The default callback group: callback groups have no effect in a single thread."""


def _rcl_interfaces() -> Any:
    return interface_module('rcl_interfaces')


class Node(NodeParameters):
    """A ROS node: publishers, subscriptions, timers, parameters, a clock and a logger."""

    def __init__(
        self,
        node_name: str,
        *,
        context: Context | None = None,
        cli_args: list[str] | None = None,
        namespace: str | None = None,
        use_global_arguments: bool = True,
        enable_rosout: bool = True,
        start_parameter_services: bool = True,
        parameter_overrides: list[Parameter] | None = None,
        allow_undeclared_parameters: bool = False,
        automatically_declare_parameters_from_overrides: bool = False,
        enable_logger_service: bool = False,
    ) -> None:
        self._destroyed = True  # until construction succeeds
        self._context = get_default_context() if context is None else context
        if not self._context.ok():
            raise NotInitializedException('cannot create node')
        validate_node_name(node_name)
        namespace = namespace or '/'
        if not namespace.startswith('/'):
            namespace = '/' + namespace
        validate_namespace(namespace)
        local_arguments = parse_ros_arguments(cli_args) if cli_args is not None else None
        # Remap rules: the node's own arguments first; parameters: the node's own win.
        self._remap_sources: tuple[RosArguments, ...] = tuple(
            arguments
            for arguments in (
                local_arguments,
                self._context._arguments if use_global_arguments else None,
            )
            if arguments is not None
        )
        remapped_name = remap_name(self._remap_sources, '__node', node_name)
        if remapped_name is not None:
            validate_node_name(remapped_name)
            node_name = remapped_name
        remapped_namespace = remap_name(self._remap_sources, '__ns', node_name)
        if remapped_namespace is not None:
            validate_namespace(remapped_namespace)
            namespace = remapped_namespace
        self._name = node_name
        self._namespace = namespace
        self._fully_qualified_name = (
            f'/{node_name}' if namespace == '/' else f'{namespace}/{node_name}'
        )
        self._logger = get_logger(logger_name_of(node_name, namespace))
        self._enable_rosout = enable_rosout
        self._executor: Executor | None = None
        self._publishers: list[Publisher] = []
        self._subscriptions: list[Subscription] = []
        self._timers: list[Timer] = []
        self._default_callback_group = _CallbackGroupPlaceholder()
        self._parameters: dict[str, Parameter] = {}
        self._descriptors: dict[str, Any] = {}
        self._pre_set_parameters_callbacks: list[Callable[[list[Parameter]], list[Parameter]]] = []
        self._on_set_parameters_callbacks: list[Callable[[list[Parameter]], Any]] = []
        self._post_set_parameters_callbacks: list[Callable[[list[Parameter]], None]] = []
        self._allow_undeclared_parameters = allow_undeclared_parameters
        self._destroyed = False
        self._context._graph.add_node(self)

        self._parameter_event_publisher: Publisher | None = self.create_publisher(
            _rcl_interfaces().ParameterEvent, '/parameter_events', qos_profile_parameter_events
        )
        override_sources = tuple(reversed(self._remap_sources))
        self._parameter_overrides: dict[str, Parameter] = {
            name: Parameter(name, value=value)
            for name, value in parameter_overrides_for(
                override_sources, self._fully_qualified_name
            ).items()
        }
        if parameter_overrides is not None:
            self._parameter_overrides.update({p.name: p for p in parameter_overrides})

        self._clock = ROSClock()
        self._clock._bind_context(self._context)
        if automatically_declare_parameters_from_overrides:
            descriptor_class = _rcl_interfaces().ParameterDescriptor
            self.declare_parameters(
                '',
                [
                    (name, parameter.value, descriptor_class())
                    for name, parameter in self._parameter_overrides.items()
                ],
                ignore_override=True,
            )
        self._time_source = TimeSource(node=self)
        self._time_source.attach_clock(self._clock)

    def __getattr__(self, name: str) -> Any:
        advice = _UNSUPPORTED_METHODS.get(name)
        if advice is None:
            msg = f"'{type(self).__name__}' object has no attribute '{name}'"
            raise AttributeError(msg)
        msg = f'Node.{name}() is not provided by the built-in runtime: {advice}'
        raise BuiltinRuntimeUnsupported(msg)

    # Identity

    @property
    def handle(self) -> Node:
        """The underlying node (the node itself); InvalidHandle once destroyed."""
        self._check_alive()
        return self

    def _check_alive(self) -> None:
        if self._destroyed:
            raise InvalidHandle('Tried to use a handle that has been destroyed.')

    @property
    def context(self) -> Context:
        """The context the node belongs to."""
        return self._context

    @property
    def executor(self) -> Executor | None:
        """The executor the node was added to, or None."""
        return self._executor

    @executor.setter
    def executor(self, new_executor: Executor | None) -> None:
        current = self._executor
        if current is new_executor:
            return
        if current is not None:
            current.remove_node(self)
        if new_executor is not None:
            new_executor.add_node(self)

    @property
    def default_callback_group(self) -> Any:
        """The default callback group (callback groups have no effect here)."""
        return self._default_callback_group

    @property
    def publishers(self) -> Iterator[Publisher]:
        """The node's publishers."""
        yield from self._publishers

    @property
    def subscriptions(self) -> Iterator[Subscription]:
        """The node's subscriptions."""
        yield from self._subscriptions

    @property
    def timers(self) -> Iterator[Timer]:
        """The node's timers."""
        yield from self._timers

    @property
    def clients(self) -> Iterator[Any]:
        """Always empty: services are not simulated."""
        yield from ()

    @property
    def services(self) -> Iterator[Any]:
        """Always empty: services are not simulated."""
        yield from ()

    @property
    def guards(self) -> Iterator[Any]:
        """Always empty: guard conditions are not simulated."""
        yield from ()

    @property
    def waitables(self) -> Iterator[Any]:
        """Always empty: waitables are not simulated."""
        yield from ()

    def get_name(self) -> str:
        """The node name (after ``__node`` remapping)."""
        self._check_alive()
        return self._name

    def get_namespace(self) -> str:
        """The node namespace (after ``__ns`` remapping), e.g. ``'/r0'``."""
        self._check_alive()
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        """Namespace and name, e.g. ``'/r0/algo'``."""
        self._check_alive()
        return self._fully_qualified_name

    def get_clock(self) -> Clock:
        """The node's ROS clock (``/clock`` time when use_sim_time is true)."""
        return self._clock

    def get_logger(self) -> RcutilsLogger:
        """The node's logger, named like rcl (``r0.algo``)."""
        return self._logger

    # Names

    def resolve_topic_name(self, topic: str, *, only_expand: bool = False) -> str:
        """Expand a topic name and (unless ``only_expand``) apply the remapping rules.

        Raises:
            InvalidTopicNameException: the name is invalid before or after expansion.
        """
        self._check_alive()
        validate_topic_name(topic)
        expanded = expand_topic_name(topic, self._name, self._namespace)
        validate_full_topic_name(expanded)
        if only_expand:
            return expanded

        def expand_rule_side(name: str) -> str | None:
            try:
                return expand_name(name, self._name, self._namespace)
            except ValueError:
                return None

        remapped = remap_name(self._remap_sources, expanded, self._name, expand=expand_rule_side)
        if remapped is None:
            return expanded
        validate_full_topic_name(remapped)
        return remapped

    def _resolve_entity_topic(self, topic: str) -> str:
        """Resolve the topic of a new publisher or subscription (TypeError if not a str)."""
        if not isinstance(topic, str):
            msg = f'topic name must be a str, got {type(topic).__name__}'
            raise TypeError(msg)
        return self.resolve_topic_name(topic)

    @staticmethod
    def _validate_qos_or_depth_parameter(qos_or_depth: QoSProfile | int) -> QoSProfile:
        if isinstance(qos_or_depth, QoSProfile):
            return qos_or_depth
        if isinstance(qos_or_depth, int):
            if qos_or_depth < 0:
                raise ValueError('history depth must be greater than or equal to zero')
            return QoSProfile(depth=qos_or_depth)
        msg = f'Expected QoSProfile or int, but received {type(qos_or_depth)!r}'
        raise TypeError(msg)

    @staticmethod
    def _reject_qos_overriding(qos_overriding_options: Any) -> None:
        if qos_overriding_options is not None:
            raise BuiltinRuntimeUnsupported(
                'qos_overriding_options are not provided by the built-in runtime: set the QoS '
                'profile in code or through your own parameters'
            )

    # Entities

    def create_publisher(
        self,
        msg_type: type,
        topic: str,
        qos_profile: QoSProfile | int,
        *,
        callback_group: Any = None,
        event_callbacks: Any = None,
        qos_overriding_options: Any = None,
        publisher_class: type[Publisher] = Publisher,
    ) -> Publisher:
        """Create a publisher; ``qos_profile`` may be a depth (RELIABLE, KEEP_LAST depth).

        Raises:
            InvalidTopicNameException: an invalid topic name.
            RuntimeError: ``msg_type`` is not a message class.
        """
        self._check_alive()
        qos = self._validate_qos_or_depth_parameter(qos_profile)
        topic_name = self._resolve_entity_topic(topic)
        self._reject_qos_overriding(qos_overriding_options)
        implementation = PublisherImpl(self, topic_name, message_typename(msg_type))
        publisher = publisher_class(
            implementation,
            msg_type,
            topic,
            qos,
            event_callbacks=event_callbacks,
            callback_group=callback_group or self._default_callback_group,
        )
        self._context._graph.add_publisher(publisher)
        self._publishers.append(publisher)
        return publisher

    def create_subscription(
        self,
        msg_type: type,
        topic: str,
        callback: Callable[..., Any],
        qos_profile: QoSProfile | int,
        *,
        callback_group: Any = None,
        event_callbacks: Any = None,
        qos_overriding_options: Any = None,
        raw: bool = False,
    ) -> Subscription:
        """Create a subscription; with ``raw=True`` the callback receives the CDR bytes.

        Raises:
            InvalidTopicNameException: an invalid topic name.
            RuntimeError: ``msg_type`` is not a message class, or the callback takes neither
                one nor two arguments.
        """
        self._check_alive()
        qos = self._validate_qos_or_depth_parameter(qos_profile)
        topic_name = self._resolve_entity_topic(topic)
        self._reject_qos_overriding(qos_overriding_options)
        implementation = SubscriptionImpl(self, topic_name, message_typename(msg_type))
        subscription = Subscription(
            implementation,
            msg_type,
            topic,
            callback,
            callback_group or self._default_callback_group,
            qos,
            raw,
            event_callbacks=event_callbacks,
        )
        subscription._owner = self._executor
        self._context._graph.add_subscription(subscription)
        self._subscriptions.append(subscription)
        return subscription

    def create_timer(
        self,
        timer_period_sec: float,
        callback: Callable[[], Any] | None,
        callback_group: Any = None,
        clock: Clock | None = None,
        autostart: bool = True,
    ) -> Timer:
        """Create a timer on the node's clock (or ``clock``) calling ``callback()`` each period."""
        self._check_alive()
        timer_period_ns = int(float(timer_period_sec) * S_TO_NS)
        timer = Timer(
            callback,
            callback_group or self._default_callback_group,
            timer_period_ns,
            self._clock if clock is None else clock,
            context=self._context,
            autostart=autostart,
        )
        timer._node = self
        timer._owner = self._executor
        if timer._owner is not None and timer.is_ready():
            timer._notify_ready()
        self._timers.append(timer)
        return timer

    def destroy_publisher(self, publisher: Publisher) -> bool:
        """Destroy one of the node's publishers; False if it is not the node's."""
        if publisher not in self._publishers:
            return False
        self._publishers.remove(publisher)
        publisher.destroy()
        return True

    def destroy_subscription(self, subscription: Subscription) -> bool:
        """Destroy one of the node's subscriptions; False if it is not the node's."""
        if subscription not in self._subscriptions:
            return False
        self._subscriptions.remove(subscription)
        subscription.destroy()
        return True

    def destroy_timer(self, timer: Timer) -> bool:
        """Destroy one of the node's timers; False if it is not the node's."""
        if timer not in self._timers:
            return False
        self._timers.remove(timer)
        timer.destroy()
        return True

    def destroy_node(self) -> None:
        """Destroy every entity of the node, then the node itself (idempotent)."""
        if self._destroyed:
            return
        self._parameter_event_publisher = None
        while self._publishers:
            self.destroy_publisher(self._publishers[0])
        while self._subscriptions:
            self.destroy_subscription(self._subscriptions[0])
        while self._timers:
            self.destroy_timer(self._timers[0])
        self._context._graph.remove_node(self)
        executor = self._executor
        if executor is not None:
            executor.remove_node(self)
        self._destroyed = True

    # Graph

    def get_topic_names_and_types(self, no_demangle: bool = False) -> list[tuple[str, list[str]]]:
        """``[(topic, ['pkg/msg/Type'])]`` for every topic with an endpoint in the context."""
        self._check_alive()
        return self._context._graph.topic_names_and_types()

    def get_node_names(self) -> list[str]:
        """Names of the nodes in the context."""
        return [name for name, _ in self.get_node_names_and_namespaces()]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """``(name, namespace)`` of the nodes in the context."""
        self._check_alive()
        return self._context._graph.node_names_and_namespaces()

    def get_fully_qualified_node_names(self) -> list[str]:
        """Fully qualified names of the nodes in the context."""
        return [
            namespace + ('' if namespace.endswith('/') else '/') + name
            for name, namespace in self.get_node_names_and_namespaces()
        ]

    def _expand_for_count(self, topic_name: str) -> str:
        expanded = expand_topic_name(topic_name, self._name, self._namespace)
        validate_full_topic_name(expanded)
        return expanded

    def count_publishers(self, topic_name: str) -> int:
        """Publishers on a topic (relative names expanded, not remapped)."""
        self._check_alive()
        return self._context._graph.count_publishers(self._expand_for_count(topic_name))

    def count_subscribers(self, topic_name: str) -> int:
        """Subscriptions on a topic (relative names expanded, not remapped)."""
        self._check_alive()
        return self._context._graph.count_subscribers(self._expand_for_count(topic_name))

    def _topic_for_info(self, topic_name: str, no_mangle: bool) -> str:
        """rclpy's name handling for endpoint info: expanded, validated and remapped.

        With ``no_mangle`` the name is taken as the middleware's topic name; the built-in
        runtime has no name mangling, so that is the graph's name as given.
        """
        if no_mangle:
            return topic_name
        expanded = expand_topic_name(topic_name, self._name, self._namespace)
        validate_full_topic_name(expanded)
        return self.resolve_topic_name(expanded)

    def get_publishers_info_by_topic(
        self, topic_name: str, no_mangle: bool = False
    ) -> list[TopicEndpointInfo]:
        """Node, type, GID and announced QoS of each publisher on a topic.

        ``topic_name`` may be relative or private (expanded with this node's namespace and
        name, then remapped, as rclpy does). The QoS profile is what the publisher announces
        in discovery (see :mod:`.topic_endpoint_info`): its resolved reliability and
        durability, history UNKNOWN with depth 0.

        Raises:
            InvalidTopicNameException: an invalid topic name.
        """
        self._check_alive()
        return self._context._graph.publishers_info(self._topic_for_info(topic_name, no_mangle))

    def get_subscriptions_info_by_topic(
        self, topic_name: str, no_mangle: bool = False
    ) -> list[TopicEndpointInfo]:
        """Node, type, GID and announced QoS of each subscription on a topic.

        Name handling as in :meth:`get_publishers_info_by_topic`.

        Raises:
            InvalidTopicNameException: an invalid topic name.
        """
        self._check_alive()
        return self._context._graph.subscriptions_info(self._topic_for_info(topic_name, no_mangle))

    def __repr__(self) -> str:
        return f'<{type(self).__name__} {self._fully_qualified_name!r} (built-in runtime)>'
