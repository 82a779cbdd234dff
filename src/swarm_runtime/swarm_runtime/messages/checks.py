"""Value checks and conversions called by the generated message classes.

These are the building blocks of the field checks rosidl_generator_py emits under
``ROS_PYTHON_CHECK_FIELDS=1`` and of the conversions to and from rosbags' message objects.
They are plain functions so the generated source stays short and each check is one call.
"""

from __future__ import annotations

import math
from array import array
from collections import UserList, UserString
from collections.abc import Iterable, Sequence, Set
from itertools import repeat
from typing import Any

import numpy as np

__all__ = [
    'all_instances',
    'array_from_numpy',
    'arrays_equal',
    'floats_in_range',
    'int8_to_octet',
    'integers_in_range',
    'is_sequence',
    'numeric_array',
    'octet_to_int8',
    'octets_from_numpy',
    'octets_to_numpy',
    'sequence_repr',
]


_PLAIN_SEQUENCES = (list, tuple)
_SEQUENCE_ABCS = (Sequence, Set, UserList)
_STRING_TYPES = (str, UserString)


def is_sequence(value: object) -> bool:
    """rosidl's container test: a set, sequence or UserList that is not a string."""
    if type(value) in _PLAIN_SEQUENCES:
        return True
    return isinstance(value, _SEQUENCE_ABCS) and not isinstance(value, _STRING_TYPES)


def all_instances(values: Iterable[object], cls: type | tuple[type, ...]) -> bool:
    """True when every element of ``values`` is an instance of ``cls``."""
    return all(map(isinstance, values, repeat(cls)))


def floats_in_range(values: Sequence[float] | Set[float], limit: float) -> bool:
    """rosidl's float bound: every value in [-limit, limit], or infinite, or NaN.

    The largest magnitude is found in C first; only when it is out of bounds (or NaN, which
    can hide it) does the exact per-element test run.
    """
    if not values:
        return True
    if max(map(abs, values)) <= limit:
        return True
    return all(not (v < -limit or v > limit) or math.isinf(v) for v in values)


def integers_in_range(values: Sequence[int] | Set[int], low: int, high: int) -> bool:
    """True when every integer lies in [low, high)."""
    if not values:
        return True
    return min(values) >= low and max(values) < high


def sequence_repr(value: Any, check_fields: bool) -> str:
    """rosidl's repr of an array.array field: the list part only, '[]' when empty."""
    if len(value) == 0:
        return '[]'
    text = repr(value)
    if check_fields:
        assert text.startswith('array(')
    return text[len("array('X', ") : -1]


def arrays_equal(first: Any, second: Any) -> bool:
    """Element-wise equality of two fixed-size arrays (False for different lengths)."""
    return bool(np.array_equal(first, second))


def octet_to_int8(value: bytes) -> int:
    """A one-byte ``bytes`` (rosidl's octet) as the signed integer rosbags packs."""
    return int.from_bytes(value, 'little', signed=True)


def int8_to_octet(value: int) -> bytes:
    """The signed integer rosbags decodes for an octet, as rosidl's one-byte ``bytes``."""
    return bytes((value & 0xFF,))


def octets_to_numpy(values: Any) -> np.ndarray:
    """A list of one-byte ``bytes`` (or a bytes-like object) as an int8 array for rosbags."""
    raw = bytes(values) if isinstance(values, (bytes, bytearray, memoryview)) else b''.join(values)
    return np.frombuffer(raw, dtype=np.int8)


def octets_from_numpy(values: np.ndarray) -> list[bytes]:
    """rosbags' int8 array of an octet sequence as rosidl's list of one-byte ``bytes``."""
    raw = values.tobytes()
    return [raw[i : i + 1] for i in range(len(raw))]


_TYPECODE_DTYPES = {
    'f': np.dtype(np.float32),
    'd': np.dtype(np.float64),
    'b': np.dtype(np.int8),
    'B': np.dtype(np.uint8),
    'h': np.dtype(np.int16),
    'H': np.dtype(np.uint16),
    'i': np.dtype(np.int32),
    'I': np.dtype(np.uint32),
    'q': np.dtype(np.int64),
    'Q': np.dtype(np.uint64),
}


def numeric_array(typecode: str, values: Any) -> array:
    """``array.array(typecode, values)``, with a fast path for a 1-D numpy array of that type."""
    if (
        type(values) is np.ndarray
        and values.ndim == 1
        and values.dtype == _TYPECODE_DTYPES[typecode]
    ):
        return array(typecode, values.tobytes())
    return array(typecode, values)


def array_from_numpy(values: np.ndarray, typecode: str) -> array:
    """A new ``array.array`` holding a copy of a 1-D numeric numpy array."""
    return array(typecode, values.tobytes())
