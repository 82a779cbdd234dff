"""One robot's controller: the per-step decision of all three schemes.

:class:`RobotController` is what the ROS node and the batch simulator both call once per
control period. It takes the robot's position, this period's RSSI samples, the peer
messages that arrived and any capture notices, and returns the displacement to make, the
peer message to broadcast and a status record. It holds no ROS and no I/O.

Order of one step (spec 1.1-1.9):

1. peers, captured targets and RSSI samples are merged into the robot's memory;
2. the particle filters fold in the robot's own samples and every neighbour's (PF schemes);
3. swarms are formed on the first step with peers, then kept by the join/split rules;
4. the robot selects a target (MSC evaluation value, or R * N_r after a capture in the
   proposed scheme) and a phase, and computes its movement vector (leader: its phase's law;
   follower: the leader's vector, its formation slot or the MSC follower update).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from msc_pf.coverage import SectorSweep
from msc_pf.errors import ObservationError
from msc_pf.mobility import (
    avoidance_vector,
    count_closer_heading_to,
    direct_approach_vector,
    evaluation_value,
    far_field_leader_vector,
    follower_slot,
    msc_follower_vector,
    msc_gradient_leader_vector,
    msc_leader_vector,
    rssi_gradient,
    step_displacement,
)
from msc_pf.particle_filter import ParticleFilterBank, TargetEstimate
from msc_pf.peers import NO_TARGET, PeerInfo, Phase, Role
from msc_pf.search import HistorySearch, unit
from msc_pf.settings import MscPfConfig
from msc_pf.swarm import SwarmMembership
from msc_pf.targeting import Candidate, select_retarget

__all__ = ['RobotController', 'RobotStatus', 'StepOutput']

_GOAL_PHASES = (Phase.DIRECT_APPROACH,)
_NO_GOAL = (math.nan, math.nan)
_MSC_PHASES = (Phase.MSC_APPROACH, Phase.FINAL_APPROACH, Phase.WORK)


@dataclass(frozen=True)
class RobotStatus:
    """What the robot reports about itself (the content of MscPfState).

    Attributes:
        robot_id: the robot's numeric ID.
        stamp_s: time of the step [s].
        phase: current phase.
        role: LEADER or FOLLOWER.
        swarm_id: the leader's ID.
        target_id: selected target (NO_TARGET for none).
        target_rssi_dbm: smoothed RSSI of that target (NaN when not heard) [dBm].
        goal_m: (2,) goal of eq. (8) in phase DIRECT_APPROACH, else NaN [m].
        estimates: current estimates of every tracked target.
        captured_ids: targets known to be captured.
    """

    robot_id: int
    stamp_s: float
    phase: Phase
    role: Role
    swarm_id: int
    target_id: int
    target_rssi_dbm: float
    goal_m: np.ndarray
    estimates: tuple[TargetEstimate, ...]
    captured_ids: tuple[int, ...]


@dataclass(frozen=True)
class StepOutput:
    """Result of one control step.

    Attributes:
        displacement_m: (2,) displacement to make during the next period [m] (at most
            max_speed * period).
        movement: (2,) the movement vector before step limiting.
        broadcast: the peer message to send.
        status: the state record to publish.
        events: notes worth logging (captures, re-targeting, filter re-initialisations).
        swarm_changes: membership changes (joins, splits), frequent in MSC phases.
    """

    displacement_m: np.ndarray
    movement: np.ndarray
    broadcast: PeerInfo
    status: RobotStatus
    events: tuple[str, ...]
    swarm_changes: tuple[str, ...] = ()


class RobotController:
    """Per-robot decision logic of MSC, MSC+PF and the proposed swarm control."""

    def __init__(self, robot_id: int, config: MscPfConfig, seed: int) -> None:
        """Create the controller of robot ``robot_id``; ``seed`` makes it reproducible."""
        self.robot_id = int(robot_id)
        self.config = config
        pf_seed, motion_seed, search_seed = np.random.SeedSequence([seed, robot_id]).spawn(3)
        self._rng = np.random.default_rng(motion_seed)
        self._search = HistorySearch(
            config.search, config.field_size_m, np.random.default_rng(search_seed)
        )
        self._sweep: SectorSweep | None = None
        if config.search.mode == 'sector':
            self._sweep = SectorSweep(
                config.field_size_m, config.search.cell_size_m, config.search.sweep_radius_m
            )
        self._start_m: np.ndarray | None = None
        self._first_seen: dict[int, tuple[float, float]] = {}
        self._marked_cell: dict[int, int] = {}
        self._bank: ParticleFilterBank | None = None
        if config.scheme.uses_particle_filter:
            self._bank = ParticleFilterBank(
                config.particle_filter,
                config.radio,
                config.field_size_m,
                np.random.default_rng(pf_seed),
            )
        self.membership = SwarmMembership(self.robot_id, config.swarm)
        self._peers: dict[int, PeerInfo] = {}
        self._rssi: dict[int, deque[float]] = {}
        self._last_heard_s: dict[int, float] = {}
        self._captured: set[int] = set()
        self._samples: dict[int, deque[tuple[float, float, float, float]]] = {}
        self._last_sampled_s: dict[int, float] = {}
        self._pbest: deque[tuple[np.ndarray, float]] = deque(maxlen=config.msc.pbest_window)
        self._pbest_target = NO_TARGET
        self._leg: list[tuple[np.ndarray, float]] = []
        self._leg_heading = np.zeros(2)
        self._velocity = np.zeros(2)
        self.phase = Phase.FORMING
        self.target_id = NO_TARGET
        self._committed = NO_TARGET
        self._goal = np.full(2, np.nan)
        self._start_s: float | None = None
        self._last_step_s = -math.inf
        self._work_since_s = 0.0
        self._work_blocked_until_s = -math.inf
        self._far_since_s: float | None = None
        self._goal_track: deque[tuple[float, float]] = deque()
        self._goal_track_target = NO_TARGET
        self._swarm_changes: tuple[str, ...] = ()
        self._with_estimates = True
        self._events: list[str] = []

    # ------------------------------------------------------------------ memory
    @property
    def captured_ids(self) -> frozenset[int]:
        """Targets this robot knows to be captured."""
        return frozenset(self._captured)

    @property
    def filters(self) -> ParticleFilterBank | None:
        """The particle filters (None in the MSC scheme)."""
        return self._bank

    def smoothed_rssi(self, target_id: int, now_s: float) -> float | None:
        """Moving average of the last samples of ``target_id``, None when not detected now."""
        last = self._last_heard_s.get(target_id)
        if last is None or now_s - last > self.config.msc.detection_memory_s:
            return None
        samples = self._rssi[target_id]
        return sum(samples) / len(samples)

    def _merge_peers(self, now_s: float, peers: Sequence[PeerInfo]) -> list[PeerInfo]:
        fresh: list[PeerInfo] = []
        for peer in sorted(peers, key=lambda p: (p.robot_id, p.stamp_s)):
            if peer.robot_id == self.robot_id:
                continue
            known = self._peers.get(peer.robot_id)
            if known is not None and peer.stamp_s <= known.stamp_s:
                continue
            self._peers[peer.robot_id] = peer
            fresh.append(peer)
        timeout = self.config.swarm.peer_timeout_s
        for robot in [r for r, p in self._peers.items() if now_s - p.stamp_s > timeout]:
            del self._peers[robot]
        return fresh

    def _merge_captured(self, ids: Iterable[int]) -> set[int]:
        new = {int(t) for t in ids} - self._captured
        for target in new:
            self._captured.add(target)
            self._rssi.pop(target, None)
            self._samples.pop(target, None)
            self._last_heard_s.pop(target, None)
            self._last_sampled_s.pop(target, None)
            if self._bank is not None:
                self._bank.forget(target)
        return new

    def _in_my_swarm(self, peer: PeerInfo) -> bool:
        leader = self.membership.leader_id
        return peer.leader_id == leader or peer.robot_id == leader

    # ------------------------------------------------------------------ step
    def step(
        self,
        now_s: float,
        position_m: Sequence[float] | np.ndarray,
        readings: Mapping[int, float],
        peers: Sequence[PeerInfo] = (),
        captured_ids: Iterable[int] = (),
        *,
        with_estimates: bool = True,
    ) -> StepOutput:
        """Run one control period.

        Args:
            now_s: current time [s]; steps must advance in time.
            position_m: (2,) own position in the field frame [m].
            readings: RSSI samples of this period by target ID [dBm]; non-finite values and
                captured targets are ignored.
            peers: peer messages received since the last step (own messages are ignored,
                older duplicates dropped).
            captured_ids: targets this robot learned are captured (e.g. its task finished).
            with_estimates: put the PF estimates into the status (False saves time when
                nobody reads them, e.g. in batch simulations).

        Raises:
            ObservationError: position not finite, or time not advancing.
        """
        position = np.asarray(position_m, dtype=np.float64)
        if position.shape != (2,) or not (
            math.isfinite(position[0]) and math.isfinite(position[1])
        ):
            raise ObservationError(f'position must be 2 finite numbers, got {position_m!r}')
        if not now_s > self._last_step_s:
            raise ObservationError(f'time {now_s} s does not advance past {self._last_step_s} s')
        self._last_step_s = now_s
        self._with_estimates = with_estimates
        if self._start_s is None:
            self._start_s = now_s
        events: list[str] = []
        self._events = events

        fresh = self._merge_peers(now_s, peers)
        newly_captured = self._merge_captured(captured_ids)
        for peer in fresh:
            newly_captured |= self._merge_captured(peer.captured_ids)
        own = {
            int(t): float(v)
            for t, v in readings.items()
            if math.isfinite(v) and int(t) not in self._captured
        }
        for target, value in sorted(own.items()):
            self._rssi.setdefault(target, deque(maxlen=self.config.msc.rssi_window)).append(value)
            self._last_heard_s[target] = now_s

        self._record_samples(now_s, position, own, fresh)
        own_cell = self._search.swarm_history.cell_of(position)
        self._search.record_swarm_visit(own_cell)
        for peer in fresh:
            if self._in_my_swarm(peer):
                self._search.record_swarm_visit(peer.visited_cell)
            else:
                self._search.record_other_visit(peer.visited_cell)

        if self._sweep is not None:
            self._update_sweep(now_s, position, own_cell, fresh)
        if self._bank is not None:
            events += self._update_filters(now_s, position, own, fresh)

        if not self.membership.formed:
            waited = now_s - self._start_s
            if self._peers or waited >= self.config.swarm.formation_timeout_s:
                self.membership.form(position, self._peers)
                self.phase = Phase.SEARCH
        if not self.membership.formed:
            return self._finish(now_s, position, own, np.zeros(2), False, own_cell, events)

        if self.target_id in newly_captured or self._committed in newly_captured:
            self._after_capture(now_s, position, events)
        own_target = self._own_target(now_s)
        self._update_work(now_s, own_target)
        change = self.membership.update(self._peers, own_target, self.phase)
        self._swarm_changes = (change,) if change else ()

        neighbours = [p.position_m for p in self._peers.values()]
        avoidance = avoidance_vector(position, neighbours, self.config.avoidance)
        leader = self._peers.get(self.membership.leader_id)
        if self.phase == Phase.WORK:
            self.target_id = own_target
            vector, is_goal = np.zeros(2), False
        elif self.membership.role is Role.FOLLOWER and leader is not None:
            vector, is_goal = self._follower_vector(now_s, position, leader, avoidance)
        else:
            self.target_id = own_target
            self.phase = self._leader_phase(now_s, position, own_target)
            vector, is_goal = self._leader_vector(now_s, position, avoidance)
        self._velocity = vector
        return self._finish(now_s, position, own, vector, is_goal, own_cell, events)

    def _record_samples(
        self,
        now_s: float,
        position: np.ndarray,
        own: Mapping[int, float],
        fresh: Sequence[PeerInfo],
    ) -> None:
        """Keep every (time, x, y, RSSI) sample of the recent window, own and neighbours'."""
        horizon = now_s - self.config.msc.pbest_window * self.config.period_s
        batches: list[tuple[float, float, Iterable[tuple[int, float]]]] = [
            (position[0], position[1], own.items())
        ]
        batches += [(p.position_m[0], p.position_m[1], p.readings) for p in fresh]
        for x, y, readings in batches:
            for target, value in readings:
                if target in self._captured or not math.isfinite(value):
                    continue
                self._samples.setdefault(target, deque()).append((now_s, x, y, value))
                self._last_sampled_s[target] = now_s
        for samples in self._samples.values():
            while samples and samples[0][0] <= horizon:
                samples.popleft()

    def _update_sweep(
        self, now_s: float, position: np.ndarray, own_cell: int, fresh: Sequence[PeerInfo]
    ) -> None:
        """Sector search: mark what this robot and its neighbours covered; plan the sector.

        A robot's coverage disc is marked each time it enters a new cell. During the first
        ``swarm.formation_timeout_s`` the robot notes every peer and where it was first
        heard; after it, it takes its sector among the searching units it noted.
        """
        sweep = self._sweep
        assert sweep is not None
        assert self._start_s is not None
        if self._start_m is None:
            self._start_m = position.copy()
        if self._marked_cell.get(self.robot_id) != own_cell:
            self._marked_cell[self.robot_id] = own_cell
            sweep.mark(position)
        planning = now_s - self._start_s < self.config.swarm.formation_timeout_s
        for peer in fresh:
            if planning:
                self._first_seen.setdefault(peer.robot_id, peer.position_m)
            if self._marked_cell.get(peer.robot_id) != peer.visited_cell:
                self._marked_cell[peer.robot_id] = peer.visited_cell
                sweep.mark(peer.position_m)
        if planning or sweep.planned:
            return
        swarm = self.config.swarm
        if swarm.search_alone or swarm.max_size == 1:
            units = {self.robot_id, *self._first_seen}
            mine = self.robot_id
        else:
            units = {self.membership.leader_id}
            units |= {p.leader_id for r, p in self._peers.items() if r in self._first_seen}
            mine = self.membership.leader_id
        starts = np.array([self._start_m, *self._first_seen.values()], dtype=np.float64)
        ranked = sorted(units)
        sweep.plan(starts.mean(axis=0), len(ranked), ranked.index(mine))

    def _search_vector(
        self, now_s: float, position: np.ndarray, avoidance: np.ndarray
    ) -> np.ndarray:
        """Phase (a): eq. (1), or the sector sweep toward its next uncovered cell."""
        sweep = self._sweep
        if sweep is None:
            return self._search.vector(now_s, position, avoidance)
        if not sweep.planned:
            return np.zeros(2)
        goal = sweep.goal(position)
        if goal is None:
            return self._search.vector(now_s, position, avoidance)
        return unit(goal - position) + self.config.search.alpha_outside * avoidance

    def _gradient(self, target: int) -> np.ndarray:
        samples = self._samples.get(target)
        if not samples:
            return np.zeros(2)
        data = np.array(samples)
        return rssi_gradient(data[:, 1:3], data[:, 3])

    # ------------------------------------------------------------------ filters
    def _update_filters(
        self,
        now_s: float,
        position: np.ndarray,
        own: Mapping[int, float],
        fresh: Sequence[PeerInfo],
    ) -> list[str]:
        assert self._bank is not None
        events: list[str] = []
        batches: list[tuple[np.ndarray, Mapping[int, float]]] = [(position, own)]
        for peer in fresh:
            batch: Mapping[int, float] = {
                t: v for t, v in peer.readings if math.isfinite(v) and t not in self._captured
            }
            if batch:
                batches.append((np.asarray(peer.position_m, dtype=np.float64), batch))
        observations = []
        for where, batch in batches:
            if batch and math.isfinite(where[0]) and math.isfinite(where[1]):
                ids = sorted(batch)
                observations.append((where, ids, [batch[t] for t in ids]))
        before = set(self._bank.tracked_ids)
        if self.config.particle_filter.fusion == 'joint':
            groups = [observations]
        else:
            groups = [[observation] for observation in observations]
        for group in groups:
            if not group:
                continue
            for target in self._bank.update_joint(group):
                events.append(f'filter of target {target} degenerated: re-initialised')
                before.discard(target)
        self._apply_coverage_prior(before)
        self._fold_in_non_detections(now_s, position, own, fresh)
        self._fold_in_unheard(now_s, position, fresh)
        self._bank.end_step()
        return events

    def _fold_in_non_detections(
        self,
        now_s: float,
        position: np.ndarray,
        own: Mapping[int, float],
        fresh: Sequence[PeerInfo],
    ) -> None:
        """``phases.non_detection_window_s``: fold this step's non-detections into every
        recently sampled filter (the robot's and its neighbours' who did not hear it).

        Observers farther from the estimate than 1.3 detection ranges plus two spreads are
        left out: their non-detection says nothing about the filter's particles.
        """
        window = self.config.phases.non_detection_window_s
        bank = self._bank
        if window <= 0.0 or bank is None:
            return
        reach = 1.3 * self.config.radio.detection_range_m
        for target in bank.tracked_ids:
            if target in self._captured:
                continue
            if now_s - self._last_sampled_s.get(target, -math.inf) > window:
                continue
            points = [] if target in own else [(float(position[0]), float(position[1]))]
            for peer in fresh:
                if target in peer.captured_ids or any(t == target for t, _ in peer.readings):
                    continue
                points.append(peer.position_m)
            if not points:
                continue
            estimate = bank.estimate(target)
            observers = np.array(points, dtype=np.float64)
            far = np.hypot(*(observers - estimate.position_m[None, :]).T)
            observers = observers[far < reach + 2.0 * estimate.spread_m]
            if len(observers):
                bank.update_unheard(target, observers)

    def _apply_coverage_prior(self, before: set[int]) -> None:
        """Sector search: weigh the particles of filters started this step (those not in
        ``before``) down where the robot knows the field searched."""
        weight = self.config.search.coverage_prior_weight
        bank, sweep = self._bank, self._sweep
        if bank is None or sweep is None or weight >= 1.0:
            return
        for target in bank.tracked_ids:
            if target in before:
                continue
            covered = sweep.covered_at(bank.particles(target))
            bank.apply_prior(target, np.where(covered, weight, 1.0))

    def _fold_in_unheard(
        self,
        now_s: float,
        position: np.ndarray,
        fresh: Sequence[PeerInfo],
    ) -> None:
        """Proposed scheme: a pursued estimate nobody hears is evidence too.

        With ``phases.unheard_updates``, while the robot pursues a target it has not heard
        for ``msc.detection_memory_s`` (a recorded or converged estimate after a capture) and
        no neighbour's sample of it arrived this step, the target's filter weighs its
        particles by the chance of not hearing it at this robot and at the members of its
        swarm heard this step (:meth:`ParticleFilterBank.update_unheard`; other neighbours
        are left out to bound the cost). The goal thus moves off ground where the target
        would have been heard; when less than ``phases.unheard_exhausted_share`` of the
        belief survives one step, the filter is dropped (the target is not where it was
        thought to be).
        """
        phases = self.config.phases
        target = self.target_id
        bank = self._bank
        if (
            not (phases.unheard_updates and self.config.scheme.uses_stored_estimates)
            or bank is None
            or target == NO_TARGET
            or target in self._captured
            or self.smoothed_rssi(target, now_s) is not None
            or not bank.is_tracked(target)
            or any(t == target for peer in fresh for t, _ in peer.readings)
        ):
            return
        observers = [position] + [
            np.asarray(p.position_m, dtype=np.float64) for p in fresh if self._in_my_swarm(p)
        ]
        kept = bank.update_unheard(target, np.array(observers))
        if kept < phases.unheard_exhausted_share:
            self._abandon(target, heard=False, why='where its filter put it')

    # ------------------------------------------------------------------ targets
    def _own_target(self, now_s: float) -> int:
        """Target this robot would pursue by itself this step."""
        if self._committed != NO_TARGET and self._committed not in self._captured:
            return self._committed
        self._committed = NO_TARGET
        msc = self.config.msc
        best, best_value = NO_TARGET, -math.inf
        for target in sorted(self._last_heard_s):
            mean = self.smoothed_rssi(target, now_s)
            if mean is None:
                continue
            others = [
                p.target_rssi_dbm
                for p in self._peers.values()
                if p.target_id == target and math.isfinite(p.target_rssi_dbm)
            ]
            n_closer = count_closer_heading_to(mean, others)
            if 0 < self.config.phases.max_pursuers <= n_closer or self._beyond_reach(target):
                continue
            value = evaluation_value(
                mean, n_closer, msc.dispersion_degree, msc.dispersion_threshold
            )
            if value > best_value:
                best, best_value = target, value
        if best == NO_TARGET and (
            self._keeps_converged(self.target_id) or self._keeps_pursuing(self.target_id, now_s)
        ):
            return self.target_id
        return best

    def _beyond_reach(self, target: int) -> bool:
        """Sector search: ``target``'s estimate lies beyond ``search.sector_reach`` sectors
        of the own one, which is not covered yet (the robot leaves it to others)."""
        reach = self.config.search.sector_reach
        sweep, bank = self._sweep, self._bank
        if reach < 0 or sweep is None or bank is None or not bank.is_tracked(target):
            return False
        if sweep.sector_offset(bank.estimate(target).position_m) <= reach:
            return False
        return not sweep.own_sector_covered()

    def _keeps_converged(self, target: int) -> bool:
        """True when a lost ``target`` is still pursued on its converged estimate."""
        return (
            self.config.phases.keep_converged_target
            and self._bank is not None
            and target != NO_TARGET
            and target not in self._captured
            and self._bank.is_converged(target)
        )

    def _keeps_pursuing(self, target: int, now_s: float) -> bool:
        """True when ``target``, not heard now, got a sample within pursue_memory_s."""
        memory = self.config.phases.pursue_memory_s
        return (
            memory > 0.0
            and self.config.scheme.uses_far_formation
            and self._bank is not None
            and target != NO_TARGET
            and target not in self._captured
            and self._bank.is_tracked(target)
            and now_s - self._last_sampled_s.get(target, -math.inf) <= memory
            and not self._beyond_reach(target)
        )

    def _evaluation(self, target: int, now_s: float) -> float:
        mean = self.smoothed_rssi(target, now_s)
        if mean is None:
            return math.nan
        msc = self.config.msc
        others = [
            p.target_rssi_dbm
            for p in self._peers.values()
            if p.target_id == target and math.isfinite(p.target_rssi_dbm)
        ]
        n_closer = count_closer_heading_to(mean, others)
        return evaluation_value(mean, n_closer, msc.dispersion_degree, msc.dispersion_threshold)

    def _after_capture(self, now_s: float, position: np.ndarray, events: list[str]) -> None:
        """(c-2): re-target on stored converged estimates (proposed scheme only)."""
        captured = self.target_id
        self._committed = NO_TARGET
        self.target_id = NO_TARGET
        if self.phase == Phase.WORK:
            self.phase = Phase.SEARCH
        if not self.config.scheme.uses_stored_estimates or self._bank is None:
            return
        phases = self.config.phases
        max_age = phases.converged_max_age_s
        candidates = [
            Candidate(e.target_id, e.position_m, self.smoothed_rssi(e.target_id, now_s))
            for e in self._bank.estimates()
            if e.converged
            and e.target_id not in self._captured
            and not self._beyond_reach(e.target_id)
            and (
                max_age <= 0.0
                or self._last_sampled_s.get(e.target_id, -math.inf) >= now_s - max_age
            )
        ]
        neighbours = np.array([p.position_m for p in self._peers.values()]).reshape(-1, 2)
        choice = select_retarget(
            candidates, position, neighbours, self.config.radio, phases, phases.max_pursuers
        )
        kind = 'its estimate'
        if choice is None and phases.retarget_unconverged:
            oldest = now_s - phases.recorded_max_age_s
            recorded = [
                Candidate(e.target_id, e.best_particle_m, self.smoothed_rssi(e.target_id, now_s))
                for e in self._bank.estimates()
                if not e.converged
                and e.target_id not in self._captured
                and not self._beyond_reach(e.target_id)
                and self._last_sampled_s.get(e.target_id, -math.inf) >= oldest
            ]
            choice = select_retarget(
                recorded, position, neighbours, self.config.radio, phases, phases.max_pursuers
            )
            kind = 'its unconverged filter'
        if choice is not None:
            self._committed = choice
            events.append(f'target {captured} captured: re-targets {choice} from {kind}')

    def _abandon(
        self,
        target: int,
        *,
        heard: bool,
        why: str = 'at its estimate',
        restart_note: str | None = None,
    ) -> None:
        """Forget ``target``'s filter (it restarts from the next sample of the target).

        When the target is not heard at all the robot also stops pursuing it; ``why`` says
        where it was not heard, ``restart_note`` why a heard target's filter restarts (the
        event notes).
        """
        assert self._bank is not None
        self._bank.forget(target)
        if self._committed == target:
            self._committed = NO_TARGET
        if heard:
            note = restart_note or f'target {target} is weak at its estimate: filter restarted'
            self._events.append(note)
            return
        self._events.append(f'target {target} not heard {why}: estimate dropped')
        self.target_id = NO_TARGET

    def _update_work(self, now_s: float, own_target: int) -> None:
        """(c-1): stop when the own target is louder than gamma3; give up after a timeout."""
        phases = self.config.phases
        if self.phase == Phase.WORK:
            if own_target == NO_TARGET:
                self.phase = Phase.SEARCH
            elif now_s - self._work_since_s >= phases.work_timeout_s:
                self.phase = Phase.FINAL_APPROACH
                self._work_blocked_until_s = now_s + phases.work_block_s
            return
        mean = self.smoothed_rssi(own_target, now_s) if own_target != NO_TARGET else None
        if mean is not None and mean > phases.gamma3_dbm and now_s >= self._work_blocked_until_s:
            self.phase = Phase.WORK
            self._work_since_s = now_s

    def _leader_phase(self, now_s: float, position: np.ndarray, target: int) -> Phase:
        if target == NO_TARGET:
            return Phase.SEARCH
        scheme, phases = self.config.scheme, self.config.phases
        previous = self.phase
        mean = self.smoothed_rssi(target, now_s)
        hysteresis = phases.hysteresis_db
        final_above = phases.gamma2_dbm - (
            hysteresis if previous in (Phase.FINAL_APPROACH, Phase.WORK) else 0.0
        )
        if mean is not None and mean > final_above:
            return Phase.FINAL_APPROACH
        bank = self._bank
        if scheme.uses_direct_approach and bank is not None and bank.is_converged(target):
            goal = bank.estimate(target).position_m
            distance = float(np.hypot(*(goal - position)))
            near = distance < phases.task_area_m
            if mean is None and distance < phases.converged_give_up_m:
                # Silent this close to a converged estimate: captured by robots out of
                # range, or a wrong estimate.
                self._abandon(target, heard=False)
                return Phase.SEARCH
            if near:
                # At the estimate but the target is not louder than gamma2: the estimate is
                # wrong (or the target was captured by robots out of range). A converged flag
                # never clears by itself, so drop the filter instead of circling the wrong
                # point; it restarts from the next sample of the target.
                self._abandon(target, heard=mean is not None)
            elif self._goal_retreats(now_s, position, target, goal):
                # Driving at the estimate did not bring it closer: the filter follows the
                # swarm from the wrong side of the target. Localise again from scratch.
                self._abandon(
                    target,
                    heard=mean is not None,
                    why='where its retreating estimate led',
                    restart_note=f'target {target}: its estimate retreats while approached,'
                    ' filter restarted',
                )
            else:
                self._goal = goal
                return Phase.DIRECT_APPROACH
            if mean is None:
                return Phase.SEARCH
        if scheme.uses_far_formation and bank is not None and bank.is_tracked(target):
            if mean is None:
                # A recorded (unconverged) estimate approached without hearing the target.
                best = bank.estimate(target).best_particle_m
                if float(np.hypot(*(best - position))) < phases.unheard_give_up_m:
                    self._abandon(target, heard=False)
                    return Phase.SEARCH
            far_below = phases.gamma1_dbm - (
                0.0 if previous == Phase.FAR_LOCALISATION else hysteresis
            )
            if mean is None or mean < far_below:
                return Phase.FAR_LOCALISATION
        return Phase.MSC_APPROACH if mean is not None else Phase.SEARCH

    def _goal_retreats(
        self, now_s: float, position: np.ndarray, target: int, goal: np.ndarray
    ) -> bool:
        """True when eq. (8) toward ``goal`` gained less than goal_progress_min_m in a window.

        The distances to the goal of the steps spent in DIRECT_APPROACH on ``target`` are
        kept for ``phases.goal_progress_window_s`` (0: never true); leaving the phase or
        changing the target starts a new record.
        """
        phases = self.config.phases
        window = phases.goal_progress_window_s
        if window <= 0.0:
            return False
        track = self._goal_track
        if self._goal_track_target != target or self.phase != Phase.DIRECT_APPROACH:
            track.clear()
            self._goal_track_target = target
        distance = float(np.hypot(*(goal - position)))
        track.append((now_s, distance))
        while track and track[0][0] < now_s - window:
            track.popleft()
        started_s, then_m = track[0]
        if now_s - started_s < window or distance <= phases.goal_progress_min_m:
            return False
        if then_m - distance >= phases.goal_progress_min_m:
            return False
        track.clear()
        return True

    # ------------------------------------------------------------------ motion
    def _personal_best(self, now_s: float, position: np.ndarray) -> np.ndarray:
        if self._pbest_target != self.target_id:
            self._pbest.clear()
            self._pbest_target = self.target_id
        mean = self.smoothed_rssi(self.target_id, now_s)
        if mean is not None:
            self._pbest.append((position.copy(), mean))
        if not self._pbest:
            return position
        return max(self._pbest, key=lambda item: item[1])[0]

    def _leader_vector(
        self, now_s: float, position: np.ndarray, avoidance: np.ndarray
    ) -> tuple[np.ndarray, bool]:
        cfg = self.config
        alpha = cfg.search.alpha_outside
        if self.phase == Phase.SEARCH:
            return self._search_vector(now_s, position, avoidance), False
        if self.phase == Phase.FAR_LOCALISATION:
            assert self._bank is not None
            estimate = self._bank.estimate(self.target_id)
            aim = estimate.best_particle_m
            if cfg.phases.far_aim == 'estimate':
                aim = estimate.position_m
            return far_field_leader_vector(position, aim, avoidance, alpha), False
        if self.phase == Phase.DIRECT_APPROACH:
            if float(np.hypot(*(self._goal - position))) < cfg.phases.task_area_m:
                alpha = cfg.search.alpha_inside
            return direct_approach_vector(position, self._goal, avoidance, alpha), True
        near_spread = cfg.phases.near_estimate_spread_m
        bank = self._bank
        if near_spread > 0.0 and bank is not None and bank.is_tracked(self.target_id):
            estimate = bank.estimate(self.target_id)
            if estimate.spread_m < near_spread:
                goal = estimate.position_m
                if float(np.hypot(*(goal - position))) < cfg.phases.task_area_m:
                    alpha = cfg.search.alpha_inside
                return direct_approach_vector(position, goal, avoidance, alpha), True
        return self._msc_leader_vector(now_s, position, avoidance), False

    def _msc_leader_vector(
        self, now_s: float, position: np.ndarray, avoidance: np.ndarray
    ) -> np.ndarray:
        msc = self.config.msc
        if msc.leader_rule == 'pbest_turn':
            return self._pbest_turn_vector(now_s, position, avoidance)
        if msc.leader_rule == 'gradient':
            gradient = self._gradient(self.target_id)
            return msc_gradient_leader_vector(self._velocity, gradient, avoidance, msc, self._rng)
        pbest = self._personal_best(now_s, position)
        return msc_leader_vector(self._velocity, position, pbest, avoidance, msc, self._rng)

    def _pbest_turn_vector(
        self, now_s: float, position: np.ndarray, avoidance: np.ndarray
    ) -> np.ndarray:
        """Leader rule 'pbest_turn': straight legs, each ended at its best point.

        The leg records (position, smoothed RSSI) since it started. While the RSSI is within
        ``turn_margin_db`` of the leg's best the heading stays; below it the leader turns
        90 degrees (random side) from the direction back to the best point, or reverses when
        the leg's first point was its best, and a new leg starts.
        """
        if self._pbest_target != self.target_id:
            self._leg.clear()
            self._pbest_target = self.target_id
        heading = unit(self._leg_heading)
        if not heading.any():
            heading = unit(self._velocity)
        if not heading.any():
            theta = self._rng.uniform(0.0, 2.0 * np.pi)
            heading = np.array([np.cos(theta), np.sin(theta)])
        mean = self.smoothed_rssi(self.target_id, now_s)
        if mean is not None:
            self._leg.append((position.copy(), mean))
            best_index = max(range(len(self._leg)), key=lambda i: self._leg[i][1])
            best_position, best_value = self._leg[best_index]
            if best_value - mean > self.config.msc.turn_margin_db:
                back = unit(best_position - position)
                if best_index == 0 or not back.any():
                    heading = -heading
                else:
                    side = 1.0 if self._rng.random() < 0.5 else -1.0
                    heading = np.array([-side * back[1], side * back[0]])
                self._leg.clear()
        self._leg_heading = heading
        return heading + self.config.msc.avoidance_degree * avoidance

    def _follower_vector(
        self, now_s: float, position: np.ndarray, leader: PeerInfo, avoidance: np.ndarray
    ) -> tuple[np.ndarray, bool]:
        self.phase = Phase(leader.phase) if leader.phase != Phase.FORMING else Phase.SEARCH
        self.target_id = leader.target_id
        leader_move = np.asarray(leader.movement, dtype=np.float64)
        if self.phase != Phase.FAR_LOCALISATION:
            self._far_since_s = None
        if self.phase == Phase.SEARCH:
            return leader_move, False
        if self.phase == Phase.DIRECT_APPROACH:
            return leader_move, True
        if self.phase == Phase.FAR_LOCALISATION:
            if self._far_since_s is None:
                self._far_since_s = now_s
            if now_s - self._far_since_s >= self.config.phases.slot_time_s:
                return leader_move, False
            slot_index = (
                leader.members.index(self.robot_id) if self.robot_id in leader.members else 0
            )
            step = step_displacement(
                leader_move, self.config.max_speed_m_s * self.config.period_s, False
            )
            slot = follower_slot(
                np.asarray(leader.position_m) + step,
                leader_move,
                slot_index,
                self.config.phases.follower_offset_m,
            )
            return slot - position, True
        # MSC phases (and a working leader): head for the best neighbour.
        msc = self.config.msc
        best_position, best_value = position, self._evaluation(self.target_id, now_s)
        for peer in sorted(self._peers.values(), key=lambda p: p.robot_id):
            if peer.target_id != self.target_id or not math.isfinite(peer.evaluation):
                continue
            if not math.isfinite(best_value) or peer.evaluation > best_value:
                best_position = np.asarray(peer.position_m, dtype=np.float64)
                best_value = peer.evaluation
        if best_position is position:
            return self._msc_leader_vector(now_s, position, avoidance), False
        pbest = self._personal_best(now_s, position)
        return msc_follower_vector(
            self._velocity,
            position,
            best_position,
            avoidance,
            msc,
            self._rng,
            personal_best_m=pbest if msc.full_pso else None,
        ), False

    # ------------------------------------------------------------------ output
    def _finish(
        self,
        now_s: float,
        position: np.ndarray,
        own: Mapping[int, float],
        vector: np.ndarray,
        is_goal: bool,
        own_cell: int,
        events: list[str],
    ) -> StepOutput:
        cfg = self.config
        max_step = cfg.max_speed_m_s * cfg.period_s
        displacement = step_displacement(vector, max_step, is_goal)
        target = self.target_id
        mean = self.smoothed_rssi(target, now_s) if target != NO_TARGET else None
        rssi = math.nan if mean is None else mean
        evaluation = self._evaluation(target, now_s) if target != NO_TARGET else math.nan
        role = self.membership.role
        captured = tuple(sorted(self._captured))
        broadcast = PeerInfo(
            robot_id=self.robot_id,
            stamp_s=float(now_s),
            position_m=(float(position[0]), float(position[1])),
            movement=(float(vector[0]), float(vector[1])),
            role=role,
            leader_id=self.membership.leader_id,
            members=self.membership.members if role is Role.LEADER else (),
            phase=self.phase,
            target_id=target,
            target_rssi_dbm=rssi,
            evaluation=evaluation,
            readings=tuple(sorted(own.items())),
            captured_ids=captured,
            visited_cell=own_cell,
        )
        goal = self._goal.copy() if self.phase == Phase.DIRECT_APPROACH else np.array(_NO_GOAL)
        status = RobotStatus(
            robot_id=self.robot_id,
            stamp_s=float(now_s),
            phase=self.phase,
            role=role,
            swarm_id=self.membership.leader_id,
            target_id=target,
            target_rssi_dbm=rssi,
            goal_m=goal,
            estimates=(
                tuple(self._bank.estimates())
                if self._bank is not None and self._with_estimates
                else ()
            ),
            captured_ids=captured,
        )
        changes, self._swarm_changes = self._swarm_changes, ()
        return StepOutput(displacement, vector.copy(), broadcast, status, tuple(events), changes)
