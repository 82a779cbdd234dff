"""The reliability studies: registered, their scenarios valid, their tables right."""

import numpy as np
import pandas as pd
import pytest
from swarm_experiments.study import (
    ReportPage,
    UsageError,
    load_registry,
    make_specs,
    parse_overrides,
)

from swarm_experiments import reliability


def test_the_studies_are_registered_through_the_entry_point():
    registry = load_registry()
    for name in ('faults-oabug', 'faults-bayes', 'faults-msc', 'faults-crash', 'sensors-oabug'):
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


def test_the_reliability_table_averages_the_same_sites_and_orders_the_faults(tmp_path):
    faults = ['dropout_robots=2', 'dropout_robots=2', 'none', 'none', 'none']
    faults += ['stale_lidar_robots=1', 'stale_lidar_robots=1']
    faults += ['none', 'none', 'dropout_robots=2', 'dropout_robots=2']
    rows = pd.DataFrame(
        {
            'status': 'ok',
            'seed': [0, 1, 0, 1, 7, 0, 1, 0, 1, 0, 1],
            'config.profile': ['paper'] * 7 + ['tuned'] * 4,
            'config.departure': 'center',
            'config.fault': faults,
            'metric.coverage': [80.0, 90.0, 100.0, 90.0, 0.0, 90.0, 90.0] + [100.0] * 4,
            'metric.complete': [False, False, True, False, False, False, False] + [True] * 4,
            'metric.max_still_s': [3.0, 4.0, 2.0, 2.0, 60.0, 30.0, 30.0] + [1.0] * 4,
            'metric.stuck_survivors': [0, 2, 0, 0, 5, 3, 3, 0, 0, 1, 0],
            'metric.stuck_by_stopped': [0, 1, 0, 0, 5, 1, 1, 0, 0, 1, 0],
            'metric.stuck_by_peer': [0, 1, 0, 0, 0, 2, 2, 0, 0, 0, 0],
            'metric.stuck_alone': 0,
            'metric.faulty_moved_m': 0.0,
        }
    )
    page = ReportPage(tmp_path, {'study': 'faults-oabug', 'seeds': [0, 1, 7]}, rows)
    reliability._report_oabug_faults(page)
    text = page.markdown()
    # The paper profile's table comes first; site 7 (run without faults only) is left out.
    paper, tuned = text.index('profile paper'), text.index('profile tuned')
    assert paper < tuned
    lines = [line for line in text[paper:tuned].splitlines() if line.startswith('| ')]
    cells = [[c.strip() for c in line.split('|')[1:-1]] for line in lines]
    header = cells[0]
    none, dropped, stale = (dict(zip(header, row, strict=True)) for row in cells[2:5])
    assert (none['fault'], dropped['fault']) == ('none', 'dropout_robots=2')
    assert none['center: coverage %'] == '95 ± 7.1'
    assert dropped['center: coverage %'] == '85 ± 7.1'
    # Paired with the fault-free run of the same site: -20 and 0.
    assert dropped['center: change (paired) %'] == '-10 ± 14'
    assert dropped['center: stuck survivors'] == '2'
    assert stale['center: stuck survivors'] == '6'
    # The stuck table compares the scenarios and sites both profiles ran: not the paper's
    # stale lidars.
    stuck = text[text.index('stood still longer') :]
    assert '| paper | center | 4 | 2 | 1 | 1 | 0 |' in stuck
    assert '| tuned | center | 4 | 1 | 1 | 0 | 0 |' in stuck


def _outcome(times, r1_x, extension=None):
    """A bridge outcome of 3 robots driving along x at 0.1 m/s, r1 along ``r1_x``."""
    n = len(times)
    poses = np.zeros((n, 3, 3))
    poses[:, 0, 0] = poses[:, 2, 0] = 0.1 * times
    poses[:, 1, 0] = r1_x
    return {
        'trajectory_times_s': times.tolist(),
        'robot_names': ['r0', 'r1', 'r2'],
        'trajectories': poses.tolist(),
        'sim_time_s': float(times[-1]),
        'stop_reason': 'budget',
        'room_entries': [[0, 0, 1.0], [3, 2, 5.0], [3, 1, 9.0]],
        'rooms_total': 10,
        'extensions': [] if extension is None else [extension],
    }


def test_crash_metrics_see_the_robot_stop_and_move_again():
    mission = reliability.CrashMission('spawn', (), ('--seed',), 1.0, 30.0, 10.0)
    times = np.arange(0.0, 100.5, 0.5)
    # r1 drives, stops 0.5 s after the kill at 30 s, moves again 4 s after the restart at 40 s.
    speed = np.where((times > 30.5) & (times < 44.0), 0.0, 0.1)
    r1_x = np.concatenate(([0.0], np.cumsum(speed[1:] * 0.5)))
    row = reliability.crash_metrics(mission, 'restart', _outcome(times, r1_x))
    assert row['coverage'] == 20.0  # rooms 0 and 3 of 10
    assert row['down_moved_m'] == 0.0
    assert row['restart_delay_s'] == 4.5  # the first sample more than 5 cm away
    assert row['restart_moved_m'] == pytest.approx(0.1 * (100.0 - 43.5))
    assert row['others_moved_m'] == pytest.approx(1.0)
    # Killed for good: it stays where it stopped; no restart figures.
    frozen = np.minimum(r1_x, r1_x[times == 30.5][0])
    row = reliability.crash_metrics(mission, 'crash', _outcome(times, frozen))
    assert row['down_moved_m'] == 0.0
    assert np.isnan(row['restart_delay_s'])
    assert np.isnan(row['restart_moved_m'])
    signal = {'kind': 'signal', 'found': True, 'tau': 0.5, 'found_time_s': 20.0, 'finder': 0}
    row = reliability.crash_metrics(mission, 'none', _outcome(times, 0.1 * times, signal))
    assert (row['found'], row['tau']) == (True, 0.5)
    assert np.isnan(row['down_moved_m'])
    rssi = {'kind': 'rssi', 'capture_times_s': [50.0, None], 'all_captured': False}
    row = reliability.crash_metrics(mission, 'crash', _outcome(times, frozen, rssi))
    assert (row['captured'], row['all_captured']) == (1, False)
    assert np.isnan(row['cct_s'])


def test_stuck_survivors_are_told_apart_by_what_touched_them():
    times = np.arange(0.0, 61.0)
    positions = np.zeros((len(times), 5, 2))
    positions[:, 1] = [0.2, 0.0]  # touches r0 all along; it stopped working at 10 s
    positions[:, 2] = [5.0, 0.0]  # stands alone
    positions[:, 3, 0] = 0.1 * times + 9.0  # drives
    positions[:, 4] = [5.0, 0.2]  # r2's working neighbour, which stands too
    positions[:30, 4, 1] = 3.0  # ... arriving at 30 s: r2 stood 30 s alone before
    working = np.array([True, False, True, True, True])
    causes = reliability.stuck_causes(times, positions, working, stopped_from_s=10.0)
    # r0: still 60 s beside a stopped robot; r2: beside a working one (from 30 s);
    # r4: still 30 s (from 30 s) beside working r2; r3 never stood.
    assert causes == {'stuck_by_stopped': 1, 'stuck_by_peer': 2, 'stuck_alone': 0}
    # Before its fault a robot is a working peer.
    causes = reliability.stuck_causes(times, positions, working, stopped_from_s=100.0)
    assert causes == {'stuck_by_stopped': 0, 'stuck_by_peer': 3, 'stuck_alone': 0}


def test_decisions_after_a_time_count_the_legs_started_since():
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 1.0]])  # legs at 0, 10, 20 s
    assert reliability.decisions_after_s(path, 0.1, 0.0) == 3
    assert reliability.decisions_after_s(path, 0.1, 10.0) == 2
    assert reliability.decisions_after_s(path, 0.1, 25.0) == 0


def test_the_sensor_table_leads_with_the_paper_profile_and_pairs_the_sites(tmp_path):
    # Two sites; the tuned rows first in storage order, the realistic runs 10 points lower
    # on site 0 and equal on site 1 (paper), 5 points higher on both sites (tuned).
    rows = pd.DataFrame(
        {
            'status': 'ok',
            'seed': [0, 1, 0, 1, 0, 1, 0, 1],
            'config.profile': ['tuned'] * 4 + ['paper'] * 4,
            'config.variant': 'gas_sound',
            'config.departure': 'center',
            'config.sensors': ['ideal', 'ideal', 'realistic', 'realistic'] * 2,
            'metric.coverage': [90.0, 80.0, 95.0, 85.0, 100.0, 90.0, 90.0, 90.0],
            'metric.complete': False,
            'metric.sim_time_s': 333.0,
        }
    )
    page = ReportPage(tmp_path, {'study': 'sensors-oabug', 'seeds': [0, 1]}, rows)
    reliability._report_sensors(page)
    assert [r[0] for r in page.exports['sensors']['rows']] == ['paper'] * 2 + ['tuned'] * 2
    paired = page.exports['sensors-paired']
    columns = paired['columns']
    by_profile = {row[columns.index('profile')]: row for row in paired['rows']}
    assert list(by_profile) == ['paper', 'tuned']
    mean_diff = columns.index('mean_diff')
    assert float(by_profile['paper'][mean_diff]) == pytest.approx(-5.0)
    assert float(by_profile['tuned'][mean_diff]) == pytest.approx(5.0)
    assert by_profile['tuned'][columns.index('wins')] == '2'


@pytest.mark.parametrize(
    ('name', 'setting', 'message'),
    [
        ('faults-msc', 'max_time_s=-1', r'^max_time_s=-1\.0: must be > 0$'),
        ('faults-msc', 'scheme=x', r"^scheme='x': choose one of proposed, msc_pf, msc$"),
        ('faults-msc', 'fault_time_s=-3', r'^fault_time_s=-3\.0: must be >= 0$'),
        (
            'faults-msc',
            'fault=dropout_robots=40',
            r"^fault='dropout_robots=40': 40 faulty robots asked for, but only 15 robots$",
        ),
        ('faults-bayes', 'stop_time_s=-1', r'^stop_time_s=-1: must be > 0$'),
        ('faults-bayes', 'fault=bogus=1', r"^fault='bogus=1': unknown parameter 'bogus'$"),
        ('faults-bayes', 'robots=-1', r'^robots=-1: must be >= 0$'),
        ('faults-oabug', 'robots=0', r'^robots=0: must be >= 1$'),
        ('faults-oabug', 'variant=zz', r"unknown variant 'zz'"),
        ('sensors-oabug', 'sensors=magic', r"^sensors='magic': choose one of ideal, realistic$"),
    ],
)
def test_a_bad_set_value_is_refused_before_anything_runs(name, setting, message):
    (study,) = [s for s in reliability.studies() if s.name == name]
    with pytest.raises(UsageError, match=message):
        make_specs(study, smoke=True, overrides=parse_overrides([setting]))


def test_every_reliability_study_but_the_crash_one_checks_its_configurations():
    for study in reliability.studies():
        assert study.check is not None, study.name
        if study.name != 'faults-crash':  # needs rclpy
            make_specs(study)
