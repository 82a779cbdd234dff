"""``rclpy.clock``: clocks on the built-in runtime's virtual time.

Time in the built-in runtime never comes from the host:

- SYSTEM_TIME and STEADY_TIME read the context's *virtual wall clock*, which starts at a fixed
  epoch and only moves when an executor advances it (straight to the next wall-timer deadline
  when nothing else is ready, see :mod:`.executors`);
- ROS_TIME reads the same virtual wall clock, unless ROS time is active (``use_sim_time``),
  in which case it reads the last ``/clock`` value its node received (0 before the first one).

A clock also keeps the timers that run on it, so that a new ``/clock`` value can hand the
timers that fell due to their executor, and so that switching ROS time on or off moves them,
with rcl's rules (the elapsed part of a period carries over, "time credit").
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from .clock_type import ClockChange, ClockType
from .duration import Duration
from .errors import BuiltinRuntimeUnsupported
from .time import Time

if TYPE_CHECKING:
    from .context import Context
    from .timer import Timer

__all__ = [
    'STEADY_EPOCH_NS',
    'SYSTEM_EPOCH_NS',
    'Clock',
    'ClockChange',
    'ClockType',
    'JumpHandle',
    'JumpThreshold',
    'ROSClock',
    'TimeJump',
]

#: SYSTEM_TIME (and inactive ROS_TIME) when a context starts: 2024-01-01T00:00:00Z.
SYSTEM_EPOCH_NS = 1_704_067_200 * 1_000_000_000
#: STEADY_TIME when a context starts (a machine that has been up for a day).
STEADY_EPOCH_NS = 86_400 * 1_000_000_000


class JumpThreshold:
    """When a clock jump is worth a callback: forward/backward size, or a source change."""

    def __init__(
        self,
        *,
        min_forward: Duration | None,
        min_backward: Duration | None,
        on_clock_change: bool = True,
    ) -> None:
        if min_forward is not None and min_forward.nanoseconds <= 0:
            raise ValueError('min_forward must be a positive non-zero duration')
        if min_backward is not None and min_backward.nanoseconds >= 0:
            raise ValueError('min_backward must be a negative non-zero duration')
        if min_forward is None and min_backward is None and not on_clock_change:
            raise ValueError('At least one jump threshold must be enabled')
        self.min_forward = min_forward
        self.min_backward = min_backward
        self.on_clock_change = on_clock_change

    def _exceeded(self, clock_change: ClockChange, delta_ns: int) -> bool:
        if clock_change in (ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED):
            return self.on_clock_change
        if delta_ns > 0 and self.min_forward is not None:
            return delta_ns >= self.min_forward.nanoseconds
        if delta_ns < 0 and self.min_backward is not None:
            return delta_ns <= self.min_backward.nanoseconds
        return False


class TimeJump:
    """What a jump callback is told: the kind of change and the jump size."""

    def __init__(self, clock_change: ClockChange, delta: Duration) -> None:
        if not isinstance(clock_change, ClockChange):
            raise TypeError('clock_change must be an instance of rclpy.clock.ClockChange')
        self._clock_change = clock_change
        self._delta = delta

    @property
    def clock_change(self) -> ClockChange:
        """ROS time activated, deactivated, or no change of source."""
        return self._clock_change

    @property
    def delta(self) -> Duration:
        """How far the clock jumped (negative: backwards)."""
        return self._delta


class JumpHandle:
    """A registered pair of jump callbacks; ``unregister()`` (or leaving ``with``) removes it."""

    def __init__(
        self,
        *,
        clock: Clock,
        threshold: JumpThreshold,
        pre_callback: Callable[[], None] | None,
        post_callback: Callable[[TimeJump], None] | None,
    ) -> None:
        if pre_callback is None and post_callback is None:
            raise ValueError('One of pre_callback or post_callback must be callable')
        if pre_callback is not None and not callable(pre_callback):
            raise ValueError('pre_callback must be callable if given')
        if post_callback is not None and not callable(post_callback):
            raise ValueError('post_callback must be callable if given')
        self._clock: Clock | None = clock
        self._threshold = threshold
        self._pre_callback = pre_callback
        self._post_callback = post_callback
        clock._jump_handles.append(self)

    def unregister(self) -> None:
        """Remove the callbacks from the clock."""
        if self._clock is not None:
            self._clock._jump_handles.remove(self)
            self._clock = None

    def __enter__(self) -> JumpHandle:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.unregister()


class Clock:
    """A clock of one type; ``Clock(clock_type=ClockType.ROS_TIME)`` builds a :class:`ROSClock`."""

    _clock_type: ClockType
    _offset_ns: int
    _context: Context | None
    _timers: list[Timer]
    _jump_handles: list[JumpHandle]

    def __new__(cls, *, clock_type: ClockType = ClockType.SYSTEM_TIME) -> Clock:
        if not isinstance(clock_type, ClockType):
            raise TypeError('Clock type must be a ClockType enum')
        if clock_type is ClockType.UNINITIALIZED:
            raise ValueError('A clock cannot be created with clock type UNINITIALIZED')
        self = super().__new__(ROSClock if clock_type is ClockType.ROS_TIME else cls)
        self._clock_type = clock_type
        self._offset_ns = (
            STEADY_EPOCH_NS if clock_type is ClockType.STEADY_TIME else SYSTEM_EPOCH_NS
        )
        self._context = None
        self._timers = []
        self._jump_handles = []
        if clock_type is ClockType.ROS_TIME:
            self._init_ros_time()
        return self

    def _init_ros_time(self) -> None:
        """Set up the ROS time state (only ROSClock has any)."""

    @property
    def clock_type(self) -> ClockType:
        """The type of this clock."""
        return self._clock_type

    @property
    def handle(self) -> Clock:
        """The underlying clock object (the clock itself in the built-in runtime)."""
        return self

    def __repr__(self) -> str:
        return f'Clock(clock_type={self._clock_type.name})'

    def _bind_context(self, context: Context) -> None:
        """Read virtual time from ``context`` instead of the current default context."""
        self._context = context

    def _time_context(self) -> Context:
        if self._context is not None:
            return self._context
        from .utilities import get_default_context

        return get_default_context()

    def _now_ns(self) -> int:
        return self._offset_ns + self._time_context()._elapsed_ns

    def now(self) -> Time:
        """Return the current time of this clock."""
        return Time._from_ns(self._now_ns(), self._clock_type)

    def create_jump_callback(
        self,
        threshold: JumpThreshold,
        *,
        pre_callback: Callable[[], None] | None = None,
        post_callback: Callable[[TimeJump], None] | None = None,
    ) -> JumpHandle:
        """Call ``pre_callback()`` before and ``post_callback(TimeJump)`` after a jump."""
        return JumpHandle(
            clock=self, threshold=threshold, pre_callback=pre_callback, post_callback=post_callback
        )

    def _call_jump_callbacks(self, clock_change: ClockChange, delta_ns: int, *, pre: bool) -> None:
        for handle in list(self._jump_handles):
            if not handle._threshold._exceeded(clock_change, delta_ns):
                continue
            if pre and handle._pre_callback is not None:
                handle._pre_callback()
            elif not pre and handle._post_callback is not None:
                handle._post_callback(TimeJump(clock_change, Duration(nanoseconds=delta_ns)))

    def sleep_until(self, until: Time, context: Any = None) -> bool:
        """Not provided: blocking would stall the single-threaded simulation."""
        raise BuiltinRuntimeUnsupported(
            'Clock.sleep_until() blocks the calling thread, which would stall the built-in '
            "runtime's single-threaded simulation; use a timer (node.create_timer) instead"
        )

    def sleep_for(self, rel_time: Duration, context: Any = None) -> bool:
        """Not provided: blocking would stall the single-threaded simulation."""
        raise BuiltinRuntimeUnsupported(
            'Clock.sleep_for() blocks the calling thread, which would stall the built-in '
            "runtime's single-threaded simulation; use a timer (node.create_timer) instead"
        )

    # Timer bookkeeping, used by rclpy.timer.Timer.

    def _add_timer(self, timer: Timer) -> None:
        self._timers.append(timer)

    def _remove_timer(self, timer: Timer) -> None:
        if timer in self._timers:
            self._timers.remove(timer)

    def _schedule_timer(self, timer: Timer) -> None:
        """File ``timer`` under its next deadline; tell its executor if it is due already."""
        heapq.heappush(
            self._time_context()._wall_heap,
            (timer._next_call_ns - self._offset_ns, timer._seq, timer._gen, timer),
        )
        if timer._next_call_ns <= self._now_ns():
            timer._notify_ready()


class ROSClock(Clock):
    """A ROS_TIME clock: the virtual wall clock, or ``/clock`` time once ROS time is active."""

    _ros_active: bool
    _ros_ns: int
    _timer_heap: list[tuple[int, int, int, Timer]]

    def __new__(cls) -> ROSClock:
        return super().__new__(cls, clock_type=ClockType.ROS_TIME)  # type: ignore[return-value]

    def _init_ros_time(self) -> None:
        self._ros_active = False
        self._ros_ns = 0
        self._timer_heap = []

    @property
    def ros_time_is_active(self) -> bool:
        """True while this clock follows ``/clock`` (use_sim_time) rather than wall time."""
        return self._ros_active

    def _now_ns(self) -> int:
        if self._ros_active:
            return self._ros_ns
        return self._offset_ns + self._time_context()._elapsed_ns

    def now(self) -> Time:
        """Return the current time: ``/clock`` time while ROS time is active, else wall time."""
        if self._ros_active:
            return Time._from_ns(self._ros_ns, ClockType.ROS_TIME)
        return Time._from_ns(self._offset_ns + self._time_context()._elapsed_ns, ClockType.ROS_TIME)

    def _schedule_timer(self, timer: Timer) -> None:
        if not self._ros_active:
            super()._schedule_timer(timer)
            return
        heapq.heappush(self._timer_heap, (timer._next_call_ns, timer._seq, timer._gen, timer))
        if timer._next_call_ns <= self._ros_ns:
            timer._notify_ready()

    def _set_ros_time_is_active(self, enabled: bool) -> None:
        """Switch between wall time and ``/clock`` time (called by the node's TimeSource)."""
        if enabled == self._ros_active:
            return
        change = ClockChange.ROS_TIME_ACTIVATED if enabled else ClockChange.ROS_TIME_DEACTIVATED
        before_ns = self._now_ns()
        self._call_jump_callbacks(change, 0, pre=True)
        for timer in self._timers:
            timer._before_clock_change(before_ns)
        self._ros_active = enabled
        self._timer_heap.clear()
        after_ns = self._now_ns()
        for timer in self._timers:
            timer._after_clock_change(after_ns)
        self._call_jump_callbacks(change, after_ns - before_ns, pre=False)

    def set_ros_time_override(self, time: Time) -> None:
        """Set the ROS time this clock reports while ROS time is active."""
        if not isinstance(time, Time):
            msg = f'Time must be specified as rclpy.time.Time. Received type: {type(time)}'
            raise TypeError(msg)
        self._set_ros_ns(time.nanoseconds)

    def _set_ros_ns(self, nanoseconds: int) -> None:
        """Set the ROS time; hand the timers that fell due to their executors."""
        if self._jump_handles or nanoseconds < self._ros_ns or not self._ros_active:
            self._set_ros_ns_with_jumps(nanoseconds)
            return
        self._ros_ns = nanoseconds
        heap = self._timer_heap
        while heap and heap[0][0] <= nanoseconds:
            entry = heapq.heappop(heap)
            timer = entry[3]
            if entry[2] == timer._gen:
                # Timer._notify_ready() inlined: queue it in its executor's ready heap.
                owner = timer._owner
                if owner is not None:
                    heapq.heappush(owner._ready, entry)

    def _set_ros_ns_with_jumps(self, nanoseconds: int) -> None:
        """The general case: jump callbacks, backward jumps, inactive ROS time."""
        if not self._ros_active:
            self._ros_ns = nanoseconds
            return
        delta_ns = nanoseconds - self._ros_ns
        self._call_jump_callbacks(ClockChange.ROS_TIME_NO_CHANGE, delta_ns, pre=True)
        self._ros_ns = nanoseconds
        if delta_ns < 0:
            for timer in list(self._timers):
                timer._after_backward_jump(nanoseconds)
        heap = self._timer_heap
        while heap and heap[0][0] <= nanoseconds:
            _, _, gen, timer = heapq.heappop(heap)
            if gen == timer._gen:
                timer._notify_ready()
        self._call_jump_callbacks(ClockChange.ROS_TIME_NO_CHANGE, delta_ns, pre=False)
