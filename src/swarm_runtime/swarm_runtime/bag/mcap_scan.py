"""MCAP files read chunk by chunk, with every check the format allows, and damaged ones mapped.

An intact file is opened through its summary (the ``mcap`` library reads the footer and the
summary section): schemas, channels, per-channel counts and the index of its chunks. A file
without a usable summary (cut short, garbage at its end, a recorder that died) is *walked*
instead: its records are read from the start, every chunk is decompressed and checked, and
where the data stops making sense the damage is noted and the walk looks for the next
intact chunk (a chunk record whose header is consistent and whose CRC matches) and goes on
from there. A chunk cut off by the end of the file still yields its complete messages when
it is uncompressed, or compressed with zstd or lz4 (both decompress as a stream).

Either way the result is a :class:`McapLayout`: the chunks (and runs of messages outside
chunks) as :class:`Segment` objects with their time ranges, which :func:`read_segment` turns
into messages. Chunk data is checked when it is read: the uncompressed size, the CRC (when
the writer stored one; rosbags' own writer stores 0), and the structure of every record.
Damage raises :class:`SegmentDamageError`.

Record layout (MCAP specification): 8-byte magic, then records of ``opcode: uint8,
length: uint64, body``; integers little-endian, strings ``uint32`` length + UTF-8.
"""

from __future__ import annotations

import mmap
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO, NamedTuple

__all__ = [
    'MCAP_MAGIC',
    'Damage',
    'McapLayout',
    'ScannedChannel',
    'ScannedMessage',
    'ScannedSchema',
    'Segment',
    'SegmentDamageError',
    'open_layout',
    'read_segment',
]

MCAP_MAGIC = b'\x89MCAP0\r\n'

_OP_HEADER = 0x01
_OP_FOOTER = 0x02
_OP_SCHEMA = 0x03
_OP_CHANNEL = 0x04
_OP_MESSAGE = 0x05
_OP_CHUNK = 0x06
_OP_DATA_END = 0x0F
_KNOWN_OPS = frozenset(range(0x01, 0x10))
_RECORD_NAMES = {
    0x01: 'header',
    0x02: 'footer',
    0x03: 'schema',
    0x04: 'channel',
    0x05: 'message',
    0x06: 'chunk',
    0x07: 'message index',
    0x08: 'chunk index',
    0x09: 'attachment',
    0x0A: 'attachment index',
    0x0B: 'statistics',
    0x0C: 'metadata',
    0x0D: 'metadata index',
    0x0E: 'summary offset',
    0x0F: 'data end',
}
_USER_OPS_START = 0x80
_RECORD_HEAD = struct.Struct('<BQ')
_CHUNK_HEAD = struct.Struct('<QQQII')  # start, end, uncompressed size, crc, compression length
_MESSAGE_HEAD = struct.Struct('<HIQQ')  # channel, sequence, log time, publish time
_COMPRESSIONS = ('', 'zstd', 'lz4')
_FOOTER_SIZE = 9 + 20  # opcode + length + summary start, summary offset start, crc


class SegmentDamageError(Exception):
    """The data of a segment (chunk) is damaged; the message says how."""


class _DamageError(Exception):
    """Raised inside the parser where the data stops making sense."""


@dataclass(frozen=True)
class ScannedSchema:
    """An MCAP schema record: a message type and its definition text."""

    id: int
    name: str
    encoding: str
    data: str


@dataclass(frozen=True)
class ScannedChannel:
    """An MCAP channel record: a topic, its schema and metadata (offered QoS, type hash)."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: dict[str, str]


class ScannedMessage(NamedTuple):
    """A message record: channel id, log time [ns], payload (CDR bytes)."""

    channel_id: int
    log_time_ns: int
    data: bytes


@dataclass(frozen=True)
class Damage:
    """An unreadable stretch of a file: where it starts, where reading resumed, and why."""

    offset: int
    resumed_at: int | None
    reason: str

    def describe(self) -> str:
        """One line: 'at byte N: reason; ...'."""
        tail = (
            'nothing after it could be read'
            if self.resumed_at is None
            else f'reading resumed at byte {self.resumed_at}'
        )
        return f'at byte {self.offset}: {self.reason}; {tail}'


@dataclass
class Segment:
    """A chunk (or a run of messages outside chunks) and what is known about it.

    ``partial_data`` holds the decompressed records of a chunk cut off by the end of the
    file (read during the walk); ``loose`` the (offset, length) of messages outside chunks.
    """

    offset: int
    end: int
    start_ns: int
    end_ns: int
    checked: bool = False
    partial_data: bytes | None = None
    loose: list[tuple[int, int]] = field(default_factory=list)

    @property
    def is_partial(self) -> bool:
        """True for the complete messages of a chunk cut off by the end of the file."""
        return self.partial_data is not None


@dataclass
class McapLayout:
    """What one MCAP file holds and where, from its summary or from a walk."""

    path: Path
    size: int
    indexed: bool
    schemas: dict[int, ScannedSchema] = field(default_factory=dict)
    channels: dict[int, ScannedChannel] = field(default_factory=dict)
    segments: list[Segment] = field(default_factory=list)
    channel_counts: dict[int, int] = field(default_factory=dict)
    damage: list[Damage] = field(default_factory=list)
    #: Why the summary could not be used (None when it was, or the file has none).
    summary_problem: str | None = None
    #: Messages of the partial chunk at a cut (complete records, CRC not checkable).
    partial_messages: int = 0
    #: Messages whose channel record was lost with a damaged chunk.
    orphan_messages: int = 0

    @property
    def message_count(self) -> int:
        """Messages the file holds (readable ones, for a walked file)."""
        return sum(self.channel_counts.values())


# --------------------------------------------------------------------------- record parsing


class _Body:
    """Cursor over one record body."""

    __slots__ = ('_data', '_pos', '_what')

    def __init__(self, data: bytes | memoryview, what: str) -> None:
        self._data = data
        self._pos = 0
        self._what = what

    def take(self, size: int) -> bytes:
        if size < 0 or self._pos + size > len(self._data):
            msg = f'{self._what} record is shorter than its fields'
            raise _DamageError(msg)
        chunk = bytes(self._data[self._pos : self._pos + size])
        self._pos += size
        return chunk

    def uint(self, fmt: str) -> int:
        return int(struct.unpack(fmt, self.take(struct.calcsize(fmt)))[0])

    def string(self) -> str:
        raw = self.take(self.uint('<I'))
        try:
            return raw.decode('utf-8')
        except UnicodeDecodeError as err:
            msg = f'{self._what} record holds invalid UTF-8'
            raise _DamageError(msg) from err

    def remaining(self) -> int:
        return len(self._data) - self._pos


def _schema(body: bytes | memoryview) -> ScannedSchema:
    record = _Body(body, 'schema')
    schema_id = record.uint('<H')
    name, encoding = record.string(), record.string()
    data = record.take(record.uint('<I')).decode('utf-8', errors='replace')
    return ScannedSchema(schema_id, name, encoding, data)


def _channel(body: bytes | memoryview) -> ScannedChannel:
    record = _Body(body, 'channel')
    channel_id, schema_id = record.uint('<H'), record.uint('<H')
    topic, encoding = record.string(), record.string()
    entries = _Body(record.take(record.uint('<I')), 'channel metadata')
    metadata: dict[str, str] = {}
    while entries.remaining():
        key = entries.string()
        metadata[key] = entries.string()
    return ScannedChannel(channel_id, schema_id, topic, encoding, metadata)


def _parse_records(
    data: bytes,
    layout: McapLayout | None,
    wanted: frozenset[int] | None,
    *,
    partial: bool,
) -> list[ScannedMessage]:
    """Records of a chunk's data: schemas and channels go to ``layout``, messages are returned.

    With ``partial`` the data may end inside a record (a chunk cut off by the file's end):
    the incomplete record is dropped. Otherwise it is damage.
    """
    messages: list[ScannedMessage] = []
    position = 0
    size = len(data)
    view = memoryview(data)
    while position < size:
        if size - position < 9:
            if partial:
                break
            msg = 'the chunk data ends inside a record header'
            raise _DamageError(msg)
        opcode, length = _RECORD_HEAD.unpack_from(data, position)
        start = position + 9
        if length > size - start:
            if partial:
                break
            msg = f'a record in the chunk claims {length} bytes beyond the chunk end'
            raise _DamageError(msg)
        position = start + length
        if opcode == _OP_MESSAGE:
            if length < _MESSAGE_HEAD.size:
                msg = f'a message record of {length} bytes is shorter than its header'
                raise _DamageError(msg)
            channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(data, start)
            if wanted is None or channel_id in wanted:
                messages.append(
                    ScannedMessage(channel_id, log_time, bytes(view[start + 22 : position]))
                )
        elif opcode == _OP_SCHEMA:
            schema = _schema(view[start:position])
            if layout is not None:
                layout.schemas.setdefault(schema.id, schema)
        elif opcode == _OP_CHANNEL:
            channel = _channel(view[start:position])
            if layout is not None:
                layout.channels.setdefault(channel.id, channel)
        elif opcode < _USER_OPS_START:
            msg = f'invalid record opcode 0x{opcode:02x} inside a chunk'
            raise _DamageError(msg)
    return messages


class _ChunkHeader(NamedTuple):
    start_ns: int
    end_ns: int
    uncompressed_size: int
    crc: int
    compression: str
    data_offset: int  # of the compressed data, relative to the record body
    compressed_size: int


def _chunk_header(body: bytes | memoryview, body_length: int) -> _ChunkHeader:
    """Parse and check a chunk record's header; ``body_length`` is the record's length field."""
    if len(body) < _CHUNK_HEAD.size:
        msg = 'the chunk record is shorter than its header'
        raise _DamageError(msg)
    start_ns, end_ns, usize, crc, clen = _CHUNK_HEAD.unpack_from(body, 0)
    if clen > 8 or len(body) < _CHUNK_HEAD.size + clen + 8:
        msg = 'the chunk header is invalid'
        raise _DamageError(msg)
    try:
        compression = bytes(body[_CHUNK_HEAD.size : _CHUNK_HEAD.size + clen]).decode('ascii')
    except UnicodeDecodeError as err:
        msg = 'the chunk header names no valid compression'
        raise _DamageError(msg) from err
    if compression not in _COMPRESSIONS:
        msg = f'unsupported chunk compression {compression!r}'
        raise _DamageError(msg)
    offset = _CHUNK_HEAD.size + clen + 8
    (csize,) = struct.unpack_from('<Q', body, offset - 8)
    if offset + csize != body_length:
        msg = 'the chunk header does not match the chunk length'
        raise _DamageError(msg)
    if start_ns > end_ns or (compression == '' and csize != usize):
        msg = 'the chunk header is inconsistent'
        raise _DamageError(msg)
    return _ChunkHeader(start_ns, end_ns, usize, crc, compression, offset, csize)


def _decompress(header: _ChunkHeader, compressed: bytes) -> bytes:
    """The chunk's records, checked against its uncompressed size and CRC."""
    try:
        if header.compression == 'zstd':
            import zstandard

            data = zstandard.ZstdDecompressor().decompress(
                compressed, max_output_size=header.uncompressed_size
            )
        elif header.compression == 'lz4':
            import lz4.frame

            data = lz4.frame.decompress(compressed)
        else:
            data = compressed
    except Exception as err:  # each codec raises its own error types
        msg = f'the chunk data cannot be decompressed ({header.compression}: {err})'
        raise _DamageError(msg) from err
    if len(data) != header.uncompressed_size:
        msg = (
            f'the chunk data is {len(data)} bytes instead of the '
            f'{header.uncompressed_size} its header gives'
        )
        raise _DamageError(msg)
    if header.crc and zlib.crc32(data) != header.crc:
        msg = 'the chunk CRC does not match its data (the data is damaged)'
        raise _DamageError(msg)
    return data


def _decompress_prefix(header: _ChunkHeader, compressed: bytes) -> bytes:
    """As much of a cut-off chunk's records as its available compressed bytes give."""
    if header.compression == '':
        return compressed
    try:
        if header.compression == 'zstd':
            import zstandard

            return bytes(zstandard.ZstdDecompressor().decompressobj().decompress(compressed))
        import lz4.frame

        return bytes(lz4.frame.LZ4FrameDecompressor().decompress(compressed))
    except Exception:  # a prefix that does not decompress yields nothing
        return b''


# --------------------------------------------------------------------------- segments


def read_segment(
    layout: McapLayout, segment: Segment, wanted: frozenset[int] | None = None
) -> list[ScannedMessage]:
    """The messages of a segment (of the ``wanted`` channels), in log-time order.

    Raises:
        SegmentDamageError: the chunk is damaged (size, CRC, record structure).
    """
    if segment.partial_data is not None:
        messages = _parse_records(segment.partial_data, None, wanted, partial=True)
    elif segment.loose:
        messages = []
        with layout.path.open('rb') as stream:
            for offset, length in segment.loose:
                stream.seek(offset)
                body = stream.read(length)
                channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(body, 0)
                if wanted is None or channel_id in wanted:
                    messages.append(ScannedMessage(channel_id, log_time, body[22:]))
    else:
        with layout.path.open('rb') as stream:
            stream.seek(segment.offset)
            record = stream.read(segment.end - segment.offset)
        try:
            if len(record) != segment.end - segment.offset:
                msg = 'the file ends inside the chunk'
                raise _DamageError(msg)
            opcode, length = _RECORD_HEAD.unpack_from(record, 0)
            if opcode != _OP_CHUNK or 9 + length != len(record):
                msg = 'the summary points to something that is not a chunk'
                raise _DamageError(msg)
            body = memoryview(record)[9:]
            header = _chunk_header(body, length)
            data = _decompress(
                header,
                bytes(body[header.data_offset : header.data_offset + header.compressed_size]),
            )
            messages = _parse_records(data, None, wanted, partial=False)
        except (_DamageError, struct.error) as err:
            raise SegmentDamageError(f'chunk at byte {segment.offset}: {err}') from err
    messages.sort(key=lambda m: m.log_time_ns)
    return messages


def open_layout(path: Path, *, walk: bool) -> McapLayout:
    """Map an MCAP file: through its summary, or (``walk``) by reading its records.

    Without ``walk`` a file whose summary cannot be used is returned with
    ``summary_problem`` set and no segments; a file that has no summary section at all is
    walked in any case (that is not damage).

    Raises:
        OSError: the file cannot be read.
    """
    size = path.stat().st_size
    layout = McapLayout(path=path, size=size, indexed=False)
    problem = _from_summary(layout)
    if problem is None and layout.indexed:
        return layout
    layout.summary_problem = problem
    if problem is not None and not walk:
        return layout
    layout.schemas.clear()
    layout.channels.clear()
    layout.channel_counts.clear()
    _walk(layout)
    return layout


_FOOTER_FIELDS = struct.Struct('<BQQQI')  # opcode, length, summary start, offsets start, crc


def _summary_crc_problem(stream: BinaryIO, size: int) -> str | None:
    """Why the summary section fails its CRC (MCAP footer), or None if it passes.

    The footer's CRC covers the bytes from the summary's start through the footer's summary
    offset field; 0 means the writer computed none. The summary holds the schemas, channels
    and chunk index that reading by the summary trusts, so a damaged one is not read.
    """
    footer_at = size - len(MCAP_MAGIC) - _FOOTER_SIZE
    stream.seek(footer_at)
    _, _, summary_start, _, crc = _FOOTER_FIELDS.unpack(stream.read(_FOOTER_SIZE))
    if crc == 0 or summary_start == 0:
        return None
    crc_end = size - len(MCAP_MAGIC) - 4
    if not len(MCAP_MAGIC) <= summary_start <= footer_at:
        return f'its MCAP footer is damaged (summary start {summary_start} outside the file)'
    stream.seek(summary_start)
    if zlib.crc32(stream.read(crc_end - summary_start)) != crc:
        return 'its summary section (schemas, channels, index) fails its CRC (it is damaged)'
    return None


def _from_summary(layout: McapLayout) -> str | None:
    """Fill ``layout`` from the file's summary; return why that is impossible, if it is."""
    from mcap.exceptions import McapError
    from mcap.reader import SeekingReader

    size = layout.size
    if size == 0:
        return 'it is empty (0 bytes)'
    with layout.path.open('rb') as stream:
        if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            return 'it does not start with the MCAP magic bytes (not an MCAP file)'
        if size < 2 * len(MCAP_MAGIC) + _FOOTER_SIZE:
            return f'it is cut: {size} bytes, no room for the MCAP footer'
        stream.seek(size - len(MCAP_MAGIC))
        if stream.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
            return (
                f'it is cut or damaged: its {size} bytes do not end with the MCAP footer '
                '(the recording was not finished, or the copy is incomplete)'
            )
        problem = _summary_crc_problem(stream, size)
        if problem is not None:
            return problem
        stream.seek(0)
        try:
            summary = SeekingReader(stream).get_summary()
        except (McapError, struct.error, ValueError, EOFError, OSError, KeyError) as err:
            return f'its MCAP footer or summary is damaged ({err})'
    if summary is None or (not summary.chunk_indexes and summary.statistics is None):
        return None  # no summary section: walk it (not damage)
    if not summary.chunk_indexes and summary.statistics and summary.statistics.message_count:
        return None  # messages outside chunks: walk it
    for schema in summary.schemas.values():
        layout.schemas[schema.id] = ScannedSchema(
            schema.id, schema.name, schema.encoding, schema.data.decode('utf-8', 'replace')
        )
    for channel in summary.channels.values():
        layout.channels[channel.id] = ScannedChannel(
            channel.id,
            channel.schema_id,
            channel.topic,
            channel.message_encoding,
            dict(channel.metadata),
        )
    for index in summary.chunk_indexes:
        start = index.chunk_start_offset
        layout.segments.append(
            Segment(
                start, start + index.chunk_length, index.message_start_time, index.message_end_time
            )
        )
    if summary.statistics is not None:
        layout.channel_counts = dict(summary.statistics.channel_message_counts)
    layout.indexed = True
    return None


# --------------------------------------------------------------------------- walking


def _walk(layout: McapLayout) -> None:
    """Read the records from the start; note damage and resume at the next intact chunk."""
    with layout.path.open('rb') as stream:
        if layout.size == 0:
            layout.damage.append(Damage(0, None, 'the file is empty'))
            return
        with mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as data:
            if data[: len(MCAP_MAGIC)] != MCAP_MAGIC:
                layout.damage.append(
                    Damage(0, None, 'the file does not start with the MCAP magic bytes')
                )
                return
            _walk_records(layout, data)


def _walk_records(layout: McapLayout, data: Any) -> None:
    size = layout.size
    pos = len(MCAP_MAGIC)
    loose: Segment | None = None
    while True:
        if pos == size:
            layout.damage.append(
                Damage(pos, None, 'the file ends without the MCAP data end and footer (cut)')
            )
            return
        if size - pos < 9:
            layout.damage.append(Damage(pos, None, 'the file is cut inside a record header'))
            return
        opcode, length = _RECORD_HEAD.unpack_from(data, pos)
        end = pos + 9 + length
        if opcode not in _KNOWN_OPS and opcode < _USER_OPS_START:
            pos = _resync(layout, data, pos, f'invalid record opcode 0x{opcode:02x}')
            if pos is None:
                return
            continue
        if end > size:
            if opcode == _OP_CHUNK:
                _partial_chunk(layout, data, pos, length)
            else:
                layout.damage.append(
                    Damage(
                        pos,
                        None,
                        f'the file is cut inside a {_RECORD_NAMES.get(opcode, "user")} record '
                        f'({size - pos - 9} of its {length} bytes present)',
                    )
                )
            return
        if opcode in (_OP_DATA_END, _OP_FOOTER):
            return
        if opcode == _OP_MESSAGE:
            loose = _loose_message(layout, data, pos, length, loose)
            pos = end
            continue
        loose = None
        try:
            if opcode == _OP_CHUNK:
                _walk_chunk(layout, data, pos, length)
            elif opcode == _OP_SCHEMA:
                schema = _schema(data[pos + 9 : end])
                layout.schemas.setdefault(schema.id, schema)
            elif opcode == _OP_CHANNEL:
                channel = _channel(data[pos + 9 : end])
                layout.channels.setdefault(channel.id, channel)
        except (_DamageError, struct.error) as err:
            resumed = _resync(layout, data, pos, str(err))
            if resumed is None:
                return
            pos = resumed
            continue
        pos = end


def _walk_chunk(layout: McapLayout, data: Any, pos: int, length: int) -> None:
    body = memoryview(data)[pos + 9 : pos + 9 + length]
    try:
        header = _chunk_header(body, length)
        compressed = bytes(body[header.data_offset : header.data_offset + header.compressed_size])
    finally:
        body.release()
    records = _decompress(header, compressed)
    messages = _parse_records(records, layout, None, partial=False)
    _count(layout, messages)
    if messages:
        layout.segments.append(
            Segment(pos, pos + 9 + length, header.start_ns, header.end_ns, checked=True)
        )


def _count(layout: McapLayout, messages: list[ScannedMessage]) -> None:
    for message in messages:
        if message.channel_id in layout.channels:
            layout.channel_counts[message.channel_id] = (
                layout.channel_counts.get(message.channel_id, 0) + 1
            )
        else:
            layout.orphan_messages += 1


def _loose_message(
    layout: McapLayout, data: Any, pos: int, length: int, loose: Segment | None
) -> Segment | None:
    if length < _MESSAGE_HEAD.size:
        return loose
    channel_id, _, log_time, _ = _MESSAGE_HEAD.unpack_from(data, pos + 9)
    if channel_id not in layout.channels:
        layout.orphan_messages += 1
        return loose
    layout.channel_counts[channel_id] = layout.channel_counts.get(channel_id, 0) + 1
    if loose is None:
        loose = Segment(pos, pos, log_time, log_time, checked=True)
        layout.segments.append(loose)
    loose.loose.append((pos + 9, length))
    loose.end = pos + 9 + length
    loose.start_ns = min(loose.start_ns, log_time)
    loose.end_ns = max(loose.end_ns, log_time)
    return loose


def _partial_chunk(layout: McapLayout, data: Any, pos: int, length: int) -> None:
    """A chunk cut off by the end of the file: keep its complete messages if it has any."""
    size = layout.size
    present = size - pos - 9
    body = bytes(data[pos + 9 : size])
    found = 0
    try:
        header = _chunk_header_prefix(body, length)
        records = _decompress_prefix(
            header, body[header.data_offset : header.data_offset + header.compressed_size]
        )
        messages = _parse_records(records, layout, None, partial=True)
    except (_DamageError, struct.error):
        messages = []
    if messages:
        found = len(messages)
        _count(layout, messages)
        layout.partial_messages += found
        layout.segments.append(
            Segment(
                pos,
                size,
                min(m.log_time_ns for m in messages),
                max(m.log_time_ns for m in messages),
                partial_data=records,
            )
        )
    layout.damage.append(
        Damage(
            pos,
            None,
            f'the file is cut inside a chunk ({present} of its {length} bytes present; '
            f'{found} complete messages read from it without a CRC check)',
        )
    )


def _chunk_header_prefix(body: bytes, body_length: int) -> _ChunkHeader:
    """The header of a chunk whose record is cut (its data shorter than announced)."""
    if len(body) < _CHUNK_HEAD.size:
        msg = 'the chunk header is cut'
        raise _DamageError(msg)
    start_ns, end_ns, usize, crc, clen = _CHUNK_HEAD.unpack_from(body, 0)
    offset = _CHUNK_HEAD.size + clen + 8
    if clen > 8 or len(body) < offset:
        msg = 'the chunk header is cut or invalid'
        raise _DamageError(msg)
    compression = body[_CHUNK_HEAD.size : _CHUNK_HEAD.size + clen].decode('ascii', 'replace')
    (csize,) = struct.unpack_from('<Q', body, offset - 8)
    if compression not in _COMPRESSIONS or offset + csize != body_length:
        msg = 'the chunk header is invalid'
        raise _DamageError(msg)
    return _ChunkHeader(start_ns, end_ns, usize, crc, compression, offset, csize)


def _resync(layout: McapLayout, data: Any, damaged_at: int, reason: str) -> int | None:
    """Find the next intact chunk after damage at ``damaged_at``; note the damage."""
    for candidate in _chunk_candidates(data, damaged_at + 1, layout.size):
        _, length = _RECORD_HEAD.unpack_from(data, candidate)
        end = candidate + 9 + length
        body = memoryview(data)[candidate + 9 : min(end, layout.size)]
        try:
            header = _chunk_header(body, length) if end <= layout.size else None
            if header is None:
                _chunk_header_prefix(bytes(body), length)
            elif header.crc:
                # Cheap before decompressing: a consistent header and a CRC that matches.
                _decompress(
                    header,
                    bytes(body[header.data_offset : header.data_offset + header.compressed_size]),
                )
            else:
                records = _decompress(
                    header,
                    bytes(body[header.data_offset : header.data_offset + header.compressed_size]),
                )
                _parse_records(records, None, None, partial=False)
        except (_DamageError, struct.error):
            continue
        finally:
            body.release()
        layout.damage.append(Damage(damaged_at, candidate, reason))
        return candidate
    layout.damage.append(Damage(damaged_at, None, reason))
    return None


def _chunk_candidates(data: Any, start: int, size: int) -> Iterator[int]:
    """Offsets of bytes that could start a chunk record (opcode 0x06 with a sane header)."""
    position = start
    while True:
        position = data.find(b'\x06', position)
        if position < 0 or position + 9 + _CHUNK_HEAD.size > size:
            return
        _, length = _RECORD_HEAD.unpack_from(data, position)
        if _CHUNK_HEAD.size + 8 <= length <= size:
            yield position
        position += 1
