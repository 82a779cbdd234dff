"""The OA-Bug robot's control loop without ROS: what the node and the batch runner both run.

:class:`RobotLoop` holds the newest reading of every sensor (sample and hold) with the time
it arrived, turns the held scan into features once per control step, checks that every
input the variant reads is fresh, and steps :class:`oabug_robot.fsm.OABugFsm`. The node
(:mod:`oabug_robot.node`) feeds it from its subscriptions and publishes what it returns; the
batch runner (``swarm_experiments.oabug_batch``) feeds it the simulated readings directly and
applies the commands to the world. Both therefore make the same decisions from the same
readings, bit for bit.

The control step runs on a fixed timer: :class:`ControlTimer` is the grid of deadlines a
ROS timer of ``control_rate_hz`` fires on (period in whole nanoseconds, first deadline one
period after the start, missed deadlines skipped). The node uses its executor's timer with
the same period; the batch runner asks the :class:`ControlTimer` when a step is due.

:func:`extract_features` computes the features of many loops at once (the loops of one
perception configuration in one call of
:func:`oabug_robot.scan_features_kernel.extract_held`, equal to each loop's own
extractor).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np
from swarm_common.stamps import NS_PER_S

from oabug_robot.errors import ScanError
from oabug_robot.fsm import Command, OABugFsm, SensorSnapshot
from oabug_robot.node_settings import OABugNodeConfig
from oabug_robot.scan_features import LaserScanData, ScanFeatureExtractor, ScanFeatures
from oabug_robot.settings import OABugConfig
from oabug_robot.sound import PeerBearings

__all__ = ['STOP', 'ControlTimer', 'LoopOutput', 'RobotLoop', 'extract_features']

#: The fail-safe command: zero velocity, pump off.
STOP = Command(linear_mps=0.0, angular_radps=0.0, pump_on=False)

_ScanT = TypeVar('_ScanT')


@dataclass(frozen=True)
class LoopOutput:
    """What one control step gives.

    Attributes:
        command: the command to apply (:data:`STOP` while an input is stale).
        stale: the inputs missing or older than the stale timeout (``scan``, ``imu``,
            ``gas``); empty when the controller stepped.
    """

    command: Command
    stale: tuple[str, ...] = ()


class ControlTimer:
    """The deadlines of a ROS timer of period ``period_s`` started at time 0 (sim time)."""

    def __init__(self, period_s: float) -> None:
        #: The period in whole nanoseconds, as a timer of ``period_s`` keeps it.
        self.period_ns = int(period_s * NS_PER_S)
        #: The next deadline [ns]; the first one is one period in.
        self.next_ns = self.period_ns

    def due(self, now_ns: int) -> bool:
        """Whether the timer fires at ``now_ns``; if so the deadline moves on (past ``now_ns``
        when deadlines were missed, as a timer skips them)."""
        if now_ns < self.next_ns:
            return False
        period = self.period_ns
        self.next_ns += period
        if self.next_ns < now_ns:
            behind = now_ns - self.next_ns
            self.next_ns += (1 + (behind - 1) // period) * period
        return True


class RobotLoop(Generic[_ScanT]):
    """One OA-Bug robot's loop: held readings in, one command per control step out.

    The scan is held as it arrives (``_ScanT``: a message, or already a
    :class:`LaserScanData`) and decoded by ``decode_scan`` only when a control step uses it,
    so a scan that is replaced before the next step costs nothing.
    """

    def __init__(
        self,
        settings: OABugNodeConfig,
        decode_scan: Callable[[_ScanT], LaserScanData] | None = None,
    ) -> None:
        """Build the loop from the node's settings.

        Args:
            settings: the node parameters (controller, rates, stale timeout, own tag).
            decode_scan: turns a held scan into :class:`LaserScanData` (may raise
                :class:`ScanError`); None when the held scans are :class:`LaserScanData`.
        """
        self.config: OABugConfig = settings.controller_config()
        self.fsm = OABugFsm(self.config)
        self.extractor = ScanFeatureExtractor(self.config.perception)
        self._decode: Callable[[Any], LaserScanData] = (
            decode_scan if decode_scan is not None else _identity
        )
        self.control_period_s = 1.0 / settings.control_rate_hz
        self.stale_timeout_s = settings.stale_timeout_s
        self.needs_gas = self.config.variant.uses_scent
        #: Loops of one group share perception settings (set by whoever batches them).
        self.perception_group = 0
        self._scan: _ScanT | None = None
        self._scan_time_s: float | None = None
        self._features: ScanFeatures | None = None
        self._features_time_s: float | None = None
        self._yaw_rad = math.nan
        self._imu_time_s: float | None = None
        self._gas_raw: int | None = None
        self._gas_time_s: float | None = None
        self._bearings: PeerBearings | None = None

    def configure(self, settings: OABugNodeConfig) -> None:
        """Take the settings a running node may change (the stale timeout)."""
        self.stale_timeout_s = settings.stale_timeout_s

    # Readings: each replaces the one held, stamped with the time it arrived [s].

    @property
    def heard(self) -> set[str]:
        """The inputs heard at least once (``scan`` counts once it gave features)."""
        stamps = (
            ('scan', self._features_time_s),
            ('imu', self._imu_time_s),
            ('gas', self._gas_time_s),
        )
        return {name for name, stamp in stamps if stamp is not None}

    @property
    def yaw_rad(self) -> float:
        """The held IMU yaw [rad]; NaN before the first IMU reading."""
        return self._yaw_rad

    @property
    def gas_raw(self) -> int | None:
        """The held gas reading (10-bit scale), None when there is none."""
        return self._gas_raw

    def hold_scan(self, scan: _ScanT, now_s: float) -> None:
        """A lidar revolution arrives."""
        self._scan = scan
        self._scan_time_s = now_s

    def hold_yaw(self, yaw_rad: float, now_s: float) -> None:
        """An IMU yaw arrives (already read from the message's orientation)."""
        self._yaw_rad = yaw_rad
        self._imu_time_s = now_s

    def hold_gas(self, raw: int | None, now_s: float) -> None:
        """A gas reading arrives (None while the sensor warms up: fresh, but no value)."""
        self._gas_raw = raw
        self._gas_time_s = now_s

    def hold_bearings(
        self, azimuths_rad: np.ndarray, distances_m: np.ndarray, now_s: float
    ) -> None:
        """A locator cycle arrives (own tag already dropped): the peers' bearings in the robot
        frame [rad] and distances [m, NaN unknown], stamped with the yaw held now (0 before
        the first IMU reading)."""
        yaw = self._yaw_rad if math.isfinite(self._yaw_rad) else 0.0
        self._bearings = PeerBearings(azimuths_rad, distances_m, now_s, yaw)

    # The control step.

    def _required_stamps(self) -> list[tuple[str, float | None]]:
        """(input, stamp of its newest reading) of the inputs the step reads."""
        required: list[tuple[str, float | None]] = [
            ('scan', self._features_time_s),
            ('imu', self._imu_time_s),
        ]
        if self.needs_gas:
            required.append(('gas', self._gas_time_s))
        return required

    def _is_stale(self, stamp: float | None, now_s: float) -> bool:
        return stamp is None or not 0.0 <= now_s - stamp <= self.stale_timeout_s

    def stale_inputs(self, now_s: float) -> list[str]:
        """The inputs the step reads that are missing or not stamped within the stale
        timeout before ``now_s`` (the scan by the time of the scan its features came from)."""
        return [name for name, stamp in self._required_stamps() if self._is_stale(stamp, now_s)]

    def _fresh(self, now_s: float) -> bool:
        """``not self.stale_inputs(now_s)``, stopping at the first stale input (a plain loop:
        every control step asks, and it costs less than a generator)."""
        for _, stamp in self._required_stamps():  # noqa: SIM110 (see the docstring)
            if self._is_stale(stamp, now_s):
                return False
        return True

    def _near_peers(self, now_s: float) -> tuple[np.ndarray, np.ndarray]:
        bearings = self._bearings
        if bearings is None or now_s - bearings.stamp_s > self.config.bearing_timeout_s:
            return np.zeros(0), np.zeros(0)
        return bearings.near_peers_now(
            self._yaw_rad, self.config.perception.peer_bearing_max_distance_m
        )

    def pending_scan(self) -> tuple[LaserScanData, int] | None:
        """The held scan the next control step turns into features and the side whose wall
        it wants (only the followed wall matters for the next step; a wall taken up in that
        step is first turned to); None when there is nothing to do (no new scan, or no yaw
        yet).

        Raises:
            ScanError: the held scan cannot be decoded (it is dropped).
        """
        scan = self._scan
        if scan is None or not math.isfinite(self._yaw_rad):
            return None
        try:
            return self._decode(scan), self.fsm.memory.wall_side
        except ScanError:
            self._scan = None
            raise

    def peer_bearings(self, now_s: float) -> tuple[np.ndarray, np.ndarray, float] | None:
        """The bearings the control step at ``now_s`` reads, before the near-peer selection:
        the held azimuths [rad] and distances [m] and the rotation since they were heard
        (``yaw_at_stamp - yaw`` [rad], added to the azimuths as
        :meth:`~oabug_robot.sound.PeerBearings.near_peers_now` does); None when none are
        held or they are older than the bearing timeout."""
        bearings = self._bearings
        if bearings is None or now_s - bearings.stamp_s > self.config.bearing_timeout_s:
            return None
        return (
            bearings.azimuths_rad,
            bearings.distances_m,
            bearings.yaw_at_stamp_rad - self._yaw_rad,
        )

    def take_features(self, features: ScanFeatures) -> None:
        """Hold the features of the pending scan (computed elsewhere, e.g. for many loops at
        once by :func:`extract_features`)."""
        self._features = features
        self._features_time_s = self._scan_time_s
        self._scan = None

    def update_features(self, now_s: float) -> None:
        """Turn the pending scan (if any) into features with the loop's own extractor.

        Raises:
            ScanError: the scan is malformed; it is dropped and the features held stay.
        """
        if self._scan is None:  # nothing new (the common case: features already taken)
            return
        pending = self.pending_scan()
        if pending is None:
            return
        scan, side = pending
        self._scan = None
        features = self.extractor.extract(
            scan, *self._near_peers(now_s), sides=(side,) if side else ()
        )
        self.take_features(features)

    def step(self, now_s: float) -> LoopOutput:
        """One control step at node time ``now_s`` [s], after :meth:`update_features` (or
        :func:`extract_features`): the controller's command, or :data:`STOP` and the stale
        inputs while any input is missing or stale."""
        command = self._step_controller(now_s)
        if command is None:
            return LoopOutput(STOP, tuple(self.stale_inputs(now_s)) or ('scan',))
        return LoopOutput(command)

    def control(self, now_s: float) -> LoopOutput:
        """:meth:`update_features` (a malformed scan is dropped) then :meth:`step`."""
        if self._scan is not None:  # else there is nothing to update
            with contextlib.suppress(ScanError):
                self.update_features(now_s)
        return self.step(now_s)

    def command(self, now_s: float) -> Command:
        """:meth:`control`'s command alone (what a batch runner applies; the stale inputs
        are not named)."""
        if self._scan is not None:
            with contextlib.suppress(ScanError):
                self.update_features(now_s)
        command = self._step_controller(now_s)
        return STOP if command is None else command

    def _step_controller(self, now_s: float) -> Command | None:
        """Step the controller on the held readings; None (no step) while an input is
        missing or stale."""
        features = self._features
        if features is None or not self._fresh(now_s):
            return None
        return self.fsm.step(
            SensorSnapshot(now_s, self._yaw_rad, features, self._gas_raw, self._bearings)
        )


def _identity(scan: LaserScanData) -> LaserScanData:
    return scan


def extract_features(loops: Sequence[RobotLoop[Any]], now_s: float) -> None:
    """:meth:`RobotLoop.update_features` of many loops, the loops of one perception group in
    one compiled call (:func:`oabug_robot.scan_features_kernel.extract_held`, equal to each
    loop's own extractor). A group whose scans the call cannot take (a :class:`ScanError`)
    is left to each loop's own extractor in its control step; a loop whose scan cannot be
    decoded drops it."""
    from oabug_robot.scan_features_kernel import extract_held

    groups: dict[int, list[tuple[RobotLoop[Any], LaserScanData, int]]] = {}
    for loop in loops:
        if loop._scan is None:  # nothing new (pending_scan would say None)
            continue
        try:
            pending = loop.pending_scan()
        except ScanError:
            continue
        if pending is not None:
            groups.setdefault(loop.perception_group, []).append((loop, *pending))
    for members in groups.values():
        try:
            features = extract_held(
                members[0][0].extractor,
                [scan for _, scan, _ in members],
                [loop.peer_bearings(now_s) for loop, _, _ in members],
                [side for _, _, side in members],
            )
        except ScanError:
            continue
        for (loop, _, _), loop_features in zip(members, features, strict=True):
            loop.take_features(loop_features)
