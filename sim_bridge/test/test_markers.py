"""The marker builders and the frame arithmetic of the bridge, without a node."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_bridge.frames import SensorMounts, compose, invert, static_transforms
from swarm_runtime.ros import message_module

from sim_bridge import markers

try:
    visualization_msgs = message_module('visualization_msgs')
except ImportError as err:
    pytest.skip(f'visualization_msgs not importable: {err}', allow_module_level=True)

Marker = visualization_msgs.Marker


def _distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance of each point to the nearest segment of ``polyline``."""
    best = np.full(len(points), np.inf)
    for a, b in itertools.pairwise(polyline):
        d = b - a
        length_sq = float(d @ d)
        t = np.zeros(len(points)) if length_sq == 0 else np.clip((points - a) @ d / length_sq, 0, 1)
        best = np.minimum(best, np.hypot(*(points - a - t[:, None] * d).T))
    return best


def test_a_straight_run_is_two_vertices_and_a_corner_adds_one() -> None:
    recorder = markers.PathRecorder(np.array([[0.0, 0.0, 0.0]]), tolerance_m=0.05, min_step_m=0.01)
    for x in np.linspace(0.1, 5.0, 50):
        recorder.add(np.array([[x, 0.0]]))
    assert recorder.path(0).tolist() == [[0.0, 0.0], [5.0, 0.0]]
    for y in np.linspace(0.1, 3.0, 30):
        recorder.add(np.array([[5.0, y]]))
    assert recorder.path(0).tolist() == [[0.0, 0.0], [5.0, 0.0], [5.0, 3.0]]


def test_a_robot_standing_still_adds_nothing() -> None:
    recorder = markers.PathRecorder(np.zeros((2, 3)), tolerance_m=0.05, min_step_m=0.02)
    for _ in range(10):
        recorder.add(np.array([[0.0, 0.005], [1.0, 0.0]]))
    assert len(recorder.path(0)) == 1
    assert recorder.path(1).tolist() == [[0.0, 0.0], [1.0, 0.0]]


@settings(max_examples=40, deadline=None)
@given(
    turns=st.lists(st.floats(-0.6, 0.6), min_size=5, max_size=120),
    step=st.floats(0.05, 0.3),
)
def test_every_recorded_sample_lies_within_the_tolerance_of_the_path(turns, step) -> None:
    heading, position = 0.0, np.zeros(2)
    samples = []
    for turn in turns:
        heading += turn
        position = position + step * np.array([math.cos(heading), math.sin(heading)])
        samples.append(position)
    recorder = markers.PathRecorder(np.zeros((1, 2)), tolerance_m=0.1, min_step_m=0.0)
    for sample in samples:
        recorder.add(sample[None, :])
    path = recorder.path(0)
    assert path[0].tolist() == [0.0, 0.0]
    assert path[-1] == pytest.approx(samples[-1])
    assert np.max(_distance_to_polyline(np.array(samples), path)) <= 0.1 + 1e-9


def test_path_markers_are_one_line_strip_per_moving_robot_in_its_colour() -> None:
    array = markers.path_markers(
        [np.array([[0.0, 0.0], [1.0, 1.0]]), np.array([[2.0, 2.0]])], 0.04, 3.5
    )
    (strip,) = array.markers
    assert (strip.ns, strip.id, strip.type) == ('paths', 0, Marker.LINE_STRIP)
    assert strip.header.frame_id == 'map'
    assert (strip.header.stamp.sec, strip.header.stamp.nanosec) == (3, 500_000_000)
    assert [(p.x, p.y) for p in strip.points] == [(0.0, 0.0), (1.0, 1.0)]
    assert (strip.color.r, strip.color.g, strip.color.b) == pytest.approx(markers.robot_rgb(0))
    assert strip.scale.x == pytest.approx(0.04)


def _area(triangles: np.ndarray) -> float:
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    u, v = b - a, c - a
    return float(np.sum(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])) / 2.0)


@pytest.mark.parametrize('clockwise', [False, True])
def test_an_l_shaped_room_is_covered_by_triangles_of_its_area(clockwise) -> None:
    outline = np.array([[0, 0], [4, 0], [4, 1], [1, 1], [1, 3], [0, 3]], dtype=float)
    if clockwise:
        outline = outline[::-1]
    triangles = markers.triangulate_polygon(outline)
    assert triangles.shape == (4, 3, 2)
    assert _area(triangles) == pytest.approx(4.0 + 2.0)
    # No triangle covers the notch of the L.
    centroids = triangles.mean(axis=1)
    assert not np.any((centroids[:, 0] > 1.0) & (centroids[:, 1] > 1.0))


def test_an_outline_without_area_is_rejected() -> None:
    with pytest.raises(ValueError, match='no ear'):
        markers.triangulate_polygon(np.array([[0, 0], [1, 0], [2, 0], [3, 0]], float))
    with pytest.raises(ValueError, match='at least 3'):
        markers.triangulate_polygon(np.array([[0, 0], [1, 0]], float))


def test_a_room_whose_outline_cannot_be_filled_keeps_its_rectangles() -> None:
    rects = [np.array([[0, 0, 1, 1]], float)]
    flat = np.array([[0, 0], [1, 0], [2, 0], [3, 0]], float)
    (unvisited, _) = markers.room_markers(rects, {}, 1, 0.0, polygons=[flat]).markers
    assert len(unvisited.points) == 6


def test_rooms_are_grouped_by_first_visitor_and_empty_groups_deleted() -> None:
    rects = [np.array([[0, 0, 1, 1]], float), np.array([[2, 0, 3, 1], [3, 0, 4, 2]], float)]
    array = markers.room_markers(rects, {1: 1}, num_robots=2, time_s=0.0)
    by_id = {m.id: m for m in array.markers}
    assert set(by_id) == {0, 1, 2}
    assert len(by_id[0].points) == 6  # room 0: one rectangle, unvisited
    assert by_id[1].action == Marker.DELETE  # robot 0 entered nothing
    assert len(by_id[2].points) == 12  # room 1 (two rectangles), entered by robot 1
    assert (by_id[2].color.r, by_id[2].color.g, by_id[2].color.b) == pytest.approx(
        markers.robot_rgb(1)
    )
    assert by_id[0].color.a < by_id[2].color.a


def test_targets_have_a_sphere_a_label_and_an_area_each() -> None:
    array = markers.target_markers(
        np.array([[1.0, 2.0], [3.0, 4.0]]),
        0.5,
        [(1, 0, 0, 1), (0, 1, 0, 1)],
        ['T0', 'T1'],
        0.1,
        2.0,
        area_radius_m=5.0,
    )
    spheres = [m for m in array.markers if m.ns == 'targets']
    areas = [m for m in array.markers if m.ns == 'target_areas']
    labels = [m for m in array.markers if m.ns == 'target_labels']
    assert [(m.pose.position.x, m.pose.position.y) for m in spheres] == [(1.0, 2.0), (3.0, 4.0)]
    assert [m.scale.x for m in areas] == [10.0, 10.0]
    assert [m.text for m in labels] == ['T0', 'T1']
    assert spheres[1].color.g == 1.0


def test_marker_sizes_follow_the_scene() -> None:
    assert markers.marker_unit_m(np.array([[0, 0], [15, 7.5]])) == pytest.approx(0.1)
    assert markers.marker_unit_m(np.array([[0, 0], [2000, 2000]])) == pytest.approx(2000 / 150)
    assert markers.marker_unit_m(np.zeros((1, 2))) == 0.01


@settings(max_examples=50, deadline=None)
@given(
    a=st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi)),
    b=st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-math.pi, math.pi)),
)
def test_composing_with_the_inverse_gives_back_the_pose(a, b) -> None:
    back = compose(compose(a, b), invert(b))
    assert back[:2] == pytest.approx(a[:2], abs=1e-9)
    assert math.cos(back[2] - a[2]) == pytest.approx(1.0, abs=1e-12)


def test_map_to_odom_puts_the_odometry_start_on_the_true_start() -> None:
    true_start = np.array([[2.0, 3.0, 0.5], [1.0, 1.0, 0.0]])
    odometry_start = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    transforms = static_transforms(['r0', 'r1'], true_start, odometry_start, SensorMounts(0.08))
    odom = {t.child: t for t in transforms if t.parent == 'map'}
    r0 = odom['r0/odom']
    assert compose((r0.x_m, r0.y_m, r0.yaw_rad), odometry_start[0]) == pytest.approx(
        tuple(true_start[0])
    )
    r1 = odom['r1/odom']
    assert (r1.x_m, r1.y_m, r1.yaw_rad) == (0.0, 0.0, 0.0)
    mounts = [t for t in transforms if t.parent == 'r0/base_link']
    assert [(t.child, t.x_m) for t in mounts] == [
        ('r0/laser', 0.0),
        ('r0/imu_link', 0.0),
        ('r0/gas_sensor', 0.08),
    ]
    without_odometry = static_transforms(['r0'], true_start[:1], None, SensorMounts(0.08))
    assert all(t.parent != 'map' for t in without_odometry)
