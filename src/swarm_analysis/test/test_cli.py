"""swarm_report recognises the mission in a bag, reports its outcome, and recovers cut bags.

The bags are written with the generated message classes, which BagWriter serializes on
either runtime, so these tests run unchanged under SWARM_RUNTIME=builtin and rclpy.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest
from swarm_analysis.cli import EXIT_BAD_INPUT, EXIT_OK, main
from swarm_runtime.bag import BagWriter
from swarm_runtime.messages import get_message_module

swarm = get_message_module('swarm_interfaces')
std_msgs = get_message_module('std_msgs')
builtin = get_message_module('builtin_interfaces')


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


def _capture_bag(path: Path, *, flush_every: int | None = None) -> Path:
    """A capture mission: /sim/targets every 10 s for 100 s, targets caught at 40 and 90 s."""
    with BagWriter(path) as bag:
        for step, time_s in enumerate(range(0, 101, 10)):
            bag.write_message('/sim/targets', time_s * 10**9, _targets(time_s, [40.0, 90.0]))
            bag.write_message('/r0/pump', time_s * 10**9 + 1, std_msgs.Bool(data=True))
            if flush_every and step % flush_every == flush_every - 1:
                bag.flush()
    return path


def _cut(bag: Path, tmp_path: Path, keep: float) -> Path:
    copy = tmp_path / 'cut'
    shutil.copytree(bag, copy)
    (mcap,) = copy.glob('*.mcap')
    data = mcap.read_bytes()
    mcap.write_bytes(data[: int(len(data) * keep)])
    return copy


def test_a_capture_mission_bag_reports_its_capture_completion_time(tmp_path, capsys) -> None:
    assert main([str(_capture_bag(tmp_path / 'bag'))]) == EXIT_OK
    out = capsys.readouterr().out
    assert 'targets: 2/2 captured' in out
    assert 'capture completion time: 90 s' in out
    assert out.index('target 0: captured at 40 s') < out.index('target 1: captured at 90 s')


def test_a_bag_without_simulator_ground_truth_is_refused_with_a_hint(tmp_path, capsys) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        bag.write_message('/r0/pump', 0, std_msgs.Bool(data=True))
    assert main([str(tmp_path / 'bag')]) == EXIT_BAD_INPUT
    assert 'not a recorded simulation (try --info)' in capsys.readouterr().err


def test_info_lists_topics_with_counts_and_types(tmp_path, capsys) -> None:
    with BagWriter(tmp_path / 'bag') as bag:
        for index in range(3):
            bag.write_message('/r0/pump', index * 10**9, std_msgs.Bool(data=bool(index % 2)))
    assert main([str(tmp_path / 'bag'), '--info']) == EXIT_OK
    out = capsys.readouterr().out
    assert 'messages: 3 over 2.0 s' in out
    assert '/r0/pump' in out
    assert 'std_msgs/msg/Bool' in out


def test_a_missing_bag_is_a_one_line_error(tmp_path, capsys) -> None:
    assert main([str(tmp_path / 'nothing-here')]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.startswith('swarm_report: ')
    assert err.count('\n') == 1
    assert '--recover' not in err  # nothing to recover


def test_a_cut_bag_is_refused_with_a_hint_to_recover(tmp_path, capsys) -> None:
    cut = _cut(_capture_bag(tmp_path / 'bag', flush_every=3), tmp_path, 0.45)
    assert main([str(cut)]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert 'cut' in err
    assert 'swarm_report --recover' in err
    assert 'allow_truncated' not in err
    assert 'Traceback' not in err


def test_recover_reports_from_what_a_cut_bag_holds_and_says_how_much(tmp_path, capsys) -> None:
    cut = _cut(_capture_bag(tmp_path / 'bag', flush_every=3), tmp_path, 0.45)
    assert main([str(cut), '--recover']) == EXIT_OK
    captured = capsys.readouterr()
    out = captured.out
    assert 'of 22 recorded messages' in out
    assert 'damaged ' in out
    assert 'at byte' in out
    # The targets up to the cut: target 0 (40 s) is in, the report is from what was read.
    assert 'target 0: captured at 40 s' in out
    assert 'Warning' not in captured.err  # the loss is summarized once, not warned per chunk


def test_recover_info_gives_recovered_and_recorded_counts_per_topic(tmp_path, capsys) -> None:
    cut = _cut(_capture_bag(tmp_path / 'bag', flush_every=3), tmp_path, 0.45)
    assert main([str(cut), '--info', '--recover']) == EXIT_OK
    out = capsys.readouterr().out
    lines = {line.split()[0]: line for line in out.splitlines() if line.startswith('  /')}
    recovered, recorded = (int(lines['/sim/targets'].split()[1]), lines['/sim/targets'].split()[3])
    assert recorded == '11'
    assert 0 < recovered < 11


def test_recover_on_an_intact_bag_says_so(tmp_path, capsys) -> None:
    bag = _capture_bag(tmp_path / 'bag')
    assert main([str(bag), '--recover']) == EXIT_OK
    out = capsys.readouterr().out
    assert 'the bag is intact' in out
    assert 'capture completion time: 90 s' in out


@pytest.mark.parametrize('argv', [['--info'], []])
def test_an_unclosed_recording_is_refused_without_python_names(tmp_path, capsys, argv) -> None:
    bag = _capture_bag(tmp_path / 'bag')
    (bag / 'metadata.yaml').unlink()
    assert main([str(bag), *argv]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert 'metadata.yaml is missing' in err
    assert '=' not in err
    assert main([str(bag), *argv, '--recover']) == EXIT_OK
