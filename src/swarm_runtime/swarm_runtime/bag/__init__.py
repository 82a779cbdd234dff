"""rosbag2 MCAP bags: record any run, read bags back as messages, replay them into a graph.

- :class:`BagWriter` writes a rosbag2 directory (metadata.yaml + one .mcap, storage mcap,
  serialization cdr, offered QoS and RIHS01 hashes), as ``ros2 bag record -s mcap`` does.
- :class:`BagRecorder` is a node that discovers topics and records the chosen ones.
- :func:`read_messages` iterates a bag (ours or a robot's) in log-time order;
  :func:`read_bag_info` summarizes it; damaged bags raise :class:`BagError` or, with
  ``allow_truncated=True``, are read up to the damage.
- :class:`BagPlayer` is a node that publishes a bag's messages and ``/clock`` from the bag's
  time, so other nodes can be fed from a bag on sim time.

The recorder and player are nodes and import the runtime (:mod:`swarm_runtime.ros`) on first
use; reading and writing do not need it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .errors import BagError, BagNotFoundError, BagTypeError, BagWriteError, CorruptBagError
from .reader import (
    BagDamage,
    BagInfo,
    BagMessage,
    TopicSummary,
    TruncatedBagWarning,
    read_bag_info,
    read_messages,
)
from .writer import BagWriter

if TYPE_CHECKING:
    from .player import BagPlayer
    from .recorder import BagRecorder

__all__ = [
    'BagDamage',
    'BagError',
    'BagInfo',
    'BagMessage',
    'BagNotFoundError',
    'BagPlayer',
    'BagRecorder',
    'BagTypeError',
    'BagWriteError',
    'BagWriter',
    'CorruptBagError',
    'TopicSummary',
    'TruncatedBagWarning',
    'read_bag_info',
    'read_messages',
]


def __getattr__(name: str) -> Any:
    if name == 'BagRecorder':
        from .recorder import BagRecorder

        return BagRecorder
    if name == 'BagPlayer':
        from .player import BagPlayer

        return BagPlayer
    msg = f'module {__name__!r} has no attribute {name!r}'
    raise AttributeError(msg)
