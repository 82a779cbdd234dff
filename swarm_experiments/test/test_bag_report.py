"""A recorded run's bag alone reproduces the spawner's coverage summary and figures."""

from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bouncer import WallBouncer
from swarm_analysis.oabug_report import load_run, main
from swarm_experiments.mission import MissionSpec, RecordingSpec, RobotNodeSpec, run_mission
from swarm_runtime.ros import using_real_rclpy
from swarm_sim.site_loading import load_site

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
# On DDS the 40 s mission runs this much faster than real time; the built-in runtime runs as
# fast as it can.
TIME_SCALE = 4.0 if using_real_rclpy() else 1.0


def record_bouncer_run(bag: Path):
    site = load_site(str(FIVE_ROOMS))
    spec = MissionSpec(
        site=site,
        initial_poses=np.array([[2.8, 1.73, 1.2], [3.4, 1.73, -1.9]]),
        robots=[RobotNodeSpec(WallBouncer), RobotNodeSpec(WallBouncer)],
        max_sim_time_s=40.0,
        recording=RecordingSpec(bag, ('/clock', '/sim/poses', '/sim/coverage', '/sim/site')),
        time_scale=TIME_SCALE,
    )
    return run_mission(spec)


@pytest.fixture(scope='module')
def recorded(tmp_path_factory):
    bag = tmp_path_factory.mktemp('bags') / 'bouncers'
    return record_bouncer_run(bag), bag


def test_bag_reproduces_the_live_coverage_and_first_visitors(recorded):
    live, bag = recorded
    run = load_run(bag)
    assert run.coverage.rooms_total == live.rooms_total == 5
    assert run.coverage.rooms_covered == live.rooms_covered
    expected = {e.room_index: live.robot_names[e.robot_index] for e in live.room_entries}
    assert run.coverage.first_visitor_by_room() == expected
    assert [v.time_s for v in run.coverage.visits] == pytest.approx(
        [e.time_s for e in live.room_entries]
    )


def test_bag_paths_match_the_true_poses_of_the_run(recorded):
    live, bag = recorded
    run = load_run(bag)
    assert run.robot_names == ('r0', 'r1')
    assert run.times_s[-1] == pytest.approx(live.sim_time_s, abs=0.5)
    assert run.coverage.end_time_s == pytest.approx(live.sim_time_s, abs=1e-6)
    # /sim/poses is sampled at 2 Hz, the live trajectory every 0.5 s: same instants.
    live_by_time = dict(zip(np.round(live.trajectory_times_s, 3), live.trajectories, strict=True))
    for t, poses in zip(run.times_s, run.poses, strict=True):
        if round(t, 3) in live_by_time:
            assert np.allclose(poses, live_by_time[round(t, 3)])
    assert len(run.site_name) > 0
    assert len(run.room_rects) == 5


def test_report_command_prints_the_summary_and_writes_both_figures(recorded, tmp_path, capsys):
    _, bag = recorded
    assert main([str(bag), '--out', str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert 'rooms first visited per robot' in out
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        'bouncers_coverage.png',
        'bouncers_paths.png',
    ]


def test_a_bag_without_ground_truth_is_reported_not_crashed(tmp_path, capsys):
    assert main([str(tmp_path / 'missing_bag')]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert err.startswith('oabug_report: ')
