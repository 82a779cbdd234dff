"""Staged bags: written into a hidden sibling, under the final name only once complete."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import pytest
from swarm_common.errors import SwarmError
from swarm_runtime.bag import BagError, BagWriteError, BagWriter, read_bag_info, read_messages
from swarm_runtime.messages import get_message_module


def _write_some(writer: BagWriter, count: int) -> None:
    std_msgs = get_message_module('std_msgs')
    for index in range(count):
        writer.write_message('/count', 1_000 + index, std_msgs.Int32(data=index))


def test_a_staged_bag_appears_under_its_name_only_when_closed(tmp_path: Path) -> None:
    final = tmp_path / 'runs' / 'mission'
    writer = BagWriter(final, staging=True)
    writer.open()
    _write_some(writer, 5)
    writer.flush()
    staged = tmp_path / 'runs' / f'.mission.{os.getpid()}.partial'
    assert not final.exists()
    assert writer.directory == staged
    assert sorted(p.name for p in staged.iterdir()) == ['mission.mcap']
    writer.close()
    assert not staged.exists()
    assert writer.path == final
    assert writer.mcap_path == final / 'mission.mcap'
    assert sorted(p.name for p in final.iterdir()) == ['metadata.yaml', 'mission.mcap']
    info = read_bag_info(final)
    assert info.message_count == 5
    assert [m.message.data for m in read_messages(final)] == [0, 1, 2, 3, 4]


def test_a_recording_that_never_closes_leaves_only_the_partial_directory(
    tmp_path: Path,
) -> None:
    final = tmp_path / 'mission'
    writer = BagWriter(final, staging=True)
    writer.open()
    _write_some(writer, 3)
    writer.flush()  # what a killed process leaves: flushed chunks, no summary, no metadata
    assert not final.exists()
    with pytest.raises(BagError):
        read_bag_info(writer.directory)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        recovered = [m.message.data for m in read_messages(writer.directory, allow_truncated=True)]
    assert recovered == [0, 1, 2]


def test_a_staged_bag_never_replaces_an_existing_one(tmp_path: Path) -> None:
    final = tmp_path / 'mission'
    final.mkdir()
    with pytest.raises(BagWriteError, match='exists already'):
        BagWriter(final, staging=True)
    later = tmp_path / 'later'
    writer = BagWriter(later, staging=True)
    writer.open()
    _write_some(writer, 1)
    later.mkdir()  # someone else took the name while recording
    with pytest.raises(BagWriteError, match='the bag is kept as'):
        writer.close()
    assert (writer.directory / 'metadata.yaml').exists()
    assert isinstance(BagWriteError('x'), SwarmError)
