"""From locator reports to the robot's peer bearings (ROS-free core of the AoA node).

:class:`BearingCollector` drops the robot's own tag, duplicated and old reports, maps the
azimuth into the robot frame and keeps the reports that arrived since the last publish.
Thread-safe: the server thread adds, the node's timer takes.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

from hw_drivers.aoa_protocol import (
    AngleReport,
    AzimuthMapping,
    SequenceFilter,
    normalise_tag_id,
)

__all__ = ['BearingCollector', 'PeerBearingData']


@dataclass(frozen=True)
class PeerBearingData:
    """One peer bearing in the robot frame (REP 103), ready for PeerBearing.

    Attributes:
        tag_id: normalised tag id.
        azimuth_rad: azimuth [rad] in (-pi, pi], 0 = forward, counter-clockwise positive.
        elevation_rad: elevation [rad]; NaN when unknown.
        distance_m: coarse distance [m]; NaN when unknown.
        quality: locator quality code (0 = OK).
        sequence: locator sequence number (0 when the locator sent none).
        rssi_dbm: RSSI [dBm]; NaN when unknown.
        time_s: receive time [s, collector clock].
    """

    tag_id: str
    azimuth_rad: float
    elevation_rad: float
    distance_m: float
    quality: int
    sequence: int
    rssi_dbm: float
    time_s: float


class BearingCollector:
    """Filter and map reports; hand out the latest per tag since the last take."""

    def __init__(
        self,
        *,
        own_tag_id: str = '',
        mapping: AzimuthMapping | None = None,
        sequence_filter: SequenceFilter | None = None,
    ) -> None:
        self.own_tag_id = normalise_tag_id(own_tag_id)
        self.mapping = mapping or AzimuthMapping()
        self.sequence_filter = sequence_filter or SequenceFilter()
        self._lock = threading.Lock()
        self._pending: dict[str, PeerBearingData] = {}
        self.own_reports = 0
        self.degraded_reports = 0
        self.last_seen_s: dict[str, float] = {}

    def add(self, report: AngleReport, time_s: float) -> bool:
        """Take one report received at ``time_s``; return False if it was dropped."""
        if self.own_tag_id and report.tag_id == self.own_tag_id:
            self.own_reports += 1
            return False
        with self._lock:
            if not self.sequence_filter.accept(report.tag_id, report.sequence):
                return False
            if report.quality != 0:
                self.degraded_reports += 1
            self._pending[report.tag_id] = PeerBearingData(
                tag_id=report.tag_id,
                azimuth_rad=self.mapping.azimuth_rad(report.azimuth_deg),
                elevation_rad=math.radians(report.elevation_deg),
                distance_m=report.distance_m,
                quality=min(report.quality, 255),
                sequence=report.sequence or 0,
                rssi_dbm=report.rssi_dbm,
                time_s=time_s,
            )
            self.last_seen_s[report.tag_id] = time_s
        return True

    def ages_s(self, now_s: float) -> dict[str, float]:
        """Seconds since each tag was last heard (thread-safe copy)."""
        with self._lock:
            return {tag: now_s - seen_s for tag, seen_s in self.last_seen_s.items()}

    @property
    def pending(self) -> bool:
        """True when a bearing waits to be taken."""
        with self._lock:
            return bool(self._pending)

    def take(self) -> list[PeerBearingData]:
        """Latest bearing of each tag heard since the previous call, sorted by tag id."""
        with self._lock:
            pending, self._pending = self._pending, {}
        return [pending[tag] for tag in sorted(pending)]
