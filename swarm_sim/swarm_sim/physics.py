"""Physics and ray-casting backends of the engine, chosen by name.

The engine needs three things of its physics: the robot bodies and their motion under
velocity commands (with collisions against the walls and each other), the lidar's ranges,
and a way to release what the backend holds. :class:`PhysicsBackend` is that contract;
:data:`PHYSICS_BACKENDS` maps each backend's name to its factory. (The wall counts on straight
paths, the bearing model's wall attenuation and the scent field's line of sight, are the
sensor models' own: they count crossings of the same wall centre lines on every backend.)

* ``numpy`` (:class:`NumpyPhysics`, the default): the kinematic disc world of
  :mod:`swarm_sim.world` (a move into contact is cancelled) and the exact 2D caster of
  :mod:`swarm_sim.geometry`, on the compiled kernels. Fast, and bit-identical to the engine
  before backends existed.
* ``pybullet`` (:class:`swarm_sim.pybullet_physics.PybulletPhysics`): rigid cylinders among
  box walls in a private pybullet client; pybullet resolves the contacts (robots slide along
  walls and push each other) and casts every ray with ``rayTestBatch``. It imports pybullet
  only when built, so this module, the engine and the numpy backend work without it.

Each factory takes one :class:`PhysicsSetup`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np

from swarm_sim.errors import ConfigurationError
from swarm_sim.geometry import RayCaster
from swarm_sim.world import BodyConfig, World

__all__ = [
    'PHYSICS_BACKENDS',
    'RENDER_MODES',
    'NumpyPhysics',
    'PhysicsBackend',
    'PhysicsSetup',
    'PybulletConfig',
    'RenderConfig',
    'make_physics',
    'require_backend',
]

RENDER_MODES = ('none', 'gui', 'frames')


@dataclass(frozen=True)
class RenderConfig:
    """How a pybullet run is shown (the numpy backend renders nothing).

    Attributes:
        mode: 'none'; 'gui' (pybullet's own window, needs a display); 'frames' (top-down
            ``getCameraImage`` frames written as PNGs to ``frames_dir``, and an animated GIF
            of them when the run ends).
        frames_dir: where 'frames' writes (created if missing).
        frame_rate_hz: frames per second of sim time ('frames').
        width_px, height_px: frame size ('frames').
        gif_frame_s: display time of one GIF frame [s] (0.1 plays 2 Hz frames 5x faster
            than sim time).
        gui_real_time_factor: 'gui' paces the run to this many sim seconds per wall second;
            0 runs as fast as the machine allows.
    """

    mode: str = 'none'
    frames_dir: Path | None = None
    frame_rate_hz: float = 2.0
    width_px: int = 640
    height_px: int = 480
    gif_frame_s: float = 0.1
    gui_real_time_factor: float = 1.0

    def __post_init__(self) -> None:
        if self.mode not in RENDER_MODES:
            msg = f'unknown render mode {self.mode!r}; choose from {", ".join(RENDER_MODES)}'
            raise ConfigurationError(msg)
        if self.mode == 'frames' and self.frames_dir is None:
            raise ConfigurationError("render mode 'frames' needs a frames directory")
        if not (math.isfinite(self.frame_rate_hz) and self.frame_rate_hz > 0.0):
            msg = f'frame_rate_hz must be positive, got {self.frame_rate_hz!r}'
            raise ConfigurationError(msg)
        if self.width_px < 16 or self.height_px < 16:
            msg = f'frames must be at least 16 x 16 pixels, got {self.width_px} x {self.height_px}'
            raise ConfigurationError(msg)
        if not (self.gif_frame_s > 0.0 and self.gui_real_time_factor >= 0.0):
            raise ConfigurationError('gif_frame_s must be > 0 and gui_real_time_factor >= 0')


@dataclass(frozen=True)
class PybulletConfig:
    """The pybullet backend's bodies and stepping (the drive limits come from BodyConfig).

    Attributes:
        substeps: pybullet steps per engine physics step; pybullet's time step is the
            engine's period divided by this whole number (10 at 10 Hz: 10 ms, a 5 mm move
            at 0.5 m/s).
        robot_mass_kg: mass of every robot (it matters only when robots push each other).
        robot_height_m: height of the robot cylinders [m].
        wall_height_m: height of the wall boxes [m].
        sensor_height_m: height of the lidar's rays [m]; below
            the robots' top so that robots see each other.
        contact_friction: friction coefficient of robot-wall and robot-robot contacts (0:
            a robot pressed against a wall slides along it and is not turned by it).
        solver_iterations: pybullet's constraint solver iterations per step.
        robot_contacts: robots collide with each other (False: they pass through each
            other, like the open-field missions' point robots; walls still stop them).
    """

    substeps: int = 10
    robot_mass_kg: float = 1.0
    robot_height_m: float = 0.2
    wall_height_m: float = 0.3
    sensor_height_m: float = 0.1
    contact_friction: float = 0.0
    solver_iterations: int = 50
    robot_contacts: bool = True

    def __post_init__(self) -> None:
        if self.substeps < 1 or self.solver_iterations < 1:
            msg = (
                f'substeps and solver_iterations must be >= 1, got {self.substeps} and '
                f'{self.solver_iterations}'
            )
            raise ConfigurationError(msg)
        for name in ('robot_mass_kg', 'robot_height_m', 'wall_height_m', 'sensor_height_m'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigurationError(msg)
        if not self.sensor_height_m < min(self.robot_height_m, self.wall_height_m):
            msg = (
                f'sensor_height_m ({self.sensor_height_m}) must be below the robots '
                f'({self.robot_height_m}) and the walls ({self.wall_height_m})'
            )
            raise ConfigurationError(msg)
        if not (math.isfinite(self.contact_friction) and self.contact_friction >= 0.0):
            msg = f'contact_friction must be >= 0, got {self.contact_friction!r}'
            raise ConfigurationError(msg)


@dataclass(frozen=True)
class PhysicsSetup:
    """What a backend is built from.

    Attributes:
        walls: (M, 2, 2) wall centre lines [m].
        initial_poses: (N, 3) start poses x [m], y [m], yaw [rad].
        body: robot body and drive limits.
        physics_period_s: the engine's step [s].
        scan_bins: lidar bins per revolution, or None when no lidar runs (no caster built).
        pybullet: the pybullet backend's settings (ignored by the numpy backend).
        render: how to show the run (pybullet only).
    """

    walls: np.ndarray
    initial_poses: np.ndarray
    body: BodyConfig = field(default_factory=BodyConfig)
    physics_period_s: float = 0.1
    scan_bins: int | None = 360
    pybullet: PybulletConfig = field(default_factory=PybulletConfig)
    render: RenderConfig = field(default_factory=RenderConfig)


class PhysicsBackend(Protocol):
    """What the engine needs of its physics and ray casting.

    Attributes:
        walls: (M, 2, 2) wall centre lines [m].
        num_bins: lidar bins per revolution of :meth:`scan` (0 without a lidar).
    """

    walls: np.ndarray
    num_bins: int

    @property
    def num_robots(self) -> int:
        """Number of robots N."""
        ...

    @property
    def poses(self) -> np.ndarray:
        """(N, 3) copy of the true poses x [m], y [m], yaw [rad] in (-pi, pi]."""
        ...

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) achieved forward speed [m/s] and yaw rate [rad/s] of the last step."""
        ...

    @property
    def collision_count(self) -> np.ndarray:
        """(N,) steps in which each robot was held up by a wall or another robot."""
        ...

    def step(self, commands: np.ndarray, dt_s: float) -> None:
        """Advance every robot by ``dt_s`` under (N, 2) speed [m/s] / yaw rate [rad/s]
        commands (clipped to the drive limits; non-finite values taken as zero)."""
        ...

    def scan(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """(N, num_bins) exact ranges [m] from the (N, 3) poses, ``inf`` beyond
        ``max_range_m``; bin k at robot-frame angle -pi + k 2 pi / num_bins. Rays start at
        the robot's centre, ignore its own body and hit walls and the other robots."""
        ...

    def close(self) -> None:
        """Release what the backend holds (idempotent)."""
        ...


class NumpyPhysics:
    """The kinematic disc world and the exact 2D caster (see :mod:`swarm_sim.world` and
    :class:`swarm_sim.geometry.RayCaster`), on the compiled kernels."""

    def __init__(self, setup: PhysicsSetup) -> None:
        self._world = World(setup.walls, setup.initial_poses, setup.body)
        self.walls = self._world.walls
        self._caster: RayCaster | None = None
        self.num_bins = 0
        if setup.scan_bins is not None:
            self._caster = RayCaster(
                self.walls,
                wall_thickness_m=setup.body.wall_thickness_m,
                robot_radius_m=setup.body.robot_radius_m,
                num_bins=setup.scan_bins,
            )
            self.num_bins = self._caster.num_bins

    @property
    def world(self) -> World:
        """The underlying :class:`~swarm_sim.world.World`."""
        return self._world

    @property
    def num_robots(self) -> int:
        """Number of robots N."""
        return self._world.num_robots

    @property
    def poses(self) -> np.ndarray:
        """(N, 3) copy of the true poses."""
        return self._world.poses

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) achieved forward speed [m/s] and yaw rate [rad/s] of the last step."""
        return self._world.velocities

    @property
    def collision_count(self) -> np.ndarray:
        """(N,) moves cancelled by a contact, per robot."""
        return self._world.collision_count

    def step(self, commands: np.ndarray, dt_s: float) -> None:
        """:meth:`swarm_sim.world.World.step`."""
        self._world.step(commands, dt_s)

    def scan(self, poses: np.ndarray, max_range_m: float) -> np.ndarray:
        """:meth:`swarm_sim.geometry.RayCaster.scan`."""
        if self._caster is None:
            raise ConfigurationError('this physics backend was built without a lidar')
        return self._caster.scan(poses, max_range_m)

    def scan_near(
        self, poses: np.ndarray, max_range_m: float, cut_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`swarm_sim.geometry.RayCaster.scan_near`."""
        if self._caster is None:
            raise ConfigurationError('this physics backend was built without a lidar')
        return self._caster.scan_near(poses, max_range_m, cut_m)

    def close(self) -> None:
        """Nothing to release."""


def _pybullet_physics(setup: PhysicsSetup) -> PhysicsBackend:
    from swarm_sim.pybullet_physics import PybulletPhysics

    return PybulletPhysics(setup)


def _require_pybullet() -> None:
    from swarm_sim.pybullet_scene import import_pybullet

    import_pybullet()


PHYSICS_BACKENDS: dict[str, Callable[[PhysicsSetup], PhysicsBackend]] = {
    'numpy': NumpyPhysics,
    'pybullet': _pybullet_physics,
}
# Per backend, a check that raises SimulationError when its library is missing.
_REQUIREMENTS: dict[str, Callable[[], None]] = {'pybullet': _require_pybullet}


def require_backend(name: str) -> None:
    """Check that backend ``name`` exists and its library is installed, without building it
    (so that a command-line tool refuses a run before it starts anything).

    Raises:
        ConfigurationError: no backend of that name.
        SimulationError: the backend's library is missing (pybullet not installed).
    """
    if name not in PHYSICS_BACKENDS:
        msg = f'unknown physics backend {name!r}; choose from {", ".join(PHYSICS_BACKENDS)}'
        raise ConfigurationError(msg)
    check = _REQUIREMENTS.get(name)
    if check is not None:
        check()


def make_physics(name: str, setup: PhysicsSetup) -> PhysicsBackend:
    """Build the backend registered as ``name`` in :data:`PHYSICS_BACKENDS`.

    Raises:
        ConfigurationError: no backend of that name, or rendering asked of a backend that
            cannot render.
        SimulationError: the backend's library is missing or failed to start.
    """
    try:
        factory = PHYSICS_BACKENDS[name]
    except KeyError:
        msg = f'unknown physics backend {name!r}; choose from {", ".join(PHYSICS_BACKENDS)}'
        raise ConfigurationError(msg) from None
    if setup.render.mode != 'none' and name != 'pybullet':
        msg = f'rendering ({setup.render.mode}) needs the pybullet backend, not {name!r}'
        raise ConfigurationError(msg)
    return factory(setup)
