"""benchmarks/bench_msc_pf.py: controller settings given on the command line (--set)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / 'benchmarks' / 'bench_msc_pf.py'


def _load_bench():
    spec = importlib.util.spec_from_file_location('bench_msc_pf', SCRIPT)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


BENCH = _load_bench()


def test_settings_are_read_as_their_fields_types():
    config = BENCH.controller_config(
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
    assert BENCH.controller_config(()) == BENCH.MscPfConfig()


@pytest.mark.parametrize(
    ('setting', 'message'),
    [
        (('phases.no_such_field', '1'), 'unknown controller setting'),
        (('nowhere.x', '1'), 'unknown controller setting'),
        (('phases.unheard_updates', 'yes'), 'expected true or false'),
        (('swarm.max_size', 'three'), 'invalid literal'),
    ],
)
def test_unknown_settings_and_bad_values_are_rejected(setting, message):
    with pytest.raises(ValueError, match=message):
        BENCH.controller_config((setting,))
