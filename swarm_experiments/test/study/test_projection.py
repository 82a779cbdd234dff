"""Wall-time projection: list scheduling of measured run costs on N cores."""

from __future__ import annotations

import math

import pandas as pd
import pytest
from study_fixtures import search_study
from swarm_experiments.study import UsageError, make_specs, parse_overrides, project_wall_time
from swarm_experiments.study.projection import costs_for_plan


def test_equal_runs_fill_the_cores_in_rounds() -> None:
    projection = project_wall_time([2.0] * 10, 4, per_task_overhead_s=0.5)
    assert projection.wall_s == pytest.approx(3 * 2.5)  # ceil(10 / 4) rounds of 2.5 s
    assert projection.lower_bound_s == pytest.approx(25.0 / 4)
    assert projection.cpu_s == pytest.approx(20.0)
    assert projection.overhead_s == pytest.approx(5.0)
    assert projection.efficiency == pytest.approx(20.0 / (4 * 7.5))
    assert projection.summary() == (
        '10 runs on 4 cores: 7.5 s wall (20.0 s CPU of runs, 5.0 s of per-task overhead, '
        'lower bound 6.2 s, 67 % efficiency)'
    )
    assert project_wall_time([3600.0] * 3, 1).summary().startswith('3 runs on 1 cores: 3.00 h')


def test_longest_first_beats_an_unlucky_order() -> None:
    costs = [1.0] * 8 + [8.0]
    given = project_wall_time(costs, 2)
    longest = project_wall_time(costs, 2, order='longest_first')
    assert given.wall_s == pytest.approx(4.0 + 8.0)
    assert longest.wall_s == pytest.approx(8.0)
    assert longest.wall_s == pytest.approx(longest.lower_bound_s)


def test_dispatch_rate_startup_and_cpu_scale_bound_the_wall_time() -> None:
    dispatch_bound = project_wall_time([0.001] * 1000, 64, dispatch_s=0.01)
    assert dispatch_bound.wall_s == pytest.approx(999 * 0.01 + 0.001)
    scaled = project_wall_time([3.0] * 4, 4, cpu_scale=0.5, startup_s=10.0)
    assert scaled.wall_s == pytest.approx(10.0 + 1.5)
    assert project_wall_time([], 8).wall_s == 0.0


@pytest.mark.parametrize(
    'kwargs',
    [
        {'cores': 0},
        {'per_task_overhead_s': -1.0},
        {'dispatch_s': math.inf},
        {'cpu_scale': 0.0},
        {'order': 'random'},
    ],
)
def test_bad_arguments_are_value_errors(kwargs: dict) -> None:
    arguments = {'cores': 2, **kwargs}
    with pytest.raises(ValueError, match=r'must|order'):
        project_wall_time([1.0], **arguments)


def test_costs_for_plan_take_the_mean_cpu_of_each_configuration() -> None:
    rows = pd.DataFrame(
        {
            'status': ['ok', 'ok', 'ok', 'failed'],
            'config.variant': ['gas', 'gas', 'sound', 'sound'],
            'config.robots': [2, 2, 2, 2],
            'cpu_s': [1.0, 3.0, 5.0, 100.0],
        }
    )
    study = search_study(axes={'variant': ('gas', 'sound'), 'robots': (2,)})
    plan = make_specs(study, runs=3)
    assert costs_for_plan(plan, rows) == [2.0, 2.0, 2.0, 5.0, 5.0, 5.0]
    wider = make_specs(study, overrides=parse_overrides(['robots=2,4']))
    with pytest.raises(UsageError, match='no measured run for 2 configurations: variant=gas'):
        costs_for_plan(wider, rows)
