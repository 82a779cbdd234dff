"""Damaged bags: clear errors naming the file, damage never decoded, and recovery of the rest."""

from __future__ import annotations

import shutil
from array import array
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from swarm_runtime.bag import (
    BagMessage,
    BagNotFoundError,
    BagWriter,
    CorruptBagError,
    TruncatedBagWarning,
    read_bag_info,
    read_messages,
)
from swarm_runtime.messages import get_message_module

MESSAGES_PER_CHUNK = 10
CHUNKS = 3
# Uncompressed chunk layout: record header (9) + chunk header (40, no compression name), then
# one record per Int32 message: header (9) + channel, sequence, two times (22) + CDR (8).
CHUNK_HEADER_BYTES = 9 + 40
INT32_RECORD_BYTES = 9 + 22 + 8


@pytest.fixture(scope='module')
def recording(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[int]]:
    """A bag of 30 Int32 messages (data == log time) in three MCAP chunks, and the MCAP file
    size after each chunk was written (so a test can damage a chosen chunk)."""
    std_msgs = get_message_module('std_msgs')
    path = tmp_path_factory.mktemp('bags') / 'intact'
    chunk_ends: list[int] = []
    with BagWriter(path) as writer:
        for index in range(MESSAGES_PER_CHUNK * CHUNKS):
            writer.write_message('/counter', index, std_msgs.Int32(data=index))
            if index % MESSAGES_PER_CHUNK == MESSAGES_PER_CHUNK - 1:
                writer.flush()
                chunk_ends.append(writer.mcap_path.stat().st_size)
    return path, chunk_ends


@pytest.fixture
def intact(recording: tuple[Path, list[int]]) -> Path:
    """The intact bag."""
    return recording[0]


@pytest.fixture
def chunk_starts(recording: tuple[Path, list[int]]) -> list[int]:
    """Byte offset of the second and third chunk (each holds only messages)."""
    ends = recording[1]
    return [0, ends[0], ends[1]]


def _damaged_copy(intact: Path, tmp_path: Path, damage: Callable[[bytes], bytes]) -> Path:
    copy = tmp_path / 'damaged'
    shutil.copytree(intact, copy)
    mcap = copy / 'intact.mcap'
    mcap.write_bytes(damage(mcap.read_bytes()))
    return copy


def _collect(messages: Iterator[BagMessage], into: list[int]) -> None:
    """Append each message's data to ``into`` (what was read before an exception)."""
    for message in messages:
        into.append(message.message.data)


def _recover(path: Path) -> tuple[list[int], list[str]]:
    with pytest.warns(TruncatedBagWarning) as caught:
        values = [m.message.data for m in read_messages(path, allow_truncated=True)]
    return values, [str(w.message) for w in caught]


def test_intact_bag_reads_without_warnings(intact: Path) -> None:
    assert [m.message.data for m in read_messages(intact)] == list(range(30))


def test_cut_mcap_raises_one_line_naming_the_file(
    intact: Path, chunk_starts: list[int], tmp_path: Path
) -> None:
    damaged = _damaged_copy(intact, tmp_path, lambda data: data[: chunk_starts[2] + 100])
    with pytest.raises(
        CorruptBagError, match=r'damaged/intact\.mcap: cannot read the bag: .*cut'
    ) as caught:
        list(read_messages(damaged))
    assert caught.value.recoverable
    assert '\n' not in str(caught.value)
    assert 'allow_truncated' not in str(caught.value)


@pytest.mark.parametrize(
    'into_chunk', [0, 30, 49, 49 + 38, 49 + 39, 49 + 5 * 39 + 20, 49 + 10 * 39 - 1]
)
def test_a_cut_inside_the_last_chunk_keeps_its_complete_messages(
    intact: Path, chunk_starts: list[int], tmp_path: Path, into_chunk: int
) -> None:
    cut = chunk_starts[2] + into_chunk
    damaged = _damaged_copy(intact, tmp_path, lambda data: data[:cut])
    values, warnings = _recover(damaged)
    complete_in_cut_chunk = max(0, (into_chunk - CHUNK_HEADER_BYTES) // INT32_RECORD_BYTES)
    assert values == list(range(2 * MESSAGES_PER_CHUNK + complete_in_cut_chunk))
    assert any('intact.mcap' in text and 'cut' in text for text in warnings)


@pytest.mark.parametrize('compression', ['zstd', 'lz4'])
def test_a_cut_inside_a_compressed_chunk_keeps_what_decompresses(
    tmp_path: Path, compression: str
) -> None:
    """Incompressible payloads make many compression blocks; a cut keeps the whole ones."""
    import numpy as np

    std_msgs = get_message_module('std_msgs')
    rng = np.random.default_rng(3)
    path = tmp_path / 'compressed'
    with BagWriter(path, chunk_compression=compression, chunk_size_bytes=1 << 24) as writer:
        for index in range(400):  # two chunks of 200 x 4 KiB
            payload = array('B', bytes(rng.integers(0, 256, 4096, dtype=np.uint8)))
            writer.write_message('/blob', index, std_msgs.UInt8MultiArray(data=payload))
            if index == 199:
                writer.flush()
    mcap = path / 'compressed.mcap'
    data = mcap.read_bytes()
    mcap.write_bytes(data[: len(data) * 3 // 4])  # the middle of the second chunk
    with pytest.warns(TruncatedBagWarning) as caught:
        recovered = [m.log_time_ns for m in read_messages(path, allow_truncated=True)]
    assert any('cut inside a chunk' in str(w.message) for w in caught)
    # The complete first chunk, and of the second what its whole compression blocks hold
    # (about half of it, less at most one zstd block of 128 KiB, 32 messages).
    assert recovered == list(range(len(recovered)))
    assert 200 + 50 < len(recovered) < 400


def test_a_flipped_byte_inside_a_chunk_is_caught_by_its_crc(
    intact: Path, chunk_starts: list[int], tmp_path: Path
) -> None:
    """The payload of message 15 (chunk 2) changes from 15 to 15 + 256: still a valid Int32."""
    position = chunk_starts[1] + CHUNK_HEADER_BYTES + 5 * INT32_RECORD_BYTES + 9 + 22 + 5

    def flip(data: bytes) -> bytes:
        assert data[position - 1] == 15
        return data[:position] + bytes([data[position] ^ 1]) + data[position + 1 :]

    damaged = _damaged_copy(intact, tmp_path, flip)
    received: list[int] = []
    with pytest.raises(CorruptBagError, match=r'intact\.mcap: damaged data: .*CRC'):
        _collect(read_messages(damaged), received)
    assert received == list(range(10))
    values, warnings = _recover(damaged)
    assert values == [*range(10), *range(20, 30)]
    assert any('CRC' in text and 'skipped' in text for text in warnings)


def test_garbage_inserted_into_a_chunk_is_skipped_and_reading_resumes_after_it(
    intact: Path, chunk_starts: list[int], tmp_path: Path
) -> None:
    middle = chunk_starts[1] + 200

    def insert_garbage(data: bytes) -> bytes:
        return data[:middle] + b'\xde\xad\xbe\xef' * 64 + data[middle:]

    damaged = _damaged_copy(intact, tmp_path, insert_garbage)
    with pytest.raises(CorruptBagError, match=r'intact\.mcap'):
        list(read_messages(damaged))
    values, warnings = _recover(damaged)
    assert values == [*range(10), *range(20, 30)]
    assert any(f'at byte {chunk_starts[1]}' in text and 'resumed' in text for text in warnings)


def test_garbage_overwriting_chunk_headers_resumes_at_the_next_intact_chunk(
    intact: Path, chunk_starts: list[int], tmp_path: Path
) -> None:
    start = chunk_starts[1] - 20

    def overwrite(data: bytes) -> bytes:
        return data[:start] + b'\xff' * 64 + data[start + 64 :]

    damaged = _damaged_copy(intact, tmp_path, overwrite)
    values, _ = _recover(damaged)
    assert values == [*range(10), *range(20, 30)]


def test_bytes_that_do_not_fit_the_type_are_not_decoded(tmp_path: Path) -> None:
    std_msgs = get_message_module('std_msgs')
    path = tmp_path / 'odd'
    with BagWriter(path) as writer:
        writer.write_message('/counter', 0, std_msgs.Int32(data=0))
        writer.write('/counter', 1, b'\x00\x01\x00\x00\x07\x00\x00\x00\x00\x00\x00\x00')
        writer.write_message('/counter', 2, std_msgs.Int32(data=2))
    received: list[int] = []
    with pytest.raises(CorruptBagError, match=r'at 1 ns does not decode as std_msgs/msg/Int32'):
        _collect(read_messages(path), received)
    assert received == [0]
    values, warnings = _recover(path)
    assert values == [0, 2]
    assert any('skipped' in text for text in warnings)


def test_missing_metadata_is_reported_and_recoverable(intact: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'unclosed'
    shutil.copytree(intact, copy)
    (copy / 'metadata.yaml').unlink()
    with pytest.raises(BagNotFoundError, match=r'unclosed/metadata\.yaml is missing') as caught:
        list(read_messages(copy))
    assert caught.value.recoverable
    assert 'allow_truncated' not in str(caught.value)
    values, warnings = _recover(copy)
    assert values == list(range(30))
    assert any('metadata.yaml is missing' in text for text in warnings)


def test_metadata_listing_a_missing_file_is_reported(intact: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'moved'
    shutil.copytree(intact, copy)
    (copy / 'intact.mcap').rename(copy / 'elsewhere.mcap')
    with pytest.raises(BagNotFoundError, match=r'lists storage files that do not exist: .*intact'):
        list(read_messages(copy))
    values, _ = _recover(copy)
    assert values == list(range(30))


def test_unwritten_recording_without_footer_is_recovered(tmp_path: Path) -> None:
    """What a recorder that died leaves: flushed chunks, no summary, no metadata.yaml."""
    std_msgs = get_message_module('std_msgs')
    path = tmp_path / 'died'
    writer = BagWriter(path)
    writer.open()
    for index in range(5):
        writer.write_message('/counter', index, std_msgs.Int32(data=index))
    writer.flush()
    writer.write_message('/counter', 5, std_msgs.Int32(data=5))  # never flushed
    with pytest.raises(BagNotFoundError, match=r'metadata\.yaml is missing'):
        list(read_messages(path))
    values, warnings = _recover(path)
    assert values == [0, 1, 2, 3, 4]
    assert any('ends without the MCAP data end and footer' in text for text in warnings)
    writer.close()


def test_bag_info_of_a_cut_bag_counts_what_can_be_read(
    intact: Path, chunk_starts: list[int], tmp_path: Path
) -> None:
    damaged = _damaged_copy(intact, tmp_path, lambda data: data[: chunk_starts[2] + 100])
    with pytest.raises(CorruptBagError):
        read_bag_info(damaged)
    info = read_bag_info(damaged, allow_truncated=True)
    assert not info.complete
    assert info.message_count == 21
    assert info.recorded_message_count == 30
    assert info.topics['/counter'].message_count == 21
    assert info.topics['/counter'].recorded_count == 30
    (damage,) = info.damage
    assert damage.offset == chunk_starts[2]
    assert damage.resumed_at is None
    assert 'intact.mcap: at byte' in damage.describe()
    assert read_bag_info(intact, allow_truncated=True).complete


def test_missing_bag_and_wrong_file_kinds_are_reported(tmp_path: Path) -> None:
    with pytest.raises(BagNotFoundError, match='no such bag'):
        read_messages(tmp_path / 'absent')  # raised by the call, before any iteration
    text_file = tmp_path / 'notes.txt'
    text_file.write_text('hello')
    with pytest.raises(BagNotFoundError, match='not a bag directory'):
        list(read_messages(text_file))
    (tmp_path / 'empty').mkdir()
    with pytest.raises(BagNotFoundError, match=r'not a bag \(no metadata.yaml and no \.mcap'):
        read_messages(tmp_path / 'empty')


def test_invalid_metadata_yaml_is_reported(intact: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'badmeta'
    shutil.copytree(intact, copy)
    (copy / 'metadata.yaml').write_text('rosbag2_bagfile_information: [unclosed')
    with pytest.raises(CorruptBagError, match=r'badmeta/metadata\.yaml: not a valid'):
        list(read_messages(copy))


def test_a_lone_mcap_file_reads_like_its_bag(intact: Path) -> None:
    values = [m.message.data for m in read_messages(intact / 'intact.mcap')]
    assert values == list(range(30))
    assert read_bag_info(intact / 'intact.mcap').message_count == 30


@pytest.mark.parametrize(
    ('text', 'problem'),
    [
        ('rosbag2_bagfile_information: {version: 5}', "the field 'relative_file_paths' is missing"),
        ('rosbag2_bagfile_information: 3', 'a field is missing or is not the mapping'),
        ('[1, 2]', 'a field is missing or is not the mapping'),
    ],
)
def test_metadata_of_the_wrong_shape_is_reported_in_its_own_terms(
    intact: Path, tmp_path: Path, text: str, problem: str
) -> None:
    copy = tmp_path / 'badmeta'
    shutil.copytree(intact, copy)
    (copy / 'metadata.yaml').write_text(text)
    with pytest.raises(CorruptBagError) as caught:
        list(read_messages(copy))
    assert problem in str(caught.value)
    assert 'NoneType' not in str(caught.value)


def test_an_empty_mcap_file_is_called_empty(intact: Path, tmp_path: Path) -> None:
    damaged = _damaged_copy(intact, tmp_path, lambda data: b'')
    with pytest.raises(CorruptBagError, match=r'intact\.mcap: cannot read the bag: it is empty'):
        list(read_messages(damaged))


def _summary_start(data: bytes) -> int:
    # Footer: opcode, length, summary start, summary offset start, CRC; then the magic.
    return int.from_bytes(data[-8 - 20 : -8 - 12], 'little')


def test_a_damaged_summary_fails_its_crc_and_recovery_reads_the_records(
    intact: Path, tmp_path: Path
) -> None:
    # The summary repeats the schema the data section holds; damage its copy only.
    def damage(data: bytes) -> bytes:
        at = data.index(b'std_msgs/msg/Int32', _summary_start(data)) + 20
        return data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :]

    damaged = _damaged_copy(intact, tmp_path, damage)
    with pytest.raises(CorruptBagError, match=r'summary section .* fails its CRC') as caught:
        list(read_messages(damaged))
    assert caught.value.recoverable
    values, warnings = _recover(damaged)
    assert values == list(range(30))
    assert any('fails its CRC' in text for text in warnings)
    info = read_bag_info(damaged, allow_truncated=True)
    assert info.message_count == 30
    assert not info.complete  # recovery says what it read around, not "intact"
    assert any('fails its CRC' in problem for problem in info.problems)
