"""A streaming read of an MCAP file's records that stops cleanly at the first damage.

rosbags reads an MCAP file through its footer and summary, so a file that was cut short
(the recorder died) or has garbage in it cannot be opened at all. This scanner walks the
records from the start instead, the way the MCAP format allows: it collects schemas and
channels as they appear, yields every message it can decode (chunks are decompressed and
checked), and when a record is incomplete or makes no sense it stops and reports where and
why in :attr:`McapScan.damage`.

Record layout (MCAP specification): 8-byte magic, then records of ``opcode: uint8,
length: uint64, body``; integers little-endian, strings ``uint32`` length + UTF-8.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from rosbags.rosbag2 import ReaderError
from rosbags.rosbag2.storage_mcap import decompress

__all__ = ['MCAP_MAGIC', 'McapScan', 'ScannedChannel', 'ScannedMessage', 'ScannedSchema']

MCAP_MAGIC = b'\x89MCAP0\r\n'

_OP_HEADER = 0x01
_OP_FOOTER = 0x02
_OP_SCHEMA = 0x03
_OP_CHANNEL = 0x04
_OP_MESSAGE = 0x05
_OP_CHUNK = 0x06
_OP_DATA_END = 0x0F
# Opcodes of the specification that carry nothing the scan needs (indexes, summary, ...).
_SKIPPED_OPS = frozenset({0x07, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E})
_USER_OPS_START = 0x80


class _DamageError(Exception):
    """Raised inside the scanner where the data stops making sense."""


@dataclass(frozen=True)
class ScannedSchema:
    """An MCAP schema record: a message type and its definition text."""

    id: int
    name: str
    encoding: str
    data: str


@dataclass(frozen=True)
class ScannedChannel:
    """An MCAP channel record: a topic, its schema and metadata (offered QoS ...)."""

    id: int
    schema_id: int
    topic: str
    message_encoding: str
    metadata: dict[str, str]


@dataclass(frozen=True)
class ScannedMessage:
    """A message record, with its channel resolved."""

    channel: ScannedChannel
    log_time_ns: int
    data: bytes


class _Body:
    """Cursor over one record body."""

    def __init__(self, data: bytes, what: str) -> None:
        self._data = data
        self._pos = 0
        self._what = what

    def take(self, size: int) -> bytes:
        if size < 0 or self._pos + size > len(self._data):
            msg = f'{self._what} record is shorter than its fields'
            raise _DamageError(msg)
        chunk = self._data[self._pos : self._pos + size]
        self._pos += size
        return chunk

    def uint(self, fmt: str) -> int:
        size = struct.calcsize(fmt)
        return int(struct.unpack(fmt, self.take(size))[0])

    def string(self) -> str:
        raw = self.take(self.uint('<I'))
        try:
            return raw.decode('utf-8')
        except UnicodeDecodeError as err:
            msg = f'{self._what} record holds invalid UTF-8'
            raise _DamageError(msg) from err

    def remaining(self) -> int:
        return len(self._data) - self._pos

    def rest(self) -> bytes:
        return self.take(self.remaining())


class McapScan:
    """Scan ``path`` record by record; iterate to get the messages.

    After iteration, :attr:`damage` is None when the file was read to its data end, or a
    sentence saying where the scan stopped and why. :attr:`schemas` and :attr:`channels`
    hold every schema and channel seen.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.schemas: dict[int, ScannedSchema] = {}
        self.channels: dict[int, ScannedChannel] = {}
        self.damage: str | None = None
        self.message_count = 0

    def __iter__(self) -> Iterator[ScannedMessage]:
        with self.path.open('rb') as stream:
            magic = stream.read(len(MCAP_MAGIC))
            if magic != MCAP_MAGIC:
                self.damage = 'the file does not start with the MCAP magic bytes'
                return
            size = self.path.stat().st_size
            yield from self._records(stream, size)

    def _records(self, stream: BinaryIO, size: int) -> Iterator[ScannedMessage]:
        while True:
            offset = stream.tell()
            head = stream.read(9)
            if not head:
                self.damage = f'the file ends at byte {offset} without a data end or footer'
                return
            if len(head) < 9:
                self.damage = f'the file is cut inside the record header at byte {offset}'
                return
            opcode, length = struct.unpack('<BQ', head)
            if length > size - offset - 9:
                self.damage = (
                    f'the record at byte {offset} (opcode 0x{opcode:02x}) claims {length} bytes '
                    f'but only {size - offset - 9} follow: the file is cut or damaged there'
                )
                return
            body = stream.read(length)
            try:
                if opcode in (_OP_FOOTER, _OP_DATA_END):
                    return
                if opcode == _OP_CHUNK:
                    yield from self._chunk(body, offset)
                elif opcode in (_OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE):
                    message = self._plain_record(opcode, body, offset)
                    if message is not None:
                        self.message_count += 1
                        yield message
                elif (
                    opcode != _OP_HEADER
                    and opcode not in _SKIPPED_OPS
                    and (opcode < _USER_OPS_START)
                ):
                    msg = f'invalid record opcode 0x{opcode:02x}'
                    raise _DamageError(msg)
            except _DamageError as err:
                self.damage = f'damaged record at byte {offset}: {err}'
                return

    def _plain_record(self, opcode: int, body: bytes, offset: int) -> ScannedMessage | None:
        if opcode == _OP_SCHEMA:
            record = _Body(body, 'schema')
            schema_id = record.uint('<H')
            name, encoding = record.string(), record.string()
            data = record.take(record.uint('<I')).decode('utf-8', errors='replace')
            self.schemas[schema_id] = ScannedSchema(schema_id, name, encoding, data)
            return None
        if opcode == _OP_CHANNEL:
            record = _Body(body, 'channel')
            channel_id, schema_id = record.uint('<H'), record.uint('<H')
            topic, encoding = record.string(), record.string()
            entries = _Body(record.take(record.uint('<I')), 'channel metadata')
            metadata: dict[str, str] = {}
            while entries.remaining():
                key = entries.string()
                metadata[key] = entries.string()
            self.channels[channel_id] = ScannedChannel(
                channel_id, schema_id, topic, encoding, metadata
            )
            return None
        record = _Body(body, 'message')
        channel_id = record.uint('<H')
        record.uint('<I')  # sequence
        log_time = record.uint('<Q')
        record.uint('<Q')  # publish time
        channel = self.channels.get(channel_id)
        if channel is None:
            msg = f'message of unknown channel {channel_id}'
            raise _DamageError(msg)
        return ScannedMessage(channel, log_time, record.rest())

    def _chunk(self, body: bytes, offset: int) -> Iterator[ScannedMessage]:
        record = _Body(body, 'chunk')
        record.uint('<Q')  # message start time
        record.uint('<Q')  # message end time
        uncompressed_size = record.uint('<Q')
        crc = record.uint('<I')
        compression = record.string()
        compressed = record.take(record.uint('<Q'))
        try:
            data = decompress(compressed, compression, uncompressed_size, crc)
        except (ReaderError, RuntimeError, ValueError, OSError) as err:
            msg = f'chunk cannot be decompressed: {err}'
            raise _DamageError(msg) from err
        # Messages of a chunk are handed out in log-time order (a recorder writes them so).
        messages: list[ScannedMessage] = []
        position = 0
        damage: _DamageError | None = None
        try:
            while position < len(data):
                if len(data) - position < 9:
                    msg = 'chunk ends inside a record header'
                    raise _DamageError(msg)
                opcode, length = struct.unpack_from('<BQ', data, position)
                start = position + 9
                if length > len(data) - start:
                    msg = f'record in chunk claims {length} bytes beyond the chunk end'
                    raise _DamageError(msg)
                body_bytes = data[start : start + length]
                position = start + length
                if opcode in (_OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE):
                    message = self._plain_record(opcode, body_bytes, offset)
                    if message is not None:
                        messages.append(message)
                elif opcode < _USER_OPS_START and opcode not in _SKIPPED_OPS:
                    msg = f'invalid record opcode 0x{opcode:02x} inside a chunk'
                    raise _DamageError(msg)
        except _DamageError as err:
            damage = err
        messages.sort(key=lambda m: m.log_time_ns)
        self.message_count += len(messages)
        yield from messages
        if damage is not None:
            raise damage
