"""History-based search (eq. 1): repulsion from searched cells, field edges, random term."""

import numpy as np
import pytest
from msc_pf.search import CoverageHistory, HistorySearch, wall_repulsion
from msc_pf.settings import SearchConfig


def test_history_repulsion_points_away_from_visited_cells():
    history = CoverageHistory(2000.0, 20.0)
    history.visit(history.cell_of(np.array([950.0, 1000.0])), 5)
    push = history.repulsion(np.array([1000.0, 1000.0]), 150.0)
    # The visited cell's centre is (950, 1010): away from it is +x, slightly -y.
    np.testing.assert_allclose(push, np.array([50.0, -10.0]) / np.hypot(50.0, 10.0))


def test_history_repulsion_ignores_cells_beyond_the_radius():
    history = CoverageHistory(2000.0, 20.0)
    history.visit(history.cell_of(np.array([700.0, 1000.0])), 5)
    assert not history.repulsion(np.array([1000.0, 1000.0]), 150.0).any()


def test_wall_repulsion_pushes_inward_near_a_corner_and_is_zero_inside():
    push = wall_repulsion(np.array([10.0, 1990.0]), 2000.0, 50.0)
    assert push[0] > 0.0
    assert push[1] < 0.0
    assert not wall_repulsion(np.array([1000.0, 1000.0]), 2000.0, 50.0).any()


def test_random_direction_is_kept_for_its_period():
    search = HistorySearch(SearchConfig(random_period_s=10.0), 2000.0, np.random.default_rng(3))
    first = search.random_direction(0.0).copy()
    np.testing.assert_array_equal(search.random_direction(9.0), first)
    assert not np.array_equal(search.random_direction(10.0), first)
    assert np.hypot(*first) == pytest.approx(1.0)


def test_search_vector_turns_away_from_the_swarm_history():
    search = HistorySearch(SearchConfig(), 2000.0, np.random.default_rng(0))
    here = np.array([1000.0, 1000.0])
    for x in range(900, 1000, 20):
        search.record_swarm_visit(search.swarm_history.cell_of(np.array([x, 1000.0])))
    # Random term (weight 1) cannot cancel k_s = 1.2 pointing +x.
    assert search.vector(0.0, here, np.zeros(2))[0] > 0.0
