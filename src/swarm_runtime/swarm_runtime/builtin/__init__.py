"""The built-in runtime: an in-process, deterministic, sim-time stand-in for rclpy 7.1.

Node code never imports this package by name: :mod:`swarm_runtime.ros` hands it out as
``rclpy`` when the real one is not available. It mirrors rclpy's module layout
(``rclpy.node``, ``rclpy.qos``, ``rclpy.executors``, ...) and the top-level functions::

    rclpy.init(args=args)
    node = Talker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()

What it provides, and how it differs from a real ROS graph, is described in docs/runtime.md.
rclpy features it does not provide (actions, services, callback groups, multi-threaded
executors, ...) raise :class:`~.errors.BuiltinRuntimeUnsupported` when node code reaches for
them, instead of being silently emulated.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from . import (
    clock,
    clock_type,
    constants,
    context,
    duration,
    errors,
    exceptions,
    executors,
    expand_topic_name,
    logging,
    node,
    parameter,
    publisher,
    qos,
    subscription,
    task,
    time,
    time_source,
    timer,
    topic_endpoint_info,
    type_hash,
    utilities,
    validate_full_topic_name,
    validate_namespace,
    validate_node_name,
    validate_parameter_name,
    validate_topic_name,
)
from .context import Context
from .errors import BuiltinRuntimeUnsupported
from .parameter import Parameter
from .task import Future
from .utilities import (
    get_default_context,
    get_rmw_implementation_identifier,
    ok,
    try_shutdown,
)
from .utilities import shutdown as _shutdown_context

if TYPE_CHECKING:
    from .executors import Executor
    from .node import Node

__all__ = [
    'clock',
    'clock_type',
    'constants',
    'context',
    'create_node',
    'duration',
    'errors',
    'exceptions',
    'executors',
    'expand_topic_name',
    'get_default_context',
    'get_global_executor',
    'get_rmw_implementation_identifier',
    'init',
    'logging',
    'node',
    'ok',
    'parameter',
    'publisher',
    'qos',
    'shutdown',
    'spin',
    'spin_once',
    'spin_until_future_complete',
    'subscription',
    'task',
    'time',
    'time_source',
    'timer',
    'topic_endpoint_info',
    'try_shutdown',
    'type_hash',
    'utilities',
    'validate_full_topic_name',
    'validate_namespace',
    'validate_node_name',
    'validate_parameter_name',
    'validate_topic_name',
]

# rclpy modules and names that exist in real rclpy but not here, with what to do instead.
_UNSUPPORTED = {
    'action': 'actions are not simulated; use topics',
    'callback_groups': 'callback groups have no effect in a single-threaded executor; omit them',
    'client': 'services are not simulated; use topics',
    'service': 'services are not simulated; use topics',
    'guard_condition': 'guard conditions are not simulated; use a timer',
    'event_handler': 'QoS event callbacks are not simulated',
    'qos_event': 'QoS event callbacks are not simulated',
    'qos_overriding_options': 'set QoS profiles in code or through your own parameters',
    'lifecycle': 'managed (lifecycle) nodes are not simulated; use a plain Node',
    'parameter_service': 'parameter services are not simulated; use set_parameters()',
    'parameter_client': 'parameter services are not simulated',
    'parameter_event_handler': 'subscribe to /parameter_events instead',
    'serialization': 'use swarm_runtime.messages.serialize_cdr / deserialize_cdr',
    'signals': 'signal handlers are not installed; Ctrl-C raises KeyboardInterrupt',
    'wait_for_message': 'waiting would block the single-threaded simulation; subscribe instead',
    'type_description_service': 'type descriptions are not simulated',
    'logging_service': 'logger services are not simulated; use Python logging levels',
    'experimental': 'experimental executors are not provided; use SingleThreadedExecutor',
    'impl': 'rclpy.impl is internal to real rclpy',
    'SignalHandlerOptions': 'signal handlers are not installed',
}


def __getattr__(name: str) -> Any:
    advice = _UNSUPPORTED.get(name)
    if advice is None:
        msg = f'module {__name__!r} has no attribute {name!r}'
        raise AttributeError(msg)
    msg = f'rclpy.{name} is not provided by the built-in runtime: {advice}'
    raise BuiltinRuntimeUnsupported(msg)


def init(
    *,
    args: Sequence[str] | None = None,
    context: Context | None = None,
    domain_id: int | None = None,
    signal_handler_options: Any = None,
) -> None:
    """Initialise a context (the default one when None) with command-line arguments.

    ``signal_handler_options`` is accepted and ignored: no signal handlers are installed, so
    Ctrl-C raises KeyboardInterrupt out of ``spin`` as the Python default does.
    """
    (get_default_context() if context is None else context).init(args, domain_id=domain_id)


def shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    """Shut down a context (the default one when None); also resets the global executor."""
    _shutdown_context(context=context)


def get_global_executor() -> Executor:
    """The executor ``spin``/``spin_once`` use when none is given (one per default context)."""
    from .executors import SingleThreadedExecutor

    default_context = get_default_context()
    executor = default_context._global_executor
    if executor is None:
        executor = default_context._global_executor = SingleThreadedExecutor()

        def reset_executor() -> None:
            executor.shutdown()
            default_context._global_executor = None

        default_context.on_shutdown(reset_executor)
    return executor


def create_node(
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
) -> Node:
    """Create a :class:`~.node.Node` (same arguments)."""
    from .node import Node

    return Node(
        node_name,
        context=context,
        cli_args=cli_args,
        namespace=namespace,
        use_global_arguments=use_global_arguments,
        enable_rosout=enable_rosout,
        start_parameter_services=start_parameter_services,
        parameter_overrides=parameter_overrides,
        allow_undeclared_parameters=allow_undeclared_parameters,
        automatically_declare_parameters_from_overrides=(
            automatically_declare_parameters_from_overrides
        ),
        enable_logger_service=enable_logger_service,
    )


def spin_once(
    node: Node, *, executor: Executor | None = None, timeout_sec: float | None = None
) -> None:
    """Add ``node`` to the executor, run at most one callback, remove the node again."""
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        executor.spin_once(timeout_sec=timeout_sec)
    finally:
        executor.remove_node(node)


def spin(node: Node, executor: Executor | None = None) -> None:
    """Run ``node``'s callbacks until the context is shut down."""
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        while executor.context.ok():
            executor.spin_once()
    finally:
        executor.remove_node(node)


def spin_until_future_complete(
    node: Node,
    future: Future,
    executor: Executor | None = None,
    timeout_sec: float | None = None,
) -> None:
    """Run callbacks until ``future`` is done, the timeout expires or shutdown."""
    executor = get_global_executor() if executor is None else executor
    added = False
    try:
        added = executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec)
    finally:
        if added:
            executor.remove_node(node)
