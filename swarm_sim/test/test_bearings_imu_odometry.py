"""AoA bearings (noise, range, walls), gyro yaw integration and wheel odometry."""

import math

import numpy as np
import pytest
from swarm_common.angles import wrap_angle, yaw_from_quaternion, yaw_to_quaternion
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.bearings import BearingConfig, BearingModel
from swarm_sim.sensors.imu import GyroYawModel, ImuConfig
from swarm_sim.sensors.odometry import OdometryConfig, WheelOdometry
from swarm_sim.sensors_kernel import imu_message_yaw_kernel, wrap_sum_kernel, yaw_change_kernel


def test_bearing_is_the_peer_direction_in_the_receiver_frame_with_a_few_degrees_of_noise():
    model = BearingModel(2, BearingConfig(dropout_probability=0.0), np.random.default_rng(0))
    # Receiver faces +y; the peer is straight ahead-left at world angle 135 deg.
    poses = np.array([[0.0, 0.0, math.pi / 2], [-3.0, 3.0, 0.0]])
    errors = []
    for _ in range(400):
        report = model.measure(poses)[0]
        assert report.tags.tolist() == [1]
        errors.append(report.azimuth_rad[0] - math.pi / 4)
    errors = np.array(errors)
    assert abs(errors.mean()) < math.radians(0.5)
    assert math.radians(2.0) < errors.std() < math.radians(4.0)


def test_peers_beyond_range_are_not_heard():
    model = BearingModel(
        2, BearingConfig(range_m=30.0, dropout_probability=0.0), np.random.default_rng(1)
    )
    near = model.measure(np.array([[0.0, 0.0, 0.0], [29.0, 0.0, 0.0]]))
    far = model.measure(np.array([[0.0, 0.0, 0.0], [31.0, 0.0, 0.0]]))
    assert near[0].tags.tolist() == [1]
    assert near[1].tags.tolist() == [0]
    assert far[0].tags.size == 0


def test_walls_shorten_the_range():
    walls = np.array([[[5.0, -1.0], [5.0, 1.0]], [[10.0, -1.0], [10.0, 1.0]]])
    config = BearingConfig(range_m=40.0, wall_range_factor=0.5, dropout_probability=0.0)
    model = BearingModel(2, config, np.random.default_rng(2), walls)
    assert model.effective_range_m(np.array([0, 1, 2])).tolist() == [40.0, 20.0, 10.0]
    heard_through_one = model.measure(np.array([[0.0, 0.0, 0.0], [9.0, 0.0, 0.0]]))[0]
    lost_behind_two = model.measure(np.array([[0.0, 0.0, 0.0], [12.0, 0.0, 0.0]]))[0]
    in_open = model.measure(np.array([[0.0, 5.0, 0.0], [12.0, 5.0, 0.0]]))[0]
    assert heard_through_one.tags.size == 1
    assert lost_behind_two.tags.size == 0
    assert in_open.tags.size == 1


def test_sequence_numbers_count_per_tag_and_wrap():
    model = BearingModel(2, BearingConfig(dropout_probability=0.0), np.random.default_rng(3))
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    seqs = [int(model.measure(poses)[0].sequence[0]) for _ in range(3)]
    assert seqs == [1, 2, 3]


def test_bearing_config_rejects_a_wall_factor_above_one():
    with pytest.raises(ConfigurationError, match='wall_range_factor'):
        BearingConfig(wall_range_factor=1.5)


def test_ideal_gyro_yaw_tracks_the_true_rotation():
    imu = GyroYawModel(
        np.array([0.5]), ImuConfig(noise_density_radps_per_sqrt_hz=0.0), np.random.default_rng(0)
    )
    for _ in range(40):
        yaw, rate = imu.update(np.array([math.pi / 40]), 0.05)
    assert yaw[0] == pytest.approx(0.5 + math.pi - 2 * math.pi)
    assert rate[0] == pytest.approx(math.pi / 40 / 0.05)


def test_gyro_bias_makes_the_yaw_drift_linearly():
    config = ImuConfig(
        noise_density_radps_per_sqrt_hz=0.0, residual_bias_std_radps=math.radians(0.05)
    )
    imu = GyroYawModel(np.zeros(200), config, np.random.default_rng(5))
    for _ in range(20 * 60):
        yaw, _ = imu.update(np.zeros(200), 0.05)
    drift_deg = np.degrees(yaw)
    # 0.05 deg/s for 60 s is a 3 deg standard deviation across robots.
    assert 2.5 < drift_deg.std() < 3.5


@pytest.mark.parametrize(
    'config',
    [
        ImuConfig(noise_density_radps_per_sqrt_hz=math.radians(0.05)),
        ImuConfig(noise_density_radps_per_sqrt_hz=0.0, residual_bias_std_radps=math.radians(0.05)),
    ],
)
def test_the_reported_yaw_variance_is_the_spread_the_model_makes(config):
    # What the IMU message reports as its yaw variance: the spread across robots of the
    # integrated yaw error after 60 s, for the white noise and for the residual bias.
    imu = GyroYawModel(np.zeros(400), config, np.random.default_rng(7))
    for _ in range(10 * 60):
        yaw, _ = imu.update(np.zeros(400), 0.1)
    assert config.yaw_variance_rad2(0.0) == 0.0
    assert yaw.var() == pytest.approx(config.yaw_variance_rad2(60.0), rel=0.2)


def test_exact_odometry_reproduces_the_true_path():
    start = np.array([[1.0, 2.0, 0.3]])
    odom = WheelOdometry(start, OdometryConfig(), np.random.default_rng(0))
    pose = start.copy()
    for _ in range(30):
        pose = pose + np.array([[0.02 * math.cos(pose[0, 2]), 0.02 * math.sin(pose[0, 2]), 0.05]])
        est, twist = odom.update(pose, 0.1)
    assert est[0] == pytest.approx(pose[0], abs=1e-9)
    assert twist[0] == pytest.approx([0.2, 0.5], abs=1e-6)


def test_noisy_odometry_drifts_away_from_the_truth():
    start = np.zeros((1, 3))
    odom = WheelOdometry(
        start, OdometryConfig(distance_noise_fraction=0.05), np.random.default_rng(0)
    )
    pose = start.copy()
    for _ in range(100):
        pose = pose + np.array([[0.05, 0.0, 0.0]])
        est, _ = odom.update(pose, 0.1)
    assert abs(est[0, 0] - pose[0, 0]) > 1e-3


@pytest.mark.parametrize(
    ('robots', 'with_walls', 'dropout'),
    [(1, True, 0.02), (2, False, 0.02), (10, True, 0.02), (25, True, 0.02), (10, True, 0.0)],
)
def test_compiled_sight_lines_give_the_numpy_reports_bit_for_bit(robots, with_walls, dropout):
    rng = np.random.default_rng(robots)
    walls = np.zeros((0, 2, 2))
    if with_walls:
        starts = rng.uniform(0.0, 30.0, (60, 2))
        walls = np.stack([starts, starts + rng.uniform(-4.0, 4.0, (60, 2))], axis=1)
    config = BearingConfig(range_m=25.0, wall_range_factor=0.6, dropout_probability=dropout)
    compiled = BearingModel(robots, config, np.random.default_rng(3), walls)
    reference = BearingModel(robots, config, np.random.default_rng(3), walls)
    heard = set()
    for _ in range(40):
        poses = np.column_stack(
            [rng.uniform(-5.0, 35.0, (robots, 2)), rng.uniform(-4.0, 4.0, robots)]
        )
        for got, want in zip(
            compiled.measure(poses), reference.measure_reference(poses), strict=True
        ):
            assert got.receiver == want.receiver
            for field in ('tags', 'azimuth_rad', 'elevation_rad', 'distance_m', 'sequence'):
                assert np.array_equal(getattr(got, field), getattr(want, field))
            heard.add(got.tags.size)
    if robots > 2:
        # Some peers were heard and some lost (to range, walls or dropouts).
        assert len(heard) > 2


@pytest.mark.parametrize(
    'config',
    [
        ImuConfig(),
        ImuConfig(residual_bias_std_radps=0.01, bias_random_walk_radps_per_sqrt_s=0.002),
        ImuConfig(noise_density_radps_per_sqrt_hz=0.0),
    ],
)
def test_compiled_gyro_integration_gives_the_numpy_yaw_bit_for_bit(config):
    """Same yaw and rates from the same random state, across the +-pi seam, with NaN and
    +-inf yaw changes and varied dt."""
    rng = np.random.default_rng(4)
    start = rng.uniform(-math.pi, math.pi, 10)
    start[0] = math.pi
    compiled = GyroYawModel(start, config, np.random.default_rng(6))
    reference = GyroYawModel(start, config, np.random.default_rng(6))
    for step in range(300):
        change = rng.normal(0.0, 0.5, 10) * rng.choice([1.0, 1e-9, 10.0], 10)
        if step % 50 == 7:
            change[rng.integers(0, 10)] = rng.choice([math.nan, math.inf, -math.inf])
        dt = 0.1 if step % 4 else float(rng.uniform(0.01, 1.0))
        yaw, rate = compiled.update(change.copy(), dt)
        with np.errstate(invalid='ignore'):  # an infinite change makes the yaw NaN
            want_yaw, want_rate = reference.update_reference(change.copy(), dt)
        assert yaw.tobytes() == want_yaw.tobytes()
        assert rate.tobytes() == want_rate.tobytes()
        if step % 50 == 7:  # a NaN yaw stays NaN: start both again from clean yaws
            clean = np.nan_to_num(want_yaw).clip(-3.0, 3.0)
            compiled = GyroYawModel(clean, config, np.random.default_rng(step))
            reference = GyroYawModel(clean, config, np.random.default_rng(step))


def test_compiled_imu_message_yaw_is_the_nodes_quaternion_round_trip_bit_for_bit():
    """imu_message_yaw_kernel equals yaw_from_quaternion(*yaw_to_quaternion(yaw)) on yaws
    across and beyond +-pi, signed zeros, tiny and huge values; NaN where the node raises."""
    rng = np.random.default_rng(9)
    yaws = np.concatenate(
        (
            rng.uniform(-4.0, 4.0, 5000),
            rng.normal(0.0, 1e-12, 200),
            [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, 1e300, -1e-320, 5e-324],
        )
    )
    held = imu_message_yaw_kernel(yaws)
    changed = 0
    for yaw, got in zip(yaws.tolist(), held.tolist(), strict=True):
        want = yaw_from_quaternion(*yaw_to_quaternion(yaw))
        assert repr(got) == repr(want)
        changed += got != yaw
    assert changed > 100  # the round trip does change yaws: the test can tell them apart
    for bad in (math.nan, math.inf):
        assert math.isnan(imu_message_yaw_kernel(np.array([bad]))[0])
        with pytest.raises(ValueError, match=r'orientation|domain'):
            yaw_from_quaternion(*yaw_to_quaternion(bad))


def test_compiled_yaw_change_is_the_wrapped_difference_bit_for_bit():
    """yaw_change_kernel (the engine's IMU input) and wrap_sum_kernel (the bearings' noise)
    equal wrap_angle of the difference and the sum, across the +-pi seam, with signed
    zeros, exact multiples of pi, huge values, NaN and inf."""
    rng = np.random.default_rng(10)
    now = np.concatenate(
        (
            rng.uniform(-math.pi, math.pi, 3000),
            [math.pi, -math.pi, 0.0, -0.0, 3 * math.pi, 1e300, math.nan, math.inf, 1e-300],
        )
    )
    before = np.concatenate(
        (
            rng.uniform(-math.pi, math.pi, 3000),
            [-math.pi, math.pi, -0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        )
    )
    with np.errstate(invalid='ignore'):
        want = wrap_angle(now - before)
        want_sum = wrap_angle(now + before)
    assert yaw_change_kernel(now, before).tobytes() == want.tobytes()
    assert wrap_sum_kernel(now, before).tobytes() == want_sum.tobytes()
