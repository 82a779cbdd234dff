"""Swarm formation, leader election, join and split (spec 1.4), decided by each robot locally.

Every rule uses only robot IDs and what peers broadcast (:class:`msc_pf.peers.PeerInfo`):

1. initial formation: in ascending ID order, each unassigned robot leads and recruits up to
   L_th - 1 of the nearest unassigned robots in range (every robot computes the same result
   from the same peer set);
2. a follower that no longer hears its leader, or whose leader does not list it for a few
   steps, leads itself; a follower whose leader joined another swarm follows the new leader;
3. split: a follower whose own selected target differs from its leader's leaves and joins a
   swarm in range heading to its target with room (lowest leader ID first), else leads itself;
4. join: a leader hearing a lower-ID leader heading to the same target (or both searching)
   follows it when the merged swarm has at most L_th robots;
5. a working robot (phase WORK) is never a follower.

With ``search_alone`` (beyond the paper) rule 1 makes every robot lead itself, rule 4 merges
only swarms heading to the same target, and a follower whose leader searches without a
target leads itself again: robots search apart and gather only on a target they heard.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from msc_pf.peers import NO_TARGET, PeerInfo, Phase, Role
from msc_pf.settings import SwarmConfig

__all__ = ['SwarmMembership', 'form_initial_swarms', 'heading_to_same']


def form_initial_swarms(
    ids: Sequence[int], positions_m: np.ndarray, max_size: int, comm_range_m: float
) -> dict[int, int]:
    """Rule 1: map every robot ID to its leader's ID.

    Args:
        ids: robot IDs.
        positions_m: (len(ids), 2) positions [m].
        max_size: L_th.
        comm_range_m: only robots within this distance of a leader are recruited [m].
    """
    positions = np.asarray(positions_m, dtype=np.float64).reshape(len(ids), 2)
    index = {robot: i for i, robot in enumerate(ids)}
    leader_of: dict[int, int] = {}
    for leader in sorted(ids):
        if leader in leader_of:
            continue
        leader_of[leader] = leader
        here = positions[index[leader]]
        free = [r for r in ids if r not in leader_of]
        free.sort(key=lambda r: (float(np.hypot(*(positions[index[r]] - here))), r))
        recruits = [r for r in free if np.hypot(*(positions[index[r]] - here)) <= comm_range_m]
        for robot in recruits[: max_size - 1]:
            leader_of[robot] = leader
    return leader_of


def heading_to_same(a_target: int, a_phase: Phase, b_target: int, b_phase: Phase) -> bool:
    """Two swarms may merge: same selected target, or both searching without one."""
    if Phase.WORK in (a_phase, b_phase):
        return False
    if a_target == NO_TARGET and b_target == NO_TARGET:
        return a_phase == Phase.SEARCH and b_phase == Phase.SEARCH
    return a_target == b_target


class SwarmMembership:
    """One robot's view of its swarm: role, leader and (for a leader) accepted members."""

    def __init__(self, robot_id: int, config: SwarmConfig) -> None:
        """Start unformed; :meth:`form` assigns the first leader."""
        self.robot_id = robot_id
        self._cfg = config
        self.formed = False
        self.leader_id = robot_id
        self.members: tuple[int, ...] = ()
        self._unlisted_steps = 0

    @property
    def role(self) -> Role:
        """LEADER when the robot leads its swarm (alone or not), else FOLLOWER."""
        return Role.LEADER if self.leader_id == self.robot_id else Role.FOLLOWER

    def _lead_alone(self) -> None:
        self.leader_id = self.robot_id
        self.members = ()
        self._unlisted_steps = 0

    def _follow(self, leader_id: int) -> None:
        self.leader_id = leader_id
        self.members = ()
        self._unlisted_steps = 0

    def form(self, position_m: np.ndarray, peers: Mapping[int, PeerInfo]) -> None:
        """Rule 1 on this robot and the peers it hears now."""
        ids = [self.robot_id, *sorted(peers)]
        positions = np.array([position_m, *(peers[r].position_m for r in sorted(peers))])
        size = 1 if self._cfg.search_alone else self._cfg.max_size
        leader_of = form_initial_swarms(ids, positions, size, self._cfg.comm_range_m)
        self.leader_id = leader_of[self.robot_id]
        self.members = tuple(sorted(r for r, lead in leader_of.items() if lead == self.robot_id))
        self.members = tuple(r for r in self.members if r != self.robot_id)
        self.formed = True

    def update(
        self,
        peers: Mapping[int, PeerInfo],
        own_target: int,
        own_phase: Phase,
    ) -> str | None:
        """Apply rules 2-5 once, after this step's peer messages arrived.

        Args:
            peers: latest message of every robot in range, by ID.
            own_target: the target this robot would choose itself (NO_TARGET for none).
            own_phase: this robot's phase (WORK makes it lead itself).

        Returns:
            A short description of a membership change, or None.
        """
        if not self.formed:
            return None
        if own_phase == Phase.WORK:
            if self.role is Role.FOLLOWER:
                self._lead_alone()
                return 'working: leaves its swarm'
            self.members = self._accepted_members(peers)
            return None
        if self.role is Role.FOLLOWER:
            return self._update_follower(peers, own_target)
        return self._update_leader(peers, own_target, own_phase)

    def _update_follower(self, peers: Mapping[int, PeerInfo], own_target: int) -> str | None:
        leader = peers.get(self.leader_id)
        if leader is None:
            lost = self.leader_id
            self._lead_alone()
            return f'lost leader {lost}: leads itself'
        if leader.role is Role.FOLLOWER:
            new_leader = leader.leader_id
            if new_leader in peers and new_leader != self.robot_id:
                self._follow(new_leader)
                return f'leader {leader.robot_id} joined {new_leader}: follows {new_leader}'
            self._lead_alone()
            return f'leader {leader.robot_id} joined a swarm out of range: leads itself'
        if self.robot_id in leader.members:
            self._unlisted_steps = 0
        else:
            self._unlisted_steps += 1
            if self._unlisted_steps > self._cfg.membership_grace_steps:
                self._lead_alone()
                return f'not accepted by leader {leader.robot_id}: leads itself'
        target = leader.target_id
        if self._cfg.search_alone and target == NO_TARGET and leader.phase == Phase.SEARCH:
            self._lead_alone()
            return f'leader {leader.robot_id} searches again: searches alone'
        if own_target != NO_TARGET and target != NO_TARGET and own_target != target:
            return self._split(peers, own_target)
        return None

    def _split(self, peers: Mapping[int, PeerInfo], own_target: int) -> str:
        for robot in sorted(peers):
            peer = peers[robot]
            if (
                peer.role is Role.LEADER
                and peer.target_id == own_target
                and peer.phase != Phase.WORK
                and peer.swarm_size < self._cfg.max_size
            ):
                self._follow(robot)
                return f'split toward target {own_target}: joins {robot}'
        self._lead_alone()
        return f'split toward target {own_target}: leads a new swarm'

    def _accepted_members(self, peers: Mapping[int, PeerInfo]) -> tuple[int, ...]:
        claimants = [
            r for r, p in peers.items() if p.role is Role.FOLLOWER and p.leader_id == self.robot_id
        ]
        # Members accepted before keep their place; newcomers by ascending ID.
        claimants.sort(key=lambda r: (r not in self.members, r))
        return tuple(sorted(claimants[: self._cfg.max_size - 1]))

    def _update_leader(
        self, peers: Mapping[int, PeerInfo], own_target: int, own_phase: Phase
    ) -> str | None:
        self.members = self._accepted_members(peers)
        size = len(self.members) + 1
        for robot in sorted(peers):
            if robot >= self.robot_id:
                break
            peer = peers[robot]
            if peer.role is not Role.LEADER:
                continue
            if not heading_to_same(own_target, own_phase, peer.target_id, peer.phase):
                continue
            if self._cfg.search_alone and own_target == NO_TARGET:
                continue
            if peer.swarm_size + size <= self._cfg.max_size:
                self._follow(robot)
                return f'joins swarm of {robot}'
        return None
