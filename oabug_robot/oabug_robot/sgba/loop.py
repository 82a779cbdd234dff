"""The SGBA robot's control loop without ROS: what the node and the batch runner both run.

:class:`SgbaLoop` holds the newest reading of every input (sample and hold) with the time it
arrived: the lidar scan, the IMU yaw, the odometry position and the peers the AoA locator
hears (tag, azimuth, RSSI-based distance). A control step turns the held scan into the range
directions, the strongest peer heard within the peer timeout into SGBA's inter-robot RSSI
(:func:`~oabug_robot.sgba.controller.rssi_from_distance`) and steps
:class:`~oabug_robot.sgba.controller.SgbaController`; while the scan, the IMU or the
odometry is missing or older than the stale timeout it returns a zero command.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np

from oabug_robot.errors import ScanError
from oabug_robot.scan_features import LaserScanData
from oabug_robot.sgba.controller import (
    Peer,
    Ranges,
    SgbaCommand,
    SgbaController,
    SgbaInputs,
    ranges_from_scan,
    rssi_from_distance,
)
from oabug_robot.sgba.settings import SgbaConfig, SgbaNodeConfig

__all__ = ['STOP', 'SgbaLoop', 'SgbaOutput', 'has_right_of_way']

#: The fail-safe command.
STOP = SgbaCommand(0.0, 0.0)

_ScanT = TypeVar('_ScanT')


@dataclass(frozen=True)
class SgbaOutput:
    """One control step's command and the stale inputs (empty when the controller stepped)."""

    command: SgbaCommand
    stale: tuple[str, ...] = ()


def has_right_of_way(peer_tag: str, own_tag: str) -> bool:
    """Whether the peer ``peer_tag`` has right of way over this robot: the lower tag id (the
    authors: the lower radio id) goes first. A robot without its own tag gives way to all."""
    if not own_tag:
        return True
    return peer_tag < own_tag


class SgbaLoop(Generic[_ScanT]):
    """One SGBA robot's loop: held readings in, one command per control step out."""

    def __init__(
        self,
        settings: SgbaNodeConfig,
        decode_scan: Callable[[_ScanT], LaserScanData] | None = None,
    ) -> None:
        """Build the loop from the node's settings; ``decode_scan`` turns a held scan into
        :class:`LaserScanData` (may raise :class:`ScanError`), None when the held scans are
        already :class:`LaserScanData`."""
        self.config: SgbaConfig = settings.controller_config()
        self.controller = SgbaController(self.config)
        self._decode: Callable[[Any], LaserScanData] = (
            decode_scan if decode_scan is not None else _identity
        )
        self.control_period_s = 1.0 / settings.control_rate_hz
        self.stale_timeout_s = settings.stale_timeout_s
        self.own_tag = settings.own_tag_id.strip().upper()
        self._scan: _ScanT | None = None
        self._ranges: Ranges | None = None
        self._ranges_time_s: float | None = None
        self._scan_time_s: float | None = None
        self._yaw_rad = math.nan
        self._imu_time_s: float | None = None
        self._position: tuple[float, float] | None = None
        self._odom_time_s: float | None = None
        self._peers: tuple[Sequence[str], np.ndarray, np.ndarray, float, float] | None = None
        #: The inputs heard at least once.
        self.heard: set[str] = set()

    def configure(self, settings: SgbaNodeConfig) -> None:
        """Take the settings a running node may change."""
        self.stale_timeout_s = settings.stale_timeout_s
        self.own_tag = settings.own_tag_id.strip().upper()

    @property
    def yaw_rad(self) -> float:
        """The held IMU yaw [rad]; NaN before the first reading."""
        return self._yaw_rad

    def hold_scan(self, scan: _ScanT, now_s: float) -> None:
        """A lidar revolution arrives."""
        self._scan = scan
        self._scan_time_s = now_s

    def hold_yaw(self, yaw_rad: float, now_s: float) -> None:
        """An IMU yaw arrives."""
        self._yaw_rad = yaw_rad
        self._imu_time_s = now_s
        self.heard.add('imu')

    def hold_position(self, x_m: float, y_m: float, now_s: float) -> None:
        """An odometry position arrives."""
        self._position = (x_m, y_m)
        self._odom_time_s = now_s
        self.heard.add('odom')

    def hold_peers(
        self, tags: Sequence[str], azimuths_rad: np.ndarray, distances_m: np.ndarray, now_s: float
    ) -> None:
        """A locator cycle arrives: the peers' tag ids (upper case), azimuths in the robot
        frame [rad] and RSSI-based distances [m, NaN unknown]; the own tag is dropped."""
        keep = [i for i, tag in enumerate(tags) if tag != self.own_tag]
        yaw = self._yaw_rad if math.isfinite(self._yaw_rad) else 0.0
        self._peers = (
            [tags[i] for i in keep],
            np.asarray(azimuths_rad, dtype=float)[keep],
            np.asarray(distances_m, dtype=float)[keep],
            now_s,
            yaw,
        )

    def update_ranges(self) -> None:
        """Turn the held scan (if a new one arrived) into the range directions.

        Raises:
            ScanError: the scan is malformed; it is dropped and the ranges held stay.
        """
        scan = self._scan
        if scan is None:
            return
        self._scan = None
        data = self._decode(scan)
        if (
            data.ranges_m.size < 4
            or not math.isfinite(data.angle_increment_rad)
            or (data.angle_increment_rad == 0.0)
        ):
            msg = 'a scan needs >= 4 rays and a finite, non-zero angle increment'
            raise ScanError(msg)
        self._ranges = ranges_from_scan(
            data.ranges_m,
            data.angle_min_rad,
            data.angle_increment_rad,
            data.range_min_m,
            data.range_max_m,
            self.config.ranger_half_width_rad,
        )
        self._ranges_time_s = self._scan_time_s
        self.heard.add('scan')

    def strongest_peer(self, now_s: float) -> Peer | None:
        """The peer with the strongest RSSI heard within the peer timeout, or None."""
        held = self._peers
        if held is None or not 0.0 <= now_s - held[3] <= self.config.peer_timeout_s:
            return None
        tags, azimuths, distances, _, yaw_at_stamp = held
        known = np.flatnonzero(np.isfinite(distances))
        if not known.size:
            return None
        best = int(known[np.argmin(distances[known])])
        return Peer(
            rssi_dbm=rssi_from_distance(float(distances[best]), self.config),
            bearing_rad=float(yaw_at_stamp + azimuths[best]),
            has_way=has_right_of_way(tags[best], self.own_tag),
        )

    def stale_inputs(self, now_s: float) -> list[str]:
        """The inputs missing or older than the stale timeout."""
        required = (
            ('scan', self._ranges_time_s),
            ('imu', self._imu_time_s),
            ('odom', self._odom_time_s),
        )
        return [
            name
            for name, stamp in required
            if stamp is None or not 0.0 <= now_s - stamp <= self.stale_timeout_s
        ]

    def control(self, now_s: float) -> SgbaOutput:
        """:meth:`update_ranges` (a malformed scan is dropped) then :meth:`step`."""
        with contextlib.suppress(ScanError):
            self.update_ranges()
        return self.step(now_s)

    def step(self, now_s: float) -> SgbaOutput:
        """One control step at node time ``now_s`` [s] on the held readings: the
        controller's command, or :data:`STOP` and the stale inputs."""
        stale = self.stale_inputs(now_s)
        if stale or self._ranges is None or self._position is None:
            return SgbaOutput(STOP, tuple(stale) or ('scan',))
        inputs = SgbaInputs(
            time_s=now_s,
            yaw_rad=self._yaw_rad,
            ranges=self._ranges,
            position_m=self._position,
            peer=self.strongest_peer(now_s),
        )
        return SgbaOutput(self.controller.step(inputs))


def _identity(scan: LaserScanData) -> LaserScanData:
    return scan
