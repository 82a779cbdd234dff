"""CDR serialization of generated messages.

Little-endian CDR (what rmw sends on every common host) is encoded and decoded by functions
generated per type (:mod:`.cdr_codegen`), which produce the same bytes as rosbags'
typestore. Big-endian data is decoded through rosbags: the message is converted from rosbags'
own message object. When a value cannot be encoded (something with the wrong type got into a
message while field checks were off), the message is walked field by field to name the culprit
in a :class:`SerializationError`.
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
from rosbags.serde import SerdeError

from .cdr_codegen import CdrDecodeError
from .errors import DeserializationError, SerializationError, UnknownMessageTypeError
from .fields import FieldSpec
from .registry import MessageRegistry

__all__ = ['TypeCodec', 'cdr_roundtrip', 'deserialize_cdr', 'message_typename', 'serialize_cdr']

# Exceptions the generated encoders and rosbags raise on values they cannot encode.
_VALUE_ERRORS = (struct.error, TypeError, ValueError, AttributeError, OverflowError, IndexError)
# Exceptions the generated decoders raise on bytes that are not a valid encoding.
_DECODE_ERRORS = (struct.error, CdrDecodeError, ValueError, UnicodeDecodeError, IndexError)
_LITTLE_ENDIAN_HEADER = b'\x00\x01'
_NATIVE_LITTLE_ENDIAN = sys.byteorder == 'little'

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
    try:
        if _NATIVE_LITTLE_ENDIAN:
            return registry.cdr_functions(typename).serialize(message)
        to_rosbags, _ = registry.converters(typename)
        return bytes(
            registry.typestore.serialize_cdr(to_rosbags(message), typename, little_endian=True)
        )
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
    if type(data) is not bytes:
        data = bytes(data)
    if data[:2] == _LITTLE_ENDIAN_HEADER and len(data) >= 4 and _NATIVE_LITTLE_ENDIAN:
        try:
            return registry.cdr_functions(full).deserialize(data)
        except _DECODE_ERRORS as err:
            msg = f'cannot decode {len(data)} bytes as {full}: {err}'
            raise DeserializationError(msg) from err
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
    if not _NATIVE_LITTLE_ENDIAN:
        return deserialize_cdr(serialize_cdr(message, registry), typename, registry)
    functions = registry.cdr_functions(typename)
    try:
        data = functions.serialize(message)
    except _VALUE_ERRORS as err:
        raise _describe_failure(message, typename, registry, err) from err
    return functions.deserialize(data)


class TypeCodec:
    """The CDR encoder and decoder of one message type, with the type looked up once.

    ``serialize(message) -> bytes`` and ``deserialize(data) -> message`` behave exactly like
    :func:`serialize_cdr` and ``deserialize_cdr(data, typename)`` (same bytes, same errors),
    without their per-call type-name and registry lookups: publishers and subscriptions keep
    one per type. The generated functions are compiled at the first call, not at creation.
    """

    __slots__ = ('_registry', '_typename', 'deserialize', 'serialize')

    def __init__(self, typename: str, registry: MessageRegistry) -> None:
        self._typename = registry.get_class(typename).__msgtype__
        self._registry = registry
        self.serialize: Callable[[Any], bytes] = self._serialize_first
        self.deserialize: Callable[[bytes | bytearray | memoryview], Any] = self._deserialize_first

    @property
    def typename(self) -> str:
        """The full type name, e.g. 'sensor_msgs/msg/LaserScan'."""
        return self._typename

    def _serialize_first(self, message: Any) -> bytes:
        self._bind()
        return self.serialize(message)

    def _deserialize_first(self, data: bytes | bytearray | memoryview) -> Any:
        self._bind()
        return self.deserialize(data)

    def _bind(self) -> None:
        """Replace the first-call stand-ins by closures over the generated functions."""
        typename = self._typename
        registry = self._registry
        if not _NATIVE_LITTLE_ENDIAN:
            self.serialize = lambda message: serialize_cdr(message, registry)
            self.deserialize = lambda data: deserialize_cdr(data, typename, registry)
            return
        functions = registry.cdr_functions(typename)
        encode = functions.serialize
        decode = functions.deserialize

        def serialize(message: Any) -> bytes:
            try:
                return encode(message)
            except _VALUE_ERRORS as err:
                raise _describe_failure(message, typename, registry, err) from err

        def deserialize(data: bytes | bytearray | memoryview) -> Any:
            if type(data) is not bytes:
                data = bytes(data)
            # Anything but a little-endian header takes the general path (and its errors).
            if len(data) < 4 or data[1] != 1 or data[0] != 0:
                return deserialize_cdr(data, typename, registry)
            try:
                return decode(data)
            except _DECODE_ERRORS as err:
                msg = f'cannot decode {len(data)} bytes as {typename}: {err}'
                raise DeserializationError(msg) from err

        self.serialize = serialize
        self.deserialize = deserialize


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
