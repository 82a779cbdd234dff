"""Sector sweep: sectors, the coverage map and the next cell to search."""

import math

import numpy as np
import pytest
from msc_pf.coverage import SectorSweep, sector_of

CENTRE = np.array([1000.0, 1000.0])


def test_sectors_split_the_bearings_evenly_counterclockwise_from_east():
    points = CENTRE + 100.0 * np.array(
        [[math.cos(a), math.sin(a)] for a in np.radians([1.0, 89.0, 91.0, 181.0, 269.0, 359.0])]
    )
    assert sector_of(points, CENTRE, 4).tolist() == [0, 0, 1, 2, 2, 3]
    assert sector_of(points, CENTRE, 1).tolist() == [0] * 6


def test_every_cell_belongs_to_exactly_one_sector():
    sweeps = [SectorSweep(2000.0, 20.0, 250.0) for _ in range(15)]
    for rank, sweep in enumerate(sweeps):
        sweep.plan(CENTRE, 15, rank)
    owned = np.zeros(100 * 100, dtype=int)
    for sweep in sweeps:
        assert sweep._sector_cells is not None
        owned[sweep._sector_cells] += 1
    assert (owned == 1).all()


def test_a_plan_needs_an_existing_sector():
    sweep = SectorSweep(2000.0, 20.0, 250.0)
    with pytest.raises(ValueError, match='does not exist'):
        sweep.plan(CENTRE, 3, 3)
    assert not sweep.planned


def test_marking_covers_the_cells_within_the_sweep_radius():
    sweep = SectorSweep(2000.0, 20.0, 250.0)
    sweep.mark((1000.0, 1000.0))
    assert sweep.covered_at(np.array([[1000.0, 1225.0], [1225.0, 1000.0]])).all()
    assert not sweep.covered_at(np.array([[1000.0, 1265.0], [1180.0, 1180.0]])).any()
    share = sweep.covered_share()
    assert share == pytest.approx(math.pi * 250.0**2 / 2000.0**2, rel=0.05)
    sweep.mark((math.nan, 3.0))  # ignored
    assert sweep.covered_share() == share


def test_the_goal_is_the_nearest_uncovered_cell_of_the_own_sector_then_anywhere():
    sweep = SectorSweep(2000.0, 20.0, 250.0)
    assert sweep.goal(CENTRE) is None  # no sector yet
    sweep.plan(CENTRE, 4, 0)  # bearings 0-90 degrees: the north-east quarter
    sweep.mark(CENTRE)
    goal = sweep.goal(CENTRE)
    assert goal is not None
    assert goal[0] >= 1000.0
    assert goal[1] >= 1000.0
    assert 250.0 < np.hypot(*(goal - CENTRE)) < 275.0
    # With the own quarter covered the robot helps elsewhere.
    sweep.covered[50:, 50:] = True
    goal = sweep.goal(np.array([1500.0, 1500.0]))
    assert goal is not None
    assert not (goal[0] > 1000.0 and goal[1] > 1000.0)
    sweep.covered[:] = True
    assert sweep.goal(CENTRE) is None
