"""CCT from a bag of /sim/targets messages."""

import math

import pytest
from swarm_analysis.cct import CctError, cct_from_bag
from swarm_runtime.bag import BagWriter
from swarm_runtime.messages import get_message_module as message_module

swarm = message_module('swarm_interfaces')
builtin = message_module('builtin_interfaces')


def targets_message(time_s, captured_at):
    msg = swarm.RssiTargetArray()
    msg.header.stamp = builtin.Time(sec=int(time_s), nanosec=0)
    msg.targets = [
        swarm.RssiTarget(
            target_id=tid,
            x=100.0 * tid,
            y=0.0,
            remaining_load=0.0 if at is not None and at <= time_s else 100.0,
            captured=at is not None and at <= time_s,
            capture_time_s=float(at) if at is not None and at <= time_s else math.nan,
        )
        for tid, at in enumerate(captured_at)
    ]
    return msg


def write_bag(path, captured_at, until_s):
    with BagWriter(path) as bag:
        for t in range(0, until_s + 1, 10):
            bag.write_message('/sim/targets', t * 1_000_000_000, targets_message(t, captured_at))


def test_cct_is_the_last_capture_once_every_target_is_captured(tmp_path):
    write_bag(tmp_path / 'bag', [30.0, 125.0, 80.0], until_s=130)
    result = cct_from_bag(tmp_path / 'bag')
    assert result.all_captured
    assert result.cct_s == 125.0
    assert result.capture_times_s == {0: 30.0, 1: 125.0, 2: 80.0}


def test_cct_is_nan_while_a_target_is_uncaptured(tmp_path):
    write_bag(tmp_path / 'bag', [30.0, None], until_s=60)
    result = cct_from_bag(tmp_path / 'bag')
    assert not result.all_captured
    assert math.isnan(result.cct_s)
    assert result.capture_times_s == {0: 30.0}
    assert result.end_time_s == 60.0


def test_a_bag_without_target_messages_is_rejected(tmp_path):
    with BagWriter(tmp_path / 'bag') as bag:
        bag.write_message('/other', 0, targets_message(0, [None]))
    with pytest.raises(CctError, match='no /sim/targets'):
        cct_from_bag(tmp_path / 'bag')
