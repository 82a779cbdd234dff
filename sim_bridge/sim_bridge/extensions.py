"""How mission-specific parts of the world plug into the sim bridge.

The bridge owns time, robot bodies and motion, and the sensors every mission shares (odom,
imu; scan, gas and bearings where the world has walls and pumps). A mission adds what only
it needs through a :class:`SimExtension`: a signal field sampled on each robot's ``signal``
topic (Bayes-Swarm), RSSI targets with a task load (MSC + PF), and so on.

An extension splits like everything else in this suite: a ROS-free model (numpy, seeded) and
a thin adapter that creates its publishers on the bridge node and fills messages. The bridge
calls the adapter in a fixed order every physics step, so runs stay deterministic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = ['RobotStates', 'SimExtension']


@dataclass(frozen=True)
class RobotStates:
    """True state of every robot at one physics step.

    Attributes:
        names: robot names in bridge order, equal to their namespaces without '/' (r0, r1...).
        poses: (N, 3) array of x [m], y [m], yaw [rad] in the world frame.
        velocities: (N, 2) array of forward speed [m/s] and yaw rate [rad/s].
    """

    names: tuple[str, ...]
    poses: np.ndarray
    velocities: np.ndarray


@runtime_checkable
class SimExtension(Protocol):
    """A mission-specific part of the simulated world."""

    def attach(self, node: Any, robot_names: tuple[str, ...]) -> None:
        """Create publishers/subscriptions on the bridge node (relative names per robot)."""

    def on_step(self, sim_time_s: float, states: RobotStates) -> None:
        """Advance the extension's model to ``sim_time_s`` and publish what is due."""

    def is_done(self) -> bool:
        """True when the mission's own stop condition is met (e.g. every target captured)."""
