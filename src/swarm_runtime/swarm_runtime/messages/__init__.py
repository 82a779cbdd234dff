"""rosidl-like message classes generated at runtime, and CDR serialization of them.

The classes come from the same definitions a ROS 2 Jazzy machine uses: the standard types
from rosbags' ROS2_JAZZY typestore and the project's own from ``swarm_interfaces/msg/*.msg``.
They behave like rosidl_generator_py's classes (keyword construction, defaults, field checks
under ``ROS_PYTHON_CHECK_FIELDS=1``, ``__eq__``, ``__repr__``, ``get_fields_and_field_types()``)::

    from swarm_runtime.messages import get_message_module, cdr_roundtrip

    sensor_msgs = get_message_module('sensor_msgs')
    scan = sensor_msgs.LaserScan(angle_increment=0.0174)
    received = cdr_roundtrip(scan)   # what another process would receive (float32 rounding)

Field checks follow Jazzy: ``ROS_PYTHON_CHECK_FIELDS=1`` turns them on; it is read once per
package, when the package's module is first created (rosidl reads it when the generated module
is imported), and ``check_fields=`` in a constructor overrides it per message. As in rosidl,
the constructor wraps a numeric sequence in ``array.array`` before checking it (so a numpy
array is accepted there), while assigning a numpy array to that field fails the check.

Node code does not import this module: it goes through :mod:`swarm_runtime.ros`, which hands
out the real generated classes on a ROS machine.
"""

from __future__ import annotations

from typing import Any

from rosbags.typesys.store import Typestore

from . import cdr as _cdr
from .codegen import GeneratedMessage
from .errors import (
    DeserializationError,
    InterfaceDefinitionError,
    InterfacesNotFoundError,
    MessageError,
    SerializationError,
    UnknownMessageTypeError,
    UnknownPackageError,
)
from .registry import MessageModule, MessageRegistry, default_registry, normalize_typename

__all__ = [
    'DeserializationError',
    'GeneratedMessage',
    'InterfaceDefinitionError',
    'InterfacesNotFoundError',
    'MessageError',
    'MessageModule',
    'MessageRegistry',
    'SerializationError',
    'UnknownMessageTypeError',
    'UnknownPackageError',
    'cdr_roundtrip',
    'default_registry',
    'deserialize_cdr',
    'get_cdr_codec',
    'get_message_class',
    'get_message_module',
    'get_typestore',
    'is_message',
    'message_typename',
    'normalize_typename',
    'serialize_cdr',
]


def get_message_module(package: str) -> MessageModule:
    """Return the module-like object of a package's messages: ``get_message_module('std_msgs')``.

    Raises:
        UnknownPackageError: no type of ``package`` is known.
        InterfacesNotFoundError: ``package`` is swarm_interfaces and its definitions cannot be
            located (see :mod:`swarm_runtime.messages.interface_paths`).
    """
    return default_registry().get_module(package)


def get_message_class(typename: str) -> type[GeneratedMessage]:
    """Return the class of 'sensor_msgs/msg/LaserScan' (or 'sensor_msgs/LaserScan').

    Raises:
        UnknownMessageTypeError: the type is not known.
    """
    return default_registry().get_class(typename)


def message_typename(message_or_class: Any) -> str:
    """Return 'sensor_msgs/msg/LaserScan' for a LaserScan message or class (generated, rosbags
    or real rclpy).

    Raises:
        UnknownMessageTypeError: the object is not a message or message class.
    """
    return _cdr.message_typename(message_or_class)


def is_message(value: Any) -> bool:
    """True for an instance of a generated message class."""
    return isinstance(value, GeneratedMessage)


def serialize_cdr(message: Any) -> bytes:
    """Serialize a generated message to CDR bytes, as rmw puts it on the wire.

    Raises:
        SerializationError: a field holds a value that cannot be encoded (names the field).
    """
    typename = getattr(type(message), '__msgtype__', None)
    if type(typename) is str:
        return default_registry().codec(typename).serialize(message)
    return _cdr.serialize_cdr(message, default_registry())


def deserialize_cdr(data: bytes | bytearray | memoryview, typename: str) -> Any:
    """Decode CDR bytes into a message of ``typename`` ('sensor_msgs/msg/LaserScan').

    Raises:
        DeserializationError: the bytes are not a valid encoding of the type.
        UnknownMessageTypeError: the type is not known.
    """
    return default_registry().codec(typename).deserialize(data)


def get_cdr_codec(typename: str) -> _cdr.TypeCodec:
    """Return the CDR codec of one type: ``codec.serialize(msg)``, ``codec.deserialize(data)``.

    Same results and errors as :func:`serialize_cdr` / :func:`deserialize_cdr`, without their
    per-call type lookups (what the built-in runtime's publishers and subscriptions use).

    Raises:
        UnknownMessageTypeError: the type is not known.
    """
    return default_registry().codec(typename)


def cdr_roundtrip(message: Any) -> Any:
    """Return what a subscriber in another process receives when ``message`` is published."""
    return _cdr.cdr_roundtrip(message, default_registry())


def get_typestore() -> Typestore:
    """Return the rosbags typestore behind the classes (ROS2_JAZZY + swarm_interfaces).

    Raises:
        InterfacesNotFoundError: the swarm_interfaces definitions cannot be located.
    """
    registry = default_registry()
    registry.require_interfaces()
    return registry.typestore
