"""DeviceWorker: reconnect policy, back-off, fatal errors, status, failing close."""

import pytest
from hw_drivers.backoff import Backoff, BackoffConfig
from hw_drivers.errors import (
    ConfigurationError,
    DeviceIdentityError,
    DeviceUnavailableError,
    ProtocolError,
)
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.worker import DeviceWorker, DiagnosticLevel


class Session:
    def __init__(self, fail_with=None, close_fails=False):
        self.fail_with = fail_with
        self.close_fails = close_fails
        self.closed = False

    def poll(self):
        if self.fail_with:
            raise self.fail_with
        return True

    def close(self):
        self.closed = True
        if self.close_fails:
            raise OSError(5, 'device vanished')


def test_backoff_doubles_up_to_the_ceiling_and_resets():
    backoff = Backoff(BackoffConfig(initial_s=1.0, max_s=5.0))
    assert [backoff.next_delay_s() for _ in range(5)] == [1.0, 2.0, 4.0, 5.0, 5.0]
    backoff.reset()
    assert backoff.next_delay_s() == 1.0
    assert backoff.next_delay_s(fatal=True) == 30.0


def test_impossible_backoff_is_refused():
    with pytest.raises(ConfigurationError):
        BackoffConfig(initial_s=6.0, max_s=5.0)


def test_fatal_errors_are_retried_slowly():
    clock = FakeClock()
    attempts = []

    def connect():
        attempts.append(clock())
        raise DeviceIdentityError('WHO_AM_I 0x70')

    worker = DeviceWorker('imu', connect, clock=clock)
    for _ in range(100):
        worker.run_once()
        clock.advance(1.0)
    assert attempts[:2] == [0.0, 30.0]
    assert 'fatal error while opening: WHO_AM_I 0x70' in worker.status.message


def test_a_failing_session_is_closed_and_reopened_after_the_delay():
    clock = FakeClock()
    sessions = [Session(fail_with=ProtocolError('bad bytes')), Session()]
    worker = DeviceWorker('dev', lambda: sessions.pop(0), clock=clock)
    worker.run_once()  # connect
    assert worker.status.level is DiagnosticLevel.OK
    worker.run_once()  # poll fails
    assert not worker.connected
    assert worker.status.values['faults'] == '1'
    clock.advance(0.5)
    worker.run_once()
    assert not worker.connected  # still waiting
    clock.advance(0.5)
    worker.run_once()
    assert worker.connected
    assert worker.run_once() is True


def test_a_failing_close_is_counted_not_raised():
    clock = FakeClock()
    session = Session(fail_with=DeviceUnavailableError('unplugged'), close_fails=True)
    worker = DeviceWorker('dev', lambda: session, clock=clock)
    worker.run_once()
    worker.run_once()
    assert session.closed
    assert worker.close_errors == 1
    assert worker.status.level is DiagnosticLevel.ERROR
