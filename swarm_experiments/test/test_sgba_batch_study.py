"""SGBA's batch path against its ROS path, and the sgba-vs-oabug study."""

from __future__ import annotations

import json

import numpy as np
import pytest
from swarm_experiments.mission import run_mission
from swarm_experiments.sgba_batch import SgbaSettings, build_sgba_mission, run_sgba_batch
from swarm_experiments.sgba_study import (
    SGBA_METHODS,
    SGBA_VS_OABUG,
    _sgba_overrides,
    run_comparison,
    studies,
)
from swarm_experiments.study import make_specs
from swarm_experiments.study.definition import load_registry
from swarm_experiments.study.engines import make_engine
from swarm_experiments.study.errors import UsageError
from swarm_experiments.study.report import write_reports
from swarm_experiments.study.runner import run_study
from swarm_sim.errors import ConfigurationError

NO_NODE = pytest.mark.runtime_independent(reason='batch runs and reports, no node')


@pytest.mark.builtin_only(reason='bit-exact determinism of the in-process ROS path')
def test_batch_and_ros_paths_give_the_same_poses_and_first_entries():
    spec, _ = build_sgba_mission(
        SgbaSettings(site='small', robots=4, departure='edge', actions=400)
    )
    ros = run_mission(spec)
    batch = run_sgba_batch(spec)
    assert ros.distance_travelled_m.min() > 1.0, 'every robot drove'
    assert ros.rooms_covered >= 1
    np.testing.assert_array_equal(batch.trajectories, ros.trajectories)
    assert batch.room_entries == ros.room_entries


@NO_NODE
def test_the_same_seed_gives_the_same_run_and_another_seed_another():
    def run(seed: int):
        spec, _ = build_sgba_mission(SgbaSettings(robots=3, seed=seed, site_seed=0, actions=60))
        return run_sgba_batch(spec).trajectories

    np.testing.assert_array_equal(run(1), run(1))
    assert not np.array_equal(run(1), run(2))


@NO_NODE
def test_the_mission_sets_its_own_parameters_and_refuses_them_from_users():
    spec, _ = build_sgba_mission(SgbaSettings(robots=3, departure='edge', seed=4))
    params = [robot.parameters for robot in spec.robots]
    assert [p['robot_index'] for p in params] == [0, 1, 2]
    assert {p['own_tag_id'] for p in params} == {'R0', 'R1', 'R2'}
    assert all(p['departure'] == params[0]['departure'] for p in params)
    with pytest.raises(ConfigurationError, match='robot_index'):
        SgbaSettings(robot_parameters={'robot_index': 1})
    spec, _ = build_sgba_mission(SgbaSettings(robots=2, robot_parameters={'nonsense': 1}))
    with pytest.raises(ConfigurationError, match='nonsense'):
        run_sgba_batch(spec)


@NO_NODE
def test_the_study_is_registered_with_oabug_rows_first():
    study = load_registry().get(SGBA_VS_OABUG)
    plan = make_specs(study)
    assert study.axes['method'][0] == 'gas_sound'
    assert study.axes['method'][-2:] == ('sgba', 'sgba_scaled')
    assert plan.params['profile'] == 'paper'
    assert study.axes['robots'] == (2, 4, 6, 8, 10), "the paper's Fig. 4 robot counts"
    assert len(plan.specs) == 2 * 4 * 5 * 2 * 20
    scaled = next(s for s in plan.specs if s.config['method'] == 'sgba_scaled')
    assert _sgba_overrides(scaled.config) == {'geometry_scale': 0.5}
    chosen = make_specs(study, overrides={'sgba.geometry_scale': '0.7'}, smoke=True)
    scaled = next(s for s in chosen.specs if s.config['method'] == 'sgba_scaled')
    assert _sgba_overrides(scaled.config) == {'geometry_scale': 0.7}, 'a setting wins'


@NO_NODE
@pytest.mark.parametrize(
    ('name', 'value', 'message'),
    [
        ('method', '[nope]', 'method'),
        ('sgba.rssi_heading_dbm', '-40', 'rssi_collision_dbm'),
        ('sgba.turn_rate_radps', '-1', 'turn_rate_radps'),
    ],
)
def test_bad_parameters_are_refused_before_any_run(name, value, message):
    (study,) = studies()
    with pytest.raises(UsageError, match=message):
        make_specs(study, overrides={name: value}, smoke=True)


@NO_NODE
def test_a_named_choice_is_accepted_as_the_spawner_accepts_it():
    (study,) = studies()
    plan = make_specs(study, overrides={'sgba.heading_scheme': 'authors'}, smoke=True)
    sgba = [spec for spec in plan.specs if spec.config['method'] in SGBA_METHODS]
    assert sgba
    assert all(_sgba_overrides(spec.config)['heading_scheme'] == 'authors' for spec in sgba)


@NO_NODE
def test_smoke_runs_both_methods_and_reports_the_paired_comparison(tmp_path):
    import matplotlib

    matplotlib.use('Agg')
    (study,) = studies()
    registry = load_registry(use_entry_points=False)
    registry.add(study)
    plan = make_specs(study, overrides={'method': '[gas_sound, sgba_scaled]'}, smoke=True)
    with make_engine('serial') as engine:
        summary = run_study(plan, tmp_path, engine)
    assert summary.complete
    (page,) = write_reports(tmp_path, registry)
    text = page.read_text()
    assert '## SGBA beside OA-Bug' in text
    assert 'sgba_scaled - gas_sound' in text
    # Both tables are exported for the docs' generated results sections.
    exported = json.loads((page.parent / 'results.json').read_text())['tables']
    assert {'coverage', 'paired'} <= set(exported)
    methods = [row[3] for row in exported['coverage']['rows']]
    assert methods.index('gas_sound') < methods.index('sgba_scaled')  # OA-Bug leads


@NO_NODE
def test_an_sgba_run_records_the_coverage_curve():
    (study,) = studies()
    plan = make_specs(
        study,
        overrides={
            'method': '[sgba]',
            'site': '[small]',
            'robots': '[10]',
            'departure': '[edge]',
            'actions': '200',
        },
        runs=1,
    )
    (spec,) = plan.specs
    row = run_comparison(spec)
    curve = row['coverage_pct_every_100_actions']
    assert len(curve) == 2
    assert curve == sorted(curve)
    assert curve[-1] == pytest.approx(row['coverage_pct'])
    assert row['robot_m'] > 10.0
