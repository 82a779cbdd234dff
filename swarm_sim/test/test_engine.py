"""The bridge engine: sensor schedule, stale-command watchdogs, pump deposits, coverage."""

import math

import numpy as np
import pytest
from swarm_sim.engine import SENSORS, EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError, WorldGeometryError
from swarm_sim.ground_truth import CoverageTracker

# A 6 m x 3 m hall with one 2 m x 3 m room on the right, door at y in [1, 2].
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


def make_engine(poses, **overrides):
    site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
    return SimEngine(site, np.array(poses, dtype=float), EngineConfig(**overrides))


def run(engine, seconds, command=None):
    outputs = []
    for _ in range(round(seconds * engine.config.physics_rate_hz)):
        if command is not None:
            for i in range(engine.num_robots):
                engine.set_velocity_command(i, *command)
        outputs.append(engine.step())
    return outputs


def test_each_sensor_keeps_its_average_rate():
    engine = make_engine([[1.0, 1.5, 0.0]])
    outputs = run(engine, 10.0)
    counts = {
        'scans': sum(o.scans is not None for o in outputs),
        'gas_raw': sum(o.gas_raw is not None for o in outputs),
        'imu': sum(o.imu is not None for o in outputs),
        'odometry': sum(o.odometry is not None for o in outputs),
        'bearings': sum(o.bearings is not None for o in outputs),
    }
    cfg = engine.config
    assert counts['scans'] == pytest.approx(10 * cfg.lidar.rate_hz, abs=1)
    assert counts['gas_raw'] == 10 * cfg.gas.rate_hz
    assert counts['imu'] == 10 * cfg.imu.rate_hz
    assert counts['odometry'] == 10 * cfg.odometry.rate_hz
    assert counts['bearings'] == 10 * cfg.bearings.rate_hz


def test_a_robot_whose_commands_go_stale_stops():
    engine = make_engine([[1.0, 1.5, 0.0]], cmd_vel_timeout_s=0.5)
    engine.set_velocity_command(0, 0.3, 0.0)
    run(engine, 2.0)
    # Moved only for the 0.5 s the command stayed fresh.
    dt = engine.config.physics_period_s
    assert engine.world.poses[0, 0] == pytest.approx(1.0 + 0.3 * 0.5, abs=0.3 * dt + 1e-9)
    assert engine.world.velocities[0, 0] == 0.0


def test_a_pump_left_on_switches_off_after_its_timeout():
    engine = make_engine([[1.0, 1.5, 0.0]], pump_timeout_s=1.0)
    engine.set_pump(0, True)
    run(engine, 5.0)
    _, times, _ = engine.scent.puffs
    assert engine.scent.num_puffs >= 4
    assert times.max() <= 1.0 + 0.25 + 1e-9


def test_non_finite_commands_are_taken_as_stop():
    engine = make_engine([[1.0, 1.5, 0.0]])
    run(engine, 1.0, command=(math.nan, math.inf))
    assert engine.world.poses[0] == pytest.approx([1.0, 1.5, 0.0])


def test_a_robot_entering_the_room_is_recorded_as_its_first_visitor():
    engine = make_engine([[1.0, 1.5, 0.0], [1.0, 0.5, math.pi]])
    outputs = run(engine, 12.0, command=(0.4, 0.0))
    entries = [e for o in outputs for e in o.new_room_entries]
    assert len(entries) == 1
    assert entries[0].robot_index == 0
    # The disc reaches the room interior at x = 4.03 - 0.1 after 2.93 m at 0.4 m/s.
    assert entries[0].time_s == pytest.approx(2.93 / 0.4, abs=engine.config.physics_period_s)
    assert engine.coverage.complete


def test_runs_with_the_same_seed_are_identical_and_other_seeds_differ():
    def trace(seed):
        engine = make_engine([[1.0, 1.5, 0.0], [2.0, 0.5, 1.0]], seed=seed)
        outputs = run(engine, 3.0, command=(0.2, 0.3))
        return np.concatenate([o.scans.ravel() for o in outputs if o.scans is not None])

    assert np.array_equal(trace(7), trace(7))
    assert not np.array_equal(trace(7), trace(8))


def test_scan_sees_the_hall_walls():
    engine = make_engine([[1.0, 1.5, 0.0]], seed=3)
    scans = next(o.scans for o in run(engine, 1.0) if o.scans is not None)
    left = scans[0, 270]  # +90 deg: the wall at y = 3
    assert left == pytest.approx(1.5 - 0.0125, rel=0.05)


def test_bad_robot_index_and_configuration_are_rejected():
    engine = make_engine([[1.0, 1.5, 0.0]])
    with pytest.raises(WorldGeometryError, match='out of range'):
        engine.set_velocity_command(3, 0.1, 0.0)
    with pytest.raises(ConfigurationError, match='physics_rate_hz'):
        EngineConfig(physics_rate_hz=0.0)


def test_coverage_counts_a_room_only_once_the_body_is_inside():
    tracker = CoverageTracker(np.array([[0.0, 0.0, 1.0, 1.0]]), robot_radius_m=0.1)
    assert tracker.update(np.array([[-0.15, 0.5]]), 1.0) == []
    first = tracker.update(np.array([[-0.05, 0.5], [0.5, 0.5]]), 2.0)
    assert [(e.room_index, e.robot_index, e.time_s) for e in first] == [(0, 0, 2.0)]
    assert tracker.update(np.array([[0.5, 0.5]]), 3.0) == []
    assert tracker.fraction == 1.0


def test_leaving_a_reading_out_changes_none_of_the_others():
    def outputs(sensors=SENSORS):
        site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
        config = EngineConfig(sensors=sensors)
        engine = SimEngine(site, np.array([[1.0, 1.5, 0.0], [2.0, 0.5, 1.0]]), config)
        for i in range(2):
            engine.set_pump(i, True)
        return run(engine, 3.0, command=(0.2, 0.3))

    full = outputs()
    lean = outputs(frozenset({'scan', 'gas', 'bearings', 'imu'}))
    assert all(o.odometry is None for o in lean)
    assert any(o.odometry is not None for o in full)
    for a, b in zip(full, lean, strict=True):
        assert np.array_equal(a.poses, b.poses)
        for name in ('scans', 'gas_raw'):
            x, y = getattr(a, name), getattr(b, name)
            assert (x is None and y is None) or np.array_equal(x, y)
        assert (a.imu is None) == (b.imu is None)
        if a.imu is not None:
            assert np.array_equal(a.imu[0], b.imu[0])
        if a.bearings is not None:
            assert [r.azimuth_rad.tolist() for r in a.bearings] == [
                r.azimuth_rad.tolist() for r in b.bearings
            ]
    with pytest.raises(ConfigurationError, match='sonar'):
        outputs(frozenset({'scan', 'sonar'}))


def test_a_mission_runs_only_the_sensors_it_chooses():
    """An odometry-only world builds no lidar, gas, scent, bearings or IMU model, and its
    odometry and poses equal those of a world running every sensor (per-sensor streams)."""

    def run_with(sensors):
        site = SiteGeometry(walls=WALLS, room_rects=ROOM, name='hall')
        config = EngineConfig(sensors=sensors, seed=5)
        engine = SimEngine(site, np.array([[1.0, 1.5, 0.0], [2.0, 0.5, 1.0]]), config)
        engine.set_pump(0, True)
        return engine, run(engine, 3.0, command=(0.2, 0.3))

    lean_engine, lean = run_with(frozenset({'odometry'}))
    _, full = run_with(SENSORS)
    models = ('lidar', 'gas', 'scent', 'bearing_model', 'imu')
    assert all(getattr(lean_engine, name) is None for name in models)
    assert lean_engine.sensors == frozenset({'odometry'})
    assert any(o.odometry is not None for o in lean)
    for a, b in zip(full, lean, strict=True):
        assert (b.scans, b.gas_raw, b.bearings, b.imu) == (None, None, None, None)
        assert np.array_equal(a.poses, b.poses)
        assert (a.odometry is None) == (b.odometry is None)
        if a.odometry is not None:
            assert all(np.array_equal(x, y) for x, y in zip(a.odometry, b.odometry, strict=True))


def test_commands_set_together_equal_commands_set_one_by_one():
    """set_commands and set_velocity_commands (the batch paths' calls) record what
    set_velocity_command and set_pump record robot by robot, non-finite values included;
    a bad index records nothing."""
    rng = np.random.default_rng(8)
    poses = [[1.0 + 0.5 * i, 1.5, 0.0] for i in range(5)]
    together, one_by_one = make_engine(poses), make_engine(poses)
    velocities = make_engine(poses)
    for _ in range(30):
        robots = sorted(rng.choice(5, int(rng.integers(0, 6)), replace=False).tolist())
        commands = [
            (float(v), float(w))
            for v, w in rng.choice(
                [0.2, -0.1, math.nan, math.inf, -math.inf, 0.0], (len(robots), 2)
            )
        ]
        pumps = [bool(p) for p in rng.random(len(robots)) < 0.5]
        together.set_commands(robots, commands, pumps)
        velocities.set_velocity_commands(robots, commands)
        for robot, command, pump in zip(robots, commands, pumps, strict=True):
            one_by_one.set_velocity_command(robot, *command)
            one_by_one.set_pump(robot, pump)
        assert together.active_commands().tobytes() == one_by_one.active_commands().tobytes()
        assert velocities.active_commands().tobytes() == one_by_one.active_commands().tobytes()
        assert together.pumps_running().tolist() == one_by_one.pumps_running().tolist()
        for engine in (together, one_by_one, velocities):
            engine.step()
    before = together.active_commands()
    with pytest.raises(WorldGeometryError, match='out of range'):
        together.set_commands([0, 7], [(0.3, 0.0), (0.3, 0.0)], [True, True])
    with pytest.raises(WorldGeometryError, match='robot index -1 out of range'):
        together.set_commands([1, -1], [(0.3, 0.0), (0.3, 0.0)], [True, True])
    assert together.active_commands().tobytes() == before.tobytes()
    with pytest.raises(ValueError, match='pump states'):
        together.set_commands([0], [(0.3, 0.0)], [])
    before = velocities.active_commands()
    with pytest.raises(WorldGeometryError, match='robot index 5 out of range'):
        velocities.set_velocity_commands([0, 5], [(0.3, 0.0), (0.3, 0.0)])
    with pytest.raises(ValueError, match='1 robots and 2 commands'):
        velocities.set_velocity_commands([0], [(0.3, 0.0), (0.3, 0.0)])
    assert velocities.active_commands().tobytes() == before.tobytes()


def test_the_compiled_watchdogs_give_the_active_commands_and_pumps():
    """The step's compiled watchdogs equal active_commands() and pumps_running() on commands
    and pump states of every age around the timeouts (signed zeros included)."""
    from swarm_sim.world_kernel import actuators_kernel

    rng = np.random.default_rng(9)
    engine = make_engine([[1.0 + 0.5 * i, 1.5, 0.0] for i in range(6)])
    config = engine.config
    for step in range(200):
        engine.time_s = 0.1 * step
        engine._command[:] = rng.choice([0.3, -0.2, 0.0, -0.0], (6, 2))
        engine._command_time_s[:] = engine.time_s - rng.choice([0.0, 0.4, 0.5, 0.6, np.inf], 6)
        engine._pump_on[:] = rng.random(6) < 0.5
        engine._pump_time_s[:] = engine.time_s - rng.choice([0.0, 0.9, 1.0, 1.1, np.inf], 6)
        commands, pumping = actuators_kernel(
            engine.time_s,
            engine._command,
            engine._command_time_s,
            config.cmd_vel_timeout_s + 1e-9,
            engine._pump_on,
            engine._pump_time_s,
            config.pump_timeout_s + 1e-9,
        )
        assert commands.tobytes() == engine.active_commands().tobytes()
        assert pumping.tolist() == engine.pumps_running().tolist()


def test_the_compiled_nozzle_and_gas_sensor_places_equal_the_numpy_ones():
    from swarm_sim.world_kernel import body_points_kernel

    rng = np.random.default_rng(10)
    engine = make_engine([[1.0, 1.5, 0.0]])
    poses = np.column_stack([rng.uniform(-20.0, 20.0, (5000, 2)), rng.uniform(-7.0, 7.0, 5000)])
    poses[:8, 2] = [0.0, -0.0, math.pi, -math.pi, math.pi / 2, 1e-300, 100.0, -1e5]
    gas = body_points_kernel(poses, engine.config.gas.sensor_offset_m)
    nozzles = body_points_kernel(poses, -engine.config.pump_offset_m)
    assert gas.tobytes() == engine.gas_sensor_positions(poses).tobytes()
    assert nozzles.tobytes() == engine.nozzle_positions(poses).tobytes()
