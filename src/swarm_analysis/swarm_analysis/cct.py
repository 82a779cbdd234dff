"""Capture completion time (CCT) of an MSC + PF mission, from a recorded bag.

CCT is the time until every target is captured (Murakami et al., Sec. IV-A). The simulator
publishes the targets' ground truth on ``/sim/targets`` (swarm_interfaces/RssiTargetArray:
per target its load, whether it is captured and when). From a bag, each target's capture
time is the first message reporting it captured (its ``capture_time_s`` field, or the
message stamp when that field is absent or NaN); the CCT is the largest capture time once
every target is captured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

__all__ = ['TARGETS_TOPIC', 'CctError', 'CctResult', 'cct_from_bag']

TARGETS_TOPIC = '/sim/targets'


class CctError(ValueError):
    """A bag lacks what the CCT needs (no target messages)."""


@dataclass(frozen=True)
class CctResult:
    """Outcome of a mission as recorded.

    Attributes:
        n_targets: targets in the mission.
        capture_times_s: capture time of each target ID [s] (captured targets only).
        all_captured: every target was captured within the recording.
        cct_s: capture completion time [s] (NaN unless every target was captured).
        end_time_s: stamp of the last target message [s].
    """

    n_targets: int
    capture_times_s: dict[int, float]
    all_captured: bool
    cct_s: float
    end_time_s: float


def cct_from_bag(
    path: str | Path, topic: str = TARGETS_TOPIC, *, allow_truncated: bool = False
) -> CctResult:
    """Read ``topic`` of the bag at ``path`` and compute the CCT.

    ``allow_truncated`` reads a damaged bag as far as it can be read (see
    :func:`swarm_runtime.bag.read_messages`).

    Raises:
        CctError: the bag has no message on ``topic``.
        swarm_runtime.bag.BagError: the bag cannot be read.
    """
    from swarm_runtime.bag import read_messages

    captured: dict[int, float] = {}
    known: set[int] = set()
    end = math.nan
    for item in read_messages(path, [topic], allow_truncated=allow_truncated):
        msg = item.message
        stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        end = stamp
        for target in msg.targets:
            tid = int(target.target_id)
            known.add(tid)
            if target.captured and tid not in captured:
                when = float(target.capture_time_s)
                captured[tid] = when if math.isfinite(when) else stamp
    if not known:
        raise CctError(f'{path}: no {topic} messages')
    complete = captured.keys() == known
    return CctResult(
        n_targets=len(known),
        capture_times_s=dict(sorted(captured.items())),
        all_captured=complete,
        cct_s=max(captured.values()) if complete else math.nan,
        end_time_s=end,
    )
