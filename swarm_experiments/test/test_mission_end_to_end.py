"""The mission runner and the OA-Bug spawner, end to end on a small fixed site."""

from pathlib import Path

import numpy as np
import pytest
from sim_bridge.bouncer import WallBouncer
from swarm_experiments.mission import MissionSpec, RobotNodeSpec, StopReason, run_mission
from swarm_runtime.ros import Node, message_module
from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import point_segment_distance
from swarm_sim.site_loading import load_site

FIVE_ROOMS = Path(__file__).parent / 'data' / 'five_rooms.lay'
geometry_msgs = message_module('geometry_msgs')


class SilentNode(Node):
    """Publishes one forward command and then nothing: its robot must stop."""

    def __init__(self, **kwargs):
        super().__init__('silent', **kwargs)
        self._pub = self.create_publisher(geometry_msgs.Twist, 'cmd_vel', 10)
        self._timer = self.create_timer(0.1, self._once)

    def _once(self):
        cmd = geometry_msgs.Twist()
        cmd.linear.x = 0.3
        self._pub.publish(cmd)
        self._timer.cancel()


def bouncer_mission(seconds, factory=WallBouncer):
    site = load_site(str(FIVE_ROOMS))
    start = np.array([[2.8, 1.73, 0.0], [3.4, 1.73, np.pi]])
    return MissionSpec(
        site=site,
        initial_poses=start,
        robots=[RobotNodeSpec(factory), RobotNodeSpec(factory)],
        max_sim_time_s=seconds,
    )


def test_runner_drives_robots_from_their_nodes_without_touching_walls():
    result = run_mission(bouncer_mission(30.0))
    assert result.stop_reason == StopReason.BUDGET
    assert result.sim_time_s == pytest.approx(30.0, abs=0.11)
    assert np.all(result.distance_travelled_m > 2.0)
    walls = np.asarray(result.site.sealed_walls).reshape(-1, 2, 2)
    xy = result.trajectories[:, :, :2].reshape(-1, 2)
    assert point_segment_distance(xy, walls).min() >= 0.1
    assert result.trajectories.shape[1:] == (2, 3)
    _, fraction = result.coverage_curve()
    assert fraction[-1] == pytest.approx(result.coverage)


def test_a_robot_whose_node_falls_silent_stops_within_the_watchdog_timeout():
    result = run_mission(bouncer_mission(5.0, factory=SilentNode))
    # One command, then 0.5 s of watchdog grace: about 0.15 m at 0.3 m/s.
    assert np.all(result.distance_travelled_m < 0.3)
    assert np.all(result.distance_travelled_m > 0.05)


def test_progress_reports_arrive_and_a_predicate_can_stop_the_run():
    reports = []
    result = run_mission(
        bouncer_mission(60.0), progress=reports.append, stop=lambda p: p.sim_time_s >= 10.0
    )
    assert result.stop_reason == StopReason.PREDICATE
    assert result.sim_time_s == pytest.approx(10.0, abs=0.11)
    assert [round(r.sim_time_s) for r in reports[:2]] == [0, 10]


def test_mission_spec_rejects_mismatched_robots_and_poses():
    site = load_site(str(FIVE_ROOMS))
    with pytest.raises(ConfigurationError, match='2 robot node specs for 1 start poses'):
        MissionSpec(site, np.zeros((1, 3)), [RobotNodeSpec(WallBouncer)] * 2, 10.0)


@pytest.mark.slow
@pytest.mark.builtin_only(reason='bit-exact determinism: two runs give the same trajectories')
def test_oabug_spawner_covers_the_small_site_deterministically(tmp_path):
    pytest.importorskip('oabug_robot.node')
    from swarm_experiments.spawn import SpawnSettings, run

    def once(out_dir):
        config = SpawnSettings(
            site=str(FIVE_ROOMS),
            departure='edge',
            robots=3,
            actions=300,
            variant='gas_sound',
            seed=1,
            out_dir=out_dir,
        )
        return run(config)

    first = once(tmp_path)
    second = once(None)
    assert first.coverage >= 0.8
    entries = [(e.room_index, e.robot_index, e.time_s) for e in first.mission.room_entries]
    assert entries == [(e.room_index, e.robot_index, e.time_s) for e in second.mission.room_entries]
    assert np.array_equal(first.mission.trajectories, second.mission.trajectories)
    assert [p.name for p in first.plots] == [
        'oabug_gas_sound_edge_five_rooms_seed1_paths.png',
        'oabug_gas_sound_edge_five_rooms_seed1_coverage.png',
    ]
    assert all(p.stat().st_size > 1000 for p in first.plots)


def test_spawner_help_reads_well(capsys):
    from swarm_experiments.spawn import main

    assert main(['--help']) == 0
    text = capsys.readouterr().out
    for option in ('--site', '--variant', '--robots', '--departure', '--actions', '--record'):
        assert option in text


def test_spawner_reports_bad_input_without_a_traceback(capsys):
    from swarm_experiments.spawn import main

    assert main(['--robots', '0']) == 2
    assert 'robots must be >= 1' in capsys.readouterr().err


def test_spawner_parameters_reach_every_robot_node_typed():
    pytest.importorskip('oabug_robot.node')
    from swarm_experiments.spawn import SpawnSettings, build_mission, oabug_parameter_overrides

    overrides = oabug_parameter_overrides(['gas_threshold=300', 'sound_turn_rule=toward'])
    spec, _ = build_mission(
        SpawnSettings(site=str(FIVE_ROOMS), departure='edge', robots=3, robot_parameters=overrides)
    )
    for index, robot in enumerate(spec.robots):
        assert robot.parameters['gas_threshold'] == 300
        assert robot.parameters['sound_turn_rule'] == 'toward'
        assert robot.parameters['robot_index'] == index


def test_spawner_parameters_change_the_run():
    pytest.importorskip('oabug_robot.node')
    from swarm_experiments.oabug_batch import run_spawn_batch
    from swarm_experiments.spawn import SpawnSettings

    def trajectories(**parameters):
        config = SpawnSettings(
            site=str(FIVE_ROOMS),
            departure='edge',
            robots=2,
            actions=120,
            variant='minimum',
            seed=1,
            robot_parameters=parameters,
        )
        return run_spawn_batch(config).mission.trajectories

    default = trajectories()
    assert np.array_equal(default, trajectories(fixed_turn='right'))
    assert not np.array_equal(default, trajectories(fixed_turn='left'))


@pytest.mark.parametrize(
    ('option', 'message'),
    [
        ('gas_treshold=300', "unknown parameter 'gas_treshold' (did you mean gas_threshold?)"),
        ('robot_count=4', "'robot_count' is set by the spawner"),
        ('wall_hit_distance_m=0.05', 'wall_hit_distance_m must exceed robot_radius_m'),
    ],
)
def test_spawner_rejects_bad_parameters_before_running(capsys, option, message):
    pytest.importorskip('oabug_robot.node')
    from swarm_experiments.spawn import main

    assert main(['--param', option, '--no-plots']) == 2
    assert message in capsys.readouterr().err
