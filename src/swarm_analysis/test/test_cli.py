"""swarm_report recognises the mission in a bag and reports its outcome."""

import math

from swarm_analysis.cli import main
from swarm_runtime.bag import BagWriter
from swarm_runtime.ros import message_module

swarm = message_module('swarm_interfaces')
std_msgs = message_module('std_msgs')
builtin = message_module('builtin_interfaces')


def _targets(time_s: int, captured_at: list[float]) -> object:
    msg = swarm.RssiTargetArray()
    msg.header.stamp = builtin.Time(sec=time_s, nanosec=0)
    msg.targets = [
        swarm.RssiTarget(
            target_id=index,
            captured=at <= time_s,
            capture_time_s=float(at) if at <= time_s else math.nan,
        )
        for index, at in enumerate(captured_at)
    ]
    return msg


def test_a_capture_mission_bag_reports_its_capture_completion_time(tmp_path, capsys) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        for time_s in range(0, 101, 10):
            bag.write_message('/sim/targets', time_s * 10**9, _targets(time_s, [40.0, 90.0]))
    assert main([str(tmp_path / 'bag')]) == 0
    out = capsys.readouterr().out
    assert 'targets: 2/2 captured' in out
    assert 'capture completion time: 90 s' in out
    assert out.index('target 0: captured at 40 s') < out.index('target 1: captured at 90 s')


def test_a_bag_without_simulator_ground_truth_is_refused_with_a_hint(tmp_path, capsys) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        bag.write_message('/r0/pump', 0, std_msgs.Bool(data=True))
    assert main([str(tmp_path / 'bag')]) == 1
    assert 'not a recorded simulation (try --info)' in capsys.readouterr().err


def test_info_lists_topics_with_counts_and_types(tmp_path, capsys) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        for index in range(3):
            bag.write_message('/r0/pump', index * 10**9, std_msgs.Bool(data=bool(index % 2)))
    assert main([str(tmp_path / 'bag'), '--info']) == 0
    out = capsys.readouterr().out
    assert 'messages: 3 over 2.0 s' in out
    assert '/r0/pump' in out
    assert 'std_msgs/msg/Bool' in out


def test_a_missing_bag_is_a_clear_error(tmp_path, capsys) -> None:
    assert main([str(tmp_path / 'nothing-here')]) == 1
    assert 'swarm_report:' in capsys.readouterr().err
