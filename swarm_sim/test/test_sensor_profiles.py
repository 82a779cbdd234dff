"""Sensor profiles: ideal leaves the engine as it is; realistic degrades AoA behind walls."""

import math

import numpy as np
import pytest
from swarm_common.angles import wrap_angle
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensor_profiles import AoaRealismConfig, RealisticSensors, apply_sensor_profile

WALLS = np.array(
    [
        [[0.0, 0.0], [6.0, 0.0]],
        [[6.0, 0.0], [6.0, 3.0]],
        [[6.0, 3.0], [0.0, 3.0]],
        [[0.0, 3.0], [0.0, 0.0]],
        [[4.0, 0.0], [4.0, 1.0]],
        [[4.0, 2.0], [4.0, 3.0]],
    ]
)
ROOM = np.array([[4.03, 0.03, 5.97, 2.97]])
# r0 and r1 in the hall (line of sight), r2 in the room behind the wall x = 4, y < 1.
POSES = np.array([[1.0, 0.5, 0.0], [2.0, 0.3, 0.5], [5.0, 0.5, 2.0]])


def cycles(config, seconds=60.0):
    site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
    engine = SimEngine(site, POSES, config, bearing_cycles=True)
    out = []
    for _ in range(round(seconds * config.physics_rate_hz)):
        step = engine.step()  # no commands: the robots stand still
        if step.bearing_cycle is not None:
            out.append(step.bearing_cycle)
    return out


def errors(cycle_list, pair):
    rx, tx = pair
    truth = math.atan2(*(POSES[tx, 1::-1] - POSES[rx, 1::-1])) - POSES[rx, 2]
    found = [c.azimuth_rad[(c.receivers == rx) & (c.tags == tx)] for c in cycle_list]
    return np.abs(wrap_angle(np.concatenate(found) - truth))


def test_the_ideal_profile_is_the_engine_default():
    base = EngineConfig()
    assert apply_sensor_profile(base, 'ideal') is base
    assert not base.aoa.active
    with pytest.raises(ConfigurationError, match='unknown sensor profile'):
        apply_sensor_profile(base, 'noisy')


def test_the_realistic_profile_sets_every_sensor():
    realistic = RealisticSensors(scent_decay_time_constant_s=120.0)
    config = apply_sensor_profile(EngineConfig(), 'realistic', realistic)
    assert config.aoa.active
    assert config.aoa == realistic.aoa
    assert config.scent.decay_time_constant_s == 120.0
    assert config.lidar.dropout_probability == realistic.lidar_dropout_probability
    assert config.lidar.range_noise_fraction == realistic.lidar_noise_fraction
    assert config.imu.residual_bias_std_radps == realistic.gyro_residual_bias_std_radps
    assert config.bearings.azimuth_noise_std_rad == realistic.aoa_noise_std_rad
    assert config.seed == EngineConfig().seed
    assert config.body == EngineConfig().body


def test_nlos_bias_and_outliers_hit_only_bearings_through_walls():
    ideal = cycles(EngineConfig(seed=2))
    aoa = AoaRealismConfig(
        nlos_bias_std_rad_per_wall=math.radians(20.0),
        outlier_probability_per_wall=0.2,
        wall_distance_factor=2.0,
    )
    real = cycles(EngineConfig(seed=2, aoa=aoa))
    # Line of sight: the very same reports (the hook has its own random stream).
    assert np.array_equal(errors(ideal, (0, 1)), errors(real, (0, 1)))
    through = errors(real, (0, 2))
    assert np.median(errors(ideal, (0, 2))) < math.radians(5.0)
    assert np.mean(through > math.radians(45.0)) > 0.1  # outliers
    assert np.median(through) > 2.0 * np.median(errors(ideal, (0, 2)))
    for a, b in zip(ideal, real, strict=True):
        wall = (a.receivers == 0) & (a.tags == 2)
        assert np.allclose(b.distance_m[wall], 2.0 * a.distance_m[wall])
        los = (a.receivers == 0) & (a.tags == 1)
        assert np.array_equal(b.distance_m[los], a.distance_m[los])


def test_the_report_list_path_gets_the_same_effects_as_the_flat_cycle():
    aoa = AoaRealismConfig(nlos_bias_std_rad_per_wall=0.3, outlier_probability_per_wall=0.3)
    site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
    flat = SimEngine(site, POSES, EngineConfig(seed=5, aoa=aoa), bearing_cycles=True)
    listed = SimEngine(site, POSES, EngineConfig(seed=5, aoa=aoa))
    for _ in range(30):
        a, b = flat.step(), listed.step()
        if a.bearing_cycle is not None:
            for x, y in zip(a.bearing_cycle.reports(), b.bearings, strict=True):
                assert np.array_equal(x.tags, y.tags)
                assert np.array_equal(x.azimuth_rad, y.azimuth_rad)
                assert np.array_equal(x.distance_m, y.distance_m)
