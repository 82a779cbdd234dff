"""Slamtec RPLidar A1 serial protocol: pure encode/decode functions (HARDWARE.md §2).

Nothing here touches a port. Requests are bytes, responses are decoded into frozen
dataclasses, and the endless scan stream is decoded incrementally by
:class:`SampleStreamDecoder`, which validates every 5-byte sample (S != !S, C == 1, angle
below 360°) and resynchronises byte by byte after garbage. :class:`RevolutionAssembler` cuts
the samples into 360° revolutions and :func:`bin_revolution` maps one revolution onto fixed
LaserScan bins in the REP 103 convention.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

import numpy as np
import numpy.typing as npt

from hw_drivers.errors import ConfigurationError, ProtocolError

__all__ = [
    'HEALTH_DESCRIPTOR',
    'INFO_DESCRIPTOR',
    'SAMPLE_SIZE',
    'SCAN_DESCRIPTOR',
    'Command',
    'Descriptor',
    'DeviceInfo',
    'Health',
    'HealthStatus',
    'Revolution',
    'RevolutionAssembler',
    'SampleStreamDecoder',
    'ScanBinning',
    'ScanSamples',
    'SendMode',
    'bin_revolution',
    'check_descriptor',
    'decode_descriptor',
    'decode_health',
    'decode_info',
    'decode_samples',
    'encode_request',
]

REQUEST_SYNC = 0xA5
RESPONSE_SYNC = (0xA5, 0x5A)
DESCRIPTOR_SIZE = 7
SAMPLE_SIZE = 5
ANGLE_Q6_FULL_TURN = 360 * 64
_EMPTY = np.zeros(0, dtype=np.uint8)
_RESYNC_WINDOW = 64


class Command(IntEnum):
    """Request command bytes (HARDWARE.md §2.2)."""

    STOP = 0x25
    RESET = 0x40
    SCAN = 0x20
    FORCE_SCAN = 0x21
    GET_INFO = 0x50
    GET_HEALTH = 0x52
    GET_SAMPLERATE = 0x59


class SendMode(IntEnum):
    """Top two bits of the descriptor's length word."""

    SINGLE = 0
    MULTIPLE = 1


class HealthStatus(IntEnum):
    """GET_HEALTH status byte."""

    GOOD = 0
    WARNING = 1
    ERROR = 2


@dataclass(frozen=True)
class Descriptor:
    """Response descriptor: payload length [bytes], send mode and data type byte."""

    length: int
    send_mode: SendMode
    data_type: int


SCAN_DESCRIPTOR = Descriptor(SAMPLE_SIZE, SendMode.MULTIPLE, 0x81)
INFO_DESCRIPTOR = Descriptor(20, SendMode.SINGLE, 0x04)
HEALTH_DESCRIPTOR = Descriptor(3, SendMode.SINGLE, 0x06)


@dataclass(frozen=True)
class DeviceInfo:
    """GET_INFO answer: model id, firmware version, hardware revision, serial number (hex)."""

    model: int
    firmware_major: int
    firmware_minor: int
    hardware: int
    serial_number: str

    @property
    def firmware(self) -> str:
        """Firmware version as 'major.minor' (minor with two digits, as Slamtec prints it)."""
        return f'{self.firmware_major}.{self.firmware_minor:02d}'


@dataclass(frozen=True)
class Health:
    """GET_HEALTH answer: status and the device's error code."""

    status: HealthStatus
    error_code: int


def encode_request(command: Command | int, payload: bytes = b'') -> bytes:
    """Return the request packet for ``command``.

    Without payload the packet is ``A5 <cmd>``; with payload ``A5 <cmd> <size> <payload>
    <checksum>`` where the checksum is the XOR of every preceding byte.
    """
    if not 0 <= int(command) <= 0xFF:
        raise ConfigurationError(f'command byte out of range: {command}')
    if not payload:
        return bytes((REQUEST_SYNC, int(command)))
    if len(payload) > 0xFF:
        raise ConfigurationError(f'request payload too long: {len(payload)} bytes')
    head = bytes((REQUEST_SYNC, int(command), len(payload))) + payload
    checksum = 0
    for byte in head:
        checksum ^= byte
    return head + bytes((checksum,))


def decode_descriptor(data: bytes) -> Descriptor:
    """Decode a 7-byte response descriptor.

    Raises:
        ProtocolError: wrong size or sync bytes.
    """
    if len(data) != DESCRIPTOR_SIZE:
        raise ProtocolError(f'descriptor must be {DESCRIPTOR_SIZE} bytes, got {len(data)}')
    if (data[0], data[1]) != RESPONSE_SYNC:
        raise ProtocolError(f'descriptor sync bytes {data[0]:02X} {data[1]:02X} != A5 5A')
    word = int.from_bytes(data[2:6], 'little')
    return Descriptor(word & 0x3FFFFFFF, SendMode(word >> 30 & 0x1), data[6])


def check_descriptor(data: bytes, expected: Descriptor) -> Descriptor:
    """Decode a descriptor and require it to be ``expected``.

    Raises:
        ProtocolError: the descriptor is malformed or announces another response.
    """
    descriptor = decode_descriptor(data)
    if (data[5] >> 6) > 1:
        raise ProtocolError(f'descriptor send mode {data[5] >> 6} is undefined')
    if descriptor != expected:
        raise ProtocolError(f'unexpected descriptor {descriptor}, wanted {expected}')
    return descriptor


def decode_info(data: bytes) -> DeviceInfo:
    """Decode the 20-byte GET_INFO payload."""
    if len(data) != INFO_DESCRIPTOR.length:
        raise ProtocolError(f'info payload must be 20 bytes, got {len(data)}')
    return DeviceInfo(
        model=data[0],
        firmware_major=data[2],
        firmware_minor=data[1],
        hardware=data[3],
        serial_number=data[4:20].hex().upper(),
    )


def decode_health(data: bytes) -> Health:
    """Decode the 3-byte GET_HEALTH payload (error code little-endian)."""
    if len(data) != HEALTH_DESCRIPTOR.length:
        raise ProtocolError(f'health payload must be 3 bytes, got {len(data)}')
    try:
        status = HealthStatus(data[0])
    except ValueError as err:
        raise ProtocolError(f'unknown health status {data[0]}') from err
    return Health(status, int.from_bytes(data[1:3], 'little'))


@dataclass(frozen=True)
class ScanSamples:
    """A batch of decoded scan samples, all arrays of shape (N,).

    Attributes:
        start: True on the first sample of a new revolution.
        quality: signal strength 0..63 (0 = no return).
        angle_deg: device angle [deg], clockwise seen from above, in [0, 360).
        distance_mm: distance [mm]; 0 means no return.
    """

    start: npt.NDArray[np.bool_]
    quality: npt.NDArray[np.uint8]
    angle_deg: npt.NDArray[np.float64]
    distance_mm: npt.NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.start.shape[0])


def _valid_offsets(buf: npt.NDArray[np.uint8]) -> npt.NDArray[np.bool_]:
    """For each offset i with 5 bytes left, whether buf[i:i+5] is a plausible sample."""
    n = buf.shape[0] - SAMPLE_SIZE + 1
    if n <= 0:
        return np.zeros(0, dtype=bool)
    b0 = buf[:n]
    b1 = buf[1 : n + 1]
    b2 = buf[2 : n + 2].astype(np.uint16)
    angle_q6 = (b1 >> 1).astype(np.uint16) | (b2 << 7)
    return ((b0 & 1) != ((b0 >> 1) & 1)) & ((b1 & 1) == 1) & (angle_q6 < ANGLE_Q6_FULL_TURN)


def decode_samples(frames: npt.NDArray[np.uint8]) -> ScanSamples:
    """Decode an (N, 5) array of already validated sample bytes."""
    b0 = frames[:, 0]
    wide = frames.astype(np.uint16)
    angle_q6 = (wide[:, 1] >> 1) | (wide[:, 2] << 7)
    distance_q2 = wide[:, 3] | (wide[:, 4] << 8)
    return ScanSamples(
        start=(b0 & 1).astype(bool),
        quality=b0 >> 2,
        angle_deg=angle_q6 * (1.0 / 64.0),
        distance_mm=distance_q2 * 0.25,
    )


class SampleStreamDecoder:
    """Incremental decoder of the standard scan stream with byte-wise resynchronisation.

    Feed it whatever the port delivered; it keeps at most 4 bytes of an incomplete sample
    between calls. A 5-byte window is accepted only if S != !S, C == 1 and the angle is below
    360°; otherwise one byte is dropped and counted in :attr:`rejected_bytes`. The search is
    vectorised: a run of aligned valid samples is taken in one numpy step.
    """

    def __init__(self) -> None:
        self._pending = _EMPTY
        self.accepted_samples = 0
        self.rejected_bytes = 0

    def reset(self) -> None:
        """Forget buffered bytes (after a flush of the port); counters are kept."""
        self._pending = _EMPTY

    def feed(self, data: bytes) -> ScanSamples:
        """Decode all complete samples in the pending bytes plus ``data``."""
        incoming = np.frombuffer(data, dtype=np.uint8)
        buf = np.concatenate((self._pending, incoming)) if self._pending.size else incoming
        valid = _valid_offsets(buf)
        n_offsets = valid.shape[0]
        runs: list[npt.NDArray[np.uint8]] = []
        pos = 0
        while pos < n_offsets:
            chain = valid[pos::SAMPLE_SIZE]
            bad = np.flatnonzero(~chain)
            run = int(bad[0]) if bad.size else chain.shape[0]
            if run:
                # A run of aligned valid samples is a contiguous block: reshape, no copy.
                runs.append(buf[pos : pos + SAMPLE_SIZE * run].reshape(run, SAMPLE_SIZE))
                pos += SAMPLE_SIZE * run
                continue
            # Look for the next plausible offset in a short window (cost independent of the
            # buffer size); an all-junk window is skipped as a whole.
            window = valid[pos + 1 : pos + 1 + _RESYNC_WINDOW]
            later = np.flatnonzero(window)
            skip = int(later[0]) + 1 if later.size else window.shape[0] + 1
            self.rejected_bytes += skip
            pos += skip
        # Every offset with 5 bytes left was taken or skipped: at most 4 bytes remain.
        self._pending = buf[pos:].copy() if pos < buf.shape[0] else _EMPTY
        if not runs:
            return decode_samples(np.zeros((0, SAMPLE_SIZE), dtype=np.uint8))
        frames = runs[0] if len(runs) == 1 else np.concatenate(runs)
        self.accepted_samples += int(frames.shape[0])
        return decode_samples(frames)


@dataclass(frozen=True)
class Revolution:
    """One 360° revolution of samples.

    Attributes:
        angle_deg: device angles [deg], shape (N,), clockwise.
        distance_mm: distances [mm], shape (N,), 0 = no return.
        quality: qualities 0..63, shape (N,).
        start_time_s: receive time of the first sample [s, caller's clock].
        period_s: time from this revolution's start to the next one's [s].
    """

    angle_deg: npt.NDArray[np.float64]
    distance_mm: npt.NDArray[np.float64]
    quality: npt.NDArray[np.uint8]
    start_time_s: float
    period_s: float

    def __len__(self) -> int:
        return int(self.angle_deg.shape[0])


class RevolutionAssembler:
    """Cut a sample stream into revolutions.

    A revolution starts at a sample with S = 1, or where the angle wraps from above
    ``wrap_high_deg`` to below ``wrap_low_deg`` (a missed S flag). The samples before the
    first boundary and revolutions with fewer than ``min_points`` samples are dropped and
    counted in :attr:`dropped_revolutions`.
    """

    def __init__(
        self, *, min_points: int = 50, wrap_high_deg: float = 350.0, wrap_low_deg: float = 10.0
    ) -> None:
        if min_points < 1:
            raise ConfigurationError(f'min_points must be >= 1, got {min_points}')
        self._min_points = min_points
        self._wrap_high_deg = wrap_high_deg
        self._wrap_low_deg = wrap_low_deg
        self._parts: list[ScanSamples] = []
        self._start_time_s: float | None = None
        self._last_angle_deg: float | None = None
        self.dropped_revolutions = 0

    def reset(self) -> None:
        """Drop the revolution in progress (after a scan restart)."""
        self._parts = []
        self._start_time_s = None
        self._last_angle_deg = None

    def add(self, samples: ScanSamples, receive_time_s: float) -> list[Revolution]:
        """Add samples received at ``receive_time_s``; return the revolutions they complete."""
        if len(samples) == 0:
            return []
        angles = samples.angle_deg
        previous = np.empty_like(angles)
        previous[0] = angles[0] if self._last_angle_deg is None else self._last_angle_deg
        previous[1:] = angles[:-1]
        wrapped = (previous > self._wrap_high_deg) & (angles < self._wrap_low_deg)
        if self._last_angle_deg is None:
            wrapped[0] = False
        boundaries = np.flatnonzero(samples.start | wrapped)
        self._last_angle_deg = float(angles[-1])
        done: list[Revolution] = []
        begin = 0
        for cut in boundaries:
            cut = int(cut)
            if cut > begin:
                self._parts.append(_slice(samples, begin, cut))
            revolution = self._close(receive_time_s)
            if revolution is not None:
                done.append(revolution)
            self._start_time_s = receive_time_s
            begin = cut
        self._parts.append(_slice(samples, begin, len(samples)))
        return done

    def _close(self, end_time_s: float) -> Revolution | None:
        parts, self._parts = self._parts, []
        start_time_s = self._start_time_s
        count = sum(len(p) for p in parts)
        if count == 0:
            return None
        if start_time_s is None or count < self._min_points:
            # A leading part whose start was not seen, or a revolution broken up by a resync.
            self.dropped_revolutions += 1
            return None
        return Revolution(
            angle_deg=np.concatenate([p.angle_deg for p in parts]),
            distance_mm=np.concatenate([p.distance_mm for p in parts]),
            quality=np.concatenate([p.quality for p in parts]),
            start_time_s=start_time_s,
            period_s=max(end_time_s - start_time_s, 0.0),
        )


def _slice(samples: ScanSamples, begin: int, end: int) -> ScanSamples:
    return ScanSamples(
        samples.start[begin:end],
        samples.quality[begin:end],
        samples.angle_deg[begin:end],
        samples.distance_mm[begin:end],
    )


@dataclass(frozen=True)
class ScanBinning:
    """How device samples become LaserScan bins (REP 103: counter-clockwise, radians).

    ROS angle = wrap(zero_offset_rad + angle_direction * device_angle). The defaults
    (direction -1, offset pi) are Slamtec's ROS mapping, which puts laser +x at the device's
    180° mark (HARDWARE.md §2.7).

    Attributes:
        bins: number of bins over [-pi, pi).
        angle_direction: +1 or -1 (the device measures clockwise).
        zero_offset_rad: ROS angle of the device's 0° mark [rad].
        range_min_m: shortest valid range [m]; shorter readings become -inf (REP 117).
        range_max_m: longest valid range [m]; longer readings become +inf.
    """

    bins: int = 360
    angle_direction: int = -1
    zero_offset_rad: float = float(np.pi)
    range_min_m: float = 0.15
    range_max_m: float = 12.0

    def __post_init__(self) -> None:
        if self.bins < 4:
            raise ConfigurationError(f'bins must be >= 4, got {self.bins}')
        if self.angle_direction not in (-1, 1):
            msg = f'angle_direction must be +1 or -1, got {self.angle_direction}'
            raise ConfigurationError(msg)
        if not 0.0 <= self.range_min_m < self.range_max_m:
            msg = f'need 0 <= range_min_m < range_max_m, got {self.range_min_m}, {self.range_max_m}'
            raise ConfigurationError(msg)
        if not np.isfinite(self.zero_offset_rad):
            raise ConfigurationError('zero_offset_rad must be finite')

    @property
    def angle_min_rad(self) -> float:
        """Angle of bin 0 [rad]."""
        return -float(np.pi)

    @property
    def angle_increment_rad(self) -> float:
        """Angle between bins [rad]."""
        return 2.0 * float(np.pi) / self.bins


def bin_revolution(
    revolution: Revolution, binning: ScanBinning
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """Put one revolution into fixed bins.

    Each sample goes to its nearest bin; when several fall into one bin the shortest finite
    range wins. Per REP 117: no return (distance 0 or beyond range_max) is +inf, a reading
    shorter than range_min is -inf, and a bin that got no sample at all is NaN.

    Returns:
        ranges [m] and intensities (quality 0..63), both float32 of shape (bins,).
    """
    ros_angle = binning.zero_offset_rad + binning.angle_direction * np.deg2rad(revolution.angle_deg)
    index = np.rint((ros_angle - binning.angle_min_rad) / binning.angle_increment_rad)
    index = np.mod(index.astype(np.int64), binning.bins)
    range_m = revolution.distance_mm / 1000.0
    range_m = np.where(
        (revolution.distance_mm <= 0.0) | (range_m > binning.range_max_m), np.inf, range_m
    )
    range_m = np.where(range_m < binning.range_min_m, -np.inf, range_m)
    order = np.lexsort((range_m, index))
    sorted_index = index[order]
    first = np.flatnonzero(np.r_[True, sorted_index[1:] != sorted_index[:-1]])
    ranges = np.full(binning.bins, np.nan, dtype=np.float32)
    intensities = np.zeros(binning.bins, dtype=np.float32)
    chosen = order[first]
    ranges[sorted_index[first]] = range_m[chosen]
    intensities[sorted_index[first]] = revolution.quality[chosen]
    return ranges, intensities
