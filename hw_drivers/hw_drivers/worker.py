"""A device loop that reconnects with back-off and never lets a device fault escape.

A driver describes one connected *session* with its device (open, do a bounded piece of I/O
per :meth:`DeviceSession.poll`, close). :class:`DeviceWorker` owns the reconnect policy: it
opens a session, polls it, and on a device fault closes it, records a :class:`DeviceStatus`
for /diagnostics and tries again after a back-off delay. Nodes read :attr:`DeviceWorker.status`
and log its changes; the worker itself never logs (libraries raise, nodes log).

The worker runs in its own thread on a robot (:meth:`DeviceWorker.start`), so blocking device
I/O never stalls the executor; tests call :meth:`DeviceWorker.run_once` with a fake clock.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Protocol

from hw_drivers.backoff import Backoff, BackoffConfig
from hw_drivers.errors import FatalDeviceError, RecoverableDeviceError

__all__ = ['DeviceSession', 'DeviceStatus', 'DeviceWorker', 'DiagnosticLevel']


class DiagnosticLevel(IntEnum):
    """Levels of diagnostic_msgs/DiagnosticStatus."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass(frozen=True)
class DeviceStatus:
    """What the worker last knew about its device, for /diagnostics."""

    level: DiagnosticLevel
    message: str
    values: Mapping[str, str] = field(default_factory=dict)


class DeviceSession(Protocol):
    """One open connection to a device."""

    def poll(self) -> bool:
        """Do one bounded piece of device I/O; return True when it produced data."""
        ...

    def close(self) -> None:
        """Release the device; must not raise."""
        ...


class DeviceWorker:
    """Open, poll and reopen a device session; keep a status for diagnostics.

    Args:
        name: device name used in status messages.
        connect: opens and initialises the device; raises a RecoverableDeviceError,
            FatalDeviceError or OSError when it cannot.
        backoff: reconnect delays.
        clock: monotonic time source [s]; injectable for tests.
        idle_wait_s: pause of the thread loop when a poll produced nothing [s].
    """

    def __init__(
        self,
        name: str,
        connect: Callable[[], DeviceSession],
        *,
        backoff: BackoffConfig | None = None,
        clock: Callable[[], float] = time.monotonic,
        idle_wait_s: float = 0.002,
    ) -> None:
        self.name = name
        self._connect = connect
        self._backoff = Backoff(backoff)
        self._clock = clock
        self._idle_wait_s = idle_wait_s
        self._session: DeviceSession | None = None
        self._next_attempt_s = clock()
        self._lock = threading.Lock()
        self._status = DeviceStatus(DiagnosticLevel.WARN, f'{name}: not connected yet')
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.connect_count = 0
        self.fault_count = 0
        self.close_errors = 0

    @property
    def status(self) -> DeviceStatus:
        """The latest status (thread-safe)."""
        with self._lock:
            return self._status

    @property
    def connected(self) -> bool:
        """True while a session is open."""
        return self._session is not None

    def _set_status(self, level: DiagnosticLevel, message: str) -> None:
        values = {
            'connects': str(self.connect_count),
            'faults': str(self.fault_count),
            'reconnect_failures': str(self._backoff.failures),
        }
        with self._lock:
            self._status = DeviceStatus(level, message, values)

    def run_once(self) -> bool:
        """Connect if due, otherwise poll the session once; return True if data was produced.

        Device faults are absorbed here and turned into a status and a reconnect delay.
        """
        if self._session is None:
            if self._clock() < self._next_attempt_s:
                return False
            try:
                self._session = self._connect()
            except FatalDeviceError as err:
                self._fail(err, fatal=True, while_='opening')
                return False
            except (RecoverableDeviceError, OSError) as err:
                self._fail(err, fatal=False, while_='opening')
                return False
            self.connect_count += 1
            self._backoff.reset()
            self._set_status(DiagnosticLevel.OK, f'{self.name}: connected')
            return False
        try:
            return self._session.poll()
        except FatalDeviceError as err:
            self._fail(err, fatal=True, while_='reading')
        except (RecoverableDeviceError, OSError) as err:
            self._fail(err, fatal=False, while_='reading')
        return False

    def _fail(self, err: BaseException, *, fatal: bool, while_: str) -> None:
        self.fault_count += 1
        self.close_session()
        delay_s = self._backoff.next_delay_s(fatal=fatal)
        self._next_attempt_s = self._clock() + delay_s
        kind = 'fatal error' if fatal else 'error'
        self._set_status(
            DiagnosticLevel.ERROR,
            f'{self.name}: {kind} while {while_}: {err}; retrying in {delay_s:.1f} s',
        )

    def close_session(self) -> None:
        """Close the current session, if any; a failing close is counted, never raised."""
        session, self._session = self._session, None
        if session is None:
            return
        try:
            session.close()
        except Exception:  # closing a vanished device must not stop the reconnect loop
            self.close_errors += 1

    def start(self) -> None:
        """Run the loop in a daemon thread until :meth:`stop`."""
        if self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(target=self._loop, name=f'{self.name}-worker', daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 2.0) -> None:
        """Stop the thread and close the device."""
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join(timeout_s)
        self.close_session()

    def _loop(self) -> None:
        while not self._stop.is_set():
            try:
                produced = self.run_once()
            except Exception as err:  # the device thread must outlive driver bugs
                self._fail(err, fatal=False, while_='running (unexpected)')
                produced = False
            if self._session is None:
                # Sleep until the next attempt is due (at most a second: the clock is
                # injectable), so a missing device costs no CPU between attempts.
                wait_s = max(0.0, min(self._next_attempt_s - self._clock(), 1.0))
                self._stop.wait(wait_s)
            elif not produced:
                self._stop.wait(self._idle_wait_s)
