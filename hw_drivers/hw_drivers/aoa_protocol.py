"""Silicon Labs BG22 AoA locator reports: JSON stream framing and validation.

The locator host sends one JSON object per angle estimate over TCP: the authors' binary
pretty-prints it over several lines and ends it with CR LF, a patched one may send compact
NDJSON. :class:`JsonStreamDecoder` accepts both: it decodes objects one after another with
``json.JSONDecoder.raw_decode`` whatever the line breaks, survives objects split across
reads, skips garbage between objects and caps its buffer. :func:`parse_angle_report`
validates one object into an :class:`AngleReport`; :class:`SequenceFilter` drops duplicated
and old reports per tag (16-bit wrap-aware); :class:`AzimuthMapping` turns the locator's
degrees into REP 103 radians in the robot frame.
"""

from __future__ import annotations

import codecs
import json
import math
from dataclasses import dataclass
from typing import Any

from hw_drivers.errors import ConfigurationError, ProtocolError

__all__ = [
    'AngleReport',
    'AzimuthMapping',
    'JsonStreamDecoder',
    'SequenceFilter',
    'normalise_tag_id',
    'parse_angle_report',
    'tag_emitter_id',
]

# A JSON literal split at the end of the buffer fails this close to it (longest: -Infinity).
_INCOMPLETE_TAIL_CHARS = 16
# Largest magnitude of a report's numbers: the bearing messages carry float32.
_FLOAT32_MAX = 3.4028234663852886e38
# Characters of an offending value quoted in an error message.
_SHOWN_CHARS = 60


class JsonStreamDecoder:
    """Incremental decoder of concatenated JSON objects from a byte stream.

    Args:
        max_buffer_bytes: undecoded text beyond this many characters is dropped (counted in
            :attr:`overflows`), so a client that never closes an object cannot grow memory.

    Counters: :attr:`objects`, :attr:`malformed` (objects that failed to decode),
    :attr:`garbage_chars` (characters skipped between objects), :attr:`overflows`.
    """

    def __init__(self, *, max_buffer_bytes: int = 16 * 1024) -> None:
        if max_buffer_bytes < 64:
            raise ConfigurationError(f'max_buffer_bytes must be >= 64, got {max_buffer_bytes}')
        self.max_buffer_bytes = max_buffer_bytes
        self._utf8 = codecs.getincrementaldecoder('utf-8')(errors='replace')
        self._json = json.JSONDecoder()
        self._text = ''
        self.objects = 0
        self.malformed = 0
        self.garbage_chars = 0
        self.overflows = 0

    def reset(self) -> None:
        """Forget buffered text (new connection)."""
        self._utf8.reset()
        self._text = ''

    @property
    def buffered_chars(self) -> int:
        """Characters waiting for the rest of an object."""
        return len(self._text)

    def feed(self, data: bytes) -> list[Any]:
        """Add received bytes; return every JSON value completed by them, in order."""
        new_text = self._utf8.decode(data)
        if self._text and '}' not in new_text:
            # Nothing can have completed: skip re-parsing (a slow client costs O(1) per read).
            self._text = self._keep_bounded(self._text + new_text)
            return []
        text = self._text + new_text
        out: list[Any] = []
        pos = 0
        end = len(text)
        while True:
            start = text.find('{', pos)
            if start < 0:
                self.garbage_chars += len(text[pos:].strip())
                pos = end
                break
            self.garbage_chars += len(text[pos:start].strip())
            try:
                value, stop = self._json.raw_decode(text, start)
            except json.JSONDecodeError as err:
                if end - err.pos <= _INCOMPLETE_TAIL_CHARS or err.msg.startswith('Unterminated'):
                    pos = start  # wait for the rest of this object
                    break
                self.malformed += 1
                pos = start + 1
                continue
            except (RecursionError, ValueError):
                # Nesting deeper than the recursion limit, an integer of more than
                # sys.get_int_max_str_digits() digits: malformed, never an escaping error.
                self.malformed += 1
                pos = start + 1
                continue
            out.append(value)
            self.objects += 1
            pos = stop
        self._text = self._keep_bounded(text[pos:])
        return out

    def _keep_bounded(self, rest: str) -> str:
        if len(rest) > self.max_buffer_bytes:
            self.overflows += 1
            return ''
        return rest


def normalise_tag_id(tag_id: str) -> str:
    """Upper-case, trimmed tag id ('d2' -> 'D2', 'ble-pd-0123...' -> 'BLE-PD-0123...')."""
    return tag_id.strip().upper()


@dataclass(frozen=True)
class AngleReport:
    """One validated angle estimate, still in the locator's own frame and units.

    Attributes:
        tag_id: normalised tag id.
        azimuth_deg: azimuth [deg] in (-180, 180].
        elevation_deg: elevation [deg]; NaN when absent.
        distance_m: RSSI-based distance [m]; NaN when absent.
        quality: IQ quality bitmask (0 = all checks passed).
        sequence: CTE packet counter 0..65535, or None when absent.
        rssi_dbm: received signal strength [dBm]; NaN when absent.
        locator_id: reporting locator, '' when absent.
    """

    tag_id: str
    azimuth_deg: float
    elevation_deg: float = math.nan
    distance_m: float = math.nan
    quality: int = 0
    sequence: int | None = None
    rssi_dbm: float = math.nan
    locator_id: str = ''


def _shown(value: Any) -> str:
    """``repr(value)`` cut to one short line for an error message."""
    try:
        text = repr(value)
    except RecursionError:  # nesting that parsed just below the limit
        return f'<deeply nested {type(value).__name__}>'
    return text if len(text) <= _SHOWN_CHARS else f'{text[:_SHOWN_CHARS]}... ({len(text)} chars)'


def _number(obj: dict[str, Any], key: str, *, required: bool = False) -> float:
    value = obj.get(key)
    if value is None:
        if required:
            raise ProtocolError(f'locator report without "{key}"')
        return math.nan
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ProtocolError(f'locator report "{key}" is not a number: {_shown(value)}')
    try:
        number = float(value)
    except OverflowError:  # an integer beyond the float range
        number = math.inf
    if not math.isfinite(number):
        raise ProtocolError(f'locator report "{key}" is not finite: {_shown(value)}')
    if abs(number) > _FLOAT32_MAX:
        raise ProtocolError(f'locator report "{key}" is out of range: {_shown(value)}')
    return number


def _wrap_deg(angle_deg: float) -> float:
    wrapped = math.remainder(angle_deg, 360.0)
    return 180.0 if wrapped == -180.0 else wrapped


def parse_angle_report(obj: Any) -> AngleReport | None:
    """Validate one decoded JSON value (the canonical fields).

    Returns None for objects of another ``type`` (the authors' server also carried
    "motion" and "olfactory" objects).

    Raises:
        ProtocolError: not an object, missing/empty tag id, missing or non-finite azimuth,
            numbers beyond the float32 range of the bearing messages, or fields of the
            wrong type.
    """
    if not isinstance(obj, dict):
        raise ProtocolError(f'locator report is not a JSON object: {_shown(obj)}')
    kind = obj.get('type', 'auditory')
    if kind != 'auditory':
        return None
    tag = obj.get('tagId')
    if not isinstance(tag, str) or not tag.strip():
        raise ProtocolError(f'locator report without a usable "tagId": {_shown(tag)}')
    quality = obj.get('quality', 0)
    if isinstance(quality, bool) or not isinstance(quality, int) or quality < 0:
        msg = f'locator report "quality" must be an unsigned integer: {_shown(quality)}'
        raise ProtocolError(msg)
    sequence = obj.get('sequence', obj.get('timeStamp'))
    if sequence is not None:
        if isinstance(sequence, bool) or not isinstance(sequence, int) or sequence < 0:
            raise ProtocolError(
                f'locator report sequence must be an unsigned integer: {_shown(sequence)}'
            )
        sequence &= 0xFFFF
    locator = obj.get('locatorId', '')
    return AngleReport(
        tag_id=normalise_tag_id(tag),
        azimuth_deg=_wrap_deg(_number(obj, 'azimuth', required=True)),
        elevation_deg=_number(obj, 'elevation'),
        distance_m=_number(obj, 'distance'),
        quality=quality,
        sequence=sequence,
        rssi_dbm=_number(obj, 'rssi'),
        locator_id=locator if isinstance(locator, str) else _shown(locator),
    )


def tag_emitter_id(tag_id: str) -> int | None:
    """Numeric emitter id of a tag for swarm_interfaces/EmitterRssi (uint32).

    The tag's hex address digits ('D2' -> 0xD2; 'BLE-PD-0123456789AB' -> low 32 bits of the
    address, 0x456789AB); None when the id has no hex digits.
    """
    digits = tag_id.upper().removeprefix('BLE-PD-').removeprefix('BLE-SR-').replace(':', '')
    try:
        return int(digits, 16) & 0xFFFFFFFF
    except ValueError:
        return None


class SequenceFilter:
    """Per-tag duplicate/old-report filter on the 16-bit CTE counter.

    A report is new when ``(seq - last) mod 65536`` is in 1..32767. After ``resync_after``
    consecutive "old" reports of one tag (the locator restarted its counters) the filter
    follows the new counter.
    """

    def __init__(self, *, resync_after: int = 3) -> None:
        self.resync_after = resync_after
        self._last: dict[str, int] = {}
        self._old_run: dict[str, int] = {}
        self.duplicates = 0
        self.old = 0

    def accept(self, tag_id: str, sequence: int | None) -> bool:
        """True if the report should be used."""
        if sequence is None:
            return True
        last = self._last.get(tag_id)
        if last is None:
            self._last[tag_id] = sequence
            return True
        step = (sequence - last) % 65536
        if step == 0:
            self.duplicates += 1
            return False
        if step >= 32768:
            run = self._old_run.get(tag_id, 0) + 1
            if run < self.resync_after:
                self._old_run[tag_id] = run
                self.old += 1
                return False
        self._old_run[tag_id] = 0
        self._last[tag_id] = sequence
        return True


@dataclass(frozen=True)
class AzimuthMapping:
    """Locator degrees to REP 103 radians in the robot frame.

    azimuth_rad = wrap(sign * radians(azimuth_deg) + offset_rad). The defaults assume the
    authors' convention (left positive) with the array's 0° facing forward; calibrate with a
    tag at 0°, ±90° and 180° (docs/hardware.md, first power-up checklist).
    """

    sign: int = 1
    offset_rad: float = 0.0

    def __post_init__(self) -> None:
        if self.sign not in (-1, 1):
            raise ConfigurationError(f'azimuth sign must be +1 or -1, got {self.sign}')
        if not math.isfinite(self.offset_rad):
            raise ConfigurationError('azimuth offset must be finite')

    def azimuth_rad(self, azimuth_deg: float) -> float:
        """Robot-frame azimuth [rad] in (-pi, pi]."""
        wrapped = math.remainder(
            self.sign * math.radians(azimuth_deg) + self.offset_rad, 2 * math.pi
        )
        return math.pi if wrapped == -math.pi else wrapped
