"""Configuration of the MSC + particle filter swarm control (defaults: the paper's Table I).

Every value the paper gives is a default here; every gap the specification had to fill
([OUR SPEC] in the algorithm specification, section 1) is a field too, so a user can try
another reading without editing code. Dataclasses are frozen: the node and the batch
simulator build one :class:`MscPfConfig` at start and hand it to the core.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from swarm_common.params import parameter, section

from msc_pf.errors import ConfigError
from msc_pf.schemes import Scheme

__all__ = [
    'AvoidanceConfig',
    'MscConfig',
    'MscPfConfig',
    'ParticleFilterConfig',
    'PhaseConfig',
    'RadioConfig',
    'SearchConfig',
    'SwarmConfig',
]

AVOIDANCE_FORMS = ('linear', 'inverse_square')
LEADER_RULES = ('gradient', 'pbest', 'pbest_turn')
INITIAL_PRIORS = ('detection_square', 'field')
FUSION_MODES = ('joint', 'sequential')
RESAMPLING_SCHEMES = ('systematic', 'multinomial')
PF_BACKENDS = ('auto', 'numpy', 'numba')
SEARCH_MODES = ('history', 'sector')
FAR_AIMS = ('best_particle', 'estimate')


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ConfigError(message)


def _require_finite(obj: object) -> None:
    for f in fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        if isinstance(value, float) and not math.isfinite(value):
            raise ConfigError(f'{type(obj).__name__}.{f.name} must be finite, got {value}')


@dataclass(frozen=True)
class RadioConfig:
    """Log-distance path loss with Gaussian receiver noise (Table I; spec section 0.1).

    The paper's "P0 = 40.046" is the reference loss at 1 m (Friis at 2.4 GHz), so the RSSI at
    1 m is ``tx_power_dbm - reference_loss_db`` = -27.046 dBm.
    """

    tx_power_dbm: float = parameter(13.0, 'target transmit power (Table I: 13).', unit='dBm')
    reference_loss_db: float = parameter(
        40.046, "path loss at 1 m (Table I's P0: 40.046).", unit='dB'
    )
    path_loss_exponent: float = parameter(3.0, 'K of eq. (4) (Table I: 3).', gt=0.0)
    noise_std_db: float = parameter(
        1.0, 'receiver noise standard deviation (Table I: variance 1).', unit='dB', ge=0.0
    )
    detection_threshold_dbm: float = parameter(
        -101.0, 'gamma_D, weaker signals are not heard (Table I: -101).', unit='dBm'
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.path_loss_exponent > 0.0, 'path_loss_exponent must be positive')
        _require(self.noise_std_db >= 0.0, 'noise_std_db must be non-negative')

    @property
    def rssi_at_1m_dbm(self) -> float:
        """RSSI at the 1 m reference distance [dBm] (P0 of the paper's eq. 4)."""
        return self.tx_power_dbm - self.reference_loss_db

    def mean_rssi_dbm(self, distance_m: float) -> float:
        """Noise-free RSSI at ``distance_m`` [dBm]; distances below 1 m count as 1 m."""
        d = max(1.0, float(distance_m))
        return self.rssi_at_1m_dbm - 10.0 * self.path_loss_exponent * math.log10(d)

    def distance_for_rssi_m(self, rssi_dbm: float) -> float:
        """Distance [m] at which the noise-free RSSI equals ``rssi_dbm``."""
        exponent = (self.rssi_at_1m_dbm - rssi_dbm) / (10.0 * self.path_loss_exponent)
        return max(1.0, 10.0**exponent)

    @property
    def detection_range_m(self) -> float:
        """Distance [m] at which the mean RSSI falls to the detection threshold (~292 m)."""
        return self.distance_for_rssi_m(self.detection_threshold_dbm)


@dataclass(frozen=True)
class ParticleFilterConfig:
    """SIR particle filter per target (eqs. 2-7; spec section 1.5)."""

    n_particles: int = parameter(5041, 'N_p (Table I: 5041 = 71 x 71).', ge=4)
    r_conv_m: float = parameter(
        20.0, 'radius of the convergence circle R_conv, eq. (6).', unit='m', gt=0.0
    )
    r_err_m: float = parameter(
        10.0, 'radius of the permissible error circle R_err, eq. (7).', unit='m', gt=0.0
    )
    window: int = parameter(
        10, 'number n of recent estimates tested by eq. (7), one per control step.', ge=2
    )
    noise_variance_db2: float = parameter(1.0, 'sigma^2 of eq. (3).', unit='dB^2', gt=0.0)
    gaussian_likelihood: bool = parameter(
        True,
        (
            'True (default) uses the Gaussian exp(-e^2 / (2 sigma^2)) for the noise '
            "variance sigma^2; False the paper's eq. (3) as printed, exp(-e^2 / sigma^2), "
            "which treats the 1 dB noise as 0.71 dB: with a dozen neighbours' samples fused "
            'per step that filter converged tens to hundreds of metres off the target.'
        ),
    )
    censored_likelihood: bool = parameter(
        True,
        (
            "divide each sample's likelihood by the chance Phi((R_j - gamma_D) / s) that a "
            'target at the particle would have been heard at all (s: the noise standard '
            'deviation the likelihood implies). The receiver reports only samples above '
            'gamma_D, so near the detection edge the reported ones are biased upward; '
            'without this a swarm lingering there converges on a wrong point.'
        ),
    )
    initial_prior: str = parameter(
        'detection_square',
        (
            "'detection_square' puts the lattice on the square around the detection disc "
            "centred on the observer; 'field' spreads it over the whole field."
        ),
        choices=INITIAL_PRIORS,
    )
    init_half_width_m: float | None = parameter(
        None,
        (
            "half width of the detection square; unset (.nan) uses the radio model's detection "
            'range (about 292 m).'
        ),
        unit='m',
        gt=0.0,
    )
    resampling: str = parameter(
        'systematic',
        "'systematic' (one uniform offset) or 'multinomial'.",
        choices=RESAMPLING_SCHEMES,
    )
    roughening_kappa: float = parameter(
        0.5,
        (
            'kappa of the roughening jitter kappa * E * N^(-1/2). The common 0.2 left the '
            'static-target filter to collapse by resampling alone onto one arc of the ring '
            'of distances a far swarm observes (spread under R_conv, estimate 100-400 m '
            'off); 0.5 keeps that ring populated until the observations decide, while the '
            'jitter it adds to the spread (about 6 m) stays well under R_conv.'
        ),
        ge=0.0,
    )
    roughening_floor_m: float = parameter(
        0.5, 'lower bound of the jitter standard deviation.', unit='m', ge=0.0
    )
    noise_pool_size: int = parameter(
        1 << 20,
        (
            'size of the pre-drawn pool of standard normals the jitter is taken from at a '
            'random offset (a speed choice: drawing 2 x 20 x 5041 normals per update costs '
            'more than the rest of the update); 0 draws fresh normals every update.'
        ),
        ge=0,
    )
    update_after_convergence: bool = parameter(
        True, 'keep folding observations in after convergence (spec: yes).'
    )
    fusion: str = parameter(
        'joint',
        (
            "'joint' folds all samples of one control step (own and neighbours') into one "
            "update per target (likelihood product, one resampling); 'sequential' makes one "
            "update per observation point. Same posterior; 'joint' resamples less often and "
            'is several times faster with many neighbours.'
        ),
        choices=FUSION_MODES,
    )
    backend: str = parameter(
        'auto',
        (
            "how the update is computed: 'numpy' (the reference, every robot has it), "
            "'numba' (compiled loops, msc_pf.pf_kernel; needs the numba package, which the "
            'robot package does not require; bit-identical results, about twice as fast) or '
            "'auto' (numba when it can be imported, else numpy)."
        ),
        choices=PF_BACKENDS,
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.n_particles >= 4, 'n_particles must be at least 4')
        _require(self.r_conv_m > 0.0 and self.r_err_m > 0.0, 'r_conv_m and r_err_m must be > 0')
        _require(self.window >= 2, 'window must hold at least 2 estimates')
        _require(self.noise_variance_db2 > 0.0, 'noise_variance_db2 must be positive')
        _require(self.initial_prior in INITIAL_PRIORS, f'initial_prior not in {INITIAL_PRIORS}')
        _require(
            self.init_half_width_m is None or self.init_half_width_m > 0.0,
            'init_half_width_m must be positive',
        )
        _require(self.fusion in FUSION_MODES, f'fusion not in {FUSION_MODES}')
        _require(self.resampling in RESAMPLING_SCHEMES, f'resampling not in {RESAMPLING_SCHEMES}')
        _require(self.backend in PF_BACKENDS, f'backend {self.backend!r} not in {PF_BACKENDS}')
        _require(self.roughening_kappa >= 0.0, 'roughening_kappa must be non-negative')
        _require(self.roughening_floor_m >= 0.0, 'roughening_floor_m must be non-negative')
        _require(
            self.noise_pool_size == 0 or self.noise_pool_size >= 4 * self.n_particles,
            'noise_pool_size must be 0 or at least 4 x n_particles',
        )


@dataclass(frozen=True)
class SearchConfig:
    """History-based search, eq. (1) (spec sections 1.2-1.3)."""

    alpha_outside: float = parameter(20.0, 'alpha of eqs. (1) and (8) outside D_th.')
    alpha_inside: float = parameter(5.0, 'alpha of eq. (8) within D_th of the goal.')
    k_s: float = parameter(1.2, 'weight of the own-history repulsion v^s.')
    k_o: float = parameter(0.5, "weight of the neighbours'-history repulsion v^o.")
    random_period_s: float = parameter(
        10.0, 'how long one random direction v^r is kept; 0 redraws every step.', unit='s', ge=0.0
    )
    cell_size_m: float = parameter(20.0, 'edge of a coverage-history cell.', unit='m', gt=0.0)
    history_radius_m: float = parameter(
        600.0,
        (
            'only cells closer than this repel. About twice the detection range (292 m), so '
            'the search sees the strip its own passes already covered; with 150 m robots '
            're-crossed searched ground and the last target took up to 18000 s.'
        ),
        unit='m',
        gt=0.0,
    )
    wall_margin_m: float = parameter(
        150.0,
        (
            'field edges closer than this repel. About half the detection range: a robot '
            'that far from an edge still hears targets on it, and with 50 m the history '
            'terms pressed swarms against the edges, half their coverage wasted.'
        ),
        unit='m',
        ge=0.0,
    )
    wall_weight: float | None = parameter(
        None, 'weight of the field-edge repulsion; unset (.nan) uses k_s.'
    )
    mode: str = parameter(
        'history',
        (
            "how searching robots move: 'history' is eq. (1); 'sector' (beyond the paper) "
            'splits the field into angular sectors around the start, one per searching unit '
            '(robot, or swarm leader), and heads for the nearest cell of the own sector not '
            "yet within ``sweep_radius_m`` of a path the robot knows (own, or neighbours' "
            'reported positions), then for the nearest such cell anywhere, then eq. (1).'
        ),
        choices=SEARCH_MODES,
    )
    coverage_prior_weight: float = parameter(
        1.0,
        (
            "'sector' search, PF schemes: when a filter starts, its particles in cells the "
            'robot knows searched (see ``sweep_radius_m``) get this weight, because a target '
            'there would have been heard before; 1 = no such prior. It cuts the ring of '
            'distances of a first sample to its unsearched side.'
        ),
        ge=0.0,
        le=1.0,
    )
    sector_reach: int = parameter(
        -1,
        (
            "'sector' search, PF schemes: until its own sector is covered, a robot takes "
            'only targets whose estimate lies within this many sectors of its own (0: its '
            'own sector only) and leaves the others to the robots sweeping there; -1 = any '
            'target. Targets near the start are heard by every robot at once.'
        ),
        ge=-1,
    )
    sweep_radius_m: float = parameter(
        250.0,
        (
            "'sector' search: a cell counts as searched once a robot came this close. Inside "
            'the ~292 m detection range, so that a target there has been heard with near '
            'certainty (mean RSSI 2 dB above gamma_D at 250 m).'
        ),
        unit='m',
        gt=0.0,
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.cell_size_m > 0.0, 'cell_size_m must be positive')
        _require(self.history_radius_m > 0.0, 'history_radius_m must be positive')
        _require(self.random_period_s >= 0.0, 'random_period_s must be non-negative')
        _require(self.wall_margin_m >= 0.0, 'wall_margin_m must be non-negative')
        _require(self.mode in SEARCH_MODES, f'search mode not in {SEARCH_MODES}')
        _require(self.sweep_radius_m > 0.0, 'sweep_radius_m must be positive')
        _require(
            0.0 <= self.coverage_prior_weight <= 1.0, 'coverage_prior_weight must be in [0, 1]'
        )

    @property
    def effective_wall_weight(self) -> float:
        """Weight of the field-edge repulsion."""
        return self.k_s if self.wall_weight is None else self.wall_weight


@dataclass(frozen=True)
class AvoidanceConfig:
    """Collision-avoidance vector S_i (spec section 1.3)."""

    safety_radius_m: float = parameter(
        3.0, 'd_s; neighbours closer than this repel (linear form).', unit='m', gt=0.0
    )
    form: str = parameter(
        'linear',
        (
            "'linear' sums (x_i - x_j)/d * (1 - d/d_s); 'inverse_square' sums (x_i - "
            'x_j)/d^3 over every neighbour within ``inverse_square_range_m``.'
        ),
        choices=AVOIDANCE_FORMS,
    )
    inverse_square_range_m: float = parameter(
        20.0, 'neighbours considered by the inverse-square form.', unit='m'
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.safety_radius_m > 0.0, 'safety_radius_m must be positive')
        _require(self.form in AVOIDANCE_FORMS, f'avoidance form not in {AVOIDANCE_FORMS}')


@dataclass(frozen=True)
class SwarmConfig:
    """Swarm formation, leader election, join and split (spec section 1.4)."""

    max_size: int = parameter(3, 'L_th, the largest swarm (Table I: 3).', ge=1)
    comm_range_m: float = parameter(
        150.0, 'range of the peer radio (Table I: 150).', unit='m', gt=0.0
    )
    formation_timeout_s: float = parameter(
        5.0, 'a robot that heard no peer by then starts alone.', unit='s'
    )
    membership_grace_steps: int = parameter(
        2, 'steps a robot may claim a leader that does not list it.', ge=1
    )
    peer_timeout_s: float = parameter(
        2.5, 'a peer not heard for longer is out of range.', unit='s', gt=0.0
    )
    search_alone: bool = parameter(
        False,
        'beyond the paper: robots search alone and gather into swarms of at most max_size '
        'only on a target they heard (no swarms at the start, no merging of searching '
        "swarms; a swarm whose leader searches again dissolves). False: the paper's "
        'swarms search together.',
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.max_size >= 1, 'max_size (L_th) must be at least 1')
        _require(self.comm_range_m > 0.0, 'comm_range_m must be positive')
        _require(self.membership_grace_steps >= 1, 'membership_grace_steps must be >= 1')
        _require(self.peer_timeout_s > 0.0, 'peer_timeout_s must be positive')


@dataclass(frozen=True)
class MscConfig:
    """MSC mobility: evaluation value and PSO-style updates (Table I; spec section 1.6)."""

    inertia: float = parameter(0.5, 'w, inertial weight.')
    cognitive: float = parameter(
        1.0, "c1, weight of the pull toward the robot's own best recent position."
    )
    social: float = parameter(1.0, 'c2, weight of the pull toward the best neighbour.')
    avoidance_degree: float = parameter(2.0, 'weight of S_i inside MSC.')
    dispersion_degree: float = parameter(
        -100.0, 'D, penalty per closer robot heading to the same target.'
    )
    dispersion_threshold: int = parameter(
        3, 'N_th; the penalty applies when more than N_th robots are closer.', ge=0
    )
    pbest_window: int = parameter(10, 'H_p, number of recent samples p_best is chosen from.', ge=1)
    rssi_window: int = parameter(
        3, 'samples in the moving average of RSSI compared with thresholds.', ge=1
    )
    leader_rule: str = parameter(
        'gradient',
        (
            'how the leader finds "where larger RSSI is likely": \'gradient\' follows the '
            "least-squares RSSI slope over the swarm's samples of the last ``pbest_window`` "
            "steps; 'pbest' pulls toward the best of its own last ``pbest_window`` "
            "positions; 'pbest_turn' (beyond the paper) keeps its heading while its own "
            'smoothed RSSI improves and, once it has fallen ``turn_margin_db`` below the best '
            'of the current straight leg, turns 90 degrees to a random side at that best '
            'point (or back, when the leg only fell from its start).'
        ),
        choices=LEADER_RULES,
    )
    turn_margin_db: float = parameter(
        2.0,
        "pbest_turn: drop of the smoothed RSSI below the leg's best that ends a leg.",
        unit='dB',
        gt=0.0,
    )
    full_pso: bool = parameter(
        False, 'every robot uses both cognitive and social terms (optional variant).'
    )
    detection_memory_s: float = parameter(
        3.0, 'a target not heard for longer counts as not detected.', unit='s', gt=0.0
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.pbest_window >= 1, 'pbest_window must be at least 1')
        _require(self.rssi_window >= 1, 'rssi_window must be at least 1')
        _require(self.dispersion_threshold >= 0, 'dispersion_threshold must be >= 0')
        _require(self.detection_memory_s > 0.0, 'detection_memory_s must be positive')
        _require(self.leader_rule in LEADER_RULES, f'leader_rule not in {LEADER_RULES}')


@dataclass(frozen=True)
class PhaseConfig:
    """Phase thresholds, far-field formation, capture and re-targeting (spec 1.1, 1.7, 1.8)."""

    gamma1_dbm: float = parameter(
        -78.0,
        'below it (and unconverged) the proposed scheme uses the far-field formation.',
        unit='dBm',
    )
    gamma2_dbm: float = parameter(
        -58.0, 'above it every scheme approaches with MSC only (b-3).', unit='dBm'
    )
    gamma3_dbm: float = parameter(-48.0, 'above it a robot stops and works (c-1).', unit='dBm')
    hysteresis_db: float = parameter(
        1.0, 'margin before dropping back to a lower phase.', unit='dB', ge=0.0
    )
    follower_offset_m: float = parameter(
        20.0, 'd_f, lateral slot spacing of followers in (b-1).', unit='m'
    )
    slot_time_s: float = parameter(
        20.0, 'time followers spend converging to their slots before copying the leader.', unit='s'
    )
    retarget_penalty: float = parameter(
        -100.0, 'R (< 0), penalty per closer robot in the re-targeting rule.', lt=0.0
    )
    retarget_threshold: int = parameter(
        3, 'N_thr for detected candidates of the re-targeting rule.', ge=0
    )
    task_area_m: float = parameter(
        5.0, 'D_th; eq. (8) uses alpha_inside within this distance of the goal.', unit='m', gt=0.0
    )
    work_timeout_s: float = parameter(
        30.0, 'a robot that worked this long without a capture resumes (b-3).', unit='s', gt=0.0
    )
    work_block_s: float = parameter(
        10.0, 'after such a timeout the robot may not stop to work again for this long.', unit='s'
    )
    keep_converged_target: bool = parameter(
        False,
        (
            "PF schemes: a robot whose selected target's estimate has converged keeps "
            'approaching it with eq. (8) when the signal drops out (the paper: "each swarm '
            'can directly approach the searching target once its location estimation is '
            'converged"). Off by default: MSC+PF filters often converge at the detection '
            'edge on a wrong point, and following such an estimate after the signal is gone '
            'leads the swarm away from the target (docs/msc_pf.md); off, the robot '
            'searches again once nothing is heard.'
        ),
    )
    retarget_unconverged: bool = parameter(
        True,
        (
            'proposed scheme, (c-2) without a converged candidate: choose among the targets '
            'whose filters are tracked but not converged (the "recorded information on '
            'location estimation" of targets heard on the way) by the same R * N_r rule, '
            'taking the largest-weight particle as the estimate, and approach it with '
            '(b-1). False searches again (or takes a target heard now).'
        ),
    )
    recorded_max_age_s: float = parameter(
        600.0,
        (
            "only unconverged filters that got a sample (own or a neighbour's) within this "
            'time are candidates: older ones are mostly of targets other robots captured '
            'meanwhile, out of radio range (capture IDs spread by contact).'
        ),
        unit='s',
        ge=0.0,
    )
    unheard_give_up_m: float = parameter(
        100.0,
        (
            'a robot that approaches an unconverged recorded estimate and does not hear the '
            'target within this distance of it drops that filter; about a third of the 292 '
            'm detection range, so an estimate 100-200 m off still gets heard.'
        ),
        unit='m',
        gt=0.0,
    )
    converged_give_up_m: float = parameter(
        0.0,
        (
            'beyond the paper, PF schemes: a robot that drives at a converged estimate and '
            'does not hear the target within this distance of it drops the estimate (a '
            'target heard from 300 m is heard for sure at 200 m; silent means captured by '
            'robots out of range, or a wrong estimate); 0 = drive on to the task area (the '
            'paper).'
        ),
        unit='m',
        ge=0.0,
    )
    converged_max_age_s: float = parameter(
        0.0,
        (
            'beyond the paper, proposed scheme: after a capture only converged estimates '
            "that got a sample (own or a neighbour's) within this time are candidates, as "
            '``recorded_max_age_s`` for unconverged ones; 0 = every converged estimate (the '
            'paper).'
        ),
        unit='s',
        ge=0.0,
    )
    unheard_updates: bool = parameter(
        False,
        (
            'proposed scheme: while the robot pursues a target it has not heard for '
            "msc.detection_memory_s and no neighbour's sample of it arrives, its filter "
            "folds in that non-detection at the robot and at its swarm's members (each "
            'particle weighted by the chance a target there would have stayed below '
            'gamma_D), so an estimate on the wrong side of the ring of distances a far '
            "swarm observed moves to the side not yet ruled out. The paper's filter uses "
            "only the samples heard; this is the same observation model's other half. Off "
            'by default: it did not lower the mean CCT (docs/notes/msc_pf.md).'
        ),
    )
    non_detection_window_s: float = parameter(
        0.0,
        (
            'beyond the paper, PF schemes: every control step, each filter that got a sample '
            'within this time also folds in the non-detections of that step: the robot and '
            'every neighbour heard this step that did not hear the target (each particle '
            'weighted by the chance a target there would have stayed below gamma_D). With '
            '``particle_filter.censored_likelihood`` off this is the full observation model '
            '(samples heard and steps not heard); 0 = off (only samples heard).'
        ),
        unit='s',
        ge=0.0,
    )
    unheard_exhausted_share: float = parameter(
        0.01,
        (
            'with ``unheard_updates``, a filter of which less than this share of the belief '
            "survives one step's non-detections is dropped (the robot has covered the "
            'ground the filter allowed without hearing the target).'
        ),
        ge=0.0,
        lt=1.0,
    )
    goal_progress_window_s: float = parameter(
        60.0,
        (
            'a leader that has driven toward a converged estimate with eq. (8) for this '
            'long and come less than ``goal_progress_min_m`` closer to it restarts that '
            "target's filter; 0 turns the check off. A filter whose particles all sit on "
            'the wrong side of the ring of distances can follow the swarm: the swarm drives '
            'away from the target, the RSSI falls, the estimate moves out with it, and the '
            'swarm chases it out of earshot.'
        ),
        unit='s',
        ge=0.0,
    )
    goal_progress_min_m: float = parameter(
        15.0, 'the least approach to the goal over that window.', unit='m', gt=0.0
    )
    pursue_memory_s: float = parameter(
        0.0,
        (
            'beyond the paper, proposed scheme: a robot keeps its selected target while its '
            "filter got a sample (own or a neighbour's) within this time, approaching the "
            'largest-weight particle (b-1) or the converged estimate (eq. 8) through signal '
            'gaps; 0 = only while heard (msc.detection_memory_s). At the detection edge '
            'single samples come and go, and a robot that searched again at every gap '
            'circled the target at 300 m.'
        ),
        unit='s',
        ge=0.0,
    )
    far_aim: str = parameter(
        'best_particle',
        (
            "where the (b-1) leader heads: 'best_particle' is the paper's largest-weight "
            "particle; 'estimate' (beyond the paper) the weighted mean of eq. (5). The "
            'largest-weight particle of a wide filter jumps between the modes of the ring of '
            'distances, and a lone robot chasing it turns back and forth; the mean moves '
            'smoothly once the other side of the ring is ruled out (coverage prior, '
            'non-detections).'
        ),
        choices=FAR_AIMS,
    )
    near_estimate_spread_m: float = parameter(
        0.0,
        (
            'beyond the paper, PF schemes: in the MSC phases (RSSI above gamma1, and the '
            'final approach above gamma2) a leader whose filter of the target has a spread '
            'below this drives at the estimate with eq. (8) instead of MSC; 0 = MSC (the '
            'paper). Near the target the filter is good to a few metres, while MSC steps '
            'follow the noisy RSSI around the 5 m task area.'
        ),
        unit='m',
        ge=0.0,
    )
    max_pursuers: int = parameter(
        0,
        (
            'beyond the paper: a robot does not take a target it hears when at least this '
            'many neighbours heading to it hear it louder (it searches on, or takes another '
            'target); 0 = no limit (the paper: the MSC dispersion penalty only).'
        ),
        ge=0,
    )

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(
            self.gamma1_dbm < self.gamma2_dbm < self.gamma3_dbm,
            'thresholds must satisfy gamma1 < gamma2 < gamma3',
        )
        _require(self.hysteresis_db >= 0.0, 'hysteresis_db must be non-negative')
        _require(self.retarget_penalty < 0.0, 'retarget_penalty R must be negative')
        _require(self.task_area_m > 0.0, 'task_area_m must be positive')
        _require(self.far_aim in FAR_AIMS, f'far_aim not in {FAR_AIMS}')
        _require(self.work_timeout_s > 0.0, 'work_timeout_s must be positive')
        _require(self.unheard_give_up_m > 0.0, 'unheard_give_up_m must be positive')
        _require(self.recorded_max_age_s >= 0.0, 'recorded_max_age_s must be non-negative')
        _require(
            0.0 <= self.unheard_exhausted_share < 1.0,
            'unheard_exhausted_share must be in [0, 1)',
        )
        _require(self.goal_progress_window_s >= 0.0, 'goal_progress_window_s must be >= 0')
        _require(self.goal_progress_min_m > 0.0, 'goal_progress_min_m must be positive')


@dataclass(frozen=True)
class MscPfConfig:
    """Everything one robot's controller needs."""

    scheme: Scheme = parameter(Scheme.PROPOSED, 'which of the three schemes runs.')
    field_size_m: float = parameter(
        2000.0, 'edge of the square field; the field spans [0, size] in x and y.', unit='m', gt=0.0
    )
    max_speed_m_s: float = parameter(1.0, 'robot speed (Table I: 1).', unit='m/s', gt=0.0)
    period_s: float = parameter(1.0, 'control period Delta t.', unit='s', gt=0.0)
    radio: RadioConfig = section(RadioConfig)
    particle_filter: ParticleFilterConfig = section(ParticleFilterConfig)
    search: SearchConfig = section(SearchConfig)
    avoidance: AvoidanceConfig = section(AvoidanceConfig)
    swarm: SwarmConfig = section(SwarmConfig)
    msc: MscConfig = section(MscConfig)
    phases: PhaseConfig = section(PhaseConfig)

    def __post_init__(self) -> None:
        if not isinstance(self.scheme, Scheme):
            try:
                object.__setattr__(self, 'scheme', Scheme(self.scheme))
            except ValueError as err:
                names = ', '.join(s.value for s in Scheme)
                raise ConfigError(f'scheme {self.scheme!r} is not one of {names}') from err
        _require_finite(self)
        _require(self.field_size_m > 0.0, 'field_size_m must be positive')
        _require(self.max_speed_m_s > 0.0, 'max_speed_m_s must be positive')
        _require(self.period_s > 0.0, 'period_s must be positive')
