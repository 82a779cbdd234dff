"""Stamp arithmetic, segment-disc entry and the command-line error conventions."""

import io
from dataclasses import dataclass

import numpy as np
import pytest
from swarm_common.cli import EXIT_UNFINISHED, EXIT_USAGE, exit_code_of, fail
from swarm_common.errors import SwarmError
from swarm_common.segments import first_entry_fraction
from swarm_common.stamps import (
    ns_to_sec_nanosec,
    seconds_to_ns,
    seconds_to_sec_nanosec,
    stamp_from_ns,
    stamp_from_seconds,
    stamp_to_seconds,
)


@dataclass
class Time:
    sec: int = 0
    nanosec: int = 0


def test_seconds_round_to_the_nearest_nanosecond_and_split_into_sec_and_nanosec():
    assert seconds_to_ns(12.3456789012) == 12_345_678_901
    assert seconds_to_sec_nanosec(12.3456789012) == (12, 345_678_901)
    assert ns_to_sec_nanosec(1_704_067_200_250_000_001) == (1_704_067_200, 250_000_001)
    assert ns_to_sec_nanosec(-1) == (-1, 999_999_999)


def test_stamps_are_built_with_the_given_type_and_read_back():
    stamp = stamp_from_seconds(12.25, Time)
    assert stamp == Time(12, 250_000_000)
    assert stamp_to_seconds(stamp) == 12.25
    assert stamp_from_ns(3_000_000_007, Time) == Time(3, 7)


def test_detection_happens_at_the_first_entry_into_the_disc():
    start, end = np.array([0.0, 0.0]), np.array([2.0, 0.0])
    assert first_entry_fraction(start, end, np.array([1.0, 0.0]), 0.5) == pytest.approx(0.25)
    assert first_entry_fraction(start, end, np.array([1.0, 1.0]), 0.5) is None
    assert first_entry_fraction(start, end, np.array([0.1, 0.0]), 0.5) == 0.0
    assert first_entry_fraction(start, start, np.array([1.0, 0.0]), 0.5) is None
    assert first_entry_fraction(start, end, np.array([3.0, 0.0]), 0.5) is None


class _UnfinishedError(SwarmError):
    exit_code = EXIT_UNFINISHED


def test_fail_prints_one_line_and_returns_the_errors_exit_code():
    out = io.StringIO()
    assert fail('tool', SwarmError('bad value\nsee --help'), file=out) == EXIT_USAGE
    assert out.getvalue() == 'tool: bad value see --help\n'
    out = io.StringIO()
    assert fail('tool', _UnfinishedError('no capture'), file=out) == EXIT_UNFINISHED
    assert fail('tool', 'plain text', 0, file=out) == 0
    assert exit_code_of(ValueError('x')) == EXIT_USAGE
