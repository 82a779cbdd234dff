"""Update rules of the comparison methods on scripted inputs."""

import math

import numpy as np
import pytest
from bayes_swarm.baselines.exhaustive import partition_arena, strip_sweep, sweep_paths
from bayes_swarm.baselines.glowworm import GlowwormState, glowworm_step, select_leaders
from bayes_swarm.baselines.levy import LevyWalk, pareto_step, wrapped_cauchy
from bayes_swarm.settings import Arena, GlowwormConfig, LevyConfig

ARENA = Arena(0.0, 10.0, 0.0, 10.0)


def test_luciferin_decays_and_grows_with_the_measured_signal():
    cfg = GlowwormConfig()
    state = GlowwormState(np.array([[1.0, 1.0], [9.0, 9.0]]), np.array([5.0, 5.0]), np.ones(2))
    new = glowworm_step(state, np.array([1.0, 0.0]), cfg, ARENA, 0.03, np.random.default_rng(0))
    np.testing.assert_allclose(new.luciferin, [0.6 * 5 + 0.6 * 1.0, 0.6 * 5])


def test_only_brighter_agents_within_the_decision_range_are_neighbours():
    positions = np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 0.0], [0.5, 0.0]])
    luciferin = np.array([1.0, 2.0, 9.0, 0.5])
    leaders, counts = select_leaders(
        positions, luciferin, np.full(4, 2.0), np.random.default_rng(0)
    )
    assert leaders[0] == 1  # agent 2 is brighter but out of range
    assert counts.tolist() == [1, 0, 0, 2]
    assert leaders[1] == -1  # no brighter neighbour: stays
    assert leaders[3] in (0, 1)


def test_leader_is_drawn_in_proportion_to_the_luciferin_difference():
    positions = np.zeros((3, 2))
    positions[1:, 0] = [1.0, -1.0]
    luciferin = np.array([1.0, 2.0, 4.0])  # gains 1 and 3 -> p = 0.25, 0.75
    rng = np.random.default_rng(5)
    picks = [select_leaders(positions, luciferin, np.full(3, 5.0), rng)[0][0] for _ in range(2000)]
    assert np.mean(np.array(picks) == 2) == pytest.approx(0.75, abs=0.03)
    det, _ = select_leaders(positions, luciferin, np.full(3, 5.0), rng, deterministic=True)
    assert det[0] == 2


def test_agents_step_toward_their_leader_and_update_their_decision_range():
    cfg = GlowwormConfig()
    state = GlowwormState(np.array([[1.0, 1.0], [2.0, 1.0]]), np.array([1.0, 5.0]), np.full(2, 3.0))
    new = glowworm_step(state, np.zeros(2), cfg, ARENA, 0.03, np.random.default_rng(0))
    np.testing.assert_allclose(new.positions_m, [[1.03, 1.0], [2.0, 1.0]])
    # r_d + beta (n_t - |N|): agent 0 has one neighbour, agent 1 none; capped at r_s = 20.
    np.testing.assert_allclose(new.decision_range_m, [3.0 + 0.08 * 4, 3.0 + 0.08 * 5])


def test_a_move_leaving_the_arena_is_rejected():
    state = GlowwormState(
        np.array([[0.0, 5.0], [-1.0, 5.0]]), np.array([1.0, 5.0]), np.full(2, 3.0)
    )
    new = glowworm_step(state, np.zeros(2), GlowwormConfig(), ARENA, 0.03, np.random.default_rng(0))
    np.testing.assert_allclose(new.positions_m[0], [0.0, 5.0])


def test_pareto_steps_follow_the_inverse_transform():
    assert pareto_step(0.5, 2.0, 0.5) == pytest.approx(1.0)
    assert pareto_step(1.0, 2.0, 0.5) == pytest.approx(0.5)
    assert pareto_step(0.25, 3.0, 0.5) == pytest.approx(1.0)


def test_levy_steps_lie_between_the_minimum_and_the_truncation():
    walk = LevyWalk(LevyConfig(max_step_m=4.0), ARENA, seed=1)
    steps = np.array([walk.draw_step_m() for _ in range(2000)])
    assert steps.min() >= 0.5
    assert steps.max() <= 4.0
    # P(l > 1) = 0.5 / 1 for mu = 2, renormalised by the truncation P(l <= 4) = 0.875.
    assert np.mean(steps > 1.0) == pytest.approx((0.5 - 0.125) / 0.875, abs=0.04)


def test_levy_waypoints_stay_in_the_arena_and_leave_walls_inward():
    walk = LevyWalk(LevyConfig(), ARENA, seed=2)
    for _ in range(200):
        wp = walk.next_waypoint(np.array([0.0, 5.0]))
        assert ARENA.contains(wp)
        assert wp[0] > 0.0


def test_wrapped_cauchy_concentrates_around_the_mean_as_rho_grows():
    assert wrapped_cauchy(0.5, 1.0, 0.2) == pytest.approx(1.0)
    spread_low = abs(wrapped_cauchy(0.9, 0.0, 0.2))
    spread_high = abs(wrapped_cauchy(0.9, 0.0, 0.9))
    assert spread_high < spread_low


def test_sweep_lanes_bring_every_point_within_half_a_lane_spacing():
    arena = Arena(0.0, 2.4, 0.0, 2.4)
    paths = sweep_paths(arena, np.zeros((5, 2)), 0.1)
    lanes = np.unique(np.concatenate([p[:, 0] for p in paths]))
    grid_x = np.linspace(0.0, 2.4, 241)
    gaps = np.min(np.abs(grid_x[:, None] - lanes[None, :]), axis=1)
    assert gaps.max() <= 0.05 + 1e-9
    for path in paths:
        assert np.all(arena.contains(path))


def test_sweep_starts_at_the_strip_corner_nearest_to_the_robot():
    path = strip_sweep(Arena(2.0, 3.0, 0.0, 5.0), 0.5, np.array([3.0, 5.0]))
    assert path[0] == pytest.approx([2.75, 5.0])
    assert path[1] == pytest.approx([2.75, 0.0])


def test_quadrant_partition_reproduces_the_papers_ten_robot_allocation():
    parts = partition_arena(Arena(-24, 24, -24, 24), 10, 'quadrants')
    quarter_of = [(p.x_min_m >= 0, p.y_min_m >= 0) for p in parts]
    counts = {q: quarter_of.count(q) for q in set(quarter_of)}
    assert counts == {(True, True): 3, (False, True): 2, (False, False): 3, (True, False): 2}
    assert sum((p.x_max_m - p.x_min_m) * (p.y_max_m - p.y_min_m) for p in parts) == (
        pytest.approx(48 * 48)
    )
    assert math.isclose(len(partition_arena(ARENA, 4, 'strips')), 4)
