"""The per-robot loop around :class:`msc_pf.robot.RobotController`: what the node runs.

:class:`RobotLoop` holds everything one robot does between its inputs and its wheels, with
no ROS: the ROS node (:mod:`msc_pf.node`) and the batch runner
(``swarm_experiments.msc_pf_batch``) both feed it and both drive with its commands, so the
two paths run one controller.

* **Sample and hold.** :meth:`RobotLoop.receive_pose` keeps the newest pose and when it came;
  :meth:`~RobotLoop.receive_rssi` merges the RSSI samples of a period (the newest sample of
  a target wins) and refuses out-of-order stamps and stamps more than
  :data:`MAX_RSSI_STAMP_LEAD_S` ahead of the caller's clock; peer messages and capture
  notices are queued until the next control step.
* **Timing.** :meth:`~RobotLoop.control` runs once per control period (the caller's timer):
  it hands the held pose and the period's samples, peers and notices to the controller and
  turns the displacement it returns into a waypoint due one period later.
* **Staleness.** A pose older than ``odom_timeout_s`` skips the control step and clears the
  waypoint; :meth:`~RobotLoop.command` returns a stop when the pose is stale, when no
  control step ran for two periods, or when there is no waypoint.
* **Steering.** Between control steps :meth:`~RobotLoop.command` steers toward the
  waypoint (:func:`msc_pf.drive.unicycle_command`), at the caller's drive rate.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from msc_pf.drive import unicycle_command
from msc_pf.errors import ObservationError
from msc_pf.peers import PeerInfo
from msc_pf.robot import RobotController, StepOutput

__all__ = ['MAX_RSSI_STAMP_LEAD_S', 'ControlResult', 'ControlStatus', 'RobotLoop', 'Steering']

#: An RSSI batch stamped more than this ahead of the receiver's clock [s] is refused: it
#: would otherwise become the newest stamp and make every correctly stamped batch after it
#: look out of order.
MAX_RSSI_STAMP_LEAD_S = 5.0


@dataclass(frozen=True)
class Steering:
    """How the loop turns waypoints into wheel commands and when it stops.

    Attributes:
        odom_timeout_s: a pose older than this is stale [s].
        max_yaw_rate_rad_s: yaw-rate limit of the base [rad/s].
        heading_gain: yaw rate per radian of heading error [1/s].
    """

    odom_timeout_s: float = 1.0
    max_yaw_rate_rad_s: float = 2.0
    heading_gain: float = 2.0


class ControlStatus(enum.Enum):
    """What one control step did."""

    STEPPED = 'stepped'
    NO_POSE = 'no fresh pose'
    REJECTED = 'observation rejected'


@dataclass(frozen=True)
class ControlResult:
    """Outcome of :meth:`RobotLoop.control`.

    Attributes:
        status: STEPPED, or why the step was skipped (the robot then holds still).
        output: the controller's output when it stepped, else None.
        error: the controller's reason when it rejected the inputs, else ''.
    """

    status: ControlStatus
    output: StepOutput | None = None
    error: str = ''


class RobotLoop:
    """Sample-and-hold, staleness, timing and steering of one robot's controller."""

    def __init__(self, controller: RobotController, steering: Steering | None = None) -> None:
        """Wrap ``controller``; ``steering`` defaults to :class:`Steering`'s defaults."""
        self.controller = controller
        self.steering = steering if steering is not None else Steering()
        self.period_s = controller.config.period_s
        self._max_speed_m_s = controller.config.max_speed_m_s
        self._pose: tuple[float, float, float] | None = None
        self._pose_time_s = -math.inf
        self._readings: dict[int, float] = {}
        self._rssi_stamp_s = -math.inf
        self._rssi_refusal = ''
        self._inbox: list[PeerInfo] = []
        self._captured: list[int] = []
        self._waypoint: tuple[float, float] | None = None
        self._deadline_s = -math.inf
        self._last_step_s = -math.inf
        self.last_output: StepOutput | None = None

    @property
    def pose(self) -> tuple[float, float, float] | None:
        """The newest pose (x [m], y [m], yaw [rad]), None before the first."""
        return self._pose

    @property
    def waypoint_m(self) -> tuple[float, float] | None:
        """Where the robot steers until the next control step, None when holding still."""
        return self._waypoint

    # ------------------------------------------------------------------ inputs
    def receive_pose(self, pose: tuple[float, float, float], now_s: float) -> bool:
        """Hold ``pose`` as received at ``now_s``; False (ignored) when it is not finite."""
        x, y, yaw = float(pose[0]), float(pose[1]), float(pose[2])
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(yaw)):
            return False
        self._pose = (x, y, yaw)
        self._pose_time_s = now_s
        return True

    def receive_rssi(
        self, stamp_s: float, readings: Mapping[int, float], now_s: float | None = None
    ) -> bool:
        """Merge one RSSI batch stamped ``stamp_s``; False (ignored, the reason in
        :attr:`last_rssi_refusal`) when the stamp is not finite, older than the previous
        batch's or, given the clock ``now_s``, more than :data:`MAX_RSSI_STAMP_LEAD_S` ahead
        of it. Later samples of a target replace earlier ones of the period."""
        if not math.isfinite(stamp_s):
            self._rssi_refusal = 'its stamp is not finite'
            return False
        if now_s is not None and stamp_s - now_s > MAX_RSSI_STAMP_LEAD_S:
            self._rssi_refusal = (
                f'its stamp is more than {MAX_RSSI_STAMP_LEAD_S:g} s ahead of the clock '
                f'({now_s:.3f} s)'
            )
            return False
        if stamp_s < self._rssi_stamp_s:
            self._rssi_refusal = f'it arrived after {self._rssi_stamp_s:.3f} s'
            return False
        self._rssi_stamp_s = stamp_s
        self._readings.update(readings)
        return True

    @property
    def last_rssi_stamp_s(self) -> float:
        """Stamp of the newest accepted RSSI batch [s] (-inf before the first)."""
        return self._rssi_stamp_s

    @property
    def last_rssi_refusal(self) -> str:
        """Why :meth:`receive_rssi` last refused a batch ('' before the first refusal)."""
        return self._rssi_refusal

    def receive_peer(self, peer: PeerInfo) -> None:
        """Queue a neighbour's broadcast for the next control step."""
        self._inbox.append(peer)

    def receive_captured(self, target_ids: Iterable[int]) -> None:
        """Queue capture notices for the next control step."""
        self._captured.extend(int(t) for t in target_ids)

    # ------------------------------------------------------------------ control
    def control(self, now_s: float, *, with_estimates: bool = True) -> ControlResult:
        """Run one control period at ``now_s`` (see the module notes)."""
        if self._pose is None or now_s - self._pose_time_s > self.steering.odom_timeout_s:
            self._waypoint = None
            return ControlResult(ControlStatus.NO_POSE)
        readings, self._readings = self._readings, {}
        inbox, self._inbox = self._inbox, []
        captured, self._captured = self._captured, []
        position = np.array(self._pose[:2])
        try:
            out = self.controller.step(
                now_s, position, readings, inbox, captured, with_estimates=with_estimates
            )
        except ObservationError as err:
            self._waypoint = None
            return ControlResult(ControlStatus.REJECTED, error=str(err))
        self.last_output = out
        self._last_step_s = now_s
        self._waypoint = (
            float(position[0] + out.displacement_m[0]),
            float(position[1] + out.displacement_m[1]),
        )
        self._deadline_s = now_s + self.period_s
        return ControlResult(ControlStatus.STEPPED, out)

    def command(self, now_s: float) -> tuple[float, float]:
        """(forward speed [m/s], yaw rate [rad/s]) to send at ``now_s``; (0, 0) to stop."""
        pose = self._pose
        stale = pose is None or now_s - self._pose_time_s > self.steering.odom_timeout_s
        late = now_s - self._last_step_s > 2.0 * self.period_s
        if stale or late or self._waypoint is None or pose is None:
            return 0.0, 0.0
        steering = self.steering
        return unicycle_command(
            pose,
            self._waypoint,
            self._deadline_s - now_s,
            max_speed_m_s=self._max_speed_m_s,
            max_yaw_rate_rad_s=steering.max_yaw_rate_rad_s,
            heading_gain=steering.heading_gain,
        )
