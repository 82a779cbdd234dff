"""``rclpy.clock_type``: the kinds of clock and the kinds of clock change."""

from __future__ import annotations

from enum import Enum

__all__ = ['ClockChange', 'ClockType']


class ClockType(Enum):
    """The time source a clock reads (values as rcl_clock_type_t)."""

    UNINITIALIZED = 0
    #: Simulated time from /clock when use_sim_time is true, otherwise system time.
    ROS_TIME = 1
    #: Wall-clock time since the Unix epoch (virtual in the built-in runtime).
    SYSTEM_TIME = 2
    #: Monotonic time (virtual in the built-in runtime).
    STEADY_TIME = 3


class ClockChange(Enum):
    """What happened to a clock in a time jump (values as rcl_clock_change_t)."""

    ROS_TIME_NO_CHANGE = 1
    ROS_TIME_ACTIVATED = 2
    ROS_TIME_DEACTIVATED = 3
    SYSTEM_TIME_NO_CHANGE = 4
