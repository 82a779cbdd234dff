"""The reliability studies: registered, their scenarios valid, their tables right."""

import pandas as pd
import pytest
from swarm_experiments.study import ReportPage, load_registry, make_specs

from swarm_experiments import reliability


def test_the_studies_are_registered_through_the_entry_point():
    registry = load_registry()
    for name in ('faults-oabug', 'faults-bayes', 'faults-msc', 'sensors-oabug'):
        study = registry.get(name)
        assert make_specs(study, smoke=True).specs


@pytest.mark.parametrize(
    'scenario',
    sorted({*reliability.OABUG_FAULTS, *reliability.BAYES_FAULTS, *reliability.MSC_FAULTS}),
)
def test_every_fault_scenario_of_the_studies_parses(scenario):
    config = reliability.parse_fault(scenario, 12.0)
    assert config.dropout_time_s == config.sensor_time_s == 12.0
    assert (scenario == 'none') == (config.describe() == 'dropout_time_s=12.0, sensor_time_s=12.0')


def test_the_reliability_table_keeps_the_planned_seeds_and_orders_the_faults(tmp_path):
    rows = pd.DataFrame(
        {
            'status': 'ok',
            'seed': [0, 1, 0, 1, 7],
            'config.departure': 'center',
            'config.fault': ['dropout_robots=2', 'dropout_robots=2', 'none', 'none', 'none'],
            'metric.coverage': [80.0, 90.0, 100.0, 90.0, 0.0],
            'metric.complete': [False, False, True, False, False],
            'metric.max_still_s': [3.0, 4.0, 2.0, 2.0, 60.0],
            'metric.stuck_survivors': [0, 1, 0, 0, 5],
            'metric.faulty_moved_m': 0.0,
        }
    )
    page = ReportPage(tmp_path, {'study': 'faults-oabug', 'seeds': [0, 1]}, rows)
    reliability._report_oabug_faults(page)
    text = page.markdown()
    lines = [line for line in text.splitlines() if line.startswith('| center')]
    assert lines[0].startswith('| center | none | 2 | 95 ± 7.1 | 50 |')
    assert lines[1].startswith('| center | dropout_robots=2 | 2 | 85 ± 7.1 | 0 |')
    assert lines[1].split('|')[7].strip() == '1'  # one run had a stuck survivor
