"""Algorithm 1 and 3 behaviour of the per-robot planner."""

import math
from dataclasses import replace

import numpy as np
import pytest
from bayes_swarm.acquisition import planned_path_points
from bayes_swarm.errors import ConfigError, GpFitError
from bayes_swarm.messages import DecisionKind, PeerUpdate
from bayes_swarm.planner import (
    MAX_SCALED_SIGNAL,
    PEER_INDEX_REORDER_WINDOW,
    BayesSwarmPlanner,
    _OuterProblem,
    first_waypoint,
)
from bayes_swarm.settings import Arena, BayesSwarmConfig, GlowwormConfig, GpConfig, LevyConfig

pytestmark = pytest.mark.runtime_independent(reason='the algorithm core')


def case1_field(points):
    """Appendix C, Eq. 19 (source at (1, 2), weaker bump at (2, 0.5))."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return np.exp(-((p - [1.0, 2.0]) ** 2).sum(1) / 3.0) + 0.5 * np.exp(
        -2.0 * ((p - [2.0, 0.5]) ** 2).sum(1)
    )


def leg(planner, start, end, n=11):
    pts = np.linspace(start, end, n)
    planner.add_observations(pts, case1_field(pts))


def test_first_decisions_fan_out_over_the_initial_direction_range():
    headings = []
    for r in range(5):
        wp = BayesSwarmPlanner(BayesSwarmConfig(robot_index=r), f'r{r}').decide([0, 0], 0.0)
        assert wp.kind is DecisionKind.FIRST
        assert np.hypot(*wp.waypoint_m) == pytest.approx(1.0)
        headings.append(math.degrees(math.atan2(wp.waypoint_m[1], wp.waypoint_m[0])))
    np.testing.assert_allclose(headings, [15, 30, 45, 60, 75])


def test_full_circle_fan_divides_by_the_swarm_size():
    wp = first_waypoint(
        np.zeros(2),
        fan_index=1,
        fan_size=10,
        direction_range_deg=360.0,
        direction_offset_deg=0.0,
        leg_m=20.0,
    )
    assert math.degrees(math.atan2(wp[1], wp[0])) == pytest.approx(36.0)


def test_decision_moves_toward_the_expected_source_within_the_leg_limit():
    cfg = BayesSwarmConfig()
    planner = BayesSwarmPlanner(cfg, 'r0', seed=1)
    planner.decide([0, 0], 0.0)
    for end in ([0.26, 0.97], [0.71, 0.71], [0.97, 0.26]):
        leg(planner, [0, 0], end)
    decision = planner.decide([0.71, 0.71], 10.0)
    assert decision.kind is DecisionKind.ACQUISITION
    assert np.hypot(*(decision.waypoint_m - [0.71, 0.71])) <= cfg.max_leg_m + 1e-9
    assert cfg.arena.contains(decision.waypoint_m)
    # The GP, fitted on three rising legs, expects the maximum up and to the right.
    assert decision.expected_source_m[0] > 0.8
    assert decision.expected_source_m[1] > 0.8
    assert decision.compute_time_s > 0.0


def test_receive_ignores_own_stale_and_duplicated_messages():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    pts = np.array([[0.1, 0.1], [0.2, 0.2]])
    update = PeerUpdate('r1', 3, np.zeros(2), np.ones(2), pts, np.array([0.2, 0.3]))
    assert planner.receive(update)
    assert not planner.receive(update)  # duplicate
    assert not planner.receive(replace(update, decision_index=2))  # stale
    assert not planner.receive(replace(update, sender='r0', decision_index=9))  # own
    assert planner.n_observations == 2
    assert planner.receive(replace(update, decision_index=4, waypoint_m=np.array([2.0, 2.0])))
    assert planner.peer_waypoints['r1'] == pytest.approx([2.0, 2.0])


def test_non_finite_samples_are_dropped_and_the_rest_kept():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    kept = planner.add_observations(
        np.array([[0.0, 0.0], [0.1, np.nan], [0.2, 0.2]]), np.array([0.1, 0.2, np.inf])
    )
    assert kept == 1
    assert planner.n_observations == 1


def test_broadcast_carries_only_the_samples_since_the_last_broadcast():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    planner.add_observations(np.zeros((1, 2)), np.array([0.2]))
    planner.decide([0, 0], 0.0)
    first = planner.broadcast(np.zeros(2))
    assert len(first.sample_values) == 1
    leg(planner, [0, 0], [0.97, 0.26])
    planner.decide([0.97, 0.26], 10.0)
    second = planner.broadcast(np.array([0.97, 0.26]))
    assert len(second.sample_values) == 11
    assert second.decision_index == 1
    assert second.waypoint_m == pytest.approx(planner._last_decision.waypoint_m)


def planner_with_data(penalty_enabled=True, peer_waypoint=None):
    cfg = BayesSwarmConfig(penalty_enabled=penalty_enabled)
    planner = BayesSwarmPlanner(cfg, 'r0', seed=4)
    planner.decide([0, 0], 0.0)
    for end in ([0.26, 0.97], [0.5, 0.87], [0.71, 0.71]):
        leg(planner, [0, 0], end)
    if peer_waypoint is not None:
        planner.receive(PeerUpdate('r1', 1, np.array([0.5, 0.87]), np.asarray(peer_waypoint)))
    return planner


def test_penalty_pushes_the_waypoint_away_from_a_peers_planned_waypoint():
    free = planner_with_data().decide([0.71, 0.71], 50.0).waypoint_m
    penalised = planner_with_data(peer_waypoint=free).decide([0.71, 0.71], 50.0).waypoint_m
    unpenalised = planner_with_data(penalty_enabled=False, peer_waypoint=free)
    other = unpenalised.decide([0.71, 0.71], 50.0).waypoint_m
    assert np.hypot(*(penalised - free)) > 0.1
    assert np.hypot(*(other - free)) < np.hypot(*(penalised - free))


def test_gp_failure_falls_back_to_a_waypoint_inside_the_arena(monkeypatch):
    planner = planner_with_data()

    def broken_fit(*args, **kwargs):
        raise GpFitError('not positive definite')

    monkeypatch.setattr(planner.gp, 'fit', broken_fit)
    decision = planner.decide([0.71, 0.71], 20.0)
    assert decision.kind is DecisionKind.FALLBACK
    assert 'GpFitError' in decision.detail
    assert planner.config.arena.contains(decision.waypoint_m)


def test_reaching_an_expected_source_that_is_not_the_source_marks_it_weaker_and_explores():
    cfg = BayesSwarmConfig(arena=Arena(0, 4, 0, 4))
    planner = BayesSwarmPlanner(cfg, 'r0', seed=0)
    planner.decide([2, 2], 0.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform(0, 4, size=(80, 2))
    planner.add_observations(pts, np.exp(-((pts - 2.0) ** 2).sum(1)))  # peak at (2, 2)
    decision = planner.decide([2.0, 2.0], 20.0)
    assert decision.kind in (DecisionKind.EXPLORE, DecisionKind.RANDOM_JUMP)
    assert planner.weaker_sources.shape == (1, 2)
    assert planner.weaker_sources[0] == pytest.approx([2.0, 2.0], abs=0.05)
    assert np.hypot(*(decision.waypoint_m - 2.0)) >= cfg.step_m


@pytest.mark.parametrize(('within_eps', 'alpha'), [(False, 0.1), (True, 0.8)])
def test_a_weaker_source_near_the_expected_one_holds_alpha_down_unless_only_eps_counts(
    within_eps, alpha
):
    cfg = BayesSwarmConfig(
        arena=Arena(0, 4, 0, 4), detection_radius_m=0.15, weaker_source_within_eps=within_eps
    )
    planner = BayesSwarmPlanner(cfg, 'r0', seed=0)
    planner.decide([1, 1], 0.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform(0, 4, size=(80, 2))
    planner.add_observations(pts, np.exp(-((pts - 2.0) ** 2).sum(1)))  # peak at (2, 2)
    # A peer searched 0.3 m from the peak: within 2 l_robot (squared), outside eps.
    mark = np.array([[2.3, 2.0]])
    planner.receive(PeerUpdate('r1', 1, np.zeros(2), np.ones(2), np.zeros((0, 2)), [], mark))
    decision = planner.decide([1.0, 1.0], 20.0)
    assert decision.expected_source_m == pytest.approx([2.0, 2.0], abs=0.05)
    assert decision.alpha == alpha


@pytest.mark.parametrize(
    ('factory', 'match'),
    [
        (lambda: BayesSwarmConfig(velocity_mps=-0.1), 'velocity_mps'),
        (lambda: BayesSwarmConfig(n_max=0), 'N_max'),
        (lambda: BayesSwarmConfig(outer_optimizer='simplex'), 'outer_optimizer'),
        (lambda: BayesSwarmConfig(robot_index=5, n_robots=5), 'robot_index'),
        (lambda: BayesSwarmConfig(detection_radius_m=float('nan')), 'detection_radius_m'),
        (lambda: GpConfig(length_scale_bounds_m=(1.0, 0.5)), 'length_scale_bounds_m'),
        (lambda: Arena(1.0, 0.0, 0.0, 1.0), 'x_max_m'),
        (lambda: GlowwormConfig(sensor_range_m=-20.0), 'sensor_range_m'),
        (lambda: LevyConfig(mu=3.5), 'mu'),
    ],
)
def test_invalid_parameters_are_rejected_with_the_field_named(factory, match):
    with pytest.raises(ConfigError, match=match):
        factory()


def test_newton_ascent_finds_the_gp_mean_maximum_found_by_a_dense_grid():
    from bayes_swarm.gp import GaussianProcess, Hyperparameters
    from bayes_swarm.planner import ascend_mean

    rng = np.random.default_rng(8)
    pts = rng.uniform(0, 2.4, size=(60, 2))
    gp = GaussianProcess(GpConfig())
    gp.fit(pts, case1_field(pts), hyperparameters=Hyperparameters(0.5, 0.8))
    arena = Arena(0, 2.4, 0, 2.4)
    found = ascend_mean(gp, np.array([[0.2, 0.2], [2.3, 0.3], [1.5, 1.5]]), arena)
    gx, gy = np.meshgrid(np.linspace(0, 2.4, 481), np.linspace(0, 2.4, 481))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    best = grid[np.argmax(gp.predict_mean(grid))]
    assert np.hypot(*(found - best)) < 0.01
    assert gp.predict_mean(found[None])[0] >= gp.predict_mean(best[None])[0] - 1e-9


def test_fixed_alpha_replaces_the_adaptive_schedule():
    planner = planner_with_data()
    assert planner.decide([0.71, 0.71], 50.0).alpha == 0.8  # Algorithm 2, no peers
    cfg = BayesSwarmConfig(fixed_alpha=1.0)
    fixed = BayesSwarmPlanner(cfg, 'r0', seed=4)
    fixed.decide([0, 0], 0.0)
    leg(fixed, [0, 0], [0.71, 0.71])
    assert fixed.decide([0.71, 0.71], 50.0).alpha == 1.0


def _decision_on_scaled_field(scale, dimensionless):
    cfg = BayesSwarmConfig(
        dimensionless_acquisition=dimensionless,
        fixed_alpha=0.9,
        gp=GpConfig(noise_std=1e-3 * scale),
        max_signal=1.2 * scale,
        lipschitz=2.0 * scale,
    )
    planner = BayesSwarmPlanner(cfg, 'r0', seed=1)
    planner.decide([0, 0], 0.0)
    for end in ([0.26, 0.97], [0.71, 0.71], [0.97, 0.26]):
        pts = np.linspace([0, 0], end, 11)
        planner.add_observations(pts, scale * case1_field(pts))
    # 0.36 m from the expected source (2.4, 1.49): Omega asks for a short leg, Sigma a long one.
    return planner.decide([2.1, 1.3], 10.0).waypoint_m


def test_dimensionless_acquisition_makes_the_decision_independent_of_the_signal_scale():
    same = _decision_on_scaled_field(1.0, True)
    np.testing.assert_allclose(_decision_on_scaled_field(100.0, True), same, atol=1e-3)
    # In the paper's units a 100 times stronger field lets the exploration term dominate.
    paper = _decision_on_scaled_field(1.0, False)
    assert np.hypot(*(_decision_on_scaled_field(100.0, False) - paper)) > 0.5


def _decision_with_signal_scale(field_scale, signal_scale):
    cfg = BayesSwarmConfig(signal_scale=signal_scale, fixed_alpha=0.9)
    planner = BayesSwarmPlanner(cfg, 'r0', seed=1)
    planner.decide([0, 0], 0.0)
    for end in ([0.26, 0.97], [0.71, 0.71], [0.97, 0.26]):
        pts = np.linspace([0, 0], end, 11)
        planner.add_observations(pts, field_scale * case1_field(pts))
    planner.receive(PeerUpdate('r1', 1, np.array([0.71, 0.71]), np.array([2.2, 1.4])))
    return planner.decide([2.1, 1.3], 10.0)


def test_signal_scale_makes_the_planner_see_the_signal_in_its_units():
    """A field 47 times stronger with signal_scale 47 is the same belief (M, L, noise in the
    scaled units), so the same decision; without the scale the penalty and Sigma change it."""
    reference = _decision_with_signal_scale(1.0, 1.0)
    scaled = _decision_with_signal_scale(47.0, 47.0)
    # Equal up to the solvers' tolerances (COBYLA's final step is 1e-4 m).
    np.testing.assert_allclose(scaled.waypoint_m, reference.waypoint_m, atol=1e-3)
    np.testing.assert_allclose(scaled.expected_source_m, reference.expected_source_m, atol=1e-4)
    unscaled = _decision_with_signal_scale(47.0, 1.0)
    assert np.hypot(*(unscaled.waypoint_m - reference.waypoint_m)) > 0.05


def test_signal_scale_must_be_positive():
    with pytest.raises(ConfigError, match='signal_scale'):
        BayesSwarmConfig(signal_scale=0.0)


def _with_data(cfg, peer_waypoint):
    planner = BayesSwarmPlanner(cfg, 'r0', seed=4)
    planner.decide([0, 0], 0.0)
    for end in ([0.26, 0.97], [0.5, 0.87], [0.71, 0.71]):
        leg(planner, [0, 0], end)
    planner.receive(PeerUpdate('r1', 1, np.array([0.5, 0.87]), np.asarray(peer_waypoint)))
    return planner


@pytest.mark.parametrize('library', ['nlopt', 'scipy'])
def test_a_penalty_ball_over_the_whole_arena_stalls_cobyla_and_the_estimate_frees_it(library):
    """With M far above the field (47 on a field of 1) and L = 2, the exclusion ball around
    the peer's waypoint is ~23 m wide: Gamma is 0 on the whole arena and the acquisition is
    flat. Powell's COBYLA (nlopt) then stays at its start and Algorithm 1 jumps at random;
    scipy's (PRIMA's) ends one rhobeg from the start. The belief-estimated M and L keep the
    ball local."""
    fixed = BayesSwarmConfig(max_signal=47.0, lipschitz=2.0, cobyla_library=library)
    decision = _with_data(fixed, [1.2, 1.2]).decide([0.71, 0.71], 50.0)
    if library == 'nlopt':
        assert decision.kind is DecisionKind.RANDOM_JUMP
    else:
        assert np.hypot(*(decision.waypoint_m - [0.71, 0.71])) == pytest.approx(1.0, abs=1e-6)
        assert decision.waypoint_m[1] == pytest.approx(0.71, abs=1e-6)  # the first step
    # In log space (GPyOpt's form) the same ball no longer flattens the objective: log Gamma
    # falls towards the peer's waypoint, so COBYLA leaves it and a real leg follows.
    in_logs = _with_data(replace(fixed, penalty_log_space=True), [1.2, 1.2])
    escaped = in_logs.decide([0.71, 0.71], 50.0)
    assert escaped.kind is DecisionKind.ACQUISITION
    assert np.hypot(*(escaped.waypoint_m - [0.71, 0.71])) > 0.5
    assert np.hypot(*(escaped.waypoint_m - [1.2, 1.2])) > np.hypot(0.49, 0.49)
    estimating = _with_data(replace(fixed, penalty_estimate=True), [1.2, 1.2])
    free = estimating.decide([0.71, 0.71], 50.0)
    assert free.kind is DecisionKind.ACQUISITION
    assert np.hypot(*(free.waypoint_m - [0.71, 0.71])) > 0.5  # a real leg, not a stall
    assert abs(free.waypoint_m[1] - 0.71) > 0.02  # not COBYLA's first step either
    gp = estimating.gp
    # M: the largest observation (Gonzalez et al.'s estimate).
    m, lipschitz = estimating._estimated_penalty_constants(np.array([0.2, 0.9, 0.4]))
    assert m == 0.9
    # L: the largest gradient norm of the GP mean over the arena (a fine grid's maximum,
    # to its spacing), above the data points' and below the paper's 2 here.
    g = np.linspace(0.0, 2.4, 241)
    grid = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    _, grad, _ = gp.mean_derivatives(grid)
    assert lipschitz == pytest.approx(float(np.max(np.hypot(grad[:, 0], grad[:, 1]))), rel=1e-3)
    _, grad, _ = gp.mean_derivatives(gp.training_inputs)
    assert lipschitz >= float(np.max(np.hypot(grad[:, 0], grad[:, 1]))) - 1e-12
    assert lipschitz < 2.0


def test_both_cobyla_libraries_reach_the_same_waypoint_on_the_leg_constraint():
    """Powell's COBYLA (nlopt) and PRIMA's (scipy) solve the same Eq. 1 to COBYLA's 1e-4 m."""
    waypoints = {}
    for library in ('nlopt', 'scipy'):
        planner = planner_with_data()
        planner._cfg = replace(planner.config, cobyla_library=library)
        decision = planner.decide([0.71, 0.71], 50.0)
        assert decision.kind is DecisionKind.ACQUISITION
        # The optimum lies on the leg constraint (Eq. 2), kept on the disc.
        assert np.hypot(*(decision.waypoint_m - [0.71, 0.71])) <= 1.0 + 1e-9
        assert np.hypot(*(decision.waypoint_m - [0.71, 0.71])) > 1.0 - 1e-4
        waypoints[library] = decision.waypoint_m
    assert np.hypot(*(waypoints['nlopt'] - waypoints['scipy'])) < 1e-4


def test_an_unknown_cobyla_library_is_rejected():
    with pytest.raises(ConfigError, match='cobyla_library'):
        BayesSwarmConfig(cobyla_library='fortran')


@pytest.mark.parametrize(
    'options',
    [
        {},
        {'authors_origin_paths': True},
        {'dimensionless_acquisition': True},
        {'penalty_log_space': True},
    ],
    ids=['paper', 'origin-paths', 'dimensionless', 'log-space'],
)
def test_the_single_point_acquisition_equals_the_batch_one(options):
    """COBYLA's objective (value) is the batch acquisition (values) at one point."""
    planner = planner_with_data(peer_waypoint=[1.0, 1.2])
    planner._cfg = replace(planner.config, **options)
    planner.decide([0.71, 0.71], 50.0)
    gp = planner.gp
    peers = np.array([[1.0, 1.2], [0.3, 1.9]])
    mean, std = gp.predict(peers)
    position = np.array([0.71, 0.71])
    problem = _OuterProblem(
        planner.config,
        position,
        np.array([1.1, 1.8]),
        0.6,
        gp.extended_std(planned_path_points(position[None], peers[:1], 0.1, 400)),
        peers,
        mean,
        std,
        1.2,
        2.0,
    )
    rng = np.random.default_rng(3)
    radius = np.sqrt(rng.uniform(0.0, 1.0, 40))
    angle = rng.uniform(0.0, 2.0 * math.pi, 40)
    points = position + radius[:, None] * np.c_[np.cos(angle), np.sin(angle)]
    batch = problem.values(points)
    single = np.array([problem.value(p) for p in points])
    np.testing.assert_allclose(single, batch, rtol=1e-12, atol=1e-15)
    assert np.ptp(batch) > 0.01  # the points see different values


def test_peer_updates_with_a_position_or_waypoint_far_outside_the_arena_are_dropped():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    pts, vals = np.array([[0.1, 0.1]]), np.array([0.3])
    good = PeerUpdate('r1', 1, np.array([0.5, 0.5]), np.array([1.0, 1.0]), pts, vals)
    far = 3.0 * planner.config.arena.diagonal_m
    for bad in (
        replace(good, waypoint_m=np.array([1e300, 1e300])),
        replace(good, position_m=np.array([1e300, -1e300])),
        replace(good, position_m=np.array([-far, 0.5])),
    ):
        assert planner.peer_update_defect(bad)
        assert not planner.receive(bad)
    assert planner.rejected_peer_updates == 3
    assert planner.n_observations == 0
    assert planner.peer_waypoints == {}
    assert planner.peer_update_defect(good) == ''
    assert planner.receive(good), 'the rejections did not latch the sender index'
    # A robot slightly outside the arena (within the margin) is still heard.
    assert planner.receive(replace(good, decision_index=2, position_m=np.array([-0.2, 2.5])))


def test_peer_samples_with_absurd_values_or_locations_are_dropped_and_the_rest_kept():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    pts = np.array([[0.1, 0.1], [0.2, 0.2], [1e300, 1e300], [0.4, 0.4], [0.5, 0.5]])
    vals = np.array([0.3, -1e300, 0.3, 1e7, -2.5])
    weaker = np.array([[1e300, 1e300], [1.0, 1.0]])
    assert planner.receive(PeerUpdate('r1', 1, np.zeros(2), np.ones(2), pts, vals, weaker))
    assert planner.n_observations == 2
    kept_pts, kept_vals = planner._data.arrays()
    assert kept_vals.tolist() == [0.3, -2.5]
    assert kept_pts.tolist() == [[0.1, 0.1], [0.5, 0.5]]
    assert planner.weaker_sources.tolist() == [[1.0, 1.0]]


def test_own_samples_beyond_the_plausible_magnitude_are_dropped_and_legitimate_ones_kept():
    planner = BayesSwarmPlanner(BayesSwarmConfig(signal_scale=47.0), 'r0')
    bound = MAX_SCALED_SIGNAL * 47.0
    values = np.array([-bound, bound, 1.01 * bound, -1e300, 47.0])
    assert planner.add_observations(np.zeros((5, 2)), values) == 3
    assert planner._data.arrays()[1].tolist() == [-bound, bound, 47.0]


def test_a_peer_update_with_an_absurd_sample_value_leaves_later_decisions_unchanged():
    clean = planner_with_data()
    poisoned = planner_with_data()
    update = PeerUpdate('r1', 1, np.array([0.5, 0.87]), np.array([1.0, 1.0]))
    clean.receive(update)
    poisoned.receive(replace(update, sample_points_m=[[1.0, 1.0]], sample_values=[-1e300]))
    for t in (50.0, 60.0):
        expected = clean.decide([0.71, 0.71], t)
        got = poisoned.decide([0.71, 0.71], t)
        assert got.kind is expected.kind is DecisionKind.ACQUISITION
        assert got.waypoint_m.tolist() == expected.waypoint_m.tolist()


def test_a_far_ahead_decision_index_does_not_silence_its_sender():
    planner = BayesSwarmPlanner(BayesSwarmConfig(), 'r0')
    update = PeerUpdate('r1', 2**32 - 1, np.zeros(2), np.ones(2))
    assert planner.receive(update)
    # The sender's real count (or a restart) is far behind: accepted, and counted from there.
    assert planner.receive(replace(update, decision_index=5, waypoint_m=np.array([2.0, 2.0])))
    assert planner.peer_waypoints['r1'].tolist() == [2.0, 2.0]
    assert planner.receive(replace(update, decision_index=6))
    # Deliveries up to PEER_INDEX_REORDER_WINDOW behind the last accepted are still stale.
    assert not planner.receive(replace(update, decision_index=6))
    late = replace(update, decision_index=20 + PEER_INDEX_REORDER_WINDOW)
    assert planner.receive(late)
    assert not planner.receive(replace(late, decision_index=20))
