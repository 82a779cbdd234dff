"""Study definitions expand into run specs with stable ids; overrides and smoke apply."""

from __future__ import annotations

import hashlib
import json

import pytest
from study_fixtures import search_study, synthetic_run
from swarm_experiments.study import (
    Smoke,
    Study,
    StudyDefinitionError,
    StudyRegistry,
    UsageError,
    load_registry,
    make_specs,
    parse_overrides,
    run_id,
)


def test_run_id_is_the_hash_of_the_canonical_json_and_ignores_key_order() -> None:
    config = {'robots': 4, 'sim': {'steps': 60, 'speed_scale': 1.0}}
    payload = '{"config":{"robots":4,"sim":{"speed_scale":1.0,"steps":60}},"seed":3,"study":"s"}'
    expected = hashlib.sha256(payload.encode()).hexdigest()[:16]
    assert run_id('s', config, 3) == expected
    reordered = {'sim': {'speed_scale': 1.0, 'steps': 60}, 'robots': 4}
    assert run_id('s', reordered, 3) == expected
    assert run_id('s', config, 4) != expected
    assert run_id('t', config, 3) != expected
    assert run_id('s', {**config, 'robots': 5}, 3) != expected


def test_run_id_rejects_values_that_are_not_json() -> None:
    with pytest.raises(StudyDefinitionError, match='not a JSON value'):
        run_id('s', {'where': object()}, 0)


def test_specs_are_the_product_of_the_axes_times_the_seeds_in_order() -> None:
    plan = make_specs(search_study())
    assert len(plan.specs) == 3 * 3 * 4
    first = plan.specs[:5]
    assert [(s.config['variant'], s.config['robots'], s.seed) for s in first] == [
        ('gas', 2, 0),
        ('gas', 2, 1),
        ('gas', 2, 2),
        ('gas', 2, 3),
        ('gas', 4, 0),
    ]
    assert len({spec.run_id for spec in plan.specs}) == len(plan.specs)
    assert first[0].configuration == {'variant': 'gas', 'robots': 2}
    assert first[0].config['sim'] == {'steps': 60, 'speed_scale': 1.0}
    assert plan.directory_name == 'synthetic-search'


def test_runs_and_smoke_change_the_seeds_axes_and_parameters() -> None:
    plan = make_specs(search_study(), runs=7)
    assert plan.seeds == tuple(range(7))
    smoke = make_specs(search_study(), smoke=True)
    assert smoke.directory_name == 'synthetic-search-smoke'
    assert smoke.seeds == (0, 1)
    assert {spec.config['robots'] for spec in smoke.specs} == {2}
    assert {spec.config['sim']['steps'] for spec in smoke.specs} == {20}
    assert len(smoke.specs) == 3 * 1 * 2
    with pytest.raises(UsageError, match='>= 1'):
        make_specs(search_study(), runs=0)


def test_overrides_set_nested_parameters_and_restrict_axes() -> None:
    overrides = parse_overrides(
        ['sim.steps=15', 'robots=2,6', 'variant=[sound]', 'fail_seeds=[1, 2]']
    )
    plan = make_specs(search_study(), overrides=overrides)
    assert {spec.config['sim']['steps'] for spec in plan.specs} == {15}
    assert {spec.config['robots'] for spec in plan.specs} == {2, 6}
    assert {spec.config['variant'] for spec in plan.specs} == {'sound'}
    assert plan.specs[0].config['fail_seeds'] == [1, 2]
    assert plan.params['sim']['speed_scale'] == 1.0
    default = make_specs(search_study())
    same = {s.run_id for s in default.specs if s.config['robots'] == 2}
    assert not same & {s.run_id for s in plan.specs}, 'changed parameters give new run ids'


@pytest.mark.parametrize(
    ('items', 'message'),
    [
        (['steps=3'], "no parameter 'steps'"),
        (['sim.nope=3'], "no parameter 'sim.nope'"),
        (['sim=3'], 'is a parameter group'),
        (['nothing.steps=3'], "no parameter group 'nothing'"),
    ],
)
def test_unknown_overrides_are_usage_errors(items: list[str], message: str) -> None:
    with pytest.raises(UsageError, match=message):
        make_specs(search_study(), overrides=parse_overrides(items))


@pytest.mark.parametrize(
    ('items', 'message'),
    [
        (['robots=abc'], r'--set robots=abc: expected a whole number \(like 2\)'),
        (['robots=2,x'], r'--set robots=x: expected a whole number'),
        (['robots=2.5'], r'--set robots=2.5: expected a whole number'),
        (['sim.steps=true'], r'--set sim.steps=true: expected a whole number'),
        (['sim.speed_scale=fast'], r'--set sim.speed_scale=fast: expected a number'),
        (['variant=[1, [2]]'], r'--set variant=\[2\]: expected a word'),
    ],
)
def test_overrides_of_the_wrong_type_name_the_parameter(items: list[str], message: str) -> None:
    with pytest.raises(UsageError, match=message):
        make_specs(search_study(), overrides=parse_overrides(items))


def test_overrides_take_the_declared_type() -> None:
    items = ['sim.speed_scale=2', 'variant=1,gas', 'sleep_s=1e-3']
    plan = make_specs(search_study(), overrides=parse_overrides(items))
    config = plan.specs[0].config
    assert config['sim']['speed_scale'] == 2.0
    assert isinstance(config['sim']['speed_scale'], float)
    assert {spec.config['variant'] for spec in plan.specs} == {'1', 'gas'}
    assert config['sleep_s'] == 0.001


def test_parse_overrides_rejects_malformed_and_repeated_items() -> None:
    with pytest.raises(UsageError, match='PARAM=VALUE'):
        parse_overrides(['steps'])
    with pytest.raises(UsageError, match='given twice'):
        parse_overrides(['a=1', 'a=2'])


@pytest.mark.parametrize(
    ('changes', 'message'),
    [
        ({'name': 'has space'}, 'study name'),
        ({'runs': 0}, 'runs must be >= 1'),
        ({'axes': {'robots': ()}}, 'non-empty sequence'),
        ({'axes': {'robots': 'abc'}}, 'non-empty sequence'),
        ({'axes': {'sleep_s': (1, 2)}}, 'both an axis and a fixed parameter'),
        ({'seed_label': 'trial'}, 'seed_label'),
        ({'smoke': Smoke(axes={'speed': (1,)})}, "unknown axis 'speed'"),
    ],
)
def test_invalid_definitions_are_rejected(changes: dict, message: str) -> None:
    with pytest.raises(StudyDefinitionError, match=message):
        search_study(**changes)


def test_registry_finds_studies_by_name_and_refuses_duplicates() -> None:
    registry = StudyRegistry([search_study()])
    assert registry.get('synthetic-search').run is synthetic_run
    assert 'synthetic-search' in registry
    with pytest.raises(StudyDefinitionError, match='two studies'):
        registry.add(search_study())
    with pytest.raises(UsageError, match="no study named 'other'"):
        registry.get('other')


def test_load_registry_takes_module_function_references() -> None:
    registry = load_registry(['study_fixtures:studies'], use_entry_points=False)
    assert [study.name for study in registry] == ['synthetic-search', 'synthetic-slow']
    with pytest.raises(UsageError, match='module:function'):
        load_registry(['study_fixtures'], use_entry_points=False)
    with pytest.raises(UsageError, match='cannot import'):
        load_registry(['no_such_module_here:studies'], use_entry_points=False)
    with pytest.raises(UsageError, match='has no'):
        load_registry(['study_fixtures:nothing'], use_entry_points=False)


def test_manifest_is_json_and_keeps_the_declared_axis_order() -> None:
    manifest = make_specs(search_study(), smoke=True).manifest()
    text = json.dumps(manifest)
    assert list(json.loads(text)['axes']) == ['variant', 'robots']
    assert manifest['runs'] == 6
    assert manifest['smoke'] is True


def test_study_requires_a_callable_run() -> None:
    with pytest.raises(StudyDefinitionError, match='not callable'):
        Study(name='x', run='not a function')  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ('items', 'message'),
    [
        (['sim.steps=0'], r'^sim\.steps=0: must be >= 1$'),
        (['sleep_s=-1'], r'^sleep_s=-1\.0: must be >= 0$'),
    ],
)
def test_a_value_the_study_check_rejects_stops_make_specs(items: list[str], message: str) -> None:
    with pytest.raises(UsageError, match=message):
        make_specs(search_study(), overrides=parse_overrides(items))


def test_the_check_sees_every_configuration_with_its_fixed_parameters() -> None:
    seen: list[dict] = []
    plan = make_specs(search_study(check=lambda config: seen.append(dict(config))), smoke=True)
    assert len(seen) == len(plan.specs) // len(plan.seeds) == 3
    assert {c['variant'] for c in seen} == {'gas', 'sound', 'random'}
    assert all(c['sim']['steps'] == 20 and c['robots'] == 2 for c in seen)


def test_a_check_that_raises_value_error_is_a_one_line_usage_error() -> None:
    def sloppy(config: dict) -> None:
        if config['robots'] > 4:
            raise ValueError('too many\nrobots')

    with pytest.raises(UsageError, match=r'^study synthetic-search: too many robots$'):
        make_specs(search_study(check=sloppy))
