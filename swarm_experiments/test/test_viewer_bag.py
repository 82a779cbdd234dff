"""A spawner's bag opens in Foxglove and RViz: transforms, markers, and the shipped configs.

One short OA-Bug run on the small site is recorded with the spawner's default topics; the
same seeded run is recorded once more without the viewer topics, to measure what they add.
The Foxglove layout and the RViz config in sim_bridge/config are checked against what the
spawner records and against the transform tree in the bag.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import json
from collections import defaultdict
from pathlib import Path

import pytest
import yaml
from sim_bridge.frames import compose
from swarm_common.angles import yaw_from_quaternion
from swarm_common.stamps import stamp_to_seconds
from swarm_runtime.bag import read_bag_info, read_messages
from swarm_runtime.ros import message_module, using_real_rclpy

try:
    message_module('tf2_msgs')
    message_module('visualization_msgs')
except ImportError as err:
    pytest.skip(f'tf2_msgs / visualization_msgs not importable: {err}', allow_module_level=True)

pytest.importorskip('oabug_robot.node')
from swarm_experiments.mission import VIEWER_TOPICS, RecordingSpec, run_mission
from swarm_experiments.spawn import SpawnSettings, build_mission, run

CONFIG = Path(__file__).resolve().parents[2] / 'sim_bridge' / 'config'
ROBOTS = 4
MARKER_TOPICS = (
    '/sim/markers/site',
    '/sim/markers/rooms',
    '/sim/markers/robots',
    '/sim/markers/paths',
)
# The viewer topics may make a bag at most this much bigger (the demo: 4.3 -> 7.9 MB).
MAX_GROWTH = 2.0
# On DDS the mission runs this much faster than real time (as far as the nodes keep up), so
# the two recordings take seconds, not minutes; the built-in runtime runs as fast as it can.
TIME_SCALE = 4.0 if using_real_rclpy() else 1.0


def _settings(bag: Path, **extra) -> SpawnSettings:
    # The mission's topics only: the growth below is the viewer topics' against those.
    return SpawnSettings(
        site='small', robots=ROBOTS, actions=200, seed=4, record=bag, record_topics='mission',
        time_scale=TIME_SCALE, **extra,
    )  # fmt: skip


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    """(bag with the spawner's default topics, the same run without the viewer topics)."""
    root = tmp_path_factory.mktemp('viewer')
    with_viewer = root / 'with'
    result = run(_settings(with_viewer))
    without = root / 'without'
    spec, _ = build_mission(_settings(without))
    topics = tuple(t for t in spec.recording.topics if t not in VIEWER_TOPICS)
    run_mission(dataclasses.replace(spec, recording=RecordingSpec(without, topics)))
    return with_viewer, without, result


def _bag_bytes(bag: Path) -> int:
    return sum(f.stat().st_size for f in bag.iterdir())


def _transform_tree(bag: Path):
    """child -> parent over /tf and /tf_static, and the last transform of every child."""
    parents, last = {}, {}
    for item in read_messages(bag, topics=['/tf', '/tf_static']):
        for t in item.message.transforms:
            parents[t.child_frame_id] = t.header.frame_id
            last[t.child_frame_id] = t
    return parents, last


def _chain(parents, frame):
    chain = [frame]
    while chain[-1] in parents:
        chain.append(parents[chain[-1]])
    return chain


def _pose(transform):
    t, q = transform.transform.translation, transform.transform.rotation
    return t.x, t.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)


def _spawner_topics(**extra) -> list[str]:
    spec, _ = build_mission(SpawnSettings(site='small', robots=10, record=Path('unused'), **extra))
    return list(spec.recording.topics)


def _recorded(topic: str, patterns) -> bool:
    return any(fnmatch.fnmatchcase(topic, pattern) for pattern in patterns)


@pytest.mark.slow
def test_the_bag_places_every_robot_and_its_sensors_in_the_map(bags) -> None:
    bag, _, result = bags
    info = read_bag_info(bag)
    assert {'/tf', '/tf_static', *MARKER_TOPICS} <= set(info.topics)
    parents, last = _transform_tree(bag)
    for i in range(ROBOTS):
        for frame in ('laser', 'imu_link', 'gas_sensor'):
            assert _chain(parents, f'r{i}/{frame}') == [
                f'r{i}/{frame}',
                f'r{i}/base_link',
                f'r{i}/odom',
                'map',
            ]
        # The last transform puts the robot where the run ended (exact odometry).
        in_map = compose(_pose(last[f'r{i}/odom']), _pose(last[f'r{i}/base_link']))
        assert in_map[:2] == pytest.approx(tuple(result.mission.trajectories[-1, i, :2]), abs=0.05)
    static = info.topics['/tf_static']
    assert static.message_count == 1
    assert all(q.durability.name == 'TRANSIENT_LOCAL' for q in static.offered_qos_profiles)


@pytest.mark.slow
def test_the_markers_in_the_bag_decode_and_show_the_run(bags) -> None:
    bag, _, result = bags
    marker = message_module('visualization_msgs').Marker
    got = defaultdict(list)
    for item in read_messages(bag, topics=list(MARKER_TOPICS)):
        got[item.topic].append(item)
    walls = next(m for m in got['/sim/markers/site'][0].message.markers if m.ns == 'walls')
    assert walls.type == marker.LINE_LIST
    assert len(walls.points) == 2 * len(result.mission.site.sealed_walls)
    # The rooms were resent at every first entry: the last message shows the final coverage.
    entries = len(result.mission.room_entries)
    assert len(got['/sim/markers/rooms']) == entries + 1 - _entries_at_start(result)
    final = got['/sim/markers/rooms'][-1].message.markers
    visited_triangles = sum(len(m.points) for m in final if m.id > 0 and m.action == marker.ADD)
    assert visited_triangles >= 6 * entries
    paths = got['/sim/markers/paths']
    assert len(paths) >= 10
    end = {m.id: m.points[-1] for m in paths[-1].message.markers}
    assert set(end) == set(range(ROBOTS))
    times = result.mission.trajectory_times_s
    last_s = stamp_to_seconds(paths[-1].message.markers[0].header.stamp)
    k = int(abs(times - last_s).argmin())
    for i, point in end.items():
        assert (point.x, point.y) == pytest.approx(
            tuple(result.mission.trajectories[k, i, :2]), abs=0.2
        )


def _entries_at_start(result) -> int:
    return sum(1 for e in result.mission.room_entries if e.time_s == 0.0)


@pytest.mark.slow
def test_the_viewer_topics_keep_the_bag_growth_modest(bags) -> None:
    bag, without, result = bags
    duration_s = result.mission.sim_time_s
    info = read_bag_info(bag)
    # /tf: one message per odometry output (10 Hz), every robot in it.
    assert info.topics['/tf'].message_count <= 10.0 * duration_s + 2
    assert info.topics['/sim/markers/paths'].message_count <= 0.5 * duration_s + 2
    assert _bag_bytes(bag) <= MAX_GROWTH * _bag_bytes(without)
    assert set(read_bag_info(without).topics).isdisjoint({'/tf', '/tf_static', *MARKER_TOPICS})


def _foxglove() -> dict:
    return json.loads((CONFIG / 'foxglove_layout.json').read_text())


def _rviz() -> dict:
    return yaml.safe_load((CONFIG / 'swarm.rviz').read_text())


def _rviz_displays() -> list[dict]:
    return _rviz()['Visualization Manager']['Displays']


def test_the_foxglove_layout_shows_what_the_spawner_records_in_the_map_frame() -> None:
    layout = _foxglove()
    panel_id = layout['layout']
    assert panel_id in layout['configById']
    assert panel_id.split('!')[0] == '3D'
    panel = layout['configById'][panel_id]
    assert panel['followTf'] == 'map'
    topics = panel['topics']
    assert set(MARKER_TOPICS) <= {t for t, s in topics.items() if s['visible']}
    recorded = _spawner_topics()
    assert [t for t in topics if not _recorded(t, recorded)] == []


def test_the_rviz_config_shows_what_the_spawner_records_in_the_map_frame() -> None:
    config = _rviz()
    assert config['Visualization Manager']['Global Options']['Fixed Frame'] == 'map'
    displays = _rviz_displays()
    classes = {d['Class'] for d in displays}
    assert classes == {
        'rviz_default_plugins/TF',
        'rviz_default_plugins/MarkerArray',
        'rviz_default_plugins/LaserScan',
    }
    by_topic = {d['Topic']['Value']: d for d in displays if 'Topic' in d}
    assert set(MARKER_TOPICS) <= set(by_topic)
    assert {f'/r{i}/scan' for i in range(10)} <= set(by_topic)
    default = _spawner_topics()
    mission_only = _spawner_topics(record_topics='mission')
    assert [t for t in by_topic if not _recorded(t, default)] == []
    # What is on when the config opens is in every bag, also a mission-only one; the scans
    # (recorded by default, not with --record-topics mission) are one tick away.
    enabled = [t for t, d in by_topic.items() if d['Enabled']]
    assert [t for t in enabled if not _recorded(t, mission_only)] == []
    assert all(not by_topic[f'/r{i}/scan']['Enabled'] for i in range(10))


@pytest.mark.slow
def test_the_viewers_fixed_frame_and_latched_topics_match_the_bag(bags) -> None:
    bag, _, _ = bags
    parents, _ = _transform_tree(bag)
    assert 'map' in set(parents.values())
    info = read_bag_info(bag)
    for display in _rviz_displays():
        if display['Class'] != 'rviz_default_plugins/MarkerArray':
            continue
        topic = display['Topic']['Value']
        if topic not in info.topics:
            continue  # /sim/markers/targets: only missions with targets publish it
        # A transient-local subscription matches only transient-local publishers.
        assert display['Topic']['Durability Policy'] == 'Transient Local'
        offered = info.topics[topic].offered_qos_profiles
        assert offered
        assert all(q.durability.name == 'TRANSIENT_LOCAL' for q in offered), topic


def test_scans_are_recorded_by_default_and_left_out_of_mission_only_bags() -> None:
    assert {f'/r{i}/scan' for i in range(10)} <= set(_spawner_topics())
    mission_only = _spawner_topics(record_topics='mission')
    assert not any(fnmatch.fnmatchcase('/r0/scan', t) for t in mission_only)
    assert set(VIEWER_TOPICS) <= set(mission_only)
