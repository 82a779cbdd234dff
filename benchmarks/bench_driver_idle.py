"""CPU time and log volume of the driver nodes when none of their devices is attached.

Each driver runs alone as its own process, as on a robot whose sensor is unplugged (the
default device paths, which do not exist on a development machine; the AoA receiver listens
on a free port with no locator connecting). After a warm-up (imports, DDS discovery) the
bench reads the process's user + system CPU time from /proc over a window of ``--seconds``
and counts the log lines it wrote in that window.

    python benchmarks/bench_driver_idle.py [--runtime rclpy|builtin|both] [--seconds 10]
        [--warmup 4] [--drivers rplidar_node mpu6050_node ...] [--output table.md]

``--runtime rclpy`` needs the rclpy wheels (gas and AoA also need the generated
swarm_interfaces messages; without them those nodes fail at import and are reported so).
``--runtime builtin`` opts in to the built-in runtime with ``SWARM_RUNTIME=builtin``.
Runs the drivers one after the other so that they do not compete for the cores.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

DRIVERS: dict[str, tuple[str, tuple[str, ...]]] = {
    'rplidar_node': ('hw_drivers.rplidar_node', ()),
    'gas_adc_node': ('hw_drivers.gas_node', ()),
    'mpu6050_node': ('hw_drivers.mpu6050_node', ()),
    'aoa_receiver_node': ('hw_drivers.aoa_receiver_node', ('listen_port:=0',)),
    'pump_node': ('hw_drivers.pump_node', ()),
}
CLOCK_TICKS = os.sysconf('SC_CLK_TCK')


@dataclass(frozen=True)
class IdleRow:
    """One driver on one runtime."""

    driver: str
    runtime: str
    window_s: float
    cpu_s: float | None
    log_lines: int
    note: str

    @property
    def core_percent(self) -> float | None:
        """CPU time over the window as a percentage of one core."""
        return None if self.cpu_s is None else 100.0 * self.cpu_s / self.window_s


def process_cpu_s(pid: int) -> float | None:
    """User + system CPU time of a live process [s] from /proc/<pid>/stat, None if gone."""
    try:
        text = Path(f'/proc/{pid}/stat').read_text()
    except OSError:
        return None
    fields = text[text.rindex(')') + 2 :].split()
    # Fields after the command name start at field 3 (state); utime and stime are 14 and 15.
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def _count_lines(path: Path) -> int:
    return path.read_bytes().count(b'\n')


def measure(
    driver: str, runtime: str, *, seconds: float, warmup_s: float, domain_id: int
) -> IdleRow:
    """Run one driver without its device and measure it."""
    module, extra = DRIVERS[driver]
    env = {
        **os.environ,
        'SWARM_RUNTIME': runtime,
        'ROS_DOMAIN_ID': str(domain_id),
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    }
    args = [sys.executable, '-m', module, '--ros-args', '-r', '__ns:=/idle']
    for param in extra:
        args += ['-p', param]
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / 'log'
        with log.open('wb') as sink:
            process = subprocess.Popen(
                args, stdout=sink, stderr=subprocess.STDOUT, env=env, start_new_session=True
            )
            try:
                time.sleep(warmup_s)
                cpu0 = process_cpu_s(process.pid)
                lines0 = _count_lines(log)
                time.sleep(seconds)
                cpu1 = process_cpu_s(process.pid)
                lines1 = _count_lines(log)
            finally:
                if process.poll() is None:
                    os.killpg(process.pid, signal.SIGINT)
                    try:
                        process.wait(10.0)
                    except subprocess.TimeoutExpired:
                        os.killpg(process.pid, signal.SIGKILL)
                        process.wait()
        if cpu0 is None or cpu1 is None or process.returncode not in (None, 0, -2):
            tail = log.read_text(errors='replace').strip().splitlines()[-1:] or ['']
            code = process.returncode
            return IdleRow(driver, runtime, seconds, None, 0, f'exited {code}: {tail[0][:90]}')
        return IdleRow(driver, runtime, seconds, cpu1 - cpu0, lines1 - lines0, '')


def format_table(rows: list[IdleRow]) -> str:
    """Markdown table of the rows."""
    lines = [
        '| driver | runtime | window [s] | CPU [s] | % of a core | log lines | note |',
        '|---|---|---:|---:|---:|---:|---|',
    ]
    for r in rows:
        cpu = '' if r.cpu_s is None else f'{r.cpu_s:.2f}'
        pct = '' if r.core_percent is None else f'{r.core_percent:.1f}'
        lines.append(
            f'| {r.driver} | {r.runtime} | {r.window_s:.0f} | {cpu} | {pct} | {r.log_lines}'
            f' | {r.note} |'
        )
    return '\n'.join(lines)


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runtime', choices=('rclpy', 'builtin', 'both'), default='both')
    parser.add_argument('--seconds', type=float, default=10.0)
    parser.add_argument('--warmup', type=float, default=4.0)
    parser.add_argument('--drivers', nargs='*', default=list(DRIVERS), choices=list(DRIVERS))
    parser.add_argument('--output', default='', help='also write the table to this file')
    args = parser.parse_args()
    runtimes = ('rclpy', 'builtin') if args.runtime == 'both' else (args.runtime,)
    rows = []
    domain_id = 150 + os.getpid() % 50
    for runtime in runtimes:
        for driver in args.drivers:
            rows.append(
                measure(
                    driver, runtime, seconds=args.seconds, warmup_s=args.warmup, domain_id=domain_id
                )
            )
            print(format_table(rows[-1:]).splitlines()[-1], flush=True)
    table = format_table(rows)
    print(table)
    if args.output:
        Path(args.output).write_text(table + '\n', encoding='utf-8')


if __name__ == '__main__':
    main()
