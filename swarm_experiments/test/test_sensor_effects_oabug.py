"""benchmarks/sensor_effects_oabug.py: one realistic effect at a time, paired with ideal."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from swarm_sim.engine import EngineConfig
from swarm_sim.sensor_profiles import RealisticSensors, apply_sensor_profile

pytestmark = pytest.mark.runtime_independent(reason='batch runs, no node')


@pytest.fixture
def effects(benchmark_script):
    return benchmark_script('sensor_effects_oabug')


def _changed_fields(config: EngineConfig, ideal: EngineConfig) -> set[str]:
    return {
        f.name
        for f in dataclasses.fields(EngineConfig)
        if getattr(config, f.name) != getattr(ideal, f.name)
    }


def test_each_effect_switches_on_only_its_own_sensor(effects):
    ideal = EngineConfig()
    configs = effects.effect_configs(ideal)
    assert configs['ideal'] == ideal
    assert configs['realistic'] == apply_sensor_profile(ideal, 'realistic')
    expected = {
        'aoa-nlos': {'aoa'},
        'aoa-bias': {'aoa'},
        'aoa-outliers': {'aoa'},
        'aoa-distances': {'aoa'},
        'aoa-random': {'aoa'},
        'aoa-los-noise': {'bearings'},
        'scent': {'scent'},
        'lidar': {'lidar'},
        'imu': {'imu'},
    }
    for name, fields in expected.items():
        assert _changed_fields(configs[name], ideal) == fields, name
    realistic_aoa = RealisticSensors().aoa
    assert configs['aoa-nlos'].aoa == realistic_aoa
    # The three parts of the NLOS model, each with the others off.
    bias, outliers, distances = (configs[f'aoa-{k}'].aoa for k in ('bias', 'outliers', 'distances'))
    assert bias.nlos_bias_std_rad_per_wall == realistic_aoa.nlos_bias_std_rad_per_wall
    assert bias.outlier_probability_per_wall == 0.0
    assert bias.wall_distance_factor == 1.0
    assert outliers.outlier_probability_per_wall == realistic_aoa.outlier_probability_per_wall
    assert outliers.nlos_bias_std_rad_per_wall == 0.0
    assert outliers.wall_distance_factor == 1.0
    assert distances.wall_distance_factor == realistic_aoa.wall_distance_factor
    assert distances.nlos_bias_std_rad_per_wall == 0.0
    assert distances.outlier_probability_los == distances.outlier_probability_per_wall == 0.0
    assert configs['aoa-random'].aoa.outlier_probability_los == 1.0


@pytest.mark.parametrize(
    ('argv', 'message'),
    [
        (['--effects', 'ideal,fog'], 'unknown effect fog'),
        (['--sites', '0'], 'at least 1'),
        (['--workers', '0'], 'at least 1'),
    ],
)
def test_bad_options_are_one_line_errors_before_any_run(
    effects, capsys, monkeypatch, argv, message
):
    monkeypatch.setattr(effects, 'run', lambda *_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as stop:
        effects.main(argv)
    assert stop.value.code == 2
    assert message in capsys.readouterr().err.strip().splitlines()[-1]


def test_the_table_pairs_every_effect_with_ideal_site_by_site(effects):
    rows = effects.table(
        {'ideal': [50.0, 40.0, 30.0], 'scent': [60.0, 40.0, 20.0], 'imu': [50.0, 40.0, 30.0]}
    )
    ideal, scent, imu = rows[2:]
    assert ideal.startswith('| ideal | 3 | 40.0 ± 10.0 |')
    # Differences +10, 0, -10: mean 0, one more, one level, one less.
    assert '| +0.0 ± 5.8 | 1 / 1 / 1 |' in scent
    assert '| +0.0 ± 0.0 | 0 / 3 / 0 | 1 |' in imu


def test_the_trace_measures_distance_rim_and_cells(effects):
    # Two robots start at (1, 1) and (3, 1); in the second half one sits at the far corner
    # (10, 10), on the rim of the poses' box, the other at (5, 5), 4 m or more from every edge.
    start = [[1.0, 1.0, 0.0], [3.0, 1.0, 0.0]]
    late = [[10.0, 10.0, 0.0], [5.0, 5.0, 0.0]]
    trajectories = np.array([start, start, late, late])
    distance, rim, cells = effects.trace_metrics(trajectories)
    expected = (np.hypot(8.0, 9.0) + np.hypot(3.0, 4.0)) / 2.0
    assert distance == pytest.approx(expected)
    assert rim == pytest.approx(0.5)
    assert cells == 4


def test_a_run_covers_rooms_and_ideal_comes_first(effects):
    fields = {'site': 'small', 'variant': 'sound', 'robots': 2, 'departure': 'center'}
    outcomes = effects.run(['aoa-random', 'ideal'], [0], fields, workers=1)
    assert list(outcomes) == ['ideal', 'aoa-random']
    for runs in outcomes.values():
        assert len(runs) == 1
        assert 0.0 < runs[0].coverage_pct <= 100.0
        assert runs[0].distance_m > 0.0
        assert 0.0 <= runs[0].rim_share <= 1.0
        assert runs[0].cells > 1
    rows = effects.trace_table(outcomes)
    assert [row.split(' | ')[0] for row in rows[2:]] == ['| ideal', '| aoa-random']
