"""The OA-Bug Fig. 4 study: registered, checked like the spawner, runs and reports."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from swarm_experiments.oabug_study import FIG4, coverage_every, run_fig4, studies
from swarm_experiments.study import make_specs
from swarm_experiments.study.definition import load_registry
from swarm_experiments.study.engines import make_engine
from swarm_experiments.study.errors import UsageError
from swarm_experiments.study.report import write_reports
from swarm_experiments.study.runner import run_study

pytestmark = pytest.mark.runtime_independent(reason='batch runs and reports, no node')


def test_the_study_is_registered_with_the_papers_design():
    study = load_registry().get(FIG4)
    plan = make_specs(study)
    # 3 sites x 5 variants x 5 robot counts x 2 departures x 100 sites.
    assert len(plan.specs) == 15000
    assert plan.seeds == tuple(range(100))
    assert plan.params['profile'] == 'paper'
    assert plan.params['actions'] is None
    smoke = make_specs(study, smoke=True)
    assert 0 < len(smoke.specs) <= 40


@pytest.mark.parametrize(
    ('override', 'message'),
    [
        ('gas_threshold=abc', 'integer'),
        ('profile=nope', 'profile'),
        ('gas_sound_wall_side=sideways', 'gas_sound_wall_side'),
        ('no_such_parameter=1', 'no parameter'),
        ('speed=-1', 'speed'),
    ],
)
def test_bad_parameters_are_refused_before_any_run(override, message):
    (study,) = studies()
    name, _, value = override.partition('=')
    with pytest.raises(UsageError, match=message):
        make_specs(study, overrides={name: value}, smoke=True)


@pytest.mark.parametrize(
    'override',
    ['sound_turn_rule=toward', 'gas_sound_wall_side=every_contact', 'fixed_turn=left'],
)
def test_named_choices_are_accepted_as_the_spawner_accepts_them(override):
    (study,) = studies()
    name, _, value = override.partition('=')
    plan = make_specs(study, overrides={name: value}, smoke=True)
    assert {spec.config[name] for spec in plan.specs} == {value}


def test_node_parameters_are_set_with_the_spawners_names():
    (study,) = studies()
    plan = make_specs(study, overrides={'gas_threshold': '300', 'robots': '4'}, smoke=True)
    assert {spec.config['gas_threshold'] for spec in plan.specs} == {300}
    assert {spec.config['robots'] for spec in plan.specs} == {4}


def test_coverage_every_carries_a_finished_run_forward():
    entries = np.array([5.0, 12.0, 12.0, 31.0])
    assert coverage_every(entries, 5, 10.0, 4) == [0.2, 0.6, 0.6, 0.8]
    assert coverage_every(np.zeros(0), 3, 1.0, 2) == [0.0, 0.0]


def test_a_run_records_coverage_every_100_actions_and_profiles_change_it(tmp_path):
    (study,) = studies()
    plan = make_specs(
        study,
        overrides={
            'site': 'small',
            'variant': 'gas_sound',
            'robots': '4',
            'departure': 'edge',
            'actions': '300',
        },
        runs=1,
    )
    (spec,) = plan.specs
    row = run_fig4(spec)
    curve = row['coverage_pct_every_100_actions']
    assert len(curve) == 3
    assert curve == sorted(curve)
    assert math.isclose(curve[-1], row['coverage_pct'])
    assert row['rooms_covered'] >= 2
    tuned = make_specs(
        study,
        overrides={
            'site': 'small',
            'variant': 'gas_sound',
            'robots': '4',
            'departure': 'edge',
            'actions': '300',
            'profile': 'tuned',
        },
        runs=1,
    )
    assert tuned.specs[0].run_id != spec.run_id
    # The profiles differ in the controller, so the swarms drive differently.
    assert run_fig4(tuned.specs[0])['robot_m'] != row['robot_m']


def test_the_report_has_the_tables_curves_and_paired_statistics(tmp_path):
    import matplotlib

    matplotlib.use('Agg')
    (study,) = studies()
    registry = load_registry(use_entry_points=False)
    registry.add(study)
    plan = make_specs(
        study,
        overrides={'site': 'small', 'variant': 'gas,gas_sound', 'robots': '2', 'actions': '100'},
        runs=2,
    )
    with make_engine('serial') as engine:
        summary = run_study(plan, tmp_path, engine)
    assert summary.complete
    (page,) = write_reports(tmp_path, registry)
    text = page.read_text()
    assert '## OA-Bug Fig. 4' in text
    assert 'small, profile paper: coverage %' in text
    assert 'gas_sound - gas' in text
    assert (page.parent / 'figures' / 'fig4-small-paper.png').is_file()
    # The coverage and paired tables are exported for the docs' generated results sections.
    exported = json.loads((page.parent / 'results.json').read_text())['tables']
    assert {'small-paper', 'small-paper-paired'} <= set(exported)
    assert any('gas_sound' in str(row) for row in exported['small-paper']['rows'])
