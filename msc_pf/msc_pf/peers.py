"""What robots tell each other every control step (the content of a MscPeer message).

The same record travels through the in-process exchange of the batch simulator and, through
:mod:`msc_pf.conversions`, through ROS peer messages.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

__all__ = ['NO_TARGET', 'PeerInfo', 'Phase', 'Role']

NO_TARGET = -1
"""Target ID meaning "no target selected"."""


class Phase(IntEnum):
    """Per-robot phase (paper Fig. 2; spec 1.1). Values are stable: they go into messages."""

    FORMING = 0
    """Waiting for the first peer messages to form swarms."""
    SEARCH = 1
    """(a) history-based search, eq. (1)."""
    FAR_LOCALISATION = 2
    """(b-1) parallel formation toward the largest-weight particle (proposed only)."""
    MSC_APPROACH = 3
    """MSC mobility while the estimate has not converged."""
    DIRECT_APPROACH = 4
    """(b-2)/(c-2) eq. (8) toward a converged estimate."""
    FINAL_APPROACH = 5
    """(b-3) MSC only, RSSI above gamma2."""
    WORK = 6
    """(c-1) stopped within D_th, working on the task."""


class Role(IntEnum):
    """Role of a robot in its swarm."""

    LEADER = 0
    FOLLOWER = 1


@dataclass(frozen=True)
class PeerInfo:
    """One robot's broadcast for one control step.

    Attributes:
        robot_id: sender's numeric ID (r3 -> 3); leaders are the minimum IDs.
        stamp_s: time of the step [s].
        position_m: (x, y) of the sender when it sampled ``readings`` [m].
        movement: (x, y) the sender's movement vector of this step [m], before step limiting.
        role: sender's role.
        leader_id: ID of the sender's leader (its own ID when it leads).
        members: for a leader, the followers it accepts (sorted); empty otherwise.
        phase: sender's phase.
        target_id: sender's selected target (NO_TARGET for none).
        target_rssi_dbm: sender's smoothed RSSI of that target (NaN if not heard) [dBm].
        evaluation: sender's MSC evaluation value for that target (NaN if none).
        readings: (target ID, RSSI [dBm]) samples the sender took this step at position_m.
        captured_ids: every target ID the sender knows to be captured.
        visited_cell: flat index of the coverage cell the sender is in (-1 if unknown).
    """

    robot_id: int
    stamp_s: float
    position_m: tuple[float, float]
    movement: tuple[float, float]
    role: Role
    leader_id: int
    members: tuple[int, ...]
    phase: Phase
    target_id: int
    target_rssi_dbm: float
    evaluation: float
    readings: tuple[tuple[int, float], ...]
    captured_ids: tuple[int, ...]
    visited_cell: int

    @property
    def swarm_size(self) -> int:
        """Size of the sender's swarm as the sender knows it (leaders only; else 1)."""
        return len(self.members) + 1 if self.role is Role.LEADER else 1
