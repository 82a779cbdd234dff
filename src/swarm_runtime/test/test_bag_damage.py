"""Damaged bags: clear errors naming the file, and recovery of everything before the damage."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from swarm_runtime.bag import (
    BagNotFoundError,
    BagWriter,
    CorruptBagError,
    TruncatedBagWarning,
    read_messages,
)
from swarm_runtime.messages import get_message_module

MESSAGES_PER_CHUNK = 10
CHUNKS = 3


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
def inside_last_chunk(recording: tuple[Path, list[int]]) -> int:
    """A byte offset in the middle of the third (last) chunk."""
    chunk_ends = recording[1]
    return (chunk_ends[1] + chunk_ends[2]) // 2


def _damaged_copy(intact: Path, tmp_path: Path, damage: callable) -> Path:
    copy = tmp_path / 'damaged'
    shutil.copytree(intact, copy)
    mcap = copy / 'intact.mcap'
    mcap.write_bytes(damage(mcap.read_bytes()))
    return copy


def _recover(path: Path) -> tuple[list[int], list[str]]:
    with pytest.warns(TruncatedBagWarning) as caught:
        values = [m.message.data for m in read_messages(path, allow_truncated=True)]
    return values, [str(w.message) for w in caught]


def test_intact_bag_reads_without_warnings(intact: Path) -> None:
    assert [m.message.data for m in read_messages(intact)] == list(range(30))


def test_cut_mcap_raises_naming_the_file(
    intact: Path, inside_last_chunk: int, tmp_path: Path
) -> None:
    damaged = _damaged_copy(intact, tmp_path, lambda data: data[:inside_last_chunk])
    with pytest.raises(CorruptBagError, match=r'damaged/intact\.mcap: cannot open the bag'):
        list(read_messages(damaged))


def test_cut_mcap_recovers_every_complete_chunk(
    intact: Path, inside_last_chunk: int, tmp_path: Path
) -> None:
    damaged = _damaged_copy(intact, tmp_path, lambda data: data[:inside_last_chunk])
    values, warnings = _recover(damaged)
    assert values == list(range(2 * MESSAGES_PER_CHUNK))
    assert any('intact.mcap' in text and 'cut' in text for text in warnings)


def test_garbage_in_the_middle_stops_reading_at_the_damage(
    intact: Path, inside_last_chunk: int, tmp_path: Path
) -> None:
    def insert_garbage(data: bytes) -> bytes:
        middle = inside_last_chunk
        return data[:middle] + b'\xde\xad\xbe\xef' * 64 + data[middle:]

    damaged = _damaged_copy(intact, tmp_path, insert_garbage)
    with pytest.raises(CorruptBagError, match=r'intact\.mcap'):
        list(read_messages(damaged))
    values, warnings = _recover(damaged)
    assert values == list(range(len(values)))
    assert 2 * MESSAGES_PER_CHUNK <= len(values) < MESSAGES_PER_CHUNK * CHUNKS
    assert any('intact.mcap' in text and 'damaged' in text for text in warnings)


def test_strict_reading_yields_messages_before_the_damage_then_raises(
    intact: Path, inside_last_chunk: int, tmp_path: Path
) -> None:
    def overwrite_last_chunk(data: bytes) -> bytes:
        start = inside_last_chunk
        return data[:start] + b'\xff' * 48 + data[start + 48 :]

    damaged = _damaged_copy(intact, tmp_path, overwrite_last_chunk)
    received: list[int] = []

    def read_all() -> None:
        for message in read_messages(damaged):
            received.append(message.message.data)

    with pytest.raises(CorruptBagError, match=r'intact\.mcap: damaged data'):
        read_all()
    assert received == list(range(len(received)))
    assert 2 * MESSAGES_PER_CHUNK <= len(received) < MESSAGES_PER_CHUNK * CHUNKS


def test_missing_metadata_is_reported_and_recoverable(intact: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'unclosed'
    shutil.copytree(intact, copy)
    (copy / 'metadata.yaml').unlink()
    with pytest.raises(BagNotFoundError, match=r'unclosed/metadata\.yaml is missing'):
        list(read_messages(copy))
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
    assert any('without a data end or footer' in text for text in warnings)
    writer.close()


def test_missing_bag_and_wrong_file_kinds_are_reported(tmp_path: Path) -> None:
    with pytest.raises(BagNotFoundError, match='no such bag'):
        read_messages(tmp_path / 'absent')  # raised by the call, before any iteration
    text_file = tmp_path / 'notes.txt'
    text_file.write_text('hello')
    with pytest.raises(BagNotFoundError, match='not a bag directory'):
        list(read_messages(text_file))


def test_invalid_metadata_yaml_is_reported(intact: Path, tmp_path: Path) -> None:
    copy = tmp_path / 'badmeta'
    shutil.copytree(intact, copy)
    (copy / 'metadata.yaml').write_text('rosbag2_bagfile_information: [unclosed')
    with pytest.raises(CorruptBagError, match=r'badmeta/metadata\.yaml: not a valid'):
        list(read_messages(copy))


def test_a_lone_mcap_file_reads_like_its_bag(intact: Path) -> None:
    values = [m.message.data for m in read_messages(intact / 'intact.mcap')]
    assert values == list(range(30))
