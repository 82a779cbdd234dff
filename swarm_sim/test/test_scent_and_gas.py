"""Scent trail and MP503 model: rise and fall, spreading, walls, and the paper's threshold."""

import itertools
import math

import numpy as np
import pytest
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.gas_sensor import RAW_MAX, GasSensorConfig, Mp503Model
from swarm_sim.sensors.scent import PumpDepositor, ScentConfig, ScentField

THRESHOLD = 200  # the paper's trail threshold on the 10-bit scale
QUIET = GasSensorConfig(noise_std_raw=0.0)


def test_clean_air_reads_below_the_paper_background():
    sensor = Mp503Model(3, GasSensorConfig(), np.random.default_rng(0))
    readings = np.concatenate([sensor.update(np.zeros(3), 0.1) for _ in range(100)])
    assert readings.max() < 100
    assert readings.min() >= 0


def test_sensor_rises_slowly_and_falls_more_slowly():
    sensor = Mp503Model(1, QUIET, np.random.default_rng(0))
    exposure = np.array([1000.0])
    rise = [int(sensor.update(exposure, 0.1)[0]) for _ in range(100)]
    fall = [int(sensor.update(np.zeros(1), 0.1)[0]) for _ in range(600)]
    assert rise[0] < THRESHOLD  # not instantaneous
    assert rise[-1] > 600  # settles high within 10 s
    assert all(b >= a for a, b in itertools.pairwise(rise))
    time_to_half_rise = next(i for i, r in enumerate(rise) if r > (rise[0] + rise[-1]) / 2)
    time_to_half_fall = next(i for i, r in enumerate(fall) if r < (fall[0] + 60) / 2)
    assert time_to_half_fall > 2 * time_to_half_rise
    assert fall[299] < THRESHOLD  # no longer a trail 30 s after leaving it
    assert fall[-1] < 100  # back to background after a minute


def test_threshold_and_concentration_conversions_invert_each_other():
    ppm = QUIET.ppm_for_raw(THRESHOLD)
    assert QUIET.raw_for_ppm(ppm) == pytest.approx(THRESHOLD)
    with pytest.raises(ConfigurationError, match='outside the sensor span'):
        QUIET.ppm_for_raw(RAW_MAX + 5)


def test_a_puff_spreads_and_decays_but_keeps_its_mass_while_spreading():
    field = ScentField(ScentConfig(decay_time_constant_s=100.0))
    field.deposit(np.array([[0.0, 0.0]]), 0.0, np.array([10.0]))
    centre = [field.concentration(np.array([[0.0, 0.0]]), t)[0] for t in (0.5, 5.0, 50.0)]
    assert centre[0] > centre[1] > centre[2] > 0.0
    grid = np.stack(np.meshgrid(np.linspace(-2, 2, 161), np.linspace(-2, 2, 161)), -1)
    total = field.concentration(grid.reshape(-1, 2), 20.0).sum() * (4 / 160) ** 2
    assert total == pytest.approx(10.0 * math.exp(-20.0 / 100.0), rel=0.02)


def test_walls_block_the_vapour():
    wall = np.array([[[0.2, -1.0], [0.2, 1.0]]])
    field = ScentField(ScentConfig(), wall)
    field.deposit(np.array([[0.0, 0.0]]), 0.0, np.array([50.0]))
    c = field.concentration(np.array([[0.1, 0.0], [0.3, 0.0]]), 20.0)
    assert c[0] > 0.0
    assert c[1] == 0.0


def pumping_robot_readings(speed_mps: float, duration_s: float, field: ScentField):
    """Drive one robot along +x with the paper's pump cycle; return its gas readings."""
    sensor = Mp503Model(1, QUIET, np.random.default_rng(0))
    depositor = PumpDepositor(field, 1)
    dt = 0.05
    readings = []
    for step in range(1, int(duration_s / dt) + 1):
        t = step * dt
        x = speed_mps * t
        pump_on = math.fmod(t, 5.0) < 0.5
        depositor.step(np.array([pump_on]), np.array([[x - 0.12, 0.0]]), t, dt)
        if step % 2 == 0:
            c = field.concentration(np.array([[x + 0.08, 0.0]]), t)
            readings.append(int(sensor.update(c, 0.1)[0]))
    return readings


def test_a_moving_robot_does_not_smell_its_own_fresh_puffs():
    readings = pumping_robot_readings(0.3, 60.0, ScentField(ScentConfig()))
    assert max(readings) < 100


def test_a_passed_trail_reads_above_threshold_within_seconds():
    field = ScentField(ScentConfig())
    pumping_robot_readings(0.3, 60.0, field)  # lays a trail along y = 0 from x = 0 to 18 m
    sensor = Mp503Model(1, QUIET, np.random.default_rng(1))
    dt, start_s = 0.1, 90.0
    above_after_s = None
    for step in range(1, 200):
        t = start_s + step * dt
        x = 2.0 + 0.3 * step * dt  # a second robot follows the same line 30 s later
        reading = sensor.update(field.concentration(np.array([[x, 0.05]]), t), dt)[0]
        if reading > THRESHOLD and above_after_s is None:
            above_after_s = step * dt
    assert above_after_s is not None
    assert above_after_s < 5.0
    assert reading > THRESHOLD


def test_a_short_pulse_still_leaves_its_puff_when_the_pump_stops():
    field = ScentField(ScentConfig(deposit_period_s=0.25, deposit_rate_ppm_m2_per_s=100.0))
    depositor = PumpDepositor(field, 2)
    depositor.step(np.array([True, False]), np.zeros((2, 2)), 0.1, 0.1)
    assert field.num_puffs == 0
    depositor.step(np.array([False, False]), np.ones((2, 2)), 0.2, 0.1)
    _, _, mass = field.puffs
    assert field.num_puffs == 1
    assert mass[0] == pytest.approx(10.0)


def test_scent_config_rejects_a_shrinking_spread():
    with pytest.raises(ConfigurationError, match='final_spread_m'):
        ScentConfig(initial_spread_m=0.5, final_spread_m=0.1)


@pytest.mark.parametrize('with_walls', [True, False])
def test_the_compiled_pair_search_gives_the_numpy_concentration_bit_for_bit(with_walls):
    rng = np.random.default_rng(11)
    walls = np.zeros((0, 2, 2))
    if with_walls:
        starts = rng.uniform(0.0, 4.0, (25, 2))
        walls = np.stack([starts, starts + rng.uniform(-1.0, 1.0, (25, 2))], axis=1)
    field = ScentField(ScentConfig(), walls)
    unblocked = ScentField(ScentConfig(walls_block=False), walls)
    points = rng.uniform(-0.5, 4.5, (12, 2))
    assert np.array_equal(field.concentration(points, 0.0), np.zeros(12))
    for step in range(1, 61):
        # Puffs laid near the query points, so that many pairs are in reach.
        near = points[rng.integers(0, 12, 20)] + rng.normal(0.0, 0.3, (20, 2))
        mass = rng.uniform(1.0, 30.0, 20)
        field.deposit(near, 0.5 * step, mass)
        unblocked.deposit(near, 0.5 * step, mass)
    checked = 0
    blocked = False
    for time_s in (30.0, 100.0, 12.25, 0.5):  # also queries of the past
        compiled = field.concentration(points, time_s)
        assert np.array_equal(compiled, field.concentration_reference(points, time_s))
        free = unblocked.concentration(points, time_s)
        assert np.array_equal(free, unblocked.concentration_reference(points, time_s))
        checked += np.count_nonzero(compiled)
        blocked |= not np.array_equal(compiled, free)
    assert checked > 20
    # With walls, some vapour paths are blocked (the wall test was exercised).
    assert blocked == with_walls


@pytest.mark.parametrize(
    'config',
    [
        GasSensorConfig(),
        GasSensorConfig(noise_std_raw=0.0, baseline_raw=0.0),
        GasSensorConfig(rise_time_constant_s=0.05, fall_time_constant_s=40.0, noise_std_raw=30.0),
    ],
)
def test_the_compiled_gas_update_gives_the_numpy_readings_bit_for_bit(config):
    """Same readings and lagged concentrations from the same random state, on concentrations
    from clean air to saturation, with NaN, +-inf, negative and -0.0 values and varied dt."""
    rng = np.random.default_rng(3)
    compiled = Mp503Model(12, config, np.random.default_rng(9))
    reference = Mp503Model(12, config, np.random.default_rng(9))
    for step in range(400):
        c = rng.choice([0.0, 1.0, 50.0, 400.0, 1e4, 1e300], 12) * rng.random(12)
        special = rng.random(12)
        c[special < 0.05] = math.nan
        c[(special >= 0.05) & (special < 0.08)] = math.inf
        c[(special >= 0.08) & (special < 0.1)] = -math.inf
        c[(special >= 0.1) & (special < 0.15)] = -3.0
        c[(special >= 0.15) & (special < 0.2)] = -0.0
        dt = 0.1 if step % 3 else float(rng.uniform(0.01, 2.0))
        got = compiled.update(c.copy(), dt)
        with np.errstate(over='ignore'):  # saturated sensors
            want = reference.update_reference(c.copy(), dt)
        assert got.dtype.kind == want.dtype.kind == 'i'
        assert got.tolist() == want.tolist()
        assert compiled.sensed_ppm.tobytes() == reference.sensed_ppm.tobytes()
    assert 0 < int(want.max()) <= RAW_MAX
