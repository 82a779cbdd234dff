"""Watching a pybullet run: top-down camera frames as PNGs and an animated GIF.

:class:`FrameRecorder` renders the scene with pybullet's CPU renderer (``getCameraImage``
with ``ER_TINY_RENDERER``, which needs no display) from a camera above the middle of the
site, writes every frame as ``frame_00000.png``, ... with the sim time printed in a corner,
and on :meth:`FrameRecorder.finish` assembles them into ``run.gif`` with pillow (which comes
with matplotlib). :func:`place_gui_camera` points pybullet's own window at the site.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from swarm_sim.errors import SimulationError

__all__ = ['FrameRecorder', 'place_gui_camera', 'robot_colours', 'site_view']

_FOV_DEG = 40.0
# Frames wider than this are halved for the GIF (it keeps every frame in memory).
_GIF_MAX_WIDTH_PX = 400


def robot_colours(count: int) -> list[tuple[float, float, float, float]]:
    """One distinct RGBA colour per robot (matplotlib's tab10, repeated)."""
    from matplotlib import colormaps

    cmap = colormaps['tab10']
    colours = []
    for i in range(count):
        red, green, blue, alpha = (float(v) for v in cmap(i % 10))
        colours.append((red, green, blue, alpha))
    return colours


def site_view(walls: np.ndarray, aspect: float) -> tuple[list[float], float]:
    """Centre (x, y, 0) of the walls' bounding box and the camera height [m] at which a
    field of view of 40 degrees and the image ``aspect`` (width / height) show all of it."""
    pts = np.asarray(walls, dtype=float).reshape(-1, 2)
    if len(pts) == 0:
        pts = np.array([[-2.0, -2.0], [2.0, 2.0]])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    half_w, half_h = 0.5 * (hi - lo) + 0.5
    half_h = max(half_h, half_w / aspect)
    height = half_h / math.tan(math.radians(0.5 * _FOV_DEG)) * 1.05
    return [float(centre[0]), float(centre[1]), 0.0], float(height)


def place_gui_camera(pybullet: Any, client: int, walls: np.ndarray) -> None:
    """Point the pybullet window's camera down at the whole site."""
    target, height = site_view(walls, 4.0 / 3.0)
    pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0, physicsClientId=client)
    pybullet.resetDebugVisualizerCamera(
        cameraDistance=height,
        cameraYaw=0.0,
        cameraPitch=-89.9,
        cameraTargetPosition=target,
        physicsClientId=client,
    )


class FrameRecorder:
    """Top-down frames of one pybullet client, written as PNGs, and their GIF."""

    def __init__(
        self,
        pybullet: Any,
        client: int,
        walls: np.ndarray,
        out_dir: Path,
        *,
        width_px: int,
        height_px: int,
        gif_frame_s: float,
    ) -> None:
        """Prepare the camera over ``walls`` and the output directory.

        Raises:
            SimulationError: the directory cannot be created.
        """
        self._p = pybullet
        self._client = client
        self.out_dir = Path(out_dir)
        try:
            self.out_dir.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            msg = f'cannot create the frames directory {self.out_dir}: {err.strerror}'
            raise SimulationError(msg) from err
        self.width_px = int(width_px)
        self.height_px = int(height_px)
        self._gif_frame_s = gif_frame_s
        target, height = site_view(walls, self.width_px / self.height_px)
        self._view = pybullet.computeViewMatrix(
            cameraEyePosition=[target[0], target[1], height],
            cameraTargetPosition=target,
            cameraUpVector=[0.0, 1.0, 0.0],
            physicsClientId=client,
        )
        self._projection = pybullet.computeProjectionMatrixFOV(
            fov=_FOV_DEG,
            aspect=self.width_px / self.height_px,
            nearVal=0.1,
            farVal=height + 1.0,
            physicsClientId=client,
        )
        self.frames: list[Path] = []

    def capture(self, time_s: float) -> Path:
        """Render the scene now and write the next PNG; return its path."""
        from PIL import Image, ImageDraw

        p = self._p
        _, _, rgba, _, _ = p.getCameraImage(
            self.width_px,
            self.height_px,
            viewMatrix=self._view,
            projectionMatrix=self._projection,
            renderer=p.ER_TINY_RENDERER,
            physicsClientId=self._client,
        )
        pixels = np.asarray(rgba, dtype=np.uint8).reshape(self.height_px, self.width_px, 4)
        image = Image.fromarray(pixels[:, :, :3])
        ImageDraw.Draw(image).text((8, 8), f't = {time_s:7.1f} s', fill=(0, 0, 0))
        path = self.out_dir / f'frame_{len(self.frames):05d}.png'
        image.save(path)
        self.frames.append(path)
        return path

    def finish(self) -> Path | None:
        """Write ``run.gif`` from the frames so far; return its path (None without frames)."""
        if not self.frames:
            return None
        from PIL import Image

        images = []
        for path in self.frames:
            with Image.open(path) as frame:
                image = frame.convert('RGB')
            if image.width > _GIF_MAX_WIDTH_PX:
                image = image.resize((image.width // 2, image.height // 2))
            images.append(image.quantize(colors=64))
        gif = self.out_dir / 'run.gif'
        images[0].save(
            gif,
            save_all=True,
            append_images=images[1:],
            duration=max(20, round(1000.0 * self._gif_frame_s)),
            loop=0,
        )
        return gif
