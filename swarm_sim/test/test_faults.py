"""Injected faults: deterministic from the seed, each acting on its own robots and readings."""

import math

import numpy as np
import pytest
from swarm_common.angles import wrap_angle
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError
from swarm_sim.faults import FAULT_KINDS, FaultConfig, FaultInjector, FaultPlan

# A 6 m x 3 m hall with a 2 m room on the right, door at y in [1, 2] (as in test_engine).
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
POSES = [[1.0, 1.5, 0.0], [2.0, 0.5, 1.0], [1.0, 2.5, -1.0]]


def run(faults=None, seconds=4.0, command=(0.1, 0.2), pump=True, poses=POSES):
    site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
    config = EngineConfig(seed=3, faults=faults or FaultConfig())
    engine = SimEngine(site, np.array(poses, dtype=float), config, bearing_cycles=True)
    outputs = []
    for _ in range(round(seconds * config.physics_rate_hz)):
        for i in range(engine.num_robots):
            engine.set_velocity_command(i, *command)
            engine.set_pump(i, pump)
        outputs.append(engine.step())
    return engine, outputs


def test_no_fault_builds_no_hook_and_faults_that_never_start_change_nothing():
    engine, base = run()
    assert engine.fault_plan is None
    assert not FaultConfig().active
    late = FaultConfig(
        dropout_robots=1,
        dropout_time_s=1e5,
        stuck_gas_robots=1,
        stale_lidar_robots=1,
        sensor_time_s=1e5,
        bearing_dropout_probability=0.5,
    )
    engine, faulty = run(late)
    assert engine.fault_plan is not None
    for a, b in zip(base, faulty, strict=True):
        assert np.array_equal(a.poses, b.poses)
        for name in ('scans', 'gas_raw'):
            x, y = getattr(a, name), getattr(b, name)
            assert (x is None and y is None) or np.array_equal(x, y)
        if a.imu is not None:
            assert np.array_equal(a.imu[0], b.imu[0])
        if a.bearing_cycle is not None:
            assert np.array_equal(a.bearing_cycle.azimuth_rad, b.bearing_cycle.azimuth_rad)
        assert not b.withheld


def test_the_faulty_robots_follow_from_the_seed_and_never_overlap():
    config = FaultConfig(dropout_robots=2, stale_lidar_robots=1, stuck_gas_robots=2)
    plans = [FaultPlan(config, 10, seed) for seed in range(6)]
    again = FaultPlan(config, 10, 0)
    assert all(np.array_equal(plans[0].robots[k], again.robots[k]) for k in FAULT_KINDS)
    assert len({tuple(p.robots['dropout']) for p in plans}) > 1
    for plan in plans:
        chosen = np.concatenate([plan.robots[k] for k in FAULT_KINDS])
        assert len(chosen) == len(set(chosen.tolist())) == 5
        assert [len(plan.robots[k]) for k in FAULT_KINDS] == [2, 1, 2, 0, 0]
    with pytest.raises(ConfigurationError, match='only 4 robots'):
        FaultPlan(config, 4, 0)


@pytest.mark.parametrize(
    'bad',
    [
        {'dropout_robots': -1},
        {'dropout_time_s': math.nan},
        {'comm_loss_probability': 1.5},
        {'comm_range_m': 0.0},
        {'bearing_dropout_probability': -0.1},
    ],
)
def test_bad_fault_values_are_rejected(bad):
    with pytest.raises(ConfigurationError):
        FaultConfig(**bad)


def test_dropped_robots_stop_for_good_with_their_pumps():
    faults = FaultConfig(dropout_robots=1, dropout_time_s=1.0)
    engine, outputs = run(faults, seconds=3.0)
    (dropped,) = engine.fault_plan.robots['dropout']
    before = [o for o in outputs if o.time_s < 1.0 - 1e-9]
    after = [o for o in outputs if o.time_s > 1.05]
    assert not np.allclose(before[0].poses[dropped], before[-1].poses[dropped])
    assert np.array_equal(after[0].poses[dropped], after[-1].poses[dropped])
    others = [i for i in range(3) if i != dropped]
    assert not np.allclose(after[0].poses[others], after[-1].poses[others])
    hook = FaultInjector(engine.fault_plan, 3)
    commands, pumps = hook.actuators(2.0, np.ones((3, 2)), np.ones(3, dtype=bool))
    assert not pumps[dropped]
    assert pumps[others].all()
    assert np.array_equal(commands[dropped], [0.0, 0.0])
    assert (commands[others] == 1.0).all()


def test_a_stale_lidar_publishes_nothing_from_the_fault_time():
    engine, outputs = run(FaultConfig(stale_lidar_robots=1, sensor_time_s=1.0))
    (stale,) = engine.fault_plan.robots['stale_lidar']
    scans = [o for o in outputs if o.scans is not None]
    assert all(o.published('scan', stale) for o in scans if o.time_s < 1.0 - 1e-9)
    late = [o for o in scans if o.time_s >= 1.0]
    assert late
    assert not any(o.published('scan', stale) for o in late)
    assert all(o.published('scan', i) for o in late for i in range(3) if i != stale)
    assert all(o.published('gas', stale) for o in outputs)


def test_stuck_and_drifting_gas_sensors_read_what_the_plan_says():
    _, base = run(seconds=6.0)
    faults = FaultConfig(
        stuck_gas_robots=1, drifting_gas_robots=1, gas_drift_per_s=20.0, sensor_time_s=2.0
    )
    engine, faulty = run(faults, seconds=6.0)
    (stuck,) = engine.fault_plan.robots['stuck_gas']
    (drifting,) = engine.fault_plan.robots['drifting_gas']
    pairs = [(a, b) for a, b in zip(base, faulty, strict=True) if a.gas_raw is not None]
    late = [(a, b) for a, b in pairs if a.time_s >= 2.0 - 1e-9]
    frozen = late[0][0].gas_raw[stuck]
    assert len({int(a.gas_raw[stuck]) for a, _ in late}) > 1  # the true reading changes
    for a, b in late:
        assert b.gas_raw[stuck] == frozen
        expected = min(1023, round(a.gas_raw[drifting] + 20.0 * (a.time_s - 2.0)))
        assert b.gas_raw[drifting] == expected
        healthy = [i for i in range(3) if i not in (stuck, drifting)]
        assert np.array_equal(a.gas_raw[healthy], b.gas_raw[healthy])
    for a, b in pairs:
        if a.time_s < 2.0 - 1e-9:
            assert np.array_equal(a.gas_raw, b.gas_raw)


def test_imu_yaw_drift_adds_its_rate_from_the_fault_time():
    _, base = run()
    engine, faulty = run(FaultConfig(imu_drift_robots=1, imu_drift_radps=0.1, sensor_time_s=1.0))
    (drift,) = engine.fault_plan.robots['imu_drift']
    for a, b in zip(base, faulty, strict=True):
        if a.imu is None:
            continue
        change = wrap_angle(b.imu[0] - a.imu[0])
        expected = 0.1 * (a.time_s - 1.0) if a.time_s >= 1.0 - 1e-9 else 0.0
        assert change[drift] == pytest.approx(expected, abs=1e-9)
        assert np.count_nonzero(change) <= 1


def entries(cycle):
    fields = (cycle.receivers, cycle.tags, cycle.azimuth_rad)
    return set(zip(*(f.tolist() for f in fields), strict=True))


def test_aoa_dropouts_lose_reports_at_their_rate_and_keep_the_rest_intact():
    _, base = run(seconds=20.0)
    _, faulty = run(FaultConfig(bearing_dropout_probability=0.5), seconds=20.0)
    total = kept = 0
    for a, b in zip(base, faulty, strict=True):
        if a.bearing_cycle is None:
            continue
        ca, cb = a.bearing_cycle, b.bearing_cycle
        total += len(ca.tags)
        kept += len(cb.tags)
        full = set(
            zip(ca.receivers.tolist(), ca.tags.tolist(), ca.azimuth_rad.tolist(), strict=False)
        )
        assert (
            set(zip(cb.receivers.tolist(), cb.tags.tolist(), cb.azimuth_rad.tolist(), strict=False))
            <= full
        )
        for i, report in enumerate(cb.reports()):
            assert report.receiver == i
            assert len(report.tags) == cb.bounds[i + 1] - cb.bounds[i]
    assert total > 200
    assert 0.4 < kept / total < 0.6


def test_link_faults_combine_with_the_algorithms_own():
    plan = FaultPlan(FaultConfig(comm_range_m=50.0, comm_loss_probability=0.5), 3, 0)
    assert plan.combined_loss(0.2) == pytest.approx(0.6)
    assert plan.combined_range_m(None) == 50.0
    assert plan.combined_range_m(20.0) == 20.0
    quiet = FaultPlan(FaultConfig(dropout_robots=1), 3, 0)
    assert quiet.combined_loss(0.1) == 0.1
    assert quiet.combined_range_m(None) is None


def test_a_stuck_signal_sensor_holds_its_first_faulty_reading():
    plan = FaultPlan(FaultConfig(stuck_gas_robots=1, sensor_time_s=5.0), 2, 0)
    (stuck,) = plan.robots['stuck_gas']
    held: dict[int, float] = {}
    assert plan.signal(stuck, 1.0, 4.0, held) == 1.0
    assert plan.signal(stuck, 2.0, 5.0, held) == 2.0
    assert plan.signal(stuck, 3.0, 6.0, held) == 2.0
    assert plan.signal(1 - stuck, 3.0, 6.0, held) == 3.0
    drifting = FaultPlan(FaultConfig(drifting_gas_robots=1, gas_drift_per_s=0.5), 1, 0)
    assert drifting.signal(0, 1.0, 4.0, {}) == pytest.approx(3.0)
