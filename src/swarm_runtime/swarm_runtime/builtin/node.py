"""``rclpy.node``: the Node class of the built-in runtime.

Names, parameters and entity creation follow rclpy 7.1 (Jazzy), including its exception
types and the exact ``SetParametersResult`` reasons. What a Node of real rclpy offers and this
one does not (services, clients, actions, rates, guard conditions, endpoint info) raises
:class:`~.errors.BuiltinRuntimeUnsupported` naming the method.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any

from ._arguments import RosArguments, parameter_overrides_for, parse_ros_arguments, remap_name
from ._messages import interface_module, message_typename
from ._names import expand_name, logger_name_of
from .clock import Clock, ROSClock
from .constants import S_TO_NS
from .errors import BuiltinRuntimeUnsupported
from .exceptions import (
    InvalidHandle,
    InvalidParameterTypeException,
    InvalidParameterValueException,
    NotInitializedException,
    ParameterAlreadyDeclaredException,
    ParameterImmutableException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from .expand_topic_name import expand_topic_name
from .logging import RcutilsLogger, get_logger
from .parameter import PARAMETER_SEPARATOR_STRING, Parameter
from .publisher import Publisher, PublisherImpl
from .qos import QoSProfile, qos_profile_parameter_events
from .subscription import Subscription, SubscriptionImpl
from .time_source import TimeSource
from .timer import Timer
from .utilities import get_default_context
from .validate_full_topic_name import validate_full_topic_name
from .validate_namespace import validate_namespace
from .validate_node_name import validate_node_name
from .validate_parameter_name import validate_parameter_name
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
    'get_publishers_info_by_topic': 'use count_publishers()',
    'get_subscriptions_info_by_topic': 'use count_subscribers()',
    'get_node_names_and_namespaces_with_enclaves': 'enclaves are not simulated',
    'wait_for_node': 'waiting would block the single-threaded simulation',
}


class _CallbackGroupPlaceholder:
    """The default callback group: callback groups have no effect in a single thread."""


def _rcl_interfaces() -> Any:
    return interface_module('rcl_interfaces')


class Node:
    """A ROS node: publishers, subscriptions, timers, parameters, a clock and a logger."""

    #: Relative tolerance when comparing floating-point parameter values with ranges.
    PARAM_REL_TOL = 1e-6

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

    # Parameters: declaration

    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
    ) -> Parameter:
        """Declare a parameter; an override (``-p``, params file, parameter_overrides) wins.

        The type is inferred from ``value`` unless ``descriptor.dynamic_typing``.

        Raises:
            ParameterAlreadyDeclaredException: declared before.
            InvalidParameterTypeException: the override has another type than the default.
            InvalidParameterValueException: a callback or the descriptor (range) rejected it.
        """
        if value is None and descriptor is None:
            spec: tuple[Any, ...] = (name,)
        else:
            descriptor = (
                _rcl_interfaces().ParameterDescriptor() if descriptor is None else descriptor
            )
            spec = (name, value, descriptor)
        return self.declare_parameters('', [spec], ignore_override)[0]

    def declare_parameters(
        self,
        namespace: str,
        parameters: Sequence[tuple[Any, ...]],
        ignore_override: bool = False,
    ) -> list[Parameter]:
        """Declare ``namespace.name`` for each ``(name[, value_or_type[, descriptor]])``.

        Raises:
            TypeError: a malformed tuple.
            ValueError: a statically typed parameter without a usable type.
            ParameterAlreadyDeclaredException, InvalidParameterTypeException,
            InvalidParameterValueException: as :meth:`declare_parameter`.
        """
        self._check_alive()
        descriptor_class = _rcl_interfaces().ParameterDescriptor
        to_declare: list[Parameter] = []
        descriptors: dict[str, Any] = {}
        for index, spec in enumerate(parameters):
            if not 1 <= len(spec) <= 3:
                msg = (
                    f'Invalid parameter tuple length at index {index} in parameters list: '
                    f'{spec}; expecting length between 1 and 3'
                )
                raise TypeError(msg)
            name = spec[0]
            if not isinstance(name, str):
                msg = f'First element {name} at index {index} in parameters list is not a str.'
                raise TypeError(msg)
            if namespace:
                name = f'{namespace}{PARAMETER_SEPARATOR_STRING}{name}'
            validate_parameter_name(name)
            second = spec[1] if len(spec) > 1 else None
            descriptor = spec[2] if len(spec) > 2 else descriptor_class()
            if not isinstance(descriptor, descriptor_class):
                msg = (
                    f'Third element {descriptor} at index {index} in parameters list '
                    'is not a ParameterDescriptor.'
                )
                raise TypeError(msg)
            if len(spec) == 1:
                warnings.warn(
                    f"when declaring parameter named '{name}', declaring a parameter only "
                    'providing its name is deprecated. You have to either:\n'
                    '\t- Pass a name and a default value different to "PARAMETER NOT SET" '
                    '(and optionally a descriptor).\n'
                    '\t- Pass a name and a parameter type.\n'
                    '\t- Pass a name and a descriptor with `dynamic_typing=True',
                    stacklevel=3,
                )
                descriptor.dynamic_typing = True
            value = None
            if isinstance(second, Parameter.Type):
                if second is Parameter.Type.NOT_SET:
                    msg = f'Cannot declare parameter {{{name}}} as statically typed of type NOT_SET'
                    raise ValueError(msg)
                if descriptor.dynamic_typing:
                    msg = (
                        f'When declaring parameter {{{name}}} passing a descriptor with'
                        '`dynamic_typing=True` is not allowed when the parameter type is provided'
                    )
                    raise ValueError(msg)
                descriptor.type = second.value
            else:
                value = second
                if not descriptor.dynamic_typing:
                    descriptor.type = Parameter.Type.from_parameter_value(value).value
                    if descriptor.type == Parameter.Type.NOT_SET.value:
                        raise ValueError(
                            'Cannot declare a statically typed parameter with default value '
                            'of type PARAMETER_NOT_SET'
                        )
            if not ignore_override and name in self._parameter_overrides:
                value = self._parameter_overrides[name].value
            to_declare.append(Parameter(name, value=value))
            descriptors[name] = descriptor
        already = [p.name for p in to_declare if p.name in self._parameters]
        if already:
            raise ParameterAlreadyDeclaredException(already)
        for parameter in to_declare:
            result = self._set_parameters_atomically_common(
                [parameter], descriptors, allow_not_set_type=True
            )
            if not result.successful:
                if result.reason.startswith('Wrong parameter type'):
                    expected = Parameter.Type(descriptors[parameter.name].type).name
                    raise InvalidParameterTypeException(parameter, expected)
                raise InvalidParameterValueException(parameter.name, parameter.value, result.reason)
        return [self._parameters[p.name] for p in to_declare]

    def undeclare_parameter(self, name: str) -> None:
        """Undeclare a parameter.

        Raises:
            ParameterNotDeclaredException: not declared.
            ParameterImmutableException: it is read-only.
        """
        if not self.has_parameter(name):
            raise ParameterNotDeclaredException(name)
        if self._descriptors[name].read_only:
            raise ParameterImmutableException(name)
        del self._parameters[name]
        del self._descriptors[name]

    def has_parameter(self, name: str) -> bool:
        """True if the parameter is declared."""
        return name in self._parameters

    # Parameters: reading

    def get_parameter(self, name: str) -> Parameter:
        """Return a declared parameter.

        Raises:
            ParameterNotDeclaredException: not declared (and undeclared ones not allowed).
            ParameterUninitializedException: statically typed and never given a value.
        """
        if name in self._parameters:
            parameter = self._parameters[name]
            if (
                parameter.type_ is not Parameter.Type.NOT_SET
                or self._descriptors[name].dynamic_typing
            ):
                return parameter
            raise ParameterUninitializedException(name)
        if self._allow_undeclared_parameters:
            return Parameter(name, Parameter.Type.NOT_SET, None)
        raise ParameterNotDeclaredException(name)

    def get_parameters(self, names: list[str]) -> list[Parameter]:
        """Return several parameters (see :meth:`get_parameter`)."""
        if not all(isinstance(name, str) for name in names):
            raise TypeError('All names must be instances of type str')
        return [self.get_parameter(name) for name in names]

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        """Return the parameter, or ``alternative_value`` if undeclared or unset."""
        if alternative_value is None:
            alternative_value = Parameter(name, Parameter.Type.NOT_SET)
        parameter = self._parameters.get(name)
        if parameter is None or parameter.type_ is Parameter.Type.NOT_SET:
            return alternative_value
        return parameter

    def get_parameter_type(self, name: str) -> Any:
        """Return the type of a parameter (its number, like rclpy; NOT_SET if undeclared)."""
        if name in self._parameters:
            return self._parameters[name].type_.value
        if self._allow_undeclared_parameters:
            return Parameter.Type.NOT_SET
        raise ParameterNotDeclaredException(name)

    def get_parameter_types(self, names: list[str]) -> list[Any]:
        """Return the types of several parameters."""
        if not all(isinstance(name, str) for name in names):
            raise TypeError('All names must be instances of type str')
        return [self.get_parameter_type(name) for name in names]

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        """Return ``{name without 'prefix.': parameter}`` for parameters under ``prefix``."""
        if prefix:
            prefix += PARAMETER_SEPARATOR_STRING
        return {
            name[len(prefix) :]: parameter
            for name, parameter in self._parameters.items()
            if name.startswith(prefix)
        }

    def describe_parameter(self, name: str) -> Any:
        """Return the ParameterDescriptor of a parameter.

        Raises:
            ParameterNotDeclaredException: not declared (and undeclared ones not allowed).
        """
        if name in self._descriptors:
            return self._descriptors[name]
        if self._allow_undeclared_parameters:
            return _rcl_interfaces().ParameterDescriptor()
        raise ParameterNotDeclaredException(name)

    def describe_parameters(self, names: list[str]) -> list[Any]:
        """Return the descriptors of several parameters."""
        return [self.describe_parameter(name) for name in names]

    def list_parameters(self, prefixes: list[str], depth: int) -> Any:
        """Return a ListParametersResult of the names (and prefixes) under ``prefixes``.

        ``depth`` 0 means unlimited; otherwise names with at most ``depth`` dots below a
        prefix.
        """
        if not isinstance(prefixes, list):
            raise TypeError('The prefixes argument must be a list')
        if not all(isinstance(prefix, str) for prefix in prefixes):
            raise TypeError('All prefixes must be instances of type str')
        if not isinstance(depth, int):
            raise TypeError('The depth must be instance of type int')
        if depth < 0:
            raise ValueError('The depth must be greater than or equal to zero')
        result = _rcl_interfaces().ListParametersResult()
        separator = PARAMETER_SEPARATOR_STRING

        def shallow(name: str) -> bool:
            return depth == 0 or name.count(separator) < depth

        names: list[str] = []
        result_prefixes: list[str] = []
        for name in self._parameters:
            if prefixes:
                selected = any(
                    name == prefix
                    or (name.startswith(prefix + separator) and shallow(name[len(prefix) + 1 :]))
                    for prefix in prefixes
                )
            else:
                selected = shallow(name)
            if not selected:
                continue
            names.append(name)
            if separator in name:
                prefix = name.rsplit(separator, 1)[0]
                if prefix not in result_prefixes:
                    result_prefixes.append(prefix)
        result.names = names
        result.prefixes = result_prefixes
        return result

    # Parameters: setting

    def set_parameters(self, parameter_list: list[Parameter]) -> list[Any]:
        """Set parameters one at a time; return one SetParametersResult each.

        A wrong type or a rejected value gives ``successful=False`` with a reason, not an
        exception.

        Raises:
            ParameterNotDeclaredException: a parameter is undeclared (and that is not allowed).
        """
        return [self._set_parameters_atomically([parameter]) for parameter in parameter_list]

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        """Set all parameters or none; return one aggregate SetParametersResult."""
        return self._set_parameters_atomically(parameter_list)

    def _set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        if self._pre_set_parameters_callbacks:
            modified: list[Parameter] = []
            for callback in self._pre_set_parameters_callbacks:
                modified.extend(callback(parameter_list))
            parameter_list = modified
            if not parameter_list:
                return _rcl_interfaces().SetParametersResult(
                    successful=False,
                    reason='parameter list cannot be empty, this might be due to '
                    'pre_set_parameters_callback modifying the original parameters list.',
                )
        if not all(isinstance(parameter, Parameter) for parameter in parameter_list):
            msg = f"parameter must be instance of type '{Parameter!r}'"
            raise TypeError(msg)
        undeclared = [p.name for p in parameter_list if p.name not in self._parameters]
        if undeclared and not self._allow_undeclared_parameters:
            raise ParameterNotDeclaredException(undeclared)
        return self._set_parameters_atomically_common(parameter_list)

    def _set_parameters_atomically_common(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, Any] | None = None,
        allow_not_set_type: bool = False,
    ) -> Any:
        set_result_class = _rcl_interfaces().SetParametersResult
        if descriptors is not None:
            result = self._apply_descriptors(parameter_list, descriptors, check_read_only=False)
        else:
            result = self._apply_descriptors(parameter_list, self._descriptors)
        if not result.successful:
            return result
        for callback in self._on_set_parameters_callbacks:
            result = callback(parameter_list)
            if not result.successful:
                return result
        new: list[Parameter] = []
        changed: list[Parameter] = []
        deleted: list[Parameter] = []
        for parameter in parameter_list:
            name = parameter.name
            if not allow_not_set_type and parameter.type_ is Parameter.Type.NOT_SET:
                deleted.append(parameter)
                self._parameters.pop(name, None)
                self._descriptors.pop(name, None)
                continue
            if descriptors is not None:
                self._descriptors[name] = descriptors[name]
            elif name not in self._descriptors:
                self._descriptors[name] = _rcl_interfaces().ParameterDescriptor(dynamic_typing=True)
            if self.get_parameter_or(name).type_ is Parameter.Type.NOT_SET:
                new.append(parameter)
            else:
                changed.append(parameter)
            self._parameters[name] = parameter
        self._publish_parameter_event(new, changed, deleted)
        for callback in self._post_set_parameters_callbacks:
            callback(parameter_list)
        return set_result_class(successful=True)

    def _publish_parameter_event(
        self, new: list[Parameter], changed: list[Parameter], deleted: list[Parameter]
    ) -> None:
        """Publish on /parameter_events, if anyone listens (building it costs)."""
        publisher = self._parameter_event_publisher
        if publisher is None or not publisher._connected:
            return
        event = _rcl_interfaces().ParameterEvent(
            stamp=self._clock.now().to_msg(),
            node=self._fully_qualified_name,
            new_parameters=[p.to_parameter_msg() for p in new],
            changed_parameters=[p.to_parameter_msg() for p in changed],
            deleted_parameters=[p.to_parameter_msg() for p in deleted],
        )
        publisher.publish(event)

    def _apply_descriptors(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, Any],
        check_read_only: bool = True,
    ) -> Any:
        for parameter in parameter_list:
            if parameter.name in descriptors:
                result = self._apply_descriptor(
                    parameter, descriptors[parameter.name], check_read_only
                )
                if not result.successful:
                    return result
        return _rcl_interfaces().SetParametersResult(successful=True)

    def _apply_descriptor(
        self, parameter: Parameter, descriptor: Any = None, check_read_only: bool = True
    ) -> Any:
        """Check a parameter against a descriptor: read-only, type, range and step."""
        result_class = _rcl_interfaces().SetParametersResult
        if descriptor is None:
            descriptor = self.describe_parameter(parameter.name)
        else:
            descriptor.name = parameter.name
        if check_read_only and descriptor.read_only:
            return result_class(
                successful=False,
                reason=f'Trying to set a read-only parameter: {parameter.name}.',
            )
        if descriptor.dynamic_typing:
            descriptor.type = parameter.type_.value
        elif self.has_parameter(parameter.name) and parameter.type_ is Parameter.Type.NOT_SET:
            return result_class(successful=False, reason='Static parameter cannot be undeclared')
        elif (
            parameter.type_ is not Parameter.Type.NOT_SET
            and parameter.type_.value != descriptor.type
        ):
            return result_class(
                successful=False,
                reason=(
                    f"Wrong parameter type, expected '{Parameter.Type(descriptor.type)}'"
                    f" got '{parameter.type_}'"
                ),
            )
        if parameter.type_ is Parameter.Type.INTEGER and descriptor.integer_range:
            return self._apply_integer_range(parameter, descriptor.integer_range[0])
        if parameter.type_ is Parameter.Type.DOUBLE and descriptor.floating_point_range:
            return self._apply_floating_point_range(parameter, descriptor.floating_point_range[0])
        return result_class(successful=True)

    def _apply_integer_range(self, parameter: Parameter, integer_range: Any) -> Any:
        result_class = _rcl_interfaces().SetParametersResult
        low = min(integer_range.from_value, integer_range.to_value)
        high = max(integer_range.from_value, integer_range.to_value)
        value = parameter.value
        if value in (low, high):
            return result_class(successful=True)
        if not low < value < high:
            return result_class(
                successful=False,
                reason=f'Parameter {parameter.name} out of range. '
                f'Min: {low}, Max: {high}, value: {value}',
            )
        step = integer_range.step
        if step != 0 and (value - low) % step != 0:
            return result_class(
                successful=False,
                reason=f'The parameter value for {parameter.name} is not a valid step. '
                f'Min: {low}, max: {high}, value: {value}, step: {step}',
            )
        return result_class(successful=True)

    def _apply_floating_point_range(self, parameter: Parameter, floating_range: Any) -> Any:
        result_class = _rcl_interfaces().SetParametersResult
        low = min(floating_range.from_value, floating_range.to_value)
        high = max(floating_range.from_value, floating_range.to_value)
        value = parameter.value
        tolerance = self.PARAM_REL_TOL
        if math.isclose(value, low, rel_tol=tolerance) or math.isclose(
            value, high, rel_tol=tolerance
        ):
            return result_class(successful=True)
        if not low < value < high:
            return result_class(
                successful=False,
                reason=f'Parameter {parameter.name} out of range '
                f'Min: {low}, Max: {high}, value: {value}',
            )
        step = floating_range.step
        if step != 0.0:
            steps = round((value - low) / step)
            if not math.isclose(low + steps * step, value, rel_tol=tolerance):
                return result_class(
                    successful=False,
                    reason=f'The parameter value for {parameter.name} is not close enough to a '
                    f'valid step. Min: {low}, max: {high}, value: {value}, step: {step}',
                )
        return result_class(successful=True)

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        """Replace a parameter's descriptor; return its (possibly replaced) ParameterValue.

        Raises:
            ParameterNotDeclaredException: not declared.
            ParameterImmutableException: read-only.
            InvalidParameterValueException: neither value complies with the new descriptor.
        """
        if not self.has_parameter(name):
            if not self._allow_undeclared_parameters:
                raise ParameterNotDeclaredException(name)
            return self.get_parameter(name).get_parameter_value()
        if self.describe_parameter(name).read_only:
            raise ParameterImmutableException(name)
        current = self.get_parameter(name)
        if alternative_value is None:
            alternative = current
        else:
            message = _rcl_interfaces().Parameter(name=name, value=alternative_value)
            alternative = Parameter.from_parameter_msg(message)
        if not self._apply_descriptor(current, descriptor, False).successful:
            result = self._apply_descriptor(alternative, descriptor, False)
            if not result.successful:
                raise InvalidParameterValueException(name, alternative.value, result.reason)
            self._parameters[name] = alternative
        self._descriptors[name] = descriptor
        return self.get_parameter(name).get_parameter_value()

    # Parameters: callbacks

    def add_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Call ``callback(parameters) -> parameters`` before validation when setting."""
        self._pre_set_parameters_callbacks.insert(0, callback)

    def add_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        """Call ``callback(parameters) -> SetParametersResult`` to accept or reject values."""
        self._on_set_parameters_callbacks.insert(0, callback)

    def add_post_set_parameters_callback(self, callback: Callable[[list[Parameter]], None]) -> None:
        """Call ``callback(parameters)`` after parameters were set or declared."""
        self._post_set_parameters_callbacks.insert(0, callback)

    def remove_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Remove a pre-set callback (ValueError if absent)."""
        self._pre_set_parameters_callbacks.remove(callback)

    def remove_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        """Remove an on-set callback (ValueError if absent)."""
        self._on_set_parameters_callbacks.remove(callback)

    def remove_post_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], None]
    ) -> None:
        """Remove a post-set callback (ValueError if absent)."""
        self._post_set_parameters_callbacks.remove(callback)

    def __repr__(self) -> str:
        return f'<{type(self).__name__} {self._fully_qualified_name!r} (built-in runtime)>'
