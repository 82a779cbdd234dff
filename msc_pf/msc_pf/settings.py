"""Configuration of the MSC + particle filter swarm control (defaults: the paper's Table I).

Every value the paper gives is a default here; every gap the specification had to fill
([OUR SPEC] in the algorithm specification, section 1) is a field too, so a user can try
another reading without editing code. Dataclasses are frozen: the node and the batch
simulator build one :class:`MscPfConfig` at start and hand it to the core.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

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
LEADER_RULES = ('gradient', 'pbest')
INITIAL_PRIORS = ('detection_square', 'field')
FUSION_MODES = ('joint', 'sequential')
RESAMPLING_SCHEMES = ('systematic', 'multinomial')
PF_BACKENDS = ('auto', 'numpy', 'numba')


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

    Attributes:
        tx_power_dbm: target transmit power [dBm] (Table I: 13).
        reference_loss_db: path loss at 1 m [dB] (Table I's P0: 40.046).
        path_loss_exponent: K of eq. (4) (Table I: 3).
        noise_std_db: receiver noise standard deviation [dB] (Table I: variance 1).
        detection_threshold_dbm: gamma_D, weaker signals are not heard [dBm] (Table I: -101).
    """

    tx_power_dbm: float = 13.0
    reference_loss_db: float = 40.046
    path_loss_exponent: float = 3.0
    noise_std_db: float = 1.0
    detection_threshold_dbm: float = -101.0

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
    """SIR particle filter per target (eqs. 2-7; spec section 1.5).

    Attributes:
        n_particles: N_p (Table I: 5041 = 71 x 71).
        r_conv_m: radius of the convergence circle R_conv, eq. (6).
        r_err_m: radius of the permissible error circle R_err, eq. (7).
        window: number n of recent estimates tested by eq. (7), one per control step.
        noise_variance_db2: sigma^2 of eq. (3) [dB^2].
        gaussian_likelihood: True (default) uses the Gaussian exp(-e^2 / (2 sigma^2)) for the
            noise variance sigma^2; False the paper's eq. (3) as printed, exp(-e^2 / sigma^2),
            which treats the 1 dB noise as 0.71 dB: with a dozen neighbours' samples fused per
            step that filter converged tens to hundreds of metres off the target.
        censored_likelihood: divide each sample's likelihood by the chance
            Phi((R_j - gamma_D) / s) that a target at the particle would have been heard at
            all (s: the noise standard deviation the likelihood implies). The receiver reports
            only samples above gamma_D, so near the detection edge the reported ones are
            biased upward; without this a swarm lingering there converges on a wrong point.
        initial_prior: 'detection_square' puts the lattice on the square around the detection
            disc centred on the observer; 'field' spreads it over the whole field.
        init_half_width_m: half width of the detection square [m]; None uses the radio model's
            detection range (about 292 m).
        resampling: 'systematic' (one uniform offset) or 'multinomial'.
        roughening_kappa: kappa of the roughening jitter kappa * E * N^(-1/2). The common
            0.2 left the static-target filter to collapse by resampling alone onto one arc of
            the ring of distances a far swarm observes (spread under R_conv, estimate 100-400 m
            off); 0.5 keeps that ring populated until the observations decide, while the
            jitter it adds to the spread (about 6 m) stays well under R_conv.
        roughening_floor_m: lower bound of the jitter standard deviation [m].
        noise_pool_size: size of the pre-drawn pool of standard normals the jitter is taken
            from at a random offset (a speed choice: drawing 2 x 20 x 5041 normals per update
            costs more than the rest of the update); 0 draws fresh normals every update.
        update_after_convergence: keep folding observations in after convergence (spec: yes).
        fusion: 'joint' folds all samples of one control step (own and neighbours') into one
            update per target (likelihood product, one resampling); 'sequential' makes one
            update per observation point. Same posterior; 'joint' resamples less often and
            is several times faster with many neighbours.
        backend: how the update is computed: 'numpy' (the reference, every robot has it),
            'numba' (compiled loops, msc_pf.pf_kernel; needs the numba package, which the
            robot package does not require; bit-identical results, about twice as fast)
            or 'auto' (numba when it can be imported, else numpy).
    """

    n_particles: int = 5041
    r_conv_m: float = 20.0
    r_err_m: float = 10.0
    window: int = 10
    noise_variance_db2: float = 1.0
    gaussian_likelihood: bool = True
    censored_likelihood: bool = True
    initial_prior: str = 'detection_square'
    init_half_width_m: float | None = None
    resampling: str = 'systematic'
    roughening_kappa: float = 0.5
    roughening_floor_m: float = 0.5
    noise_pool_size: int = 1 << 20
    update_after_convergence: bool = True
    fusion: str = 'joint'
    backend: str = 'auto'

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
    """History-based search, eq. (1) (spec sections 1.2-1.3).

    Attributes:
        alpha_outside: alpha of eqs. (1) and (8) outside D_th.
        alpha_inside: alpha of eq. (8) within D_th of the goal.
        k_s: weight of the own-history repulsion v^s.
        k_o: weight of the neighbours'-history repulsion v^o.
        random_period_s: how long one random direction v^r is kept [s]; 0 redraws every step.
        cell_size_m: edge of a coverage-history cell [m].
        history_radius_m: only cells closer than this repel [m]. About twice the detection
            range (292 m), so the search sees the strip its own passes already covered; with
            150 m robots re-crossed searched ground and the last target took up to 18000 s.
        wall_margin_m: field edges closer than this repel [m]. About half the detection range:
            a robot that far from an edge still hears targets on it, and with 50 m the
            history terms pressed swarms against the edges, half their coverage wasted.
        wall_weight: weight of the field-edge repulsion; None uses k_s.
    """

    alpha_outside: float = 20.0
    alpha_inside: float = 5.0
    k_s: float = 1.2
    k_o: float = 0.5
    random_period_s: float = 10.0
    cell_size_m: float = 20.0
    history_radius_m: float = 600.0
    wall_margin_m: float = 150.0
    wall_weight: float | None = None

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.cell_size_m > 0.0, 'cell_size_m must be positive')
        _require(self.history_radius_m > 0.0, 'history_radius_m must be positive')
        _require(self.random_period_s >= 0.0, 'random_period_s must be non-negative')
        _require(self.wall_margin_m >= 0.0, 'wall_margin_m must be non-negative')

    @property
    def effective_wall_weight(self) -> float:
        """Weight of the field-edge repulsion."""
        return self.k_s if self.wall_weight is None else self.wall_weight


@dataclass(frozen=True)
class AvoidanceConfig:
    """Collision-avoidance vector S_i (spec section 1.3).

    Attributes:
        safety_radius_m: d_s; neighbours closer than this repel (linear form).
        form: 'linear' sums (x_i - x_j)/d * (1 - d/d_s); 'inverse_square' sums
            (x_i - x_j)/d^3 over every neighbour within ``inverse_square_range_m``.
        inverse_square_range_m: neighbours considered by the inverse-square form [m].
    """

    safety_radius_m: float = 3.0
    form: str = 'linear'
    inverse_square_range_m: float = 20.0

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.safety_radius_m > 0.0, 'safety_radius_m must be positive')
        _require(self.form in AVOIDANCE_FORMS, f'avoidance form not in {AVOIDANCE_FORMS}')


@dataclass(frozen=True)
class SwarmConfig:
    """Swarm formation, leader election, join and split (spec section 1.4).

    Attributes:
        max_size: L_th, the largest swarm (Table I: 3).
        comm_range_m: range of the peer radio [m] (Table I: 150).
        formation_timeout_s: a robot that heard no peer by then starts alone [s].
        membership_grace_steps: steps a robot may claim a leader that does not list it.
        peer_timeout_s: a peer not heard for longer is out of range [s].
    """

    max_size: int = 3
    comm_range_m: float = 150.0
    formation_timeout_s: float = 5.0
    membership_grace_steps: int = 2
    peer_timeout_s: float = 2.5

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.max_size >= 1, 'max_size (L_th) must be at least 1')
        _require(self.comm_range_m > 0.0, 'comm_range_m must be positive')
        _require(self.membership_grace_steps >= 1, 'membership_grace_steps must be >= 1')
        _require(self.peer_timeout_s > 0.0, 'peer_timeout_s must be positive')


@dataclass(frozen=True)
class MscConfig:
    """MSC mobility: evaluation value and PSO-style updates (Table I; spec section 1.6).

    Attributes:
        inertia: w, inertial weight.
        cognitive: c1, weight of the pull toward the robot's own best recent position.
        social: c2, weight of the pull toward the best neighbour.
        avoidance_degree: weight of S_i inside MSC.
        dispersion_degree: D, penalty per closer robot heading to the same target.
        dispersion_threshold: N_th; the penalty applies when more than N_th robots are closer.
        pbest_window: H_p, number of recent samples p_best is chosen from.
        rssi_window: samples in the moving average of RSSI compared with thresholds.
        leader_rule: how the leader finds "where larger RSSI is likely": 'gradient' follows
            the least-squares RSSI slope over the swarm's samples of the last ``pbest_window``
            steps; 'pbest' pulls toward the best of its own last ``pbest_window`` positions.
        full_pso: every robot uses both cognitive and social terms (optional variant).
        detection_memory_s: a target not heard for longer counts as not detected [s].
    """

    inertia: float = 0.5
    cognitive: float = 1.0
    social: float = 1.0
    avoidance_degree: float = 2.0
    dispersion_degree: float = -100.0
    dispersion_threshold: int = 3
    pbest_window: int = 10
    rssi_window: int = 3
    leader_rule: str = 'gradient'
    full_pso: bool = False
    detection_memory_s: float = 3.0

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(self.pbest_window >= 1, 'pbest_window must be at least 1')
        _require(self.rssi_window >= 1, 'rssi_window must be at least 1')
        _require(self.dispersion_threshold >= 0, 'dispersion_threshold must be >= 0')
        _require(self.detection_memory_s > 0.0, 'detection_memory_s must be positive')
        _require(self.leader_rule in LEADER_RULES, f'leader_rule not in {LEADER_RULES}')


@dataclass(frozen=True)
class PhaseConfig:
    """Phase thresholds, far-field formation, capture and re-targeting (spec 1.1, 1.7, 1.8).

    Attributes:
        gamma1_dbm: below it (and unconverged) the proposed scheme uses the far-field formation.
        gamma2_dbm: above it every scheme approaches with MSC only (b-3).
        gamma3_dbm: above it a robot stops and works (c-1).
        hysteresis_db: margin before dropping back to a lower phase.
        follower_offset_m: d_f, lateral slot spacing of followers in (b-1).
        slot_time_s: time followers spend converging to their slots before copying the leader.
        retarget_penalty: R (< 0), penalty per closer robot in the re-targeting rule.
        retarget_threshold: N_thr for detected candidates of the re-targeting rule.
        task_area_m: D_th; eq. (8) uses alpha_inside within this distance of the goal.
        work_timeout_s: a robot that worked this long without a capture resumes (b-3).
        work_block_s: after such a timeout the robot may not stop to work again for this long.
        keep_converged_target: PF schemes: a robot whose selected target's estimate has
            converged keeps approaching it with eq. (8) when the signal drops out (the paper:
            "each swarm can directly approach the searching target once its location
            estimation is converged"). Off by default: MSC+PF filters often converge at the
            detection edge on a wrong point, and following such an estimate after the signal
            is gone cost MSC+PF seed 0 (10 targets) 13419 s of CCT instead of 4888 s; off, the
            robot searches again once nothing is heard.
        retarget_unconverged: proposed scheme, (c-2) without a converged candidate: choose
            among the targets whose filters are tracked but not converged (the "recorded
            information on location estimation" of targets heard on the way) by the same
            R * N_r rule, taking the largest-weight particle as the estimate, and approach it
            with (b-1). False searches again (or takes a target heard now).
        recorded_max_age_s: only unconverged filters that got a sample (own or a neighbour's)
            within this time are candidates [s]: older ones are mostly of targets other
            robots captured meanwhile, out of radio range (capture IDs spread by contact).
        unheard_give_up_m: a robot that approaches an unconverged recorded estimate and does
            not hear the target within this distance of it drops that filter [m]; about a third
            of the 292 m detection range, so an estimate 100-200 m off still gets heard.
        unheard_updates: proposed scheme: while the robot pursues a target it has not heard
            for msc.detection_memory_s and no neighbour's sample of it arrives, its filter
            folds in that non-detection at the robot and at its swarm's members (each
            particle weighted by the chance a target there would have stayed below gamma_D),
            so an estimate on the wrong side of the ring of distances a far swarm observed
            moves to the side not yet ruled out. The paper's filter uses only the samples
            heard; this is the same observation model's other half. Off by default: on 8
            screened runs it fixed such losses but did not lower the mean CCT.
        unheard_exhausted_share: with ``unheard_updates``, a filter of which less than this
            share of the belief survives one step's non-detections is dropped (the robot has
            covered the ground the filter allowed without hearing the target).
        goal_progress_window_s: a leader that has driven toward a converged estimate with
            eq. (8) for this long and come less than ``goal_progress_min_m`` closer to it
            restarts that target's filter [s]; 0 turns the check off. A filter whose
            particles all sit on the wrong side of the ring of distances can follow the
            swarm: the swarm drives away from the target, the RSSI falls, the estimate moves
            out with it, and the swarm chases it out of earshot.
        goal_progress_min_m: the least approach to the goal over that window [m].
    """

    gamma1_dbm: float = -78.0
    gamma2_dbm: float = -58.0
    gamma3_dbm: float = -48.0
    hysteresis_db: float = 1.0
    follower_offset_m: float = 20.0
    slot_time_s: float = 20.0
    retarget_penalty: float = -100.0
    retarget_threshold: int = 3
    task_area_m: float = 5.0
    work_timeout_s: float = 30.0
    work_block_s: float = 10.0
    keep_converged_target: bool = False
    retarget_unconverged: bool = True
    recorded_max_age_s: float = 600.0
    unheard_give_up_m: float = 100.0
    unheard_updates: bool = False
    unheard_exhausted_share: float = 0.01
    goal_progress_window_s: float = 60.0
    goal_progress_min_m: float = 15.0

    def __post_init__(self) -> None:
        _require_finite(self)
        _require(
            self.gamma1_dbm < self.gamma2_dbm < self.gamma3_dbm,
            'thresholds must satisfy gamma1 < gamma2 < gamma3',
        )
        _require(self.hysteresis_db >= 0.0, 'hysteresis_db must be non-negative')
        _require(self.retarget_penalty < 0.0, 'retarget_penalty R must be negative')
        _require(self.task_area_m > 0.0, 'task_area_m must be positive')
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
    """Everything one robot's controller needs.

    Attributes:
        scheme: which of the three schemes runs.
        field_size_m: edge of the square field [m]; the field spans [0, size] in x and y.
        max_speed_m_s: robot speed [m/s] (Table I: 1).
        period_s: control period Delta t [s].
    """

    scheme: Scheme = Scheme.PROPOSED
    field_size_m: float = 2000.0
    max_speed_m_s: float = 1.0
    period_s: float = 1.0
    radio: RadioConfig = field(default_factory=RadioConfig)
    particle_filter: ParticleFilterConfig = field(default_factory=ParticleFilterConfig)
    search: SearchConfig = field(default_factory=SearchConfig)
    avoidance: AvoidanceConfig = field(default_factory=AvoidanceConfig)
    swarm: SwarmConfig = field(default_factory=SwarmConfig)
    msc: MscConfig = field(default_factory=MscConfig)
    phases: PhaseConfig = field(default_factory=PhaseConfig)

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
