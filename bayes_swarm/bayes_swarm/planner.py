"""Bayes-Swarm-P waypoint planner of one robot (paper Algorithm 1, with Algorithms 2 and 3).

The planner owns the robot's belief (a :class:`~bayes_swarm.gp.GaussianProcess`), its data
set D (own and peers' observations), the peers' latest plans and the list of weaker sources.
It is driven from outside, by the ROS node or by the batch simulator, with the same calls:

* :meth:`BayesSwarmPlanner.add_observations` for the robot's own samples,
* :meth:`BayesSwarmPlanner.receive` for peers' broadcasts (Algorithm 3, RECEIVEINFORMATION),
* :meth:`BayesSwarmPlanner.decide` on arrival at a waypoint (Algorithm 1, TAKEDECISION),
* :meth:`BayesSwarmPlanner.broadcast` after a decision (Algorithm 3, SENDINFORMATION).

Solvers. The inner problem (Eq. 5, argmax of the GP mean) is solved from several starts (the
best grid/data points, the previous solution and a random point) by the paper's L-BFGS-B
('lbfgsb', the default) or by a projected trust-region Newton ascent with the analytic
gradient and Hessian, all starts at once ('newton'). The outer problem (Eq. 1 s.t. Eq. 2) is
by default the paper's 'cobyla', COBYLA from the current position (``cobyla_library``: the
compiled nlopt version of Powell's code, or scipy's, which since scipy 1.16 is a pure-Python
rewrite costing tens of milliseconds per call); 'grid' evaluates the acquisition on a polar
grid of the reachable disk, where paths along one heading share their samples so every
candidate's path integral comes from one cumulative sum, and a local polar pattern search
refines the best grid point; 'pso' is a particle swarm over the reachable disk.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.linalg import LinAlgError
from scipy.optimize import minimize
from scipy.special import erfc, log_ndtr

from bayes_swarm.acquisition import acquisition, omega, planned_path_points, ray_integrals
from bayes_swarm.alpha import AlphaBranch, AlphaDecision, exploitation_weight
from bayes_swarm.errors import BayesSwarmError, ObservationError
from bayes_swarm.gp import ExtendedVariance, GaussianProcess, downsample_indices
from bayes_swarm.lbfgsb import minimize_box
from bayes_swarm.messages import Decision, DecisionKind, PeerUpdate
from bayes_swarm.observations import ObservationStore, finite_samples
from bayes_swarm.penalty import local_penalty, log_local_penalty
from bayes_swarm.settings import Arena, BayesSwarmConfig
from bayes_swarm.trust_region import projected_newton_step

__all__ = [
    'MAX_SCALED_SIGNAL',
    'PEER_ARENA_MARGIN_FRACTION',
    'PEER_INDEX_REORDER_WINDOW',
    'BayesSwarmPlanner',
    'ascend_mean',
    'first_heading_rad',
    'first_waypoint',
]

# Largest plausible |signal sample| in units of ``signal_scale`` (own and peers' samples).
# The belief is set up for values of a few scales: M and L are in these units (M = 1.2) and
# the GP's signal-variance bound (1e5 by default) allows amplitudes of ~316 scales. 1e6
# scales is far beyond any field the configuration describes, so no legitimate sample is
# dropped, while squares of kept values (1e12 scales^2) stay finite and far from overflow.
# A larger value is a corrupt reading or message (a -1e300 sample turned every later
# decision into a random jump). Merely surprising values below the bound are kept: judging
# them is the model's job, not the input check's.
MAX_SCALED_SIGNAL = 1e6
# A peer's position, waypoint, sample locations and weaker sources must lie in the arena
# grown on every side by this fraction of its diagonal (a robot drifts or is pushed slightly
# outside; waypoints are clipped into the arena). Points further away are a corrupt message:
# a waypoint or position at 1e300 m made every later decision fail (Maximum allowed size
# exceeded) because the planner samples paths between such points.
PEER_ARENA_MARGIN_FRACTION = 0.5
# A peer message whose decision index is not newer than the last one accepted from the same
# sender, but at most this many decisions behind it, is a stale or duplicated delivery and is
# ignored. One further behind means the sender restarted its count (or the last index was
# corrupt, e.g. 2**32 - 1): it is accepted and the sender's sequence restarts from it, so a
# far-ahead index cannot silence a sender forever.
PEER_INDEX_REORDER_WINDOW = 16

_MEAN_GRID_SIZE = 16
# Added to the raw acquisition before its log (``penalty_log_space``): it is 0 only on a
# leg of length 0 with alpha = 0, which must stay finite (GPyOpt adds 1e-50).
_LOG_FLOOR = 1e-300
_SQRT2 = math.sqrt(2.0)
_MAX_RAY_STEPS = 25
_REFINE_LEVELS = 2
# (radius, heading) multiples of the pattern search's 3 x 3 stencil, centre excluded.
_POLAR_STENCIL = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1) if a or b], float)


def first_heading_rad(
    *, fan_index: int, fan_size: int, direction_range_deg: float, direction_offset_deg: float
) -> float:
    """TAKEFIRSTDECISION's heading [rad]: theta = r dtheta / m over a full circle, else
    r dtheta / (m + 1), measured from ``direction_offset_deg`` (``fan_index`` r is 1-based,
    ``fan_size`` m)."""
    if math.isclose(direction_range_deg, 360.0):
        theta_deg = fan_index * direction_range_deg / fan_size
    else:
        theta_deg = fan_index * direction_range_deg / (fan_size + 1)
    return math.radians(theta_deg + direction_offset_deg)


def first_waypoint(
    position_m: np.ndarray,
    *,
    fan_index: int,
    fan_size: int,
    direction_range_deg: float,
    direction_offset_deg: float,
    leg_m: float,
) -> np.ndarray:
    """TAKEFIRSTDECISION: leg of length V T along theta = r dtheta / m (or / (m + 1)).

    ``fan_index`` is r (1-based) and ``fan_size`` m; the heading is measured from
    ``direction_offset_deg``. Returns the (2,) waypoint [m] (not clipped).
    """
    theta = first_heading_rad(
        fan_index=fan_index,
        fan_size=fan_size,
        direction_range_deg=direction_range_deg,
        direction_offset_deg=direction_offset_deg,
    )
    return np.asarray(position_m, dtype=float) + leg_m * np.array(
        [math.cos(theta), math.sin(theta)]
    )


class BayesSwarmPlanner:
    """Decentralised Bayes-Swarm-P (or -O with ``penalty_enabled=False``) for one robot."""

    def __init__(
        self,
        config: BayesSwarmConfig,
        robot_name: str,
        seed: int | None = None,
        *,
        fan_index: int | None = None,
        fan_size: int | None = None,
        direction_offset_deg: float = 0.0,
    ) -> None:
        self._cfg = config
        self._name = robot_name
        self._rng = np.random.default_rng(seed)
        self._gp = GaussianProcess(config.gp)
        self._data = ObservationStore()
        self._own_unsent_points: list[np.ndarray] = []
        self._own_unsent_values: list[np.ndarray] = []
        self._peer_plans: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._peer_last_index: dict[str, int] = {}
        self.rejected_peer_updates = 0
        self._weaker: list[np.ndarray] = []
        self._k = 0
        self._last_decision: Decision | None = None
        self._last_expected_source: np.ndarray | None = None
        self._fan_index = config.robot_index + 1 if fan_index is None else fan_index
        self._fan_size = config.n_robots if fan_size is None else fan_size
        self._direction_offset_deg = direction_offset_deg
        arena = config.arena
        gx = np.linspace(arena.x_min_m, arena.x_max_m, _MEAN_GRID_SIZE)
        gy = np.linspace(arena.y_min_m, arena.y_max_m, _MEAN_GRID_SIZE)
        # Fixed start candidates of Eq. 5: a (g * g, 2) grid over the arena [m].
        self._mean_grid = np.stack(np.meshgrid(gx, gy), axis=-1).reshape(-1, 2)

    # ----------------------------------------------------------------- inputs
    @property
    def name(self) -> str:
        """Robot name used as the sender of broadcasts."""
        return self._name

    @property
    def config(self) -> BayesSwarmConfig:
        """The planner's configuration."""
        return self._cfg

    @property
    def decision_index(self) -> int:
        """Number of decisions taken so far (k_r)."""
        return self._k

    @property
    def n_observations(self) -> int:
        """Size of D (own plus received samples, before downsampling)."""
        return len(self._data)

    @property
    def weaker_sources(self) -> np.ndarray:
        """(w, 2) known weaker-source locations [m] (own and received)."""
        return np.array(self._weaker).reshape(-1, 2)

    @property
    def peer_waypoints(self) -> dict[str, np.ndarray]:
        """Latest known planned waypoint (2,) of every peer heard from."""
        return {name: plan[1].copy() for name, plan in self._peer_plans.items()}

    @property
    def gp(self) -> GaussianProcess:
        """The belief model as of the last decision."""
        return self._gp

    def add_observations(self, points_m: np.ndarray, values: np.ndarray) -> int:
        """Add the robot's own samples: (k, 2) locations [m] and (k,) values.

        Non-finite rows and values above :data:`MAX_SCALED_SIGNAL` in magnitude are dropped.
        Returns the number of rows kept.
        """
        pts, vals = finite_samples(points_m, values, max_abs_value=self._max_abs_signal)
        self._data.extend(pts, vals)
        if vals.shape[0]:
            self._own_unsent_points.append(pts)
            self._own_unsent_values.append(vals)
        return int(vals.shape[0])

    @property
    def _max_abs_signal(self) -> float:
        return MAX_SCALED_SIGNAL * self._cfg.signal_scale

    def _peer_region(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) corners [m] of the arena grown by the peer margin."""
        arena = self._cfg.arena
        margin = PEER_ARENA_MARGIN_FRACTION * arena.diagonal_m
        return arena.lower - margin, arena.upper + margin

    def peer_update_defect(self, update: PeerUpdate) -> str:
        """Why ``update`` is malformed and would be dropped as a whole, or '' if it is not.

        Its position and waypoint must be finite and within the arena grown by
        :data:`PEER_ARENA_MARGIN_FRACTION` of its diagonal; the sample arrays must match.
        (Single implausible samples and weaker sources are dropped by :meth:`receive`.)
        """
        checked = self._checked_peer(update)
        return checked if isinstance(checked, str) else ''

    def _checked_peer(
        self, update: PeerUpdate
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | str:
        """``update``'s position, waypoint and the samples :meth:`receive` keeps (each
        array read once), or why it is malformed (:meth:`peer_update_defect`)."""
        lower, upper = self._peer_region()
        try:
            position = np.asarray(update.position_m, dtype=float).reshape(2)
            waypoint = np.asarray(update.waypoint_m, dtype=float).reshape(2)
            pts, vals = finite_samples(
                update.sample_points_m,
                update.sample_values,
                max_abs_value=self._max_abs_signal,
                lower_m=lower,
                upper_m=upper,
            )
        except (ValueError, TypeError) as err:
            return f'malformed arrays ({err})'
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(waypoint))):
            return 'position or waypoint not finite'
        for name, point in (('position', position), ('waypoint', waypoint)):
            if np.any(point < lower) or np.any(point > upper):
                return f'{name} {point.tolist()} m far outside the arena'
        return position, waypoint, pts, vals

    def receive(self, update: PeerUpdate) -> bool:
        """RECEIVEINFORMATION: merge a peer's broadcast; False if it was ignored.

        The robot's own broadcasts and messages not newer than the last accepted one from the
        same sender, but at most :data:`PEER_INDEX_REORDER_WINDOW` decisions behind it (stale
        or duplicated deliveries), are ignored; an index further behind restarts the sender's
        sequence. A malformed update (:meth:`peer_update_defect`) is dropped as a whole and
        counted in ``rejected_peer_updates``; of an accepted one, samples with a non-finite or
        implausible value (above :data:`MAX_SCALED_SIGNAL` signal scales in magnitude) or a
        location far outside the arena are dropped, and so are such weaker sources.
        """
        if update.sender == self._name:
            return False
        index = int(update.decision_index)
        last = self._peer_last_index.get(update.sender)
        if last is not None and last - PEER_INDEX_REORDER_WINDOW <= index <= last:
            return False
        checked = self._checked_peer(update)
        if isinstance(checked, str):
            self.rejected_peer_updates += 1
            return False
        position, waypoint, pts, vals = checked
        lower, upper = self._peer_region()
        self._peer_last_index[update.sender] = index
        self._data.extend(pts, vals)
        self._peer_plans[update.sender] = (position, waypoint)
        for weak in np.asarray(update.weaker_sources_m, dtype=float).reshape(-1, 2):
            if np.all(weak >= lower) and np.all(weak <= upper):
                self._add_weaker(weak)
        return True

    def _add_weaker(self, point: np.ndarray) -> None:
        if not np.all(np.isfinite(point)):
            return
        for known in self._weaker:
            if np.hypot(*(known - point)) < self._cfg.robot_size_m:
                return
        self._weaker.append(np.asarray(point, dtype=float).copy())

    def broadcast(self, position_m: np.ndarray) -> PeerUpdate:
        """SENDINFORMATION: planned waypoint and the own samples not broadcast yet."""
        if self._last_decision is None:
            msg = 'broadcast() needs a decision first'
            raise ObservationError(msg)
        if self._own_unsent_points:
            pts = np.vstack(self._own_unsent_points)
            vals = np.concatenate(self._own_unsent_values)
        else:
            pts, vals = np.zeros((0, 2)), np.zeros(0)
        self._own_unsent_points, self._own_unsent_values = [], []
        return PeerUpdate(
            sender=self._name,
            decision_index=self._last_decision.decision_index,
            position_m=np.asarray(position_m, dtype=float).copy(),
            waypoint_m=self._last_decision.waypoint_m.copy(),
            sample_points_m=pts,
            sample_values=vals,
            weaker_sources_m=self.weaker_sources,
        )

    # --------------------------------------------------------------- decision
    def decide(self, position_m: np.ndarray, time_s: float) -> Decision:
        """TAKEDECISION at the robot's (2,) position [m] and mission time [s]."""
        start = time.perf_counter()
        start_cpu = time.process_time()
        position = np.asarray(position_m, dtype=float).reshape(2)
        if not np.all(np.isfinite(position)):
            msg = f'position must be finite, got {position}'
            raise ObservationError(msg)
        cfg = self._cfg
        if self._k == 0:
            waypoint = cfg.arena.clip(
                first_waypoint(
                    position,
                    fan_index=self._fan_index,
                    fan_size=self._fan_size,
                    direction_range_deg=cfg.initial_direction_range_deg,
                    direction_offset_deg=self._direction_offset_deg,
                    leg_m=cfg.max_leg_m,
                )
            )
            decision = Decision(waypoint, 0, DecisionKind.FIRST, n_samples=len(self._data))
        elif len(self._data) == 0:
            decision = self._random_jump(position, 'no observations yet')
        else:
            try:
                decision = self._bayes_decision(position, time_s)
            except (BayesSwarmError, LinAlgError, ValueError, FloatingPointError) as err:
                decision = self._random_jump(
                    position, f'fallback after {type(err).__name__}: {err}'
                )
        decision = Decision(
            waypoint_m=decision.waypoint_m,
            decision_index=self._k,
            kind=decision.kind,
            alpha=decision.alpha,
            expected_source_m=decision.expected_source_m,
            n_samples=decision.n_samples,
            compute_time_s=time.perf_counter() - start,
            detail=decision.detail,
            cpu_time_s=time.process_time() - start_cpu,
        )
        self._k += 1
        self._last_decision = decision
        return decision

    def _random_jump(self, position: np.ndarray, detail: str = '') -> Decision:
        """Algorithm 1 lines 16-18: a random leg of length U(0.1, 0.9) V T, inside the arena."""
        r1 = self._rng.uniform(0.0, 1.0)
        r2 = self._rng.uniform(0.1, 0.9)
        angle = 2.0 * math.pi * r1
        waypoint = self._cfg.arena.clip(
            position + r2 * self._cfg.max_leg_m * np.array([math.cos(angle), math.sin(angle)])
        )
        kind = DecisionKind.FALLBACK if detail else DecisionKind.RANDOM_JUMP
        return Decision(waypoint, self._k, kind, detail=detail)

    def _training_data(self) -> tuple[np.ndarray, np.ndarray]:
        pts, vals = self._data.arrays()
        cfg = self._cfg
        if cfg.authors_floor_downsampling and pts.shape[0] >= cfg.n_max:
            order = np.lexsort((vals, pts[:, 1], pts[:, 0]))
            pts, vals = pts[order], vals[order]
            keep = downsample_indices(pts.shape[0], cfg.n_max, floor_rule=True)
            keep = keep[keep < pts.shape[0] - 1]
        else:
            keep = downsample_indices(pts.shape[0], cfg.n_max)
        return pts[keep], vals[keep] / cfg.signal_scale

    def _estimated_penalty_constants(self, values: np.ndarray) -> tuple[float, float]:
        """M and L of the penalty from the belief (local penalization, Gonzalez et al. 2016).

        M is the largest observation (their estimate of the maximum). L is the largest norm
        of the GP mean's gradient over the arena: the best of the arena grid and the data
        points, refined by L-BFGS-B on the analytic gradient of that norm (as GPyOpt
        estimates it); the configured L if the belief is flat (below 1e-7).
        """
        gp = self._gp
        points = np.vstack([self._mean_grid, gp.training_inputs])
        _, grad, _ = gp.mean_derivatives(points)
        norms = np.hypot(grad[:, 0], grad[:, 1])
        best = int(np.argmax(norms))
        lipschitz = float(norms[best])
        if math.isfinite(lipschitz) and lipschitz > 1e-7:
            arena = self._cfg.arena
            _, value = minimize_box(
                _negated_gradient_norm,
                points[best],
                np.asarray(arena.lower, dtype=float),
                np.asarray(arena.upper, dtype=float),
                args=(gp,),
            )
            if np.isfinite(value):
                lipschitz = max(lipschitz, -value)
        else:
            lipschitz = self._cfg.lipschitz
        return float(np.max(values)), lipschitz

    def _bayes_decision(self, position: np.ndarray, time_s: float) -> Decision:
        cfg = self._cfg
        lipschitz = cfg.lipschitz
        pts, vals = self._training_data()
        self._gp.fit(pts, vals)
        expected = self._expected_source()
        self._last_expected_source = expected
        peers = list(self._peer_plans.values())
        peer_starts = np.array([p[0] for p in peers]).reshape(-1, 2)
        peer_waypoints = np.array([p[1] for p in peers]).reshape(-1, 2)
        alpha = (
            AlphaDecision(cfg.fixed_alpha, AlphaBranch.FIXED)
            if cfg.fixed_alpha is not None
            else exploitation_weight(
                expected,
                peer_waypoints,
                self.weaker_sources,
                robot_size_m=cfg.robot_size_m,
                weaker_source_radius_m=(
                    cfg.detection_radius_m if cfg.weaker_source_within_eps else None
                ),
                time_s=time_s,
                max_mission_time_s=cfg.max_mission_time_s,
                time_scale=cfg.alpha_time_scale,
            )
        )
        if cfg.authors_origin_paths:
            starts = np.zeros_like(peer_starts)
            ends = peer_waypoints - peer_starts
        else:
            starts, ends = peer_starts, peer_waypoints
        extra = planned_path_points(starts, ends, cfg.step_m, cfg.max_peer_path_points)
        ext = self._gp.extended_std(extra)
        if cfg.penalty_enabled and peer_waypoints.shape[0]:
            peer_mean, peer_std = self._gp.predict(peer_waypoints)
            if cfg.authors_negated_m:
                max_signal = -float(self._gp.predict_mean(expected.reshape(1, 2))[0])
            else:
                max_signal = cfg.max_signal
            if cfg.penalty_estimate:
                max_signal, lipschitz = self._estimated_penalty_constants(vals)
        else:
            peer_waypoints = np.zeros((0, 2))
            peer_mean = peer_std = np.zeros(0)
            max_signal = cfg.max_signal
        problem = _OuterProblem(
            cfg,
            position,
            expected,
            alpha.value,
            ext,
            peer_waypoints,
            peer_mean,
            peer_std,
            max_signal,
            lipschitz,
        )
        waypoint = problem.solve(self._rng)
        kind = DecisionKind.ACQUISITION
        if np.hypot(*(waypoint - position)) < cfg.step_m:
            # Algorithm 1 lines 11-18: the robot would stay where it is.
            distance_to_expected = float(np.hypot(*(expected - position)))
            previous = self._last_decision.kind if self._last_decision else None
            if distance_to_expected < 0.9 * cfg.detection_radius_m:
                self._add_weaker(expected)
                alpha = AlphaDecision(0.0, AlphaBranch.EXPLORE)
                problem.alpha = 0.0
                waypoint = problem.solve(self._rng)
                kind = DecisionKind.EXPLORE
                if np.hypot(*(waypoint - position)) < cfg.step_m:
                    waypoint, kind = (
                        self._random_jump(position).waypoint_m,
                        DecisionKind.RANDOM_JUMP,
                    )
            elif distance_to_expected < cfg.step_m and previous is not DecisionKind.APPROACH:
                # Not in Algorithm 1: the expected source is closer than one sampling step but
                # outside 0.9 eps; the literal rule would jump away from it. Go there once.
                waypoint, kind = expected.copy(), DecisionKind.APPROACH
            else:
                waypoint, kind = self._random_jump(position).waypoint_m, DecisionKind.RANDOM_JUMP
        return Decision(
            waypoint,
            self._k,
            kind,
            alpha=alpha.value,
            expected_source_m=expected,
            n_samples=pts.shape[0],
        )

    def _expected_source(self) -> np.ndarray:
        """Eq. 5: argmax of the GP mean in the arena, from several starts (``inner_optimizer``)."""
        cfg = self._cfg
        arena = cfg.arena
        candidates = np.vstack([self._mean_grid, self._gp.training_inputs])
        means = self._gp.predict_mean(candidates)
        order = np.argsort(-means)
        seeds = [candidates[order[0]]]
        for idx in order[1:]:
            if len(seeds) >= cfg.n_inner_starts - 1:
                break
            if min(np.hypot(*(candidates[idx] - s)) for s in seeds) > 0.05 * arena.diagonal_m:
                seeds.append(candidates[idx])
        previous = self._last_expected_source
        if previous is not None and min(np.hypot(*(previous - s)) for s in seeds) > 0.05 * (
            arena.diagonal_m
        ):
            seeds.append(previous)
        seeds.append(self._rng.uniform(arena.lower, arena.upper))
        if cfg.inner_optimizer == 'newton':
            return ascend_mean(self._gp, np.array(seeds), arena)
        lower = np.asarray(arena.lower, dtype=float)
        upper = np.asarray(arena.upper, dtype=float)
        best_x, best_f = seeds[0], -math.inf
        for seed in seeds:
            x, value = minimize_box(_negated_mean, seed, lower, upper, args=(self._gp,))
            if np.isfinite(value) and -value > best_f:
                best_x, best_f = x, -value
        return arena.clip(np.asarray(best_x, dtype=float))


def _negated_gradient_norm(x: np.ndarray, gp: GaussianProcess) -> tuple[float, np.ndarray]:
    """-|grad mu(x)| and its gradient -H g / |g| (L-BFGS-B objective of the estimated L)."""
    _, grad, hess = gp.mean_derivatives(np.asarray(x, dtype=float).reshape(1, 2))
    g, h = grad[0], hess[0]
    norm = float(np.hypot(g[0], g[1]))
    if norm < 1e-300:
        return -norm, np.zeros(2)
    return -norm, -(h @ g) / norm


def _negated_mean(x: np.ndarray, gp: GaussianProcess) -> tuple[float, np.ndarray]:
    value, grad = gp.mean_and_gradient(x)
    return -value, -grad


def ascend_mean(
    gp: GaussianProcess, seeds_m: np.ndarray, arena: Arena, max_iterations: int = 15
) -> np.ndarray:
    """Eq. 5 from several starts at once: projected trust-region Newton ascent of the GP mean.

    Every seed (s, 2) climbs with :func:`~bayes_swarm.trust_region.projected_newton_step` on
    the negated mean (Newton steps where the mean is locally concave, gradient steps of the
    trust radius elsewhere, coordinates pressed against the arena boundary held there), the
    trust radius starting at half a length scale; a step is kept only if the mean rises, and
    a seed whose step is shorter than 1e-5 length scales is done. Returns the (2,) best point.

    The GP derivatives of the seeds still moving come from one vectorised call per iteration;
    the 2 x 2 step algebra is plain float arithmetic.
    """
    x = arena.clip(np.asarray(seeds_m, dtype=float).reshape(-1, 2))
    ell = gp.hyperparameters.length_scale_m
    radius = [0.5 * ell] * x.shape[0]
    mean, grad, hess = gp.mean_derivatives(x)
    tolerance = 1e-5 * max(ell, 1e-9)
    lower, upper = (arena.x_min_m, arena.y_min_m), (arena.x_max_m, arena.y_max_m)
    active = list(range(x.shape[0]))
    for _ in range(max_iterations):
        moving: list[int] = []
        targets: list[tuple[float, float]] = []
        for i in active:
            xi = (float(x[i, 0]), float(x[i, 1]))
            s0, s1 = projected_newton_step(xi, -grad[i], -hess[i], lower, upper, radius[i])
            cx = min(max(xi[0] + s0, lower[0]), upper[0])
            cy = min(max(xi[1] + s1, lower[1]), upper[1])
            if not math.hypot(cx - xi[0], cy - xi[1]) < tolerance:  # NaN: not converged
                moving.append(i)
                targets.append((cx, cy))
        if not moving:
            break
        candidate = np.array(targets)
        c_mean, c_grad, c_hess = gp.mean_derivatives(candidate)
        for j, i in enumerate(moving):
            if c_mean[j] > mean[i]:
                x[i], mean[i], grad[i], hess[i] = candidate[j], c_mean[j], c_grad[j], c_hess[j]
                radius[i] = min(2.0 * radius[i], 2.0 * ell)
            else:
                radius[i] = 0.25 * radius[i]
        active = moving
    return x[int(np.argmax(mean))].copy()


class _OuterProblem:
    """Eq. 1 subject to Eq. 2 for one decision, with its solvers."""

    def __init__(
        self,
        cfg: BayesSwarmConfig,
        position: np.ndarray,
        expected: np.ndarray,
        alpha: float,
        ext: ExtendedVariance,
        peer_waypoints: np.ndarray,
        peer_mean: np.ndarray,
        peer_std: np.ndarray,
        max_signal: float,
        lipschitz: float,
    ) -> None:
        self.cfg = cfg
        self.log_space = cfg.penalty_log_space
        self.lipschitz = lipschitz
        self.position = position
        self.expected = expected
        self.alpha = alpha
        self.ext = ext
        self.peer_waypoints = peer_waypoints
        self.peer_mean = peer_mean
        self.peer_std = peer_std
        self.max_signal = max_signal
        self.n_steps = max(1, min(_MAX_RAY_STEPS, math.ceil(cfg.max_leg_m / cfg.step_m)))
        self.ray_step_m = cfg.max_leg_m / self.n_steps
        # Path parameter u in [0, 1] (n_steps + 1,) of the paths sampled by values().
        self.path_u = np.linspace(0.0, 1.0, self.n_steps + 1)
        # Trapezoid weights on path_u: the path integral of one candidate is one dot product.
        self.path_weights = np.full(self.n_steps + 1, 1.0 / self.n_steps)
        self.path_weights[[0, -1]] *= 0.5
        self.path_base = np.zeros(2) if cfg.authors_origin_paths else position
        self._path_u_column = self.path_u[:, None]
        # The penalty's per-peer constants of value(): z = (L d - M + mu) / (sqrt(2) sigma).
        self.peer_shift = np.asarray(peer_mean, dtype=float) - max_signal
        self.peer_scale = 1.0 / (
            math.sqrt(2.0) * np.maximum(np.asarray(peer_std, dtype=float), cfg.penalty_std_floor)
        )
        # value() forms -z directly ((L d - M + mu) * (-scale) is -z exactly), in place.
        self._peer_x = np.ascontiguousarray(peer_waypoints[:, 0], dtype=float)
        self._peer_y = np.ascontiguousarray(peer_waypoints[:, 1], dtype=float)
        self._negated_peer_scale = -self.peer_scale
        # The paper's units: Omega with distances in metres, Sigma in signal * m. Dimensionless:
        # Omega with distances in leg lengths V T, Sigma divided by its largest value (the prior
        # std along the longest leg); both then lie in [0, 1] whatever the field's scale.
        self.sigma_scale = 1.0
        self.omega_unit_m = 1.0
        if cfg.dimensionless_acquisition:
            self.omega_unit_m = cfg.max_leg_m
            prior_std = math.sqrt(ext.hyperparameters.signal_variance)
            self.sigma_scale = 1.0 / max(prior_std * cfg.max_leg_m, 1e-300)

    def gamma(self, points: np.ndarray) -> np.ndarray:
        return local_penalty(
            points,
            self.peer_waypoints,
            self.peer_mean,
            self.peer_std,
            max_signal=self.max_signal,
            lipschitz=self.lipschitz,
            std_floor=self.cfg.penalty_std_floor,
        )

    def log_gamma(self, points: np.ndarray) -> np.ndarray:
        return log_local_penalty(
            points,
            self.peer_waypoints,
            self.peer_mean,
            self.peer_std,
            max_signal=self.max_signal,
            lipschitz=self.lipschitz,
            std_floor=self.cfg.penalty_std_floor,
        )

    def _combine(
        self, omega_values: np.ndarray, sigma_values: np.ndarray, points: np.ndarray
    ) -> np.ndarray:
        """The maximised objective (q,) from Eq. 1's terms at (q, 2) ``points``: Eq. 1 itself,
        or with ``penalty_log_space`` its log, log(raw acquisition) + log Gamma."""
        if not self.log_space:
            return acquisition(self.alpha, omega_values, sigma_values, self.gamma(points))
        raw = acquisition(self.alpha, omega_values, sigma_values, np.ones_like(omega_values))
        return np.log(raw + _LOG_FLOOR) + self.log_gamma(points)

    def value(self, x: np.ndarray) -> float:
        """Acquisition at one reachable (2,) point: :meth:`values` without its batch set-up.

        The same terms in the same units (COBYLA's objective, called tens of times per
        decision); equal to ``values(x)[0]`` up to rounding.
        """
        x0, x1 = float(x[0]), float(x[1])
        ox, oy = x0 - float(self.position[0]), x1 - float(self.position[1])
        std = self.ext.std(self.path_base + self._path_u_column * np.array([ox, oy]))
        sigma = math.hypot(ox, oy) * float(self.path_weights @ std) * self.sigma_scale
        ex, ey = x0 - float(self.expected[0]), x1 - float(self.expected[1])
        omega_value = 1.0 / (1.0 + (ex * ex + ey * ey) / self.omega_unit_m**2)
        raw = self.alpha * omega_value + (1.0 - self.alpha) * sigma
        if not self._peer_x.shape[0]:
            return math.log(raw + _LOG_FLOOR) if self.log_space else raw
        factors = np.hypot(self._peer_x - x0, self._peer_y - x1)
        factors *= self.lipschitz
        factors += self.peer_shift
        factors *= self._negated_peer_scale  # -z of every peer
        if self.log_space:
            factors *= -_SQRT2  # log gamma = log Phi(sqrt(2) z)
            return math.log(raw + _LOG_FLOOR) + float(np.sum(log_ndtr(factors)))
        erfc(factors, out=factors)
        factors *= 0.5
        return raw * float(np.multiply.reduce(factors))

    def values(self, points: np.ndarray) -> np.ndarray:
        """Acquisition (q,) at arbitrary (q, 2) reachable points (paths sampled uniformly)."""
        pts = np.asarray(points, dtype=float).reshape(-1, 2)
        u = self.path_u
        base = np.zeros(2) if self.cfg.authors_origin_paths else self.position
        offsets = pts - self.position
        samples = base + u[None, :, None] * offsets[:, None, :]
        std = self.ext.std(samples.reshape(-1, 2)).reshape(pts.shape[0], -1)
        length = np.hypot(offsets[:, 0], offsets[:, 1])
        sigma = length * np.trapezoid(std, u, axis=1)
        sigma *= self.sigma_scale
        return self._combine(omega(pts, self.expected, self.omega_unit_m), sigma, pts)

    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Candidates (c, 2) on the polar grid of the reachable disk and their values (c,)."""
        cfg = self.cfg
        headings = np.linspace(0.0, 2.0 * math.pi, cfg.n_candidate_headings, endpoint=False)
        toward = self.expected - self.position
        if np.hypot(*toward) > 1e-9:
            headings = np.append(headings, math.atan2(toward[1], toward[0]))
        candidates, sigma = ray_integrals(
            self.ext.std,
            self.position,
            headings,
            self.ray_step_m,
            self.n_steps,
            from_origin=cfg.authors_origin_paths,
        )
        pts = candidates.reshape(-1, 2)
        values = self._combine(
            omega(pts, self.expected, self.omega_unit_m), self.sigma_scale * sigma.reshape(-1), pts
        )
        values[~cfg.arena.contains(pts)] = -np.inf
        return pts, values

    def _project(self, x: np.ndarray) -> np.ndarray:
        """``x`` moved onto the reachable disc (Eq. 2) and into the arena.

        COBYLA returns points on the constraint boundary that violate it by its tolerance
        (about 1e-8 m); rejecting them would leave the robot where it is and trigger
        Algorithm 1's random jump, so they are pulled back instead.
        """
        offset = np.asarray(x, dtype=float) - self.position
        distance = float(np.hypot(*offset))
        if distance > self.cfg.max_leg_m:
            offset = offset * (self.cfg.max_leg_m / distance)
        return self.cfg.arena.clip(self.position + offset)

    def _feasible(self, x: np.ndarray) -> bool:
        return bool(
            np.hypot(*(x - self.position)) <= self.cfg.max_leg_m + 1e-9
            and self.cfg.arena.contains(x)
        )

    def _cobyla(self, x0: np.ndarray, rhobeg: float) -> np.ndarray:
        """COBYLA from ``x0``: the leg constraint of Eq. 2 and the arena, final step 1e-4 m.

        ``cobyla_library`` 'nlopt' is the compiled C version of Powell's COBYLA (the
        algorithm of the Fortran code that the authors' scipy 1.10 wrapped), with the arena
        as bounds, so no candidate outside it is evaluated; 'scipy' is scipy's COBYLA, which
        since scipy 1.16 is PRIMA's rewrite in pure Python (its own iterations cost more
        than the acquisition), the arena as four linear constraints as in the authors' code.
        """
        if self.cfg.cobyla_library == 'nlopt':
            return self._cobyla_nlopt(x0, rhobeg)
        cfg = self.cfg
        arena = cfg.arena
        constraints = [
            {'type': 'ineq', 'fun': lambda x: cfg.max_leg_m - np.hypot(*(x - self.position))},
            {'type': 'ineq', 'fun': lambda x: x[0] - arena.x_min_m},
            {'type': 'ineq', 'fun': lambda x: arena.x_max_m - x[0]},
            {'type': 'ineq', 'fun': lambda x: x[1] - arena.y_min_m},
            {'type': 'ineq', 'fun': lambda x: arena.y_max_m - x[1]},
        ]
        result = minimize(
            lambda x: -self.value(x),
            x0,
            method='COBYLA',
            constraints=constraints,
            options={'rhobeg': rhobeg, 'maxiter': cfg.cobyla_max_iterations, 'tol': 1e-4},
        )
        return np.asarray(result.x, dtype=float)

    def _cobyla_nlopt(self, x0: np.ndarray, rhobeg: float) -> np.ndarray:
        import nlopt

        cfg = self.cfg
        arena = cfg.arena
        px, py = float(self.position[0]), float(self.position[1])
        leg = cfg.max_leg_m
        best: list[tuple[float, np.ndarray]] = []

        def objective(x: np.ndarray, _grad: np.ndarray) -> float:
            value = -self.value(x)
            improves = math.isfinite(value) and (not best or value < best[0][0])
            if improves and math.hypot(x[0] - px, x[1] - py) <= leg:
                best[:] = [(value, np.array(x, dtype=float))]
            return value if math.isfinite(value) else math.inf

        opt = nlopt.opt(nlopt.LN_COBYLA, 2)
        opt.set_lower_bounds([arena.x_min_m, arena.y_min_m])
        opt.set_upper_bounds([arena.x_max_m, arena.y_max_m])
        opt.set_min_objective(objective)
        opt.add_inequality_constraint(lambda x, _g: math.hypot(x[0] - px, x[1] - py) - leg, 0.0)
        opt.set_initial_step(rhobeg)
        opt.set_xtol_abs(1e-4)
        opt.set_maxeval(cfg.cobyla_max_iterations)
        try:
            return np.asarray(opt.optimize(np.asarray(x0, dtype=float)), dtype=float)
        except (nlopt.RoundoffLimited, nlopt.ForcedStop, RuntimeError):
            # Stopped by rounding errors or a generic nlopt failure: the best feasible point
            # evaluated so far (the start if none).
            return best[0][1] if best else np.asarray(x0, dtype=float)

    def _pso(self, rng: np.random.Generator) -> np.ndarray:
        cfg = self.cfg
        n = cfg.pso_particles
        radius = cfg.max_leg_m * np.sqrt(rng.uniform(0.0, 1.0, n))
        angle = rng.uniform(0.0, 2.0 * math.pi, n)
        pos = cfg.arena.clip(self.position + radius[:, None] * np.c_[np.cos(angle), np.sin(angle)])
        vel = np.zeros_like(pos)
        best_pos, best_val = pos.copy(), self.values(pos)
        g = int(np.argmax(best_val))
        for _ in range(cfg.pso_iterations):
            r1, r2 = rng.uniform(size=(2, n, 1))
            vel = 0.7 * vel + 1.5 * r1 * (best_pos - pos) + 1.5 * r2 * (best_pos[g] - pos)
            pos = pos + vel
            offset = pos - self.position
            dist = np.hypot(offset[:, 0], offset[:, 1])
            scale = np.minimum(1.0, cfg.max_leg_m / np.maximum(dist, 1e-12))
            pos = cfg.arena.clip(self.position + offset * scale[:, None])
            val = self.values(pos)
            improved = val > best_val
            best_pos[improved], best_val[improved] = pos[improved], val[improved]
            g = int(np.argmax(best_val))
        return best_pos[g]

    def _refine(self, x0: np.ndarray) -> np.ndarray:
        """Local polar pattern search around a grid point: 3 x 3 stencils, halving the step."""
        cfg = self.cfg
        offset = x0 - self.position
        radius = float(np.hypot(*offset))
        heading = math.atan2(offset[1], offset[0])
        best_value = -math.inf
        best = x0
        d_r = 0.5 * self.ray_step_m
        d_theta = math.pi / cfg.n_candidate_headings
        stencil = _POLAR_STENCIL
        for level in range(_REFINE_LEVELS):
            radii = np.clip(radius + d_r * stencil[:, 0], 0.0, cfg.max_leg_m)
            headings = heading + d_theta * stencil[:, 1]
            pts = self.position + radii[:, None] * np.column_stack(
                [np.cos(headings), np.sin(headings)]
            )
            pts = cfg.arena.clip(pts)
            if level == 0:
                # The start point's value comes with the first stencil, in the same call.
                vals = self.values(np.vstack([x0, pts]))
                best_value, vals = float(vals[0]), vals[1:]
            else:
                vals = self.values(pts)
            i = int(np.argmax(vals))
            if vals[i] > best_value:
                best_value, best = float(vals[i]), pts[i]
                offset = best - self.position
                radius = float(np.hypot(*offset))
                heading = math.atan2(offset[1], offset[0])
            d_r *= 0.5
            d_theta *= 0.5
        return best

    def solve(self, rng: np.random.Generator) -> np.ndarray:
        """Best reachable waypoint (2,) [m]; infeasible or non-finite results fall back."""
        cfg = self.cfg
        if cfg.outer_optimizer == 'pso':
            candidate = self._pso(rng)
            best = candidate
        elif cfg.outer_optimizer == 'cobyla':
            best = cfg.arena.clip(self.position)
            candidate = self._cobyla(best, rhobeg=min(1.0, cfg.max_leg_m))
            if np.all(np.isfinite(candidate)):
                candidate = self._project(candidate)
        else:
            pts, values = self.grid()
            best = pts[int(np.argmax(values))]
            candidate = self._refine(best)
        if not self._feasible(best):
            best = cfg.arena.clip(self.position)
        if not (np.all(np.isfinite(candidate)) and self._feasible(candidate)):
            return best
        if cfg.outer_optimizer == 'grid':
            return candidate  # the pattern search only ever accepts improvements
        if self.values(candidate)[0] >= self.values(best)[0]:
            return candidate
        return best
