"""``rclpy.duration``: a signed span of time with nanosecond resolution."""

from __future__ import annotations

from typing import Any

from ._messages import interface_class
from .constants import S_TO_NS

__all__ = ['Duration', 'Infinite']

_INT64_MIN = -(2**63)
_INT64_MAX = 2**63 - 1


class Duration:
    """A period between two time points, with nanosecond precision (may be negative)."""

    __slots__ = ('_nanoseconds',)

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0) -> None:
        total = int(seconds * S_TO_NS) + int(nanoseconds)
        if not _INT64_MIN <= total <= _INT64_MAX:
            msg = 'Total nanoseconds value is too large to store in C duration.'
            raise OverflowError(msg)
        self._nanoseconds = total

    @property
    def nanoseconds(self) -> int:
        """The duration in nanoseconds."""
        return self._nanoseconds

    def __repr__(self) -> str:
        return f'Duration(nanoseconds={self._nanoseconds})'

    def __str__(self) -> str:
        if self._nanoseconds == _INT64_MAX:
            return 'Infinite'
        return f'{self._nanoseconds} nanoseconds'

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds == other._nanoseconds
        # rclpy raises rather than answering False, so `Duration(...) == 5` is a loud bug.
        raise TypeError("Can't compare duration with object of type: ", type(other))

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __lt__(self, other: Duration) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds < other._nanoseconds
        return NotImplemented

    def __le__(self, other: Duration) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds <= other._nanoseconds
        return NotImplemented

    def __gt__(self, other: Duration) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds > other._nanoseconds
        return NotImplemented

    def __ge__(self, other: Duration) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds >= other._nanoseconds
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # unhashable, like rclpy's

    def to_msg(self) -> Any:
        """Return the duration as a ``builtin_interfaces.msg.Duration``."""
        sec, nanosec = divmod(self._nanoseconds, S_TO_NS)
        return interface_class('builtin_interfaces', 'Duration')(sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any) -> Duration:
        """Build a Duration from a ``builtin_interfaces.msg.Duration``."""
        if not isinstance(msg, interface_class('builtin_interfaces', 'Duration')):
            raise TypeError('Must pass a builtin_interfaces.msg.Duration object')
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec)


#: An infinite duration (RMW_DURATION_INFINITE).
Infinite = Duration(nanoseconds=_INT64_MAX)
