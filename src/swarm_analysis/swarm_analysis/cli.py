"""``swarm_report BAG``: the outcome of any recorded mission, from its bag alone.

The mission is recognised by the simulator's ground-truth topics in the bag:

- ``/sim/coverage`` (OA-Bug): room coverage summary, Fig.-6 paths PNG, coverage over time;
- ``/sim/source_search`` (Bayes-Swarm and its baselines): relative completion time tau;
- ``/sim/targets`` (MSC + PF): capture completion time and per-target capture times.

``--info`` lists the bag's topics instead, like ``ros2 bag info``. ``--recover`` reads a
damaged bag (cut short, never closed, garbage in it) as far as it can be read, says how much
was recovered per topic and where the damage is, then reports from what was recovered.

Exit codes: 0 on success, 2 when the input cannot be read or holds no mission to report on.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from swarm_analysis.cct import TARGETS_TOPIC, CctError, cct_from_bag
from swarm_analysis.oabug_report import COVERAGE_TOPIC, ReportError, load_run, write_report
from swarm_analysis.tau import STATUS_TOPIC, TauError, tau_from_bag

__all__ = ['EXIT_BAD_INPUT', 'EXIT_OK', 'main']

EXIT_OK = 0
EXIT_BAD_INPUT = 2


def _count(summary: Any, recovering: bool) -> str:
    if recovering and summary.recorded_count is not None:
        return f'{summary.message_count:>7} of {summary.recorded_count}'
    return f'{summary.message_count:>7}'


def _format_info(info: Any, *, recovering: bool) -> str:
    duration_s = (info.end_time_ns - info.start_time_ns) * 1e-9
    lines = [f'bag: {info.path}', f'messages: {info.message_count} over {duration_s:.1f} s']
    if recovering:
        lines = [*lines[:1], *_recovery_lines(info), lines[1]]
    lines.append('topics:')
    width = max((len(topic) for topic in info.topics), default=0)
    for topic, summary in sorted(info.topics.items()):
        lines.append(f'  {topic:<{width}}  {_count(summary, recovering)}  {summary.typename}')
    return '\n'.join(lines)


def _recovery_lines(info: Any) -> list[str]:
    """What recovery read: totals, damage, per-topic counts against the recorded ones."""
    if info.complete:
        return ['recovery: the bag is intact, every message was read']
    recorded = info.recorded_message_count
    if recorded:
        share = 100.0 * info.message_count / recorded
        head = f'recovered {info.message_count} of {recorded} recorded messages ({share:.1f} %)'
    else:
        head = f'recovered {info.message_count} messages (the bag does not say how many it had)'
    lines = [head]
    lines.extend(f'  {problem}' for problem in info.problems)
    lines.extend(f'  damaged {damage.describe()}' for damage in info.damage)
    return lines


def _tau_report(path: Path, recover: bool) -> str:
    result = tau_from_bag(path, allow_truncated=recover)
    if not result.found:
        return 'source not found within the recording (tau undefined)'
    return f'source found by {result.finder} at {result.found_time_s:.1f} s: tau = {result.tau:.3f}'


def _cct_report(path: Path, recover: bool) -> str:
    result = cct_from_bag(path, allow_truncated=recover)
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


def _oabug_report(path: Path, out_dir: Path | None, recover: bool) -> str:
    run = load_run(path, allow_truncated=recover)
    figures = write_report(run, out_dir if out_dir is not None else path, path.name)
    lines = [run.coverage.format_report(f'Coverage of {run.site_name}')]
    lines.extend(f'wrote {figure}' for figure in figures)
    return '\n'.join(lines)


def _report(args: argparse.Namespace) -> int:
    from swarm_runtime.bag import read_bag_info

    info = read_bag_info(args.bag, allow_truncated=args.recover)
    if args.info:
        sys.stdout.write(_format_info(info, recovering=args.recover) + '\n')
        return EXIT_OK
    if args.recover:
        sys.stdout.write('\n'.join([f'bag: {info.path}', *_recovery_lines(info)]) + '\n')
    topics = set(info.topics)
    if COVERAGE_TOPIC in topics:
        text = _oabug_report(args.bag, args.out_dir, args.recover)
    elif STATUS_TOPIC in topics:
        text = _tau_report(args.bag, args.recover)
    elif TARGETS_TOPIC in topics:
        text = _cct_report(args.bag, args.recover)
    else:
        sys.stderr.write(
            f'swarm_report: {args.bag} has none of {COVERAGE_TOPIC}, {STATUS_TOPIC}, '
            f'{TARGETS_TOPIC}: not a recorded simulation (try --info)\n'
        )
        return EXIT_BAD_INPUT
    sys.stdout.write(text + '\n')
    return EXIT_OK


def _one_line(err: BaseException) -> str:
    text = ' '.join(str(err).split())
    return text or type(err).__name__


def main(argv: Sequence[str] | None = None) -> int:
    """Print the report of the mission recorded in a bag; returns the exit code."""
    parser = argparse.ArgumentParser(
        prog='swarm_report',
        description='Outcome of a recorded mission (OA-Bug, Bayes-Swarm or MSC + PF).',
    )
    parser.add_argument('bag', type=Path, help='rosbag2 directory (or .mcap file)')
    parser.add_argument('--out-dir', type=Path, default=None, help='PNG directory (OA-Bug)')
    parser.add_argument('--info', action='store_true', help='list topics and counts only')
    parser.add_argument(
        '--recover',
        action='store_true',
        help='read a damaged bag (cut, unfinished) as far as possible and say what was lost',
    )
    args = parser.parse_args(argv)

    from swarm_runtime.bag import BagError, TruncatedBagWarning

    try:
        with warnings.catch_warnings():
            # What recovery lost is summarized once, above the report.
            warnings.simplefilter('ignore', TruncatedBagWarning)
            return _report(args)
    except BagError as err:
        hint = ' (swarm_report --recover reads what it holds)' if err.recoverable else ''
        sys.stderr.write(f'swarm_report: {_one_line(err)}{hint}\n')
    except (CctError, ReportError, TauError) as err:
        sys.stderr.write(f'swarm_report: {_one_line(err)}\n')
    return EXIT_BAD_INPUT


if __name__ == '__main__':
    sys.exit(main())
