"""Limited-range, lossy relay of peer broadcasts (the papers' limited-communication runs).

Each robot publishes its broadcast on ``peers/out``; the relay forwards it to the ``peers/in``
of every other robot within ``comm_range_m`` of the sender, dropping each delivery with
``loss_probability``. This module decides who receives what; the bridge node moves messages.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from swarm_sim.errors import ConfigurationError

if TYPE_CHECKING:
    from swarm_sim.faults import FaultPlan

__all__ = ['RELAY_STREAM', 'RelayConfig', 'RelayModel', 'parse_message_type']

#: The relay's random stream of a mission seeded ``seed``: ``SeedSequence([seed, 7])``, the
#: same in the sim bridge and the batch runners, so they drop the same deliveries.
RELAY_STREAM = 7


@dataclass(frozen=True)
class RelayConfig:
    """Parameters of the peer relay.

    Attributes:
        msg_type: ROS type of the peer messages, e.g. 'swarm_interfaces/msg/BayesSwarmPeer';
            empty disables the relay.
        comm_range_m: largest sender-receiver distance of a delivery [m]; inf for unlimited.
        loss_probability: chance that one delivery is dropped.
    """

    msg_type: str = ''
    comm_range_m: float = math.inf
    loss_probability: float = 0.0

    def __post_init__(self) -> None:
        if self.msg_type:
            parse_message_type(self.msg_type)
        if not self.comm_range_m > 0.0:
            msg = f'comm_range_m must be positive, got {self.comm_range_m}'
            raise ConfigurationError(msg)
        if not 0.0 <= self.loss_probability <= 1.0:
            msg = f'loss_probability must be in [0, 1], got {self.loss_probability}'
            raise ConfigurationError(msg)

    @property
    def enabled(self) -> bool:
        """True when a message type is configured."""
        return bool(self.msg_type)


def parse_message_type(msg_type: str) -> tuple[str, str]:
    """Split 'pkg/msg/Name' (or 'pkg/Name') into (package, message name)."""
    parts = msg_type.strip().split('/')
    if len(parts) == 3 and parts[1] == 'msg' and all(parts):
        return parts[0], parts[2]
    if len(parts) == 2 and all(parts):
        return parts[0], parts[1]
    msg = f"peer message type {msg_type!r} is not of the form 'package/msg/Name'"
    raise ConfigurationError(msg)


class RelayModel:
    """Chooses the receivers of each broadcast."""

    def __init__(self, config: RelayConfig, rng: np.random.Generator) -> None:
        self.config = config
        self._rng = rng
        self.delivered = 0
        self.dropped = 0

    @staticmethod
    def mission_config(config: RelayConfig, plan: FaultPlan | None) -> RelayConfig:
        """``config`` limited further by a fault plan's link faults (range, loss), if any."""
        if plan is None:
            return config
        comm_range_m = plan.combined_range_m(config.comm_range_m)
        return replace(
            config,
            comm_range_m=config.comm_range_m if comm_range_m is None else comm_range_m,
            loss_probability=plan.combined_loss(config.loss_probability),
        )

    @classmethod
    def for_mission(
        cls, config: RelayConfig, seed: int, plan: FaultPlan | None = None
    ) -> RelayModel:
        """The relay of a mission seeded ``seed``: :meth:`mission_config` on the relay's
        own random stream (:data:`RELAY_STREAM`)."""
        rng = np.random.default_rng(np.random.SeedSequence([seed, RELAY_STREAM]))
        return cls(cls.mission_config(config, plan), rng)

    def receivers(self, sender: int, positions: np.ndarray) -> np.ndarray:
        """Indices of the robots that receive ``sender``'s broadcast.

        Args:
            sender: index of the sending robot.
            positions: (N, 2+) true positions [m] of every robot.
        """
        xy = np.asarray(positions, dtype=float)[:, :2]
        dist = np.hypot(*(xy - xy[sender]).T)
        in_range = dist <= self.config.comm_range_m
        in_range[sender] = False
        candidates = np.flatnonzero(in_range)
        if self.config.loss_probability > 0.0 and len(candidates):
            kept = self._rng.random(len(candidates)) >= self.config.loss_probability
            self.dropped += int((~kept).sum())
            candidates = candidates[kept]
        self.delivered += len(candidates)
        return candidates
