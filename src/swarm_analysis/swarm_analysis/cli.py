"""``swarm_report BAG``: the outcome of any recorded mission, from its bag alone.

The mission is recognised by the simulator's ground-truth topics in the bag:

- ``/sim/coverage`` (OA-Bug): room coverage summary, Fig.-6 paths PNG, coverage over time;
- ``/sim/source_search`` (Bayes-Swarm and its baselines): relative completion time tau;
- ``/sim/targets`` (MSC + PF): capture completion time and per-target capture times.

``--info`` lists the bag's topics instead, like ``ros2 bag info``.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

from swarm_analysis.cct import TARGETS_TOPIC, CctError, cct_from_bag
from swarm_analysis.oabug_report import COVERAGE_TOPIC, ReportError
from swarm_analysis.oabug_report import main as oabug_report_main
from swarm_analysis.tau import STATUS_TOPIC, TauError, tau_from_bag

__all__ = ['main']


def _format_info(path: Path) -> str:
    from swarm_runtime.bag import read_bag_info

    info = read_bag_info(path)
    duration_s = (info.end_time_ns - info.start_time_ns) * 1e-9
    lines = [
        f'bag: {info.path}',
        f'messages: {info.message_count} over {duration_s:.1f} s',
        'topics:',
    ]
    width = max((len(topic) for topic in info.topics), default=0)
    for topic, summary in sorted(info.topics.items()):
        lines.append(f'  {topic:<{width}}  {summary.message_count:>7}  {summary.typename}')
    return '\n'.join(lines)


def _tau_report(path: Path) -> str:
    result = tau_from_bag(path)
    if not result.found:
        return 'source not found within the recording (tau undefined)'
    return f'source found by {result.finder} at {result.found_time_s:.1f} s: tau = {result.tau:.3f}'


def _cct_report(path: Path) -> str:
    result = cct_from_bag(path)
    lines = [
        f'targets: {len(result.capture_times_s)}/{result.n_targets} captured',
        (
            f'capture completion time: {result.cct_s:.0f} s'
            if result.all_captured and math.isfinite(result.cct_s)
            else f'not all captured by the end of the recording ({result.end_time_s:.0f} s)'
        ),
    ]
    for target, time_s in sorted(result.capture_times_s.items(), key=lambda item: item[1]):
        lines.append(f'  target {target}: captured at {time_s:.0f} s')
    return '\n'.join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the report of the mission recorded in a bag; returns the exit code."""
    parser = argparse.ArgumentParser(
        prog='swarm_report',
        description='Outcome of a recorded mission (OA-Bug, Bayes-Swarm or MSC + PF).',
    )
    parser.add_argument('bag', type=Path, help='rosbag2 directory (or .mcap file)')
    parser.add_argument('--out-dir', type=Path, default=None, help='PNG directory (OA-Bug)')
    parser.add_argument('--info', action='store_true', help='list topics and counts only')
    args = parser.parse_args(argv)

    from swarm_runtime.bag import BagError, read_bag_info

    try:
        if args.info:
            sys.stdout.write(_format_info(args.bag) + '\n')
            return 0
        topics = set(read_bag_info(args.bag).topics)
        if COVERAGE_TOPIC in topics:
            extra = ['--out-dir', str(args.out_dir)] if args.out_dir is not None else []
            return oabug_report_main([str(args.bag), *extra])
        if STATUS_TOPIC in topics:
            sys.stdout.write(_tau_report(args.bag) + '\n')
            return 0
        if TARGETS_TOPIC in topics:
            sys.stdout.write(_cct_report(args.bag) + '\n')
            return 0
    except (BagError, CctError, ReportError, TauError) as err:
        sys.stderr.write(f'swarm_report: {err}\n')
        return 1
    sys.stderr.write(
        f'swarm_report: {args.bag} has none of {COVERAGE_TOPIC}, {STATUS_TOPIC}, '
        f'{TARGETS_TOPIC}: not a recorded simulation (try --info)\n'
    )
    return 1


if __name__ == '__main__':
    sys.exit(main())
