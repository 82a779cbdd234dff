"""Physics backends chosen by name: the registry, the numpy default, and the pybullet backend's
motion, contacts, rays, determinism and rendering (skipped where pybullet is missing)."""

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError, SimulationError
from swarm_sim.geometry import point_segment_distance
from swarm_sim.physics import (
    PHYSICS_BACKENDS,
    NumpyPhysics,
    PhysicsSetup,
    PybulletConfig,
    RenderConfig,
    make_physics,
)
from swarm_sim.site_geometry import geometry_from_site
from swarm_sim.site_loading import load_site

# A 6 m x 3 m hall with a 2 m room on the right, door at y in [1, 2].
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
HALF_T = 0.0125
RADIUS = 0.1


def needs_pybullet():
    return pytest.importorskip('pybullet', reason='pybullet is not installed (Python > 3.11?)')


def setup_of(poses, walls=WALLS, **pybullet):
    return PhysicsSetup(
        walls=walls,
        initial_poses=np.array(poses, dtype=float),
        pybullet=PybulletConfig(**pybullet),
    )


def drive(backend, commands, seconds, dt=0.1):
    for _ in range(round(seconds / dt)):
        backend.step(np.array(commands, dtype=float), dt)


# The registry -------------------------------------------------------------------------


def test_backends_are_chosen_by_name_and_unknown_names_are_refused():
    assert set(PHYSICS_BACKENDS) == {'numpy', 'pybullet'}
    assert isinstance(make_physics('numpy', setup_of([[1.0, 1.0, 0.0]])), NumpyPhysics)
    with pytest.raises(ConfigurationError, match=r"unknown physics backend 'bullet'.*numpy"):
        make_physics('bullet', setup_of([[1.0, 1.0, 0.0]]))
    with pytest.raises(ConfigurationError, match='unknown physics backend'):
        EngineConfig(physics='ode')


def test_rendering_needs_the_pybullet_backend():
    with pytest.raises(ConfigurationError, match='needs the pybullet physics'):
        EngineConfig(render=RenderConfig(mode='gui'))
    with pytest.raises(ConfigurationError, match='frames directory'):
        RenderConfig(mode='frames')
    with pytest.raises(ConfigurationError, match='unknown render mode'):
        RenderConfig(mode='movie')


def test_pybullet_settings_are_checked():
    with pytest.raises(ConfigurationError, match='substeps'):
        PybulletConfig(substeps=0)
    with pytest.raises(ConfigurationError, match='sensor_height_m'):
        PybulletConfig(sensor_height_m=0.25)


def test_default_engine_runs_the_numpy_backend():
    site = SiteGeometry(walls=WALLS, room_rects=np.array([[4.03, 0.03, 5.97, 2.97]]))
    engine = SimEngine(site, np.array([[1.0, 1.5, 0.0]]), EngineConfig())
    assert isinstance(engine.world, NumpyPhysics)


def test_the_simulator_imports_and_runs_without_pybullet():
    # pybullet blocked: every module of the engine imports, the numpy backend runs and the
    # pybullet backend says why it cannot start.
    code = textwrap.dedent(
        """
        import sys
        sys.modules['pybullet'] = None
        import numpy as np
        from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
        from swarm_sim.errors import SimulationError
        site = SiteGeometry(walls=np.array([[[0.0, 0.0], [4.0, 0.0]]]),
                            room_rects=np.array([[0.0, 0.0, 4.0, 3.0]]))
        engine = SimEngine(site, np.array([[1.0, 1.0, 0.0]]))
        engine.set_velocity_command(0, 0.3, 0.0)
        out = engine.step()
        assert out.poses[0, 0] > 1.0
        try:
            SimEngine(site, np.array([[1.0, 1.0, 0.0]]), EngineConfig(physics='pybullet'))
        except SimulationError as err:
            print('refused:', err)
        """
    )
    done = subprocess.run(
        [sys.executable, '-c', code], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert 'refused: pybullet is not installed' in done.stdout


# pybullet: motion and contacts ----------------------------------------------------------


def test_free_motion_follows_the_unicycle():
    needs_pybullet()
    with_pb = make_physics('pybullet', setup_of([[1.0, 1.5, 0.0]]))
    exact = make_physics('numpy', setup_of([[1.0, 1.5, 0.0]]))
    try:
        for backend in (with_pb, exact):
            drive(backend, [[0.3, 0.4]], 3.0)
        # 10 pybullet steps per 0.1 s: chords of the arc, within a millimetre after 0.9 m.
        assert np.allclose(with_pb.poses, exact.poses, atol=1e-3)
        assert with_pb.velocities[0] == pytest.approx([0.3, 0.4], abs=1e-3)
    finally:
        with_pb.close()


def test_commands_are_clipped_and_garbage_stops_the_robot():
    needs_pybullet()
    backend = make_physics('pybullet', setup_of([[1.0, 1.5, 0.0]]))
    try:
        drive(backend, [[5.0, 0.0]], 1.0)
        assert backend.poses[0, 0] == pytest.approx(1.5, abs=1e-6)  # 0.5 m/s limit
        drive(backend, [[math.nan, math.inf]], 1.0)
        assert backend.poses[0, 0] == pytest.approx(1.5, abs=1e-6)
    finally:
        backend.close()


def test_a_robot_driving_into_a_wall_stops_at_its_face():
    needs_pybullet()
    backend = make_physics('pybullet', setup_of([[3.0, 0.5, 0.0]]))
    try:
        drive(backend, [[0.5, 0.0]], 4.0)  # towards the room's wall at x = 4
        x = backend.poses[0, 0]
        assert 4.0 - HALF_T - RADIUS - 1e-3 <= x <= 4.0 - HALF_T - RADIUS + 1e-3
        assert backend.velocities[0, 0] == pytest.approx(0.0, abs=0.01)
        assert backend.collision_count[0] > 0
    finally:
        backend.close()


def test_a_robot_pressed_against_a_wall_at_an_angle_slides_along_it():
    needs_pybullet()
    # Heading 45 degrees down into the floor wall y = 0, 0.3 m/s.
    backend = make_physics('pybullet', setup_of([[1.0, 0.3, -math.pi / 4]]))
    numpy_world = make_physics('numpy', setup_of([[1.0, 0.3, -math.pi / 4]]))
    try:
        for b in (backend, numpy_world):
            drive(b, [[0.3, 0.0]], 5.0)
        x, y, yaw = backend.poses[0]
        assert y == pytest.approx(HALF_T + RADIUS, abs=1e-3)
        assert yaw == pytest.approx(-math.pi / 4, abs=1e-3)  # frictionless: not turned
        # After reaching the wall it slides at 0.3 cos 45 deg; the numpy robot stalls.
        assert x > 1.0 + 0.17 + 0.3 * math.cos(math.pi / 4) * 4.0
        assert numpy_world.poses[0, 0] < 1.0 + 0.2
    finally:
        backend.close()


def test_a_robot_pushes_another_and_contacts_can_be_switched_off():
    needs_pybullet()
    poses = [[1.0, 1.5, 0.0], [1.5, 1.5, 0.0]]
    pushing = make_physics('pybullet', setup_of(poses))
    passing = make_physics('pybullet', setup_of(poses, robot_contacts=False))
    try:
        for b in (pushing, passing):
            drive(b, [[0.4, 0.0], [0.0, 0.0]], 3.0)
        gap = pushing.poses[1, 0] - pushing.poses[0, 0]
        assert gap == pytest.approx(2 * RADIUS, abs=2e-3)
        assert pushing.poses[1, 0] > 1.6  # shoved along
        assert passing.poses[1, 0] == pytest.approx(1.5, abs=1e-9)
        assert passing.poses[0, 0] == pytest.approx(2.2, abs=1e-3)
    finally:
        pushing.close()
        passing.close()


def test_pybullet_runs_are_deterministic():
    needs_pybullet()
    rng = np.random.default_rng(3)
    poses = [[1.0, 0.5, 0.3], [1.0, 1.5, -0.2], [2.0, 2.5, 2.0], [3.0, 1.0, 1.0]]
    commands = rng.uniform([-0.2, -2.0], [0.5, 2.0], (60, 4, 2))
    results = []
    for _ in range(2):
        backend = make_physics('pybullet', setup_of(poses))
        try:
            trace = []
            for cmd in commands:
                backend.step(cmd, 0.1)
                trace.append(backend.poses)
            results.append((np.array(trace), backend.scan(backend.poses, 12.0)))
        finally:
            backend.close()
    assert np.array_equal(results[0][0], results[1][0])
    assert np.array_equal(results[0][1], results[1][1])


def test_a_different_physics_period_is_split_into_the_same_substeps():
    needs_pybullet()
    backend = make_physics('pybullet', setup_of([[1.0, 1.5, 0.0]], substeps=4))
    try:
        drive(backend, [[0.2, 0.0]], 1.0, dt=0.05)
        assert backend.poses[0, 0] == pytest.approx(1.2, abs=1e-9)
    finally:
        backend.close()


# pybullet: rays ---------------------------------------------------------------------


def _clear_points(walls, count, rng, spacing_m=0.0):
    lo, hi = walls.reshape(-1, 2).min(axis=0), walls.reshape(-1, 2).max(axis=0)
    points: list[np.ndarray] = []
    while len(points) < count:
        p = rng.uniform(lo, hi)
        if point_segment_distance(p[None], walls).min() <= RADIUS + HALF_T + 0.01:
            continue
        if all(np.hypot(*(p - q)) > spacing_m for q in points):
            points.append(p)
    return np.array(points)


def test_lidar_ranges_agree_with_the_numpy_caster_on_a_static_scene():
    needs_pybullet()
    walls = geometry_from_site(load_site('small', seed=1)).walls
    rng = np.random.default_rng(0)
    xy = _clear_points(walls, 10, rng, spacing_m=2 * RADIUS + 0.01)
    poses = np.column_stack([xy, rng.uniform(-3.0, 3.0, 10)])
    numpy_backend = make_physics('numpy', setup_of(poses, walls))
    backend = make_physics('pybullet', setup_of(poses, walls))
    try:
        expected = numpy_backend.scan(poses, 12.0)
        got = backend.scan(poses, 12.0)
    finally:
        backend.close()
    assert np.array_equal(np.isinf(got), np.isinf(expected))
    finite = np.isfinite(expected)
    error = np.where(finite, np.abs(got - np.where(finite, expected, 0.0)), 0.0)
    # Every ray agrees within 1 cm but those grazing another robot's disc within 2 mm of
    # its edge (Bullet's cylinder tolerance turns a near miss into a hit).
    angles = poses[:, 2, None] - math.pi + 2 * math.pi / 360 * np.arange(360)
    direction = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    offsets = xy[None, :, :] - xy[:, None, :]  # viewer, target
    along = np.einsum('vbk,vtk->vbt', direction, offsets)
    across = np.abs(np.einsum('vbk,vtk->vbt', direction[..., ::-1] * [1, -1], offsets))
    grazing = ((np.abs(across - RADIUS) < 2e-3) & (along > 0)).any(axis=2)
    assert error[~grazing].max() < 0.01
    assert grazing.sum() < 0.01 * grazing.size  # few rays are left out


# pybullet: rendering ------------------------------------------------------------------


def test_frames_are_written_as_pngs_and_an_animated_gif(tmp_path):
    needs_pybullet()
    image = pytest.importorskip('PIL.Image')
    render = RenderConfig(mode='frames', frames_dir=tmp_path / 'frames', frame_rate_hz=5.0)
    setup = PhysicsSetup(walls=WALLS, initial_poses=np.array([[1.0, 1.5, 0.0]]), render=render)
    backend = make_physics('pybullet', setup)
    drive(backend, [[0.5, 0.0]], 1.0)
    backend.close()
    frames = sorted((tmp_path / 'frames').glob('frame_*.png'))
    assert len(frames) == 6  # t = 0, 0.2, ..., 1.0 s
    first, last = (
        np.asarray(image.open(f).convert('RGB'), dtype=int) for f in (frames[0], frames[-1])
    )
    assert first.shape == (480, 640, 3)
    assert np.abs(first - last).sum() > 0  # the robot moved
    with image.open(tmp_path / 'frames' / 'run.gif') as gif:
        assert gif.n_frames == 6


def test_the_window_without_a_display_is_refused_in_one_line(monkeypatch):
    needs_pybullet()
    monkeypatch.delenv('DISPLAY', raising=False)
    monkeypatch.delenv('WAYLAND_DISPLAY', raising=False)
    monkeypatch.setattr(sys, 'platform', 'linux')
    setup = PhysicsSetup(
        walls=WALLS, initial_poses=np.array([[1.0, 1.5, 0.0]]), render=RenderConfig(mode='gui')
    )
    with pytest.raises(SimulationError, match='needs a display') as err:
        make_physics('pybullet', setup)
    assert '\n' not in str(err.value)


def test_a_pybullet_engine_runs_every_sensor():
    needs_pybullet()
    site = SiteGeometry(walls=WALLS, room_rects=np.array([[4.03, 0.03, 5.97, 2.97]]))
    poses = np.array([[1.0, 1.5, 0.0], [5.0, 0.5, 0.0]])
    with SimEngine(site, poses, EngineConfig(physics='pybullet', seed=2)) as engine:
        client = engine.world.client
        engine.set_velocity_command(0, 0.3, 0.0)
        outs = [engine.step() for _ in range(5)]
        assert any(out.scans is not None for out in outs)
        assert any(out.bearings is not None for out in outs)
        assert engine.world.poses[0, 0] == pytest.approx(1.15, abs=1e-3)
    assert client >= 0
    assert engine.world.client == -1  # released by the with block
