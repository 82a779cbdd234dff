"""A DDS domain of its own for each test process, with discovery kept on this machine.

Tests on real rclpy talk over DDS. Two test processes in one domain would see each other's
nodes and topics (a recorder records the other's messages, ``wait_for_graph`` counts the
other's publishers), so every test process, each pytest-xdist worker and every concurrent
test session on the host, gets a domain id no other test process holds, and discovery
stays on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``). Both must be in the
environment before rclpy is imported; child processes a test starts inherit them and join
the same domain. The repository's root ``conftest.py`` does this once per process::

    reservation = isolate_test_process()      # before anything imports rclpy
    reservation.domain_id                     # also in os.environ['ROS_DOMAIN_ID']

The preferred domain is ``SWARM_TEST_DOMAIN_BASE`` (default 40) plus the pytest-xdist worker
number (``gw3`` -> base + 3). A domain is held by an advisory lock on a file in the temporary
directory for as long as the process lives; when another test process holds the preferred
one, the next free id up to 101 is taken (wrapping round to 1). Ids above 101 are not used:
with Fast DDS and Cyclone DDS their ports reach Linux's ephemeral port range.

This module imports nothing of ROS, so it can run before rclpy is imported.
"""

from __future__ import annotations

import fcntl
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import IO

__all__ = [
    'DOMAIN_BASE_ENV_VAR',
    'MAX_TEST_DOMAIN_ID',
    'DomainReservation',
    'DomainsExhaustedError',
    'dds_test_environment',
    'isolate_test_process',
    'preferred_test_domain',
    'reserve_test_domain',
]

#: Environment variable that moves the block of domain ids the tests prefer.
DOMAIN_BASE_ENV_VAR = 'SWARM_TEST_DOMAIN_BASE'
DEFAULT_DOMAIN_BASE = 40
#: The highest id whose ports stay below the ephemeral range on Linux (ROS 2 domain id docs).
MAX_TEST_DOMAIN_ID = 101
# Domain 0 is every ROS installation's default: never used by tests.
_FIRST_TEST_DOMAIN_ID = 1
_LOCK_DIR_NAME = 'swarm-search-ros-test-domains'


class DomainsExhaustedError(RuntimeError):
    """Every test domain id is held by another test process on this machine."""


@dataclass
class DomainReservation:
    """A domain id held by this process; the lock goes with :meth:`release` or the process."""

    domain_id: int
    _lock: IO[str] | None

    def release(self) -> None:
        """Give the domain back (for tests of this module; processes just exit)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None


def preferred_test_domain(environ: dict[str, str] | None = None) -> int:
    """``SWARM_TEST_DOMAIN_BASE`` (default 40) + the pytest-xdist worker number.

    Raises:
        ValueError: the base is not an integer, or the result is outside 1..101.
    """
    env = os.environ if environ is None else environ
    raw = env.get(DOMAIN_BASE_ENV_VAR, str(DEFAULT_DOMAIN_BASE))
    try:
        base = int(raw)
    except ValueError:
        msg = f'{DOMAIN_BASE_ENV_VAR}={raw!r} is not an integer'
        raise ValueError(msg) from None
    match = re.search(r'(\d+)$', env.get('PYTEST_XDIST_WORKER', ''))
    domain = base + (int(match.group(1)) if match else 0)
    if not _FIRST_TEST_DOMAIN_ID <= domain <= MAX_TEST_DOMAIN_ID:
        msg = (
            f'test domain id {domain} ({DOMAIN_BASE_ENV_VAR}={base} + worker) is outside '
            f'{_FIRST_TEST_DOMAIN_ID}..{MAX_TEST_DOMAIN_ID}'
        )
        raise ValueError(msg)
    return domain


def _try_lock(path: Path) -> IO[str] | None:
    try:
        handle = path.open('a')
    except OSError:
        return None  # e.g. a lock file of another user
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.close()
        return None
    return handle


def reserve_test_domain(
    preferred: int | None = None, *, lock_dir: Path | None = None
) -> DomainReservation:
    """Hold ``preferred`` (default :func:`preferred_test_domain`) or the next free domain.

    Raises:
        DomainsExhaustedError: all of 1..101 are held by other processes.
    """
    start = preferred_test_domain() if preferred is None else preferred
    directory = lock_dir or Path(tempfile.gettempdir()) / _LOCK_DIR_NAME
    directory.mkdir(exist_ok=True)
    count = MAX_TEST_DOMAIN_ID - _FIRST_TEST_DOMAIN_ID + 1
    for offset in range(count):
        domain = _FIRST_TEST_DOMAIN_ID + (start - _FIRST_TEST_DOMAIN_ID + offset) % count
        handle = _try_lock(directory / f'{domain}.lock')
        if handle is not None:
            return DomainReservation(domain, handle)
    msg = f'all {count} test ROS domains are held by other test processes ({directory})'
    raise DomainsExhaustedError(msg)


def dds_test_environment(domain_id: int) -> dict[str, str]:
    """The environment of a test process in ``domain_id``, discovery on this host only."""
    return {'ROS_DOMAIN_ID': str(domain_id), 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}


def isolate_test_process() -> DomainReservation:
    """Reserve a domain and put it in ``os.environ`` (call before rclpy is imported).

    Also drops ``ROS_STATIC_PEERS``, which would reach beyond this machine.
    """
    reservation = reserve_test_domain()
    os.environ.update(dds_test_environment(reservation.domain_id))
    os.environ.pop('ROS_STATIC_PEERS', None)
    return reservation
