"""Recovery of a realistic recording cut at several points returns every complete message.

The bag has what a swarm run records (three robots' 360-ray scans at 10 Hz, IMU at 50 Hz,
velocity commands at 10 Hz, /clock at 100 Hz, a latched site message), flushed every 5 s
like the recorder. The ground truth is independent of the reader: every message record whose
bytes lie entirely before the cut (:func:`swarm_runtime.bag.testing.message_record_ends`).
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path
from typing import Any

import pytest
from swarm_runtime.bag import BagWriter, read_bag_info, read_messages
from swarm_runtime.bag.testing import message_record_ends
from swarm_runtime.messages import get_message_module

SECONDS = 20
CUTS = (0.02, 0.1, 0.333, 0.5, 0.77, 0.9, 0.999)


@pytest.fixture(scope='module')
def realistic_bag(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[int], list[Any]]:
    """The bag, the end offsets of its message records, and its messages read intact."""
    sensor_msgs = get_message_module('sensor_msgs')
    geometry_msgs = get_message_module('geometry_msgs')
    rosgraph_msgs = get_message_module('rosgraph_msgs')
    builtin = get_message_module('builtin_interfaces')
    std_msgs = get_message_module('std_msgs')
    path = tmp_path_factory.mktemp('realistic') / 'run'
    with BagWriter(path) as writer:
        writer.write_message('/sim/site', 0, std_msgs.String(data='site ' * 200))
        for tick in range(SECONDS * 100):  # 10 ms steps
            t_ns = tick * 10_000_000
            stamp = builtin.Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9)
            writer.write_message('/clock', t_ns, rosgraph_msgs.Clock(clock=stamp))
            for robot in range(3):
                if tick % 2 == 0:
                    imu = sensor_msgs.Imu(header=std_msgs.Header(stamp=stamp))
                    writer.write_message(f'/r{robot}/imu', t_ns + 1, imu)
                if tick % 10 == robot:
                    scan = sensor_msgs.LaserScan(
                        header=std_msgs.Header(stamp=stamp, frame_id=f'r{robot}/laser'),
                        ranges=[float(tick % 7 + i % 5) for i in range(360)],
                    )
                    writer.write_message(f'/r{robot}/scan', t_ns + 2, scan)
                    twist = geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=0.3))
                    writer.write_message(f'/r{robot}/cmd_vel', t_ns + 3, twist)
            if tick % 500 == 499:
                writer.flush()
    (mcap,) = path.glob('*.mcap')
    return path, message_record_ends(mcap), list(read_messages(path))


@pytest.mark.parametrize('fraction', CUTS)
def test_recovery_returns_every_complete_message_before_the_cut(
    realistic_bag: tuple[Path, list[int], list[Any]], tmp_path: Path, fraction: float
) -> None:
    bag, ends, intact = realistic_bag
    (mcap,) = bag.glob('*.mcap')
    cut = int(mcap.stat().st_size * fraction)
    copy = tmp_path / 'cut'
    shutil.copytree(bag, copy)
    (copy / mcap.name).write_bytes(mcap.read_bytes()[:cut])

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        recovered = list(read_messages(copy, allow_truncated=True))
    complete = sum(1 for end in ends if end <= cut)
    assert len(recovered) == complete
    assert caught  # the loss is reported
    times = [m.log_time_ns for m in recovered]
    assert times == sorted(times)
    # What recovery reads is what the intact bag holds, message for message.
    assert [(m.topic, m.log_time_ns) for m in recovered] == [
        (m.topic, m.log_time_ns) for m in intact[: len(recovered)]
    ]
    assert recovered[-1].message == intact[len(recovered) - 1].message

    info = read_bag_info(copy, allow_truncated=True)
    assert info.message_count == complete
    assert info.recorded_message_count == len(ends)
