"""``rclpy.type_hash``: the REP 2011 hash of a message type (RIHS01 in Jazzy)."""

from __future__ import annotations

from typing import TypedDict

__all__ = ['TypeHash', 'TypeHashDictionary']

_TYPE_HASH_SIZE = 32


class TypeHashDictionary(TypedDict):
    """The form rmw hands a type hash to rclpy in: ``{'version': 1, 'value': b'...'}``."""

    version: int
    value: bytes


class TypeHash:
    """Version and 32-byte value of a type hash; the default (version -1) means unknown."""

    __slots__ = ('_value', '_version')

    _TYPE_HASH_SIZE = _TYPE_HASH_SIZE

    def __init__(self, version: int = -1, value: bytes = bytes(_TYPE_HASH_SIZE)) -> None:
        self.version = version
        self.value = value

    @property
    def version(self) -> int:
        """Hash algorithm version (1 for RIHS01; -1 when unknown)."""
        return self._version

    @version.setter
    def version(self, value: int) -> None:
        if not isinstance(value, int):
            raise AssertionError(f'version must be an int, got {value!r}')
        self._version = value

    @property
    def value(self) -> bytes:
        """The hash bytes."""
        return self._value

    @value.setter
    def value(self, value: bytes) -> None:
        if not isinstance(value, bytes):
            raise AssertionError(f'value must be bytes, got {value!r}')
        self._value = value

    @classmethod
    def _from_text(cls, text: str) -> TypeHash:
        """Parse ``'RIHS01_<64 hex digits>'``; anything else gives the unknown hash."""
        prefix, _, digits = text.partition('_')
        if len(prefix) != 6 or not prefix.startswith('RIHS') or not prefix[4:].isdigit():
            return cls()
        try:
            value = bytes.fromhex(digits)
        except ValueError:
            return cls()
        if len(value) != _TYPE_HASH_SIZE:
            return cls()
        return cls(version=int(prefix[4:]), value=value)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TypeHash):
            return False
        return (self._version, self._value) == (other._version, other._value)

    __hash__ = None  # type: ignore[assignment]  # mutable, like rclpy's

    def __str__(self) -> str:
        if self._version <= 0 or len(self._value) != _TYPE_HASH_SIZE:
            return 'INVALID'
        return f'RIHS{self._version:02}_{self._value.hex()}'

    def __repr__(self) -> str:
        return f'TypeHash(version={self._version}, value={self._value!r})'
