"""Slamtec RPLidar A1 serial protocol: pure encode/decode functions.

Nothing here touches a port. Requests are bytes, responses are decoded into frozen
dataclasses, and the endless scan stream is decoded incrementally by
:class:`SampleStreamDecoder`, which accepts a 5-byte sample only inside a run of consistent
samples (check bits S != !S and C == 1, angle below 360°, small angle steps from sample to
sample, plausible ends) and resynchronises byte by byte after garbage.
:class:`RevolutionAssembler` cuts the samples into 360° revolutions by the rotation swept
since the last start flag, and :func:`bin_revolution` maps one revolution onto fixed
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
    'MAX_BINS',
    'SAMPLE_SIZE',
    'SCAN_DESCRIPTOR',
    'Command',
    'Descriptor',
    'DeviceInfo',
    'Health',
    'HealthStatus',
    'ResyncConfig',
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
#: Most LaserScan bins (the A1 gives ~1500 samples per revolution; more bins only cost memory).
MAX_BINS = 4096
ANGLE_Q6_FULL_TURN = 360 * 64
_EMPTY = np.zeros(0, dtype=np.uint8)


class Command(IntEnum):
    """Request command bytes."""

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


@dataclass(frozen=True)
class ResyncConfig:
    """How the scan decoder tells samples from junk (see :class:`SampleStreamDecoder`).

    Attributes:
        min_run: consecutive consistent samples needed to accept a stretch of the stream
            after junk or at the start; a single window that passes the check bits is not
            enough.
        max_angle_step_deg: largest angle change between consecutive samples, either way
            [deg]. The A1 steps about 1-2 deg per sample; samples without a return (distance
            0) may sit several degrees ahead of their neighbours.
        edge_distance_rel: a sample at the end of a consistent run (next to junk) with a
            return must be within this fraction of the nearest return in the run...
        edge_distance_abs_mm: ...or within this many millimetres [mm].
        edge_quality_step: ...and its quality within this many steps of that return's.
        edge_reference_samples: how far into the run that nearest return is looked for.
        compare_samples: after junk, the runs starting at ``compare_offsets`` consecutive
            offsets are compared over this many samples and the longest is taken...
        compare_offsets: ...from the first offset where a run starts on...
        min_turn_deg: ...and of runs as long, the one with the most links that turn by at
            least this much [deg] (the A1 turns about 1 deg per sample; a run shifted
            against the samples barely turns).
    """

    min_run: int = 4
    max_angle_step_deg: float = 15.0
    edge_distance_rel: float = 0.25
    edge_distance_abs_mm: float = 150.0
    edge_quality_step: int = 24
    edge_reference_samples: int = 3
    compare_samples: int = 8
    compare_offsets: int = 15
    min_turn_deg: float = 0.25

    def __post_init__(self) -> None:
        if self.min_run < 3:
            raise ConfigurationError(f'min_run must be >= 3, got {self.min_run}')
        if not 0.0 < self.max_angle_step_deg < 180.0:
            msg = f'max_angle_step_deg must be in (0, 180), got {self.max_angle_step_deg}'
            raise ConfigurationError(msg)
        if self.edge_distance_rel < 0.0 or self.edge_distance_abs_mm < 0.0:
            raise ConfigurationError('edge distance tolerances must be >= 0')
        if self.compare_offsets < SAMPLE_SIZE:
            msg = f'compare_offsets must be >= {SAMPLE_SIZE}, got {self.compare_offsets}'
            raise ConfigurationError(msg)
        if self.compare_samples < self.min_run:
            msg = f'compare_samples must be >= min_run, got {self.compare_samples}'
            raise ConfigurationError(msg)
        if not 0.0 <= self.min_turn_deg < self.max_angle_step_deg:
            msg = f'min_turn_deg must be in [0, max_angle_step_deg), got {self.min_turn_deg}'
            raise ConfigurationError(msg)
        if self.edge_quality_step < 0 or self.edge_reference_samples < 1:
            raise ConfigurationError('edge_quality_step must be >= 0, edge_reference_samples >= 1')


def _window_fields(
    buf: npt.NDArray[np.uint8],
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.int64]]:
    """For each offset with 5 bytes left: do the check bits pass, and the angle_q6 there."""
    n = buf.shape[0] - SAMPLE_SIZE + 1
    if n <= 0:
        return np.zeros(0, dtype=bool), np.zeros(0, dtype=np.int64)
    b0 = buf[:n]
    b1 = buf[1 : n + 1]
    angle_q6 = (b1 >> 1).astype(np.int64) | (buf[2 : n + 2].astype(np.int64) << 7)
    valid = ((b0 & 1) != ((b0 >> 1) & 1)) & ((b1 & 1) == 1) & (angle_q6 < ANGLE_Q6_FULL_TURN)
    return valid, angle_q6


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


def _frame_distance_mm(frame: npt.NDArray[np.uint8]) -> float:
    return (int(frame[3]) | int(frame[4]) << 8) * 0.25


class SampleStreamDecoder:
    """Incremental decoder of the standard scan stream that accepts only consistent runs.

    A 5-byte window is a *candidate* sample when its check bits pass (S != !S, C == 1) and
    its angle is below 360°. Two candidates 5 bytes apart are *linked* when their angles
    differ by at most ``max_angle_step_deg`` (modulo 360°), as consecutive samples of a
    spinning lidar do. The decoder accepts:

    * the samples of a run of at least ``min_run`` linked candidates, found by trying one
      byte offset after another (every offset passed over is a rejected byte);
    * while in such a run, each next sample linked to the previous one.

    A sample at either end of a run (linked on one side only, i.e. next to junk or a gap) is
    accepted only if it is plausible against the nearest return in the run: either no return
    itself (distance 0) or a distance and quality close to that return's (``edge_*``
    settings). Random junk passes the check bits in about one window
    of six and a link in about one of twelve, so runs of junk are rare, and a junk window
    glued to a real run by chance is caught by the edge test.

    Feed it whatever the port delivered; decisions wait until the bytes they need have
    arrived, so the output does not depend on how the stream was split into reads. At most
    ``5 * compare_samples + compare_offsets - 2`` bytes stay pending between calls
    (:attr:`pending_bytes`).
    """

    def __init__(self, config: ResyncConfig | None = None) -> None:
        self.config = config or ResyncConfig()
        self._max_step_q6 = round(self.config.max_angle_step_deg * 64.0)
        self._min_turn_q6 = round(self.config.min_turn_deg * 64.0)
        self._pending = _EMPTY
        self._last: npt.NDArray[np.uint8] | None = None  # last accepted sample while in a run
        self._recent: list[npt.NDArray[np.uint8]] = []  # the run's last accepted samples
        self.accepted_samples = 0
        self.rejected_bytes = 0
        self.rejected_edges = 0

    @property
    def pending_bytes(self) -> int:
        """Bytes received but not yet accepted or rejected."""
        return int(self._pending.shape[0])

    def reset(self) -> None:
        """Forget buffered bytes and the current run (after a flush); counters are kept."""
        self._pending = _EMPTY
        self._last = None
        self._recent = []

    def _edge_ok(self, frame: npt.NDArray[np.uint8], run: list[npt.NDArray[np.uint8]]) -> bool:
        """Whether a run's end sample ``frame`` fits the run (``run``: nearest first)."""
        distance = _frame_distance_mm(frame)
        if distance == 0.0:
            return True
        config = self.config
        for other in run[: config.edge_reference_samples]:
            reference = _frame_distance_mm(other)
            if reference == 0.0:
                continue
            tolerance = max(config.edge_distance_rel * reference, config.edge_distance_abs_mm)
            quality_step = abs(int(frame[0] >> 2) - int(other[0] >> 2))
            return abs(distance - reference) <= tolerance and quality_step <= (
                config.edge_quality_step
            )
        return False

    def _links(
        self, buf: npt.NDArray[np.uint8]
    ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.int64], int]:
        """link[i]: candidates at i and i + 5 with a plausible angle step between them.

        Also returns the size of that step (angle_q6, either way) and the number of links.
        """
        valid, angle_q6 = _window_fields(buf)
        n_links = max(buf.shape[0] - 2 * SAMPLE_SIZE + 1, 0)
        step = np.abs(angle_q6[SAMPLE_SIZE : SAMPLE_SIZE + n_links] - angle_q6[:n_links])
        step = np.minimum(step, ANGLE_Q6_FULL_TURN - step)
        link = valid[:n_links] & valid[SAMPLE_SIZE : SAMPLE_SIZE + n_links]
        link &= step <= self._max_step_q6
        return link, step, n_links

    def _longest_run_start(
        self,
        link: npt.NDArray[np.bool_],
        step_q6: npt.NDArray[np.int64],
        n_links: int,
        found: int,
    ) -> int | None:
        """Of the runs starting at ``found`` and the next ``compare_offsets - 1`` offsets, the best.

        Bytes where junk meets real samples can form a run shifted against the real samples
        by a few bytes, sometimes led in by a junk window or two. Its angles come from the
        samples' quality and distance bytes, which change slowly, so it barely turns; the
        real samples form the longer run, or one as long in which more links turn. Runs are
        compared over up to ``compare_samples`` samples by length, then by the number of
        links that turn by at least ``min_turn_deg`` (not by the total angle: one junk link
        that leads a shifted run in can turn further than the real run's links together),
        then by the angle they turn through. None when the bytes needed to decide have not
        all arrived.
        """
        cap = self.config.compare_samples - 1  # links
        width = self.config.compare_offsets
        if found + width - 1 + SAMPLE_SIZE * (cap - 1) >= n_links:
            return None
        lengths = np.zeros(width, dtype=np.int64)
        turning = np.zeros(width, dtype=np.int64)
        turned = np.zeros(width, dtype=np.int64)
        alive = np.ones(width, dtype=bool)
        for k in range(cap):
            start = found + SAMPLE_SIZE * k
            alive &= link[start : start + width]
            steps = step_q6[start : start + width]
            lengths += alive
            turning += alive & (steps >= self._min_turn_q6)
            turned += np.where(alive, steps, 0)
        # Longest first, then the most turning links, then the most turned.
        best = np.lexsort((-turned, -turning, -lengths))[0]
        return found + int(best)

    def feed(self, data: bytes) -> ScanSamples:
        """Decode all samples that the pending bytes plus ``data`` decide."""
        incoming = np.frombuffer(data, dtype=np.uint8)
        head = self._pending if self._last is None else np.concatenate((self._last, self._pending))
        buf = np.concatenate((head, incoming)) if head.size else incoming
        link, step_q6, n_links = self._links(buf)
        min_run = self.config.min_run
        # start_ok[i]: min_run candidates linked one to the next begin at offset i.
        n_starts = max(buf.shape[0] - SAMPLE_SIZE * min_run + 1, 0)
        start_ok = np.ones(n_starts, dtype=bool)
        for k in range(min_run - 1):
            start_ok &= link[SAMPLE_SIZE * k : SAMPLE_SIZE * k + n_starts]
        # Accepted samples as (first offset, count) segments of consecutive samples.
        accepted: list[tuple[int, int]] = []
        in_run = self._last is not None
        earlier = self._recent if in_run else []  # the run's samples from earlier feeds
        run_begin = 0  # index into ``accepted`` of the current run's first segment
        n_ref = self.config.edge_reference_samples
        pos = SAMPLE_SIZE if in_run else 0
        while True:
            if in_run:
                # Invariant: the sample at pos - 5 is the run's last accepted sample.
                if pos - SAMPLE_SIZE >= n_links:
                    break  # the window at pos is not complete yet
                chain = link[pos - SAMPLE_SIZE : n_links : SAMPLE_SIZE]
                broken = np.flatnonzero(~chain)
                # ``linked`` samples from pos on are linked to their predecessor; all but the
                # last of them are linked to their successor as well.
                linked = int(broken[0]) if broken.size else int(chain.shape[0])
                if linked > 1:
                    accepted.append((pos, linked - 1))
                    pos += SAMPLE_SIZE * (linked - 1)
                if not broken.size:
                    break  # whether pos links forwards is decided by the next bytes
                if linked:
                    # pos ends the run: linked backwards only.
                    run = _last_frames(buf, accepted[run_begin:], n_ref)
                    if self._edge_ok(buf[pos : pos + SAMPLE_SIZE], run + earlier):
                        accepted.append((pos, 1))
                        pos += SAMPLE_SIZE
                    else:
                        self.rejected_edges += 1
                        self.rejected_bytes += 1
                        pos += 1
                in_run = False
                earlier = []
                continue
            if pos >= n_starts:
                break
            later = np.flatnonzero(start_ok[pos:])
            if not later.size:
                self.rejected_bytes += n_starts - pos
                pos = n_starts
                break
            found = pos + int(later[0])
            best = self._longest_run_start(link, step_q6, n_links, found)
            if best is None:
                self.rejected_bytes += found - pos
                pos = found
                break  # the competing offsets are not decidable yet
            self.rejected_bytes += best - pos
            pos = best
            # A run starts at pos; its first sample is linked forwards only.
            following = [
                buf[pos + SAMPLE_SIZE * k : pos + SAMPLE_SIZE * (k + 1)] for k in range(1, min_run)
            ]
            run_begin = len(accepted)
            if self._edge_ok(buf[pos : pos + SAMPLE_SIZE], following):
                accepted.append((pos, 1))
            else:
                self.rejected_edges += 1
                self.rejected_bytes += SAMPLE_SIZE
                pos += SAMPLE_SIZE
                accepted.append((pos, 1))  # linked on both sides within the run (min_run >= 3)
            pos += SAMPLE_SIZE
            in_run = True
        blocks = [buf[a : a + SAMPLE_SIZE * c].reshape(c, SAMPLE_SIZE) for a, c in accepted]
        if not blocks:
            frames = np.zeros((0, SAMPLE_SIZE), dtype=np.uint8)
        else:
            frames = blocks[0] if len(blocks) == 1 else np.concatenate(blocks)
        if in_run:
            run = [f.copy() for f in _last_frames(buf, accepted[run_begin:], n_ref)]
            self._recent = (run + earlier)[:n_ref]
            self._last = buf[pos - SAMPLE_SIZE : pos].copy()
        else:
            self._recent = []
            self._last = None
        self._pending = buf[pos:].copy()
        self.accepted_samples += int(frames.shape[0])
        return decode_samples(frames)


def _last_frames(
    buf: npt.NDArray[np.uint8], segments: list[tuple[int, int]], count: int
) -> list[npt.NDArray[np.uint8]]:
    """The last ``count`` accepted frames of ``segments``, nearest (latest) first."""
    frames: list[npt.NDArray[np.uint8]] = []
    for first, n in reversed(segments):
        for k in range(n - 1, -1, -1):
            if len(frames) == count:
                return frames
            offset = first + SAMPLE_SIZE * k
            frames.append(buf[offset : offset + SAMPLE_SIZE])
    return frames


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
    """Cut a sample stream into revolutions by the rotation swept since the last start.

    The rotation is followed sample by sample (angle steps modulo 360°; a step back of up
    to ``max_back_step_deg`` is jitter, not a turn). A sample with the start flag S begins
    a new revolution once at least ``min_sweep_deg`` have been swept since the current one
    began; an earlier S is ignored (counted in :attr:`ignored_start_flags`), so a stray
    flag cannot break a revolution into fragments. No sample is dropped at an angle wrap: a
    start flag that comes late keeps the samples between the wrap and the flag in the
    revolution. When ``max_sweep_deg`` have been swept without a start flag (S was lost),
    the revolution is cut where it completed 360° and the rest begins the next one.

    The samples before the first boundary form a revolution only if they sweep at least
    ``min_sweep_deg`` (a turn whose first samples were lost); otherwise they are dropped,
    like revolutions with fewer than ``min_points`` samples, and counted in
    :attr:`dropped_revolutions` and :attr:`dropped_samples`.
    """

    def __init__(
        self,
        *,
        min_points: int = 50,
        min_sweep_deg: float = 270.0,
        max_sweep_deg: float = 380.0,
        max_back_step_deg: float = 30.0,
    ) -> None:
        if min_points < 1:
            raise ConfigurationError(f'min_points must be >= 1, got {min_points}')
        if not 0.0 < min_sweep_deg < 360.0 <= max_sweep_deg < 720.0:
            msg = (
                'need 0 < min_sweep_deg < 360 <= max_sweep_deg < 720,'
                f' got {min_sweep_deg} and {max_sweep_deg}'
            )
            raise ConfigurationError(msg)
        if not 0.0 <= max_back_step_deg < 180.0:
            msg = f'max_back_step_deg must be in [0, 180), got {max_back_step_deg}'
            raise ConfigurationError(msg)
        self._min_points = min_points
        self._min_sweep = min_sweep_deg
        self._max_sweep = max_sweep_deg
        self._max_back = max_back_step_deg
        # The revolution in progress: its samples, their cumulative rotation, where it began.
        self._parts: list[ScanSamples] = []
        self._parts_deg: list[npt.NDArray[np.float64]] = []
        self._begin_deg = 0.0
        self._start_time_s = 0.0
        self._in_revolution = False
        self._last_angle_deg: float | None = None
        self._unwrapped_deg = 0.0
        self.dropped_revolutions = 0
        self.dropped_samples = 0
        self.ignored_start_flags = 0

    def reset(self) -> None:
        """Drop the revolution in progress (after a scan restart)."""
        self._parts = []
        self._parts_deg = []
        self._in_revolution = False
        self._last_angle_deg = None
        self._unwrapped_deg = 0.0

    def _unwrap(self, angles: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Cumulative rotation [deg] at each sample, continuing from the previous batch."""
        previous = np.empty_like(angles)
        previous[0] = angles[0] if self._last_angle_deg is None else self._last_angle_deg
        previous[1:] = angles[:-1]
        step = np.mod(angles - previous, 360.0)
        step[step > 360.0 - self._max_back] -= 360.0
        unwrapped = self._unwrapped_deg + np.cumsum(step)
        self._last_angle_deg = float(angles[-1])
        self._unwrapped_deg = float(unwrapped[-1])
        return unwrapped

    def _append(self, samples: ScanSamples, unwrapped: npt.NDArray[np.float64]) -> None:
        if len(samples):
            self._parts.append(samples)
            self._parts_deg.append(unwrapped)

    def _begin(
        self, samples: ScanSamples, unwrapped: npt.NDArray[np.float64], time_s: float
    ) -> None:
        """Start a new revolution with ``samples`` (its first sample is the boundary)."""
        self._in_revolution = True
        self._start_time_s = time_s
        self._begin_deg = float(unwrapped[0])
        self._append(samples, unwrapped)

    def add(self, samples: ScanSamples, receive_time_s: float) -> list[Revolution]:
        """Add samples received at ``receive_time_s``; return the revolutions they complete."""
        n = len(samples)
        if n == 0:
            return []
        fresh = self._last_angle_deg is None
        unwrapped = self._unwrap(samples.angle_deg)
        begin = 0  # first sample of this batch not yet in the revolution in progress
        search = 0  # first sample that may begin the next revolution
        if fresh:
            # The first sample after a reset begins a part: a revolution if it carries S.
            self._begin(_slice(samples, 0, 1), unwrapped[:1], receive_time_s)
            self._in_revolution = bool(samples.start[0])
            begin = search = 1
        done: list[Revolution] = []
        while search < n:
            swept = unwrapped[search:] - self._begin_deg
            flagged = samples.start[search:]
            if self._in_revolution:
                boundary = (flagged & (swept >= self._min_sweep)) | (swept >= self._max_sweep)
            else:
                boundary = flagged | (swept >= self._max_sweep)
            hits = np.flatnonzero(boundary)
            end = search + int(hits[0]) if hits.size else n
            if self._in_revolution:
                self.ignored_start_flags += int(np.count_nonzero(samples.start[search:end]))
            if not hits.size:
                break
            self._append(_slice(samples, begin, end), unwrapped[begin:end])
            if samples.start[end] and swept[end - search] <= self._max_sweep:
                revolution = self._close(receive_time_s, float(unwrapped[end - 1]))
                carried: tuple[ScanSamples, npt.NDArray[np.float64]] | None = None
            else:
                revolution, carried = self._cut_missed_start(receive_time_s)
            if revolution is not None:
                done.append(revolution)
            if carried is not None:
                self._begin(*carried, receive_time_s)
                self._append(_slice(samples, end, end + 1), unwrapped[end : end + 1])
            else:
                self._begin(_slice(samples, end, end + 1), unwrapped[end : end + 1], receive_time_s)
            begin = search = end + 1
        self._append(_slice(samples, begin, n), unwrapped[begin:])
        return done

    def _cut_missed_start(
        self, time_s: float
    ) -> tuple[Revolution | None, tuple[ScanSamples, npt.NDArray[np.float64]] | None]:
        """No S within max_sweep: close at 360°, return the rest as the next one's start."""
        whole = _concat(self._parts)
        degrees = np.concatenate(self._parts_deg)
        cut = int(np.searchsorted(degrees - self._begin_deg, 360.0))
        cut = max(cut, 1)
        self._parts = [_slice(whole, 0, cut)]
        self._parts_deg = [degrees[:cut]]
        revolution = self._close(time_s, float(degrees[cut - 1]))
        if cut >= len(whole):
            return revolution, None
        return revolution, (_slice(whole, cut, len(whole)), degrees[cut:])

    def _close(self, end_time_s: float, last_deg: float) -> Revolution | None:
        parts, self._parts = self._parts, []
        self._parts_deg = []
        count = sum(len(p) for p in parts)
        if count == 0:
            return None
        partial = not self._in_revolution and last_deg - self._begin_deg < self._min_sweep
        if partial or count < self._min_points:
            # Most of a turn before the first start flag, or too few samples.
            self.dropped_revolutions += 1
            self.dropped_samples += count
            return None
        whole = _concat(parts)
        return Revolution(
            angle_deg=whole.angle_deg,
            distance_mm=whole.distance_mm,
            quality=whole.quality,
            start_time_s=self._start_time_s,
            period_s=max(end_time_s - self._start_time_s, 0.0),
        )


def _concat(parts: list[ScanSamples]) -> ScanSamples:
    if len(parts) == 1:
        return parts[0]
    return ScanSamples(
        np.concatenate([p.start for p in parts]),
        np.concatenate([p.quality for p in parts]),
        np.concatenate([p.angle_deg for p in parts]),
        np.concatenate([p.distance_mm for p in parts]),
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
    180° mark.

    Attributes:
        bins: number of bins over [-pi, pi), 4..MAX_BINS.
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
        if not 4 <= self.bins <= MAX_BINS:
            raise ConfigurationError(f'bins must be 4..{MAX_BINS}, got {self.bins}')
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
