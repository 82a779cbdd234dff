"""``rclpy.timer``: periodic timers with rcl's scheduling rules, on virtual time.

Rules (rcl ``timer.c``): a timer created at time t with period p is first due at t + p. When
it is called at time now, its next deadline moves on by one period; if that is still in the
past (the clock jumped, or the executor was busy), it skips ahead to the first deadline of the
same grid after now, so missed periods are not replayed. A period of 0 is always due.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from .clock import Clock
from .errors import BuiltinRuntimeUnsupported
from .exceptions import InvalidHandle

if TYPE_CHECKING:
    from .context import Context
    from .executors import Executor
    from .node import Node

__all__ = ['Rate', 'Timer']

# Creation order of timers, the tie-breaker between equal deadlines (process-wide, only
# compared, never reset: order matters, values do not).
_creation_order = itertools.count()


class Timer:
    """A timer created by :meth:`Node.create_timer`; do not construct it directly."""

    def __init__(
        self,
        callback: Callable[[], Any] | None,
        callback_group: Any,
        timer_period_ns: int,
        clock: Clock,
        *,
        context: Context | None = None,
        autostart: bool = True,
    ) -> None:
        if not isinstance(clock, Clock):
            raise TypeError(f'clock must be an rclpy.clock.Clock, got {type(clock)}')
        if timer_period_ns < 0:
            msg = f'timer period must not be negative, got {timer_period_ns} ns'
            raise ValueError(msg)
        self.callback = callback
        self.callback_group = callback_group
        self._clock = clock
        self._context = context
        self._period_ns = int(timer_period_ns)
        self._seq = next(_creation_order)
        # Bumped on every reschedule; queued references with an older value are stale.
        self._gen = 0
        self._owner: Executor | None = None
        self._node: Node | None = None
        self._destroyed = False
        self._canceled = not autostart
        self._time_credit_ns = 0
        now = clock._now_ns()
        self._last_call_ns = now
        self._next_call_ns = now + self._period_ns
        clock._add_timer(self)
        if autostart:
            clock._schedule_timer(self)

    @property
    def handle(self) -> Timer:
        """The underlying timer object (the timer itself in the built-in runtime)."""
        self._check_alive()
        return self

    @property
    def clock(self) -> Clock:
        """The clock this timer reads."""
        return self._clock

    @property
    def timer_period_ns(self) -> int:
        """The period in nanoseconds; a new value takes effect after the next call."""
        self._check_alive()
        return self._period_ns

    @timer_period_ns.setter
    def timer_period_ns(self, value: int) -> None:
        self._check_alive()
        if value < 0:
            msg = f'timer period must not be negative, got {value} ns'
            raise ValueError(msg)
        self._period_ns = int(value)

    def is_ready(self) -> bool:
        """True when the timer is running and its deadline has passed."""
        self._check_alive()
        return not self._canceled and self._clock._now_ns() >= self._next_call_ns

    def is_canceled(self) -> bool:
        """True after :meth:`cancel` (or when created with ``autostart=False``)."""
        self._check_alive()
        return self._canceled

    def cancel(self) -> None:
        """Stop the timer; :meth:`reset` starts it again."""
        self._check_alive()
        self._canceled = True
        self._gen += 1

    def reset(self) -> None:
        """(Re)start the timer: next deadline one period from now."""
        self._check_alive()
        self._canceled = False
        self._next_call_ns = self._clock._now_ns() + self._period_ns
        self._reschedule()

    def time_since_last_call(self) -> int:
        """Nanoseconds since the timer was last called (or created)."""
        self._check_alive()
        return self._clock._now_ns() - self._last_call_ns

    def time_until_next_call(self) -> int | None:
        """Nanoseconds until the next deadline (negative when overdue); None when canceled."""
        self._check_alive()
        if self._canceled:
            return None
        return self._next_call_ns - self._clock._now_ns()

    def destroy(self) -> None:
        """Destroy the timer (use :meth:`Node.destroy_timer` from node code)."""
        if self._destroyed:
            return
        self._destroyed = True
        self._canceled = True
        self._gen += 1
        self._owner = None
        self._clock._remove_timer(self)

    def __enter__(self) -> Timer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.destroy()

    def _check_alive(self) -> None:
        if self._destroyed:
            raise InvalidHandle('Tried to use a handle that has been destroyed.')

    # Scheduling, driven by the clock and the executor.

    def _reschedule(self) -> None:
        self._gen += 1
        if not self._canceled and not self._destroyed:
            self._clock._schedule_timer(self)

    def _notify_ready(self) -> None:
        """Queue this timer in its executor's ready heap (stale duplicates are harmless)."""
        owner = self._owner
        if owner is not None:
            heapq.heappush(owner._ready, (self._next_call_ns, self._seq, self._gen, self))

    def _call(self) -> None:
        """Run the timer: move to the next deadline as rcl_timer_call does, then the callback.

        The next deadline moves on by one period; if that is still in the past, it skips to
        the first deadline of the same grid after now (missed periods are not replayed).
        """
        clock = self._clock
        now = clock._now_ns()
        period = self._period_ns
        self._last_call_ns = now
        next_call = self._next_call_ns + period
        if next_call < now:
            if period == 0:
                next_call = now
            else:
                behind = now - next_call
                next_call += (1 + (behind - 1) // period) * period
        self._next_call_ns = next_call
        self._gen += 1
        if not self._canceled:
            clock._schedule_timer(self)
        if self.callback is not None:
            self.callback()

    def _before_clock_change(self, now_ns: int) -> None:
        """ROS time is about to be switched on or off: remember the time left (rcl).

        As in rcl, an uninitialised clock (time 0) records nothing.
        """
        if now_ns != 0:
            self._time_credit_ns = self._next_call_ns - now_ns

    def _after_clock_change(self, now_ns: int) -> None:
        """ROS time was switched: carry the period over to the new time base (rcl's rule).

        rcl sets the next call to ``now - credit + period`` (so a timer 0.6 s before its
        deadline waits 0.4 s of a 1 s period in the new time). As in rcl, nothing is carried
        over while the new time is 0 (no /clock yet): the timer keeps its old deadline, so
        a wall-time deadline far in the future of sim time.
        """
        credit = self._time_credit_ns
        if now_ns != 0 and credit:
            self._time_credit_ns = 0
            self._next_call_ns = now_ns - credit + self._period_ns
            self._last_call_ns = now_ns - credit
        self._reschedule()

    def _after_backward_jump(self, now_ns: int) -> None:
        """The clock went back past the last call: next deadline one period from now."""
        if now_ns < self._last_call_ns:
            self._next_call_ns = now_ns + self._period_ns
            self._last_call_ns = now_ns
            self._reschedule()


class Rate:
    """Not provided: ``Rate.sleep()`` blocks, which would stall the single-threaded simulation."""

    def __init__(self, timer: Any, *, context: Any) -> None:
        raise BuiltinRuntimeUnsupported(
            'rclpy Rate (node.create_rate) blocks in sleep(), which would stall the built-in '
            "runtime's single-threaded simulation; use node.create_timer instead"
        )
