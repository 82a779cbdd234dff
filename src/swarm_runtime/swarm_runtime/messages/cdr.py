"""CDR serialization of generated messages through rosbags' typestore.

A message is converted to rosbags' own message object (a generated, specialised function per
type) and serialized by the typestore; decoding goes the other way. When rosbags rejects a
value (something with the wrong type that got into a message while field checks were off),
the message is walked field by field to name the culprit in a :class:`SerializationError`.
"""

from __future__ import annotations

import struct
from typing import Any

import numpy as np
from rosbags.serde import SerdeError

from .errors import DeserializationError, SerializationError, UnknownMessageTypeError
from .fields import FieldSpec
from .registry import MessageRegistry

__all__ = ['cdr_roundtrip', 'deserialize_cdr', 'message_typename', 'serialize_cdr']

# Exceptions rosbags' generated (de)serializers and our converters raise on bad values.
_VALUE_ERRORS = (struct.error, TypeError, ValueError, AttributeError, OverflowError, IndexError)

_STRUCT_FORMATS = {
    'bool': '?',
    'byte': 'b',
    'char': 'B',
    'int8': 'b',
    'uint8': 'B',
    'int16': 'h',
    'uint16': 'H',
    'int32': 'i',
    'uint32': 'I',
    'int64': 'q',
    'uint64': 'Q',
    'float32': 'f',
    'float64': 'd',
}


def message_typename(message_or_class: Any) -> str:
    """Return the full type name of a message or message class: 'sensor_msgs/msg/LaserScan'.

    Works for the generated classes, for rosbags' message classes and for real rclpy
    (rosidl-generated) classes.

    Raises:
        UnknownMessageTypeError: the object is not a message or message class.
    """
    cls = message_or_class if isinstance(message_or_class, type) else type(message_or_class)
    typename = getattr(cls, '__msgtype__', None)
    if isinstance(typename, str):
        return typename
    parts = cls.__module__.split('.')
    if (
        len(parts) >= 2
        and parts[1] in ('msg', 'srv', 'action')
        and hasattr(cls, 'get_fields_and_field_types')
    ):
        return f'{parts[0]}/{parts[1]}/{cls.__name__}'
    msg = f'{cls.__module__}.{cls.__qualname__} is not a ROS message class'
    raise UnknownMessageTypeError(msg)


def serialize_cdr(message: Any, registry: MessageRegistry) -> bytes:
    """Serialize a generated message to little-endian CDR (with the 4-byte encapsulation header).

    Raises:
        SerializationError: a field holds a value CDR cannot encode; the message names the
            type, the field path and the offending value.
    """
    typename = message_typename(message)
    to_rosbags, _ = registry.converters(typename)
    try:
        return bytes(registry.typestore.serialize_cdr(to_rosbags(message), typename))
    except (*_VALUE_ERRORS, SerdeError) as err:
        raise _describe_failure(message, typename, registry, err) from err


def deserialize_cdr(
    data: bytes | bytearray | memoryview, typename: str, registry: MessageRegistry
) -> Any:
    """Decode CDR bytes into a generated message of ``typename``.

    Raises:
        DeserializationError: the bytes are not a valid CDR encoding of ``typename``.
    """
    full = registry.get_class(typename).__msgtype__
    _, from_rosbags = registry.converters(full)
    try:
        raw = registry.typestore.deserialize_cdr(data, full)
    except (SerdeError, *_VALUE_ERRORS) as err:
        msg = f'cannot decode {len(data)} bytes as {full}: {err}'
        raise DeserializationError(msg) from err
    return from_rosbags(raw)


def cdr_roundtrip(message: Any, registry: MessageRegistry) -> Any:
    """Return what a subscriber in another process receives for ``message``.

    Equivalent to ``deserialize_cdr(serialize_cdr(message), typename)``: float32 fields come
    back rounded, arrays come back as fresh ``array.array`` / ``numpy.ndarray`` objects.
    """
    typename = message_typename(message)
    to_rosbags, from_rosbags = registry.converters(typename)
    typestore = registry.typestore
    try:
        raw = typestore.serialize_cdr(to_rosbags(message), typename)
    except (*_VALUE_ERRORS, SerdeError) as err:
        raise _describe_failure(message, typename, registry, err) from err
    return from_rosbags(typestore.deserialize_cdr(raw, typename))


# --------------------------------------------------------------------------- diagnosis


def _describe_failure(
    message: Any, typename: str, registry: MessageRegistry, err: Exception
) -> SerializationError:
    problem = _find_problem(message, typename, registry, '')
    if problem is None:
        return SerializationError(f'cannot serialize {typename}: {err}')
    return SerializationError(f'cannot serialize {typename}: {problem}')


def _value_text(value: Any) -> str:
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + '...'
    return f'{type(value).__name__} {text}'


def _find_problem(
    message: Any, typename: str, registry: MessageRegistry, prefix: str
) -> str | None:
    cls = registry.get_class(typename)
    if not isinstance(message, cls):
        return f"field '{prefix[:-1]}' holds {_value_text(message)}, expected a {typename} message"
    for field in registry.spec(typename).fields:
        value = getattr(message, f'_{field.name}')
        path = f'{prefix}{field.name}'
        if field.is_nested:
            problem = _container_problem(value, field, registry, path)
        else:
            problem = _element_problem(value, field, registry, path)
        if problem is not None:
            return problem
    return None


def _element_problem(
    value: Any, field: FieldSpec, registry: MessageRegistry, path: str
) -> str | None:
    element = field.element
    if element.is_message:
        return _find_problem(value, element.nested, registry, f'{path}.')
    if element.is_string:
        if not isinstance(value, str):
            return f"field '{path}' holds {_value_text(value)}, expected str"
        if element.string_bound and len(value) > element.string_bound:
            return f"field '{path}' is longer than its bound of {element.string_bound} characters"
        return None
    if element.base == 'byte':
        if isinstance(value, (bytes, bytearray)) and len(value) == 1:
            return None
        return f"field '{path}' holds {_value_text(value)}, expected bytes of length 1"
    try:
        struct.pack(_STRUCT_FORMATS[element.base], value)
    except (struct.error, TypeError, OverflowError) as err:
        return (
            f"field '{path}' holds {_value_text(value)}, which is not a valid {element.base}: {err}"
        )
    return None


def _container_problem(
    value: Any, field: FieldSpec, registry: MessageRegistry, path: str
) -> str | None:
    try:
        length = len(value)
    except TypeError:
        return f"field '{path}' holds {_value_text(value)}, expected a sequence"
    if field.is_array and length != field.length:
        return f"field '{path}' has {length} elements, expected exactly {field.length}"
    if field.is_sequence and field.length and length > field.length:
        return f"field '{path}' has {length} elements, more than its bound of {field.length}"
    element = field.element
    if element.is_numeric:
        try:
            np.asarray(value, dtype=element.dtype)
        except (TypeError, ValueError, OverflowError) as err:
            text = _value_text(value)
            return f"field '{path}' holds {text}, not convertible to {element.base}: {err}"
        return None
    for index, item in enumerate(value):
        problem = _element_problem(item, field, registry, f'{path}[{index}]')
        if problem is not None:
            return problem
    return None
