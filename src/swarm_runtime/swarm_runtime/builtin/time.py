"""``rclpy.time``: a point in time of one clock type, with nanosecond resolution."""

from __future__ import annotations

from functools import cache
from typing import Any

from ._messages import interface_class
from .clock_type import ClockType
from .constants import S_TO_NS
from .duration import Duration

__all__ = ['Time']


@cache
def _time_msg_class() -> Any:
    return interface_class('builtin_interfaces', 'Time')


@cache
def _time_msg_layout() -> tuple[Any, bool]:
    """The Time message class and the field-check default its new messages get."""
    cls = _time_msg_class()
    return cls, cls()._check_fields


_new = object.__new__


_LIMIT = 2**63
_INT32_MIN = -(2**31)
_INT32_MAX = 2**31 - 1


class Time:
    """A point in time: nanoseconds since the epoch of a clock type.

    Times are only comparable with times of the same clock type (a TypeError otherwise).
    """

    __slots__ = ('_clock_type', '_nanoseconds')

    def __init__(
        self,
        *,
        seconds: float = 0,
        nanoseconds: int = 0,
        clock_type: ClockType = ClockType.SYSTEM_TIME,
    ) -> None:
        if not isinstance(clock_type, ClockType):
            raise TypeError('Clock type must be a ClockType enum')
        if seconds < 0:
            raise ValueError('Seconds value must not be negative')
        if nanoseconds < 0:
            raise ValueError('Nanoseconds value must not be negative')
        total = int(seconds * S_TO_NS) + int(nanoseconds)
        if total >= _LIMIT:
            raise OverflowError('Total nanoseconds value is too large to store in C time point.')
        self._nanoseconds = total
        self._clock_type = clock_type

    @classmethod
    def _from_ns(cls, nanoseconds: int, clock_type: ClockType) -> Time:
        """Build a Time from already validated values (the clock's fast path)."""
        time = cls.__new__(cls)
        time._nanoseconds = nanoseconds
        time._clock_type = clock_type
        return time

    @property
    def nanoseconds(self) -> int:
        """Nanoseconds since the clock's epoch."""
        return self._nanoseconds

    @property
    def clock_type(self) -> ClockType:
        """The type of clock this time belongs to."""
        return self._clock_type

    def seconds_nanoseconds(self) -> tuple[int, int]:
        """Return ``(seconds, nanoseconds)`` with 0 <= nanoseconds < 1e9."""
        return divmod(self._nanoseconds, S_TO_NS)

    def __repr__(self) -> str:
        return f'Time(nanoseconds={self._nanoseconds}, clock_type={self._clock_type.name})'

    def __add__(self, other: Duration) -> Time:
        if not isinstance(other, Duration):
            return NotImplemented
        try:
            return Time(
                nanoseconds=self._nanoseconds + other.nanoseconds, clock_type=self._clock_type
            )
        except OverflowError as err:
            raise OverflowError('Addition leads to overflow in C storage.') from err

    def __radd__(self, other: Duration) -> Time:
        return self.__add__(other)

    def __sub__(self, other: Time | Duration) -> Any:
        if isinstance(other, Time):
            self._check_same_clock(other, 'subtract')
            return Duration(nanoseconds=self._nanoseconds - other._nanoseconds)
        if isinstance(other, Duration):
            try:
                return Time(
                    nanoseconds=self._nanoseconds - other.nanoseconds, clock_type=self._clock_type
                )
            except ValueError as err:
                raise ValueError('Subtraction leads to negative time.') from err
        return NotImplemented

    def _check_same_clock(self, other: Time, verb: str) -> None:
        if self._clock_type != other._clock_type:
            msg = f"Can't {verb} times with different clock types"
            raise TypeError(msg)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Time):
            self._check_same_clock(other, 'compare')
            return self._nanoseconds == other._nanoseconds
        raise TypeError("Can't compare time with object of type: ", type(other))

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)

    def __lt__(self, other: Time) -> bool:
        if isinstance(other, Time):
            self._check_same_clock(other, 'compare')
            return self._nanoseconds < other._nanoseconds
        return NotImplemented

    def __le__(self, other: Time) -> bool:
        if isinstance(other, Time):
            self._check_same_clock(other, 'compare')
            return self._nanoseconds <= other._nanoseconds
        return NotImplemented

    def __gt__(self, other: Time) -> bool:
        if isinstance(other, Time):
            self._check_same_clock(other, 'compare')
            return self._nanoseconds > other._nanoseconds
        return NotImplemented

    def __ge__(self, other: Time) -> bool:
        if isinstance(other, Time):
            self._check_same_clock(other, 'compare')
            return self._nanoseconds >= other._nanoseconds
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # unhashable, like rclpy's

    def to_msg(self) -> Any:
        """Return the time as a ``builtin_interfaces.msg.Time``."""
        sec, nanosec = divmod(self._nanoseconds, S_TO_NS)
        cls, check_fields = _time_msg_layout()
        if _INT32_MIN <= sec <= _INT32_MAX:
            # What the constructor would build, without its checks (the values pass them).
            msg = _new(cls)
            msg._check_fields = check_fields
            msg._sec = sec
            msg._nanosec = nanosec
            return msg
        return cls(sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any, clock_type: ClockType = ClockType.ROS_TIME) -> Time:
        """Build a Time from a ``builtin_interfaces.msg.Time`` (ROS time by default)."""
        if not isinstance(msg, _time_msg_class()):
            raise TypeError('Must pass a builtin_interfaces.msg.Time object')
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec, clock_type=clock_type)
