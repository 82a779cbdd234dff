"""Stamp arithmetic: seconds <-> nanoseconds <-> (sec, nanosec) of builtin_interfaces/Time.

ROS-free: the functions that build or read a stamp take any object with ``sec`` and
``nanosec`` fields, or the Time class to build one with.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    'NS_PER_S',
    'ns_to_sec_nanosec',
    'seconds_to_ns',
    'seconds_to_sec_nanosec',
    'stamp_from_ns',
    'stamp_from_seconds',
    'stamp_to_seconds',
]

NS_PER_S = 1_000_000_000


def seconds_to_ns(time_s: float) -> int:
    """Time [s] in whole nanoseconds (rounded to the nearest)."""
    return round(time_s * 1e9)


def ns_to_sec_nanosec(time_ns: int) -> tuple[int, int]:
    """(sec, nanosec) of a time in nanoseconds, with 0 <= nanosec < 1e9."""
    sec, nanosec = divmod(int(time_ns), NS_PER_S)
    return sec, nanosec


def seconds_to_sec_nanosec(time_s: float) -> tuple[int, int]:
    """(sec, nanosec) of a time [s], rounded to the nanosecond."""
    return ns_to_sec_nanosec(seconds_to_ns(time_s))


def stamp_to_seconds(stamp: Any) -> float:
    """Seconds of a builtin_interfaces/Time (anything with ``sec`` and ``nanosec``)."""
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def stamp_from_ns(time_ns: int, time_type: Any) -> Any:
    """``time_type(sec=..., nanosec=...)`` of a time in nanoseconds."""
    sec, nanosec = ns_to_sec_nanosec(time_ns)
    return time_type(sec=sec, nanosec=nanosec)


def stamp_from_seconds(time_s: float, time_type: Any) -> Any:
    """``time_type(sec=..., nanosec=...)`` of a time [s], rounded to the nanosecond."""
    return stamp_from_ns(seconds_to_ns(time_s), time_type)
