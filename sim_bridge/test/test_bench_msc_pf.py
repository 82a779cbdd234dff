"""benchmarks/bench_msc_pf.py: controller settings given on the command line (--set)."""

from __future__ import annotations

import pytest


@pytest.fixture
def bench(benchmark_script):
    return benchmark_script('bench_msc_pf')


def test_settings_are_read_as_their_fields_types(bench):
    config = bench.controller_config(
        (
            ('phases.unheard_updates', 'true'),
            ('phases.recorded_max_age_s', '900'),
            ('swarm.max_size', '4'),
            ('msc.leader_rule', 'pbest'),
        )
    )
    assert config.phases.unheard_updates is True
    assert config.phases.recorded_max_age_s == 900.0
    assert config.swarm.max_size == 4
    assert config.msc.leader_rule == 'pbest'
    assert bench.controller_config(()) == bench.MscPfConfig()


@pytest.mark.parametrize(
    ('setting', 'message'),
    [
        (('phases.no_such_field', '1'), 'unknown controller setting'),
        (('nowhere.x', '1'), 'unknown controller setting'),
        (('phases.unheard_updates', 'yes'), 'expected true or false'),
        (('swarm.max_size', 'three'), 'invalid literal'),
    ],
)
def test_unknown_settings_and_bad_values_are_rejected(bench, setting, message):
    with pytest.raises(ValueError, match=message):
        bench.controller_config((setting,))
