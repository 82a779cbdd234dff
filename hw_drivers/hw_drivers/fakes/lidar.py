"""A synthetic RPLidar A1: answers requests and streams a rectangular room."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from hw_drivers.rplidar_protocol import Command

__all__ = [
    'FakeRPLidar',
    'FakeRPLidarPort',
    'RectangularRoom',
    'drifting_scan_frames',
    'encode_sample',
    'revolution_bytes',
]

_INFO_PAYLOAD = bytes((0x18, 29, 1, 7)) + bytes(range(16))


def encode_sample(angle_deg: float, distance_mm: float, quality: int, *, start: bool) -> bytes:
    """Encode one standard scan sample (5 bytes) as the lidar sends it."""
    angle_q6 = round(angle_deg * 64.0) % (360 * 64)
    distance_q2 = max(0, min(round(distance_mm * 4.0), 0xFFFF))
    s_bit = 1 if start else 0
    byte0 = (quality & 0x3F) << 2 | (1 - s_bit) << 1 | s_bit
    return bytes(
        (
            byte0,
            (angle_q6 & 0x7F) << 1 | 1,
            angle_q6 >> 7 & 0xFF,
            distance_q2 & 0xFF,
            distance_q2 >> 8 & 0xFF,
        )
    )


def _descriptor(length: int, mode: int, data_type: int) -> bytes:
    return bytes((0xA5, 0x5A)) + (length | mode << 30).to_bytes(4, 'little') + bytes((data_type,))


@dataclass(frozen=True)
class RectangularRoom:
    """A lidar at (x, y) inside an axis-aligned room [0, width] x [0, depth] [m].

    ``heading_rad`` is the direction of the device's 0° mark in the room frame; the device
    measures clockwise.
    """

    width_m: float = 4.0
    depth_m: float = 3.0
    x_m: float = 1.0
    y_m: float = 1.0
    heading_rad: float = 0.0

    def range_m(self, device_angle_deg: float) -> float:
        """Distance to the first wall along a device angle [m]."""
        direction = self.heading_rad - math.radians(device_angle_deg)
        dx, dy = math.cos(direction), math.sin(direction)
        hits = []
        if dx > 1e-12:
            hits.append((self.width_m - self.x_m) / dx)
        if dx < -1e-12:
            hits.append(-self.x_m / dx)
        if dy > 1e-12:
            hits.append((self.depth_m - self.y_m) / dy)
        if dy < -1e-12:
            hits.append(-self.y_m / dy)
        return min(hits)


class FakeRPLidar:
    """Protocol-level RPLidar: bytes in (requests), bytes out (responses, scan stream).

    Args:
        room: geometry that the synthetic scans see.
        samples_per_revolution: samples per 360° (A1 standard scan: ~360 at 5.5 Hz).
        health_status: 0 Good, 1 Warning, 2 Error (reported until a RESET if
            ``error_until_reset``).
    """

    def __init__(
        self,
        room: RectangularRoom | None = None,
        *,
        samples_per_revolution: int = 360,
        health_status: int = 0,
        error_until_reset: bool = True,
    ) -> None:
        self.room = room or RectangularRoom()
        self.samples_per_revolution = samples_per_revolution
        self.health_status = health_status
        self.error_until_reset = error_until_reset
        self.scanning = False
        self.requests: list[int] = []
        self._sample_index = 0
        step = 360.0 / samples_per_revolution
        self._angles = [i * step + 0.25 for i in range(samples_per_revolution)]
        self._ranges_mm = [self.room.range_m(a) * 1000.0 for a in self._angles]

    def handle(self, data: bytes) -> bytes:
        """Consume request bytes and return the immediate response bytes."""
        out = bytearray()
        i = 0
        while i + 1 < len(data):
            if data[i] != 0xA5:
                i += 1
                continue
            command = data[i + 1]
            i += 2
            self.requests.append(command)
            out += self._respond(command)
        return bytes(out)

    def _respond(self, command: int) -> bytes:
        if command == Command.STOP:
            self.scanning = False
            return b''
        if command == Command.RESET:
            self.scanning = False
            if self.error_until_reset and self.health_status == 2:
                self.health_status = 0
            return b'RP LIDAR System.\r\n'
        if command == Command.GET_INFO:
            return _descriptor(20, 0, 0x04) + _INFO_PAYLOAD
        if command == Command.GET_HEALTH:
            return _descriptor(3, 0, 0x06) + bytes((self.health_status, 0x12, 0x80))
        if command in (Command.SCAN, Command.FORCE_SCAN):
            self.scanning = True
            self._sample_index = 0
            return _descriptor(5, 1, 0x81)
        return b''

    def scan_bytes(self, count: int) -> bytes:
        """The next ``count`` samples of the endless scan stream (empty when not scanning)."""
        if not self.scanning:
            return b''
        out = bytearray()
        n = self.samples_per_revolution
        for _ in range(count):
            k = self._sample_index % n
            out += encode_sample(self._angles[k], self._ranges_mm[k], 40, start=k == 0)
            self._sample_index += 1
        return bytes(out)


class FakeRPLidarPort:
    """An in-memory SerialPort wired to a :class:`FakeRPLidar`.

    The scan stream is produced at ``samples_per_s`` against an injectable clock, so reads
    return what a real A1 would have sent by then.
    """

    def __init__(
        self,
        device: FakeRPLidar,
        *,
        samples_per_s: float = 2000.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.device = device
        self.samples_per_s = samples_per_s
        self._clock = clock
        self._buffer = bytearray()
        self._last_s = clock()
        self._fraction = 0.0
        self.dtr = True
        self.closed = False
        self.unplugged = False
        self.inject: Callable[[bytes], bytes] | None = None

    def _pump(self) -> None:
        now = self._clock()
        exact = (now - self._last_s) * self.samples_per_s + self._fraction
        self._last_s = now
        count = int(exact)
        self._fraction = exact - count
        if count and self.device.scanning:
            chunk = self.device.scan_bytes(count)
            self._buffer += self.inject(chunk) if self.inject else chunk

    def _check(self) -> None:
        if self.unplugged:
            raise OSError(5, 'device reports readiness to read but returned no data')

    @property
    def in_waiting(self) -> int:
        """Bytes ready to read."""
        self._check()
        self._pump()
        return len(self._buffer)

    def read(self, size: int = 1) -> bytes:
        """Return up to ``size`` buffered bytes."""
        self._check()
        self._pump()
        data = bytes(self._buffer[:size])
        del self._buffer[:size]
        return data

    def write(self, data: bytes) -> int:
        """Hand a request to the device."""
        self._check()
        self._pump()
        self._buffer += self.device.handle(data)
        return len(data)

    def reset_input_buffer(self) -> None:
        """Drop buffered input."""
        self._pump()
        self._buffer.clear()

    def close(self) -> None:
        """Mark the port closed."""
        self.closed = True


def revolution_bytes(device: FakeRPLidar, revolutions: int) -> bytes:
    """Scan-stream bytes of whole revolutions, for decoder tests and benchmarks."""
    was_scanning = device.scanning
    device.scanning = True
    data = device.scan_bytes(revolutions * device.samples_per_revolution)
    device.scanning = was_scanning
    return data


def drifting_scan_frames(
    revolutions: int,
    *,
    samples_per_revolution: int = 360,
    start_drift_deg: float = 0.0,
    room: RectangularRoom | None = None,
    quality: int = 40,
    revolution_tag_mm: float = 0.0,
) -> list[bytes]:
    """Sample frames (5 bytes each) of ``revolutions`` turns whose start flag drifts.

    The rotation is continuous (angles step by 360 / samples_per_revolution from 0.25°), but
    the start flag S of revolution ``k`` sits on the sample nearest ``k * start_drift_deg``
    past the 0° mark, as on a unit whose flag comes a little later every turn: each
    revolution then spans 360° plus the drift. Ranges come from ``room``, plus
    ``k * revolution_tag_mm`` in revolution ``k`` (0.25 mm, the distance resolution, makes the
    samples of every revolution distinct, for tests that match samples one by one).
    """
    room = room or RectangularRoom()
    step = 360.0 / samples_per_revolution
    starts = [
        k * samples_per_revolution + round(k * start_drift_deg / step)
        for k in range(revolutions + 1)
    ]
    frames: list[bytes] = []
    for k in range(revolutions):
        for i in range(starts[k], starts[k + 1]):
            angle = (i * step + 0.25) % 360.0
            distance = room.range_m(angle) * 1000.0 + k * revolution_tag_mm
            frames.append(encode_sample(angle, distance, quality, start=i == starts[k]))
    return frames
