"""Update rules of the comparison methods on scripted inputs."""

import math

import numpy as np
import pytest
from bayes_swarm.baselines.exhaustive import partition_arena, strip_sweep, sweep_paths
from bayes_swarm.baselines.glowworm import GlowwormAgent, select_leader
from bayes_swarm.baselines.levy import LevyWalk, pareto_step, wrapped_cauchy
from bayes_swarm.settings import Arena, GlowwormConfig, LevyConfig

ARENA = Arena(0.0, 10.0, 0.0, 10.0)


def _agent(**options) -> GlowwormAgent:
    return GlowwormAgent(GlowwormConfig(**options), ARENA, velocity_mps=3.0, seed=0)


def test_luciferin_decays_and_grows_with_the_measured_signal():
    agent = _agent()
    assert agent.update_luciferin(1.0) == pytest.approx(0.6 * 5.0 + 0.6 * 1.0)
    assert agent.update_luciferin(0.0) == pytest.approx(0.6 * 3.6)


def test_only_brighter_peers_within_the_decision_range_are_neighbours():
    # Peers as (x, y, luciferin): brighter and near, brighter but far, dimmer and near.
    peers = [(1.0, 0.0, 2.0), (5.0, 0.0, 9.0), (0.5, 0.0, 0.5)]
    rng = np.random.default_rng(0)
    assert select_leader((0.0, 0.0), 1.0, 2.0, peers, rng) == (0, 1)
    assert select_leader((0.0, 0.0), 1.0, 6.0, peers, rng)[1] == 2
    assert select_leader((0.0, 0.0), 10.0, 6.0, peers, rng) == (-1, 0)  # none brighter: stay
    assert select_leader((0.0, 0.0), 1.0, 2.0, [], rng) == (-1, 0)


def test_leader_is_drawn_in_proportion_to_the_luciferin_difference():
    peers = [(1.0, 0.0, 2.0), (-1.0, 0.0, 4.0)]  # gains 1 and 3 -> p = 0.25, 0.75
    rng = np.random.default_rng(5)
    picks = [select_leader((0.0, 0.0), 1.0, 5.0, peers, rng)[0] for _ in range(4000)]
    assert np.mean(np.array(picks) == 1) == pytest.approx(0.75, abs=0.03)
    assert select_leader((0.0, 0.0), 1.0, 5.0, peers, rng, deterministic=True) == (1, 2)


def test_the_agent_steps_toward_its_leader_and_updates_its_decision_range():
    agent = _agent(sensor_range_m=3.0)  # step min(0.03, 3.0 / 100) = 0.03 m
    agent.luciferin = 1.0
    target = agent.next_waypoint(np.array([1.0, 1.0]), [(2.0, 1.0, 5.0)])
    np.testing.assert_allclose(target, [1.03, 1.0])
    # r_d + beta (n_t - |N|) with one neighbour, capped at r_s = 3.
    assert agent.decision_range_m == pytest.approx(3.0)
    agent.decision_range_m = 1.5
    agent.next_waypoint(np.array([1.0, 1.0]), [(2.0, 1.0, 5.0)])
    assert agent.decision_range_m == pytest.approx(1.5 + 0.08 * 4)
    # No brighter neighbour: the agent stays and its range grows by beta n_t.
    agent.luciferin = 9.0
    np.testing.assert_array_equal(
        agent.next_waypoint(np.array([1.0, 1.0]), [(2.0, 1.0, 5.0)]), [1.0, 1.0]
    )
    assert agent.decision_range_m == pytest.approx(1.82 + 0.08 * 5)


def test_a_move_leaving_the_arena_is_rejected():
    agent = _agent()
    agent.luciferin = 1.0
    stay = agent.next_waypoint(np.array([0.0, 5.0]), [(-1.0, 5.0, 5.0)])
    np.testing.assert_array_equal(stay, [0.0, 5.0])


def test_the_step_is_what_the_robot_covers_in_one_decision_at_most():
    assert _agent().step_m == pytest.approx(0.03)
    slow = GlowwormAgent(GlowwormConfig(), ARENA, velocity_mps=0.1, seed=0)
    assert slow.step_m == pytest.approx(0.001)


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
