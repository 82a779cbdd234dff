"""RSSI targets: radio model, detection, task load and capture."""

import numpy as np
import pytest
from swarm_sim.rssi_targets import (
    RadioModel,
    RssiTargetConfig,
    RssiTargetError,
    RssiTargetField,
    place_robots,
)


def field_with(*positions, **overrides):
    config = RssiTargetConfig(n_targets=len(positions), **overrides)
    return RssiTargetField(config, np.array(positions, dtype=float))


def test_mean_rssi_follows_the_log_distance_model_and_clamps_below_one_metre():
    radio = RadioModel()
    assert radio.mean_rssi_dbm(1.0) == pytest.approx(13.0 - 40.046)
    assert radio.mean_rssi_dbm(0.2) == pytest.approx(13.0 - 40.046)
    assert radio.mean_rssi_dbm(10.0) == pytest.approx(13.0 - 40.046 - 30.0)
    # gamma3 = -48 dBm is reached at D_th = 5 m.
    assert radio.mean_rssi_dbm(5.0) == pytest.approx(-48.0, abs=0.02)


def test_samples_have_unit_noise_and_are_hidden_below_the_detection_threshold():
    field = field_with((1000.0, 1000.0))
    rng = np.random.default_rng(0)
    near = np.tile([[1100.0, 1000.0]], (4000, 1))
    samples = field.sample_rssi(near, rng)[:, 0]
    assert samples.mean() == pytest.approx(RadioModel().mean_rssi_dbm(100.0), abs=0.05)
    assert samples.std() == pytest.approx(1.0, abs=0.05)
    far = field.sample_rssi(np.array([[1400.0, 1000.0]]), rng)
    assert np.isnan(far[0, 0])


def test_detection_edge_is_near_292_m():
    field = field_with((0.0, 0.0))
    rng = np.random.default_rng(1)
    inside = field.sample_rssi(np.tile([[250.0, 0.0]], (500, 1)), rng)
    outside = field.sample_rssi(np.tile([[340.0, 0.0]], (500, 1)), rng)
    assert np.mean(~np.isnan(inside)) > 0.95
    assert np.mean(~np.isnan(outside)) < 0.05


def test_one_robot_captures_a_target_after_w_over_r_w_seconds():
    field = field_with((100.0, 100.0))
    robot = np.array([[103.0, 100.0]])
    captures = []
    for t in range(1, 25):
        captures += field.work(robot, np.array([0.0]), 1.0, float(t))
    assert [c.target_id for c in captures] == [0]
    assert captures[0].time_s == 20.0  # 100 load / 5 load/s
    assert captures[0].robot_indices == (0,)
    assert field.all_captured


def test_moving_or_distant_robots_do_no_work_and_workers_share_the_load():
    field = field_with((100.0, 100.0))
    robots = np.array([[101.0, 100.0], [100.0, 102.0], [100.0, 96.0], [110.0, 100.0]])
    speeds = np.array([0.0, 0.0, 1.0, 0.0])  # third moves, fourth is 10 m away
    captures = []
    for t in range(1, 11):
        captures += field.work(robots, speeds, 1.0, float(t))
    assert captures[0].time_s == 10.0
    assert captures[0].robot_indices == (0, 1)


def test_captured_targets_are_no_longer_heard():
    field = field_with((100.0, 100.0), (150.0, 100.0))
    field.remaining_load[0] = 0.0
    samples = field.sample_rssi(np.array([[120.0, 100.0]]), np.random.default_rng(2))
    assert np.isnan(samples[0, 0])
    assert not np.isnan(samples[0, 1])


def test_random_targets_lie_in_the_field_and_robots_in_the_start_disc():
    rng = np.random.default_rng(3)
    field = RssiTargetField.random(RssiTargetConfig(n_targets=200), rng)
    assert field.positions_m.min() >= 0.0
    assert field.positions_m.max() <= 2000.0
    robots = place_robots(500, (1000.0, 1000.0), 30.0, rng)
    assert np.hypot(*(robots - 1000.0).T).max() <= 30.0


def test_invalid_configuration_is_rejected():
    with pytest.raises(RssiTargetError, match='work_load'):
        RssiTargetConfig(work_load=0.0)
    with pytest.raises(RssiTargetError, match='target positions'):
        RssiTargetField(RssiTargetConfig(n_targets=2), np.zeros((3, 2)))
