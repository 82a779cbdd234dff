"""Field type descriptors used in ``SLOT_TYPES``, named like ``rosidl_parser.definition``.

Generated rosidl classes carry a ``SLOT_TYPES`` tuple of ``rosidl_parser.definition`` objects
(one per field) that generic code such as message printers inspects. These small immutable
records offer the same names and attributes (``typename``, ``value_type``, ``size``,
``maximum_size``, ``namespaces``, ``name``) without depending on rosidl_parser.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    'AbstractNestedType',
    'AbstractSequence',
    'AbstractType',
    'Array',
    'BasicType',
    'BoundedSequence',
    'BoundedString',
    'NamespacedType',
    'UnboundedSequence',
    'UnboundedString',
]


class AbstractType:
    """Base class of every field type descriptor."""

    __slots__ = ()


@dataclass(frozen=True, slots=True)
class BasicType(AbstractType):
    """A primitive type by IDL name: 'float', 'double', 'int8' ... 'uint64', 'boolean', 'octet'."""

    typename: str


@dataclass(frozen=True, slots=True)
class UnboundedString(AbstractType):
    """A ``string`` field."""

    def has_maximum_size(self) -> bool:
        """Return False: the string is unbounded."""
        return False


@dataclass(frozen=True, slots=True)
class BoundedString(AbstractType):
    """A ``string<=N`` field."""

    maximum_size: int

    def has_maximum_size(self) -> bool:
        """Return True: the string has an upper bound."""
        return True


@dataclass(frozen=True, slots=True)
class NamespacedType(AbstractType):
    """A nested message type, e.g. ``NamespacedType(('std_msgs', 'msg'), 'Header')``."""

    namespaces: tuple[str, ...]
    name: str

    def namespaced_name(self) -> tuple[str, ...]:
        """Return the namespaces followed by the name."""
        return (*self.namespaces, self.name)


class AbstractNestedType(AbstractType):
    """Base class of arrays and sequences."""

    __slots__ = ()


class AbstractSequence(AbstractNestedType):
    """Base class of bounded and unbounded sequences."""

    __slots__ = ()


@dataclass(frozen=True, slots=True)
class Array(AbstractNestedType):
    """A fixed-size array ``T[N]``."""

    value_type: AbstractType
    size: int


@dataclass(frozen=True, slots=True)
class UnboundedSequence(AbstractSequence):
    """An unbounded sequence ``T[]``."""

    value_type: AbstractType


@dataclass(frozen=True, slots=True)
class BoundedSequence(AbstractSequence):
    """A bounded sequence ``T[<=N]``."""

    value_type: AbstractType
    maximum_size: int
