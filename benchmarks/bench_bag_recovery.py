"""How much of a cut bag recovery reads back: a recorded mission bag cut at several points.

By default it records a realistic bag first (an OA-Bug mission on the small site, 6 robots,
the spawner's default topics: /clock, cmd_vel, pump and state of every robot, the ground
truth; about 32,000 messages), or takes ``--bag``. For each cut point it copies the bag,
truncates its .mcap file there, reads it back with recovery and prints:

- recovered: messages ``read_messages(..., allow_truncated=True)`` returned;
- complete: messages whose MCAP record lies entirely before the cut (what an ideal
  recovery of an uncompressed bag can return; found by locating each message's record
  bytes in the intact file, independently of the reader);
- total: messages in the intact bag.

::

    python benchmarks/bench_bag_recovery.py                       # record, then cut
    python benchmarks/bench_bag_recovery.py --bag runs/x/bag --cuts 0.1 0.5 0.9
"""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

from swarm_common.cli import EXIT_SUCCESS, EXIT_UNFINISHED, ToolParser, run_tool
from swarm_common.errors import UsageError
from swarm_runtime.bag.testing import message_record_ends

DEFAULT_CUTS = (0.1, 0.25, 0.5, 0.75, 0.9, 0.99)


def record_mission(out: Path) -> Path:
    """Run the OA-Bug spawner with recording; return the bag directory."""
    bag = out / 'bag'
    command = [
        sys.executable,
        '-m',
        'swarm_experiments.spawn',
        '--site',
        'small',
        '--robots',
        '6',
        '--seed',
        '1',
        '--record',
        str(bag),
        '--out',
        str(out),
        '--no-plots',
        '--quiet',
    ]
    # Exit status 1: the budget ran out before every room was covered, a normal outcome
    # whose bag is complete; anything else is a failure.
    finished = subprocess.run(command, check=False, stdout=subprocess.DEVNULL)
    if finished.returncode not in (EXIT_SUCCESS, EXIT_UNFINISHED):
        raise subprocess.CalledProcessError(finished.returncode, command)
    return bag


def recovered_count(bag: Path) -> int:
    """Messages recovery reads from ``bag`` (the warnings it gives are not printed)."""
    from swarm_runtime.bag import read_messages

    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return sum(1 for _ in read_messages(bag, allow_truncated=True, raw=True))


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='bench_bag_recovery', description=__doc__.splitlines()[0])
    parser.add_argument('--bag', type=Path, help='bag to cut (default: record a mission)')
    parser.add_argument('--cuts', type=float, nargs='+', default=list(DEFAULT_CUTS))
    args = parser.parse_args(argv)
    if any(not 0.0 <= fraction <= 1.0 for fraction in args.cuts):
        raise UsageError(f'--cuts are fractions of the file in [0, 1], got {args.cuts}')
    print('command:', shlex.join([Path(sys.argv[0]).name, *argv]))

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        bag = args.bag if args.bag is not None else record_mission(work / 'mission')
        (mcap,) = sorted(bag.glob('*.mcap'))
        ends = message_record_ends(mcap)
        size = mcap.stat().st_size
        print(f'bag: {len(ends)} messages, {size} bytes')
        print(f'{"cut":>6} {"at byte":>10} {"recovered":>10} {"complete":>10} {"total":>7}  time')
        for fraction in args.cuts:
            cut = int(size * fraction)
            copy = work / f'cut_{fraction}'
            shutil.copytree(bag, copy)
            copied = copy / mcap.name
            copied.write_bytes(mcap.read_bytes()[:cut])
            complete = sum(1 for end in ends if end <= cut)
            start = time.perf_counter()
            recovered = recovered_count(copy)
            elapsed = time.perf_counter() - start
            print(
                f'{fraction:>6.0%} {cut:>10} {recovered:>10} {complete:>10} {len(ends):>7}'
                f'  {elapsed:.2f} s'
            )
            shutil.rmtree(copy)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; exit codes as every tool's (docs/conventions.md)."""
    return run_tool('bench_bag_recovery', _main, argv)


if __name__ == '__main__':
    sys.exit(main())
