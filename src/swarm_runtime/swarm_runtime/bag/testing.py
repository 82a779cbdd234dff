"""Helpers for tests of bags, recorders and players on either runtime.

The same test runs on the built-in runtime (virtual time, immediate discovery) and on real
rclpy over DDS (real time, discovery takes a while), so tests wait for what they expect
with a budget of host time::

    assert spin_until(executor, lambda: recorder.message_count >= 5, timeout_s=10.0)

The DDS domain of each test process is set up before rclpy is imported, by the root
conftest.py with :mod:`swarm_runtime.dds_isolation`.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = [
    'message_record_ends',
    'spin_for',
    'spin_until',
]


def spin_until(
    executor: Any, predicate: Callable[[], bool], *, timeout_s: float, step_s: float = 0.02
) -> bool:
    """Run callbacks until ``predicate()``; False if ``timeout_s`` of host time ran out.

    On the built-in runtime each turn advances virtual time by at most ``step_s`` when
    nothing is ready, so timers run as fast as the CPU allows; on real rclpy the turns wait
    in real time.
    """
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=step_s)
    return True


def spin_for(executor: Any, clock: Any, duration_s: float, *, step_s: float = 0.02) -> None:
    """Run callbacks for ``duration_s`` of ``clock`` (a node's clock or a steady clock)."""
    end_ns = clock.now().nanoseconds + int(duration_s * 1e9)
    deadline = time.monotonic() + max(10.0, 10.0 * duration_s)
    while clock.now().nanoseconds < end_ns and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=step_s)


def message_record_ends(mcap: Path) -> list[int]:
    """End offset of every message record of an intact MCAP file with uncompressed chunks.

    Ground truth for recovery tests, independent of this package's MCAP parser: the
    messages come from the ``mcap`` library's reader, and each one's record bytes are
    located in the file. A recovery of the file cut at byte ``n`` can at best return the
    messages whose record ends at or before ``n``.

    Raises:
        ValueError: a record is not found verbatim (compressed chunks).
    """
    from mcap.reader import make_reader

    data = mcap.read_bytes()
    ends: list[int] = []
    position = 0
    with mcap.open('rb') as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            head = struct.pack(
                '<BQHIQQ',
                0x05,
                22 + len(message.data),
                channel.id,
                message.sequence,
                message.log_time,
                message.publish_time,
            )
            record = head + message.data
            found = data.find(record, position)
            if found < 0:
                found = data.find(record)
            if found < 0:
                msg = f'{mcap}: a message record is not in the file verbatim (compressed chunks?)'
                raise ValueError(msg)
            ends.append(found + len(record))
            position = found + 1
    return sorted(ends)
