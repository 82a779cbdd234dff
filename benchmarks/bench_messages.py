"""Cost of the generated message classes: construction, CDR serialization and round trip.

Measures, for the messages the simulation publishes most (LaserScan with 360 ranges, Imu,
GasReading), the time to construct one message, to serialize it to CDR, to decode it, and
the full round trip a subscriber in another process sees (``cdr_roundtrip``), with field
checks on and off. Each figure is the best of ``--repeat`` timing runs of ``--number`` calls,
in microseconds per call, in one process. Example::

    python benchmarks/bench_messages.py --number 5000 --repeat 5
"""

from __future__ import annotations

import os
import subprocess
import sys
import timeit
from collections.abc import Callable
from typing import Any

import numpy as np
from swarm_common.cli import ToolParser, run_tool
from swarm_common.errors import UsageError


def _cases() -> dict[str, Callable[[], Any]]:
    from swarm_runtime.messages import get_message_module

    sensor_msgs = get_message_module('sensor_msgs')
    std_msgs = get_message_module('std_msgs')
    geometry_msgs = get_message_module('geometry_msgs')
    builtin_interfaces = get_message_module('builtin_interfaces')
    swarm = get_message_module('swarm_interfaces')
    ranges_list = [0.5 + 0.01 * i for i in range(360)]
    ranges_array = np.asarray(ranges_list, dtype=np.float32)

    def header(frame: str) -> Any:
        return std_msgs.Header(stamp=builtin_interfaces.Time(sec=12, nanosec=500), frame_id=frame)

    def scan(ranges: Any) -> Any:
        return sensor_msgs.LaserScan(
            header=header('r0/laser'),
            angle_min=-3.14159,
            angle_max=3.14159,
            angle_increment=0.0174533,
            scan_time=0.1,
            range_min=0.15,
            range_max=12.0,
            ranges=ranges,
        )

    return {
        'LaserScan, 360 ranges from a list': lambda: scan(ranges_list),
        'LaserScan, 360 ranges from float32 ndarray': lambda: scan(ranges_array),
        'Imu': lambda: sensor_msgs.Imu(
            header=header('r0/imu'),
            orientation=geometry_msgs.Quaternion(z=0.0998, w=0.995),
            angular_velocity=geometry_msgs.Vector3(z=0.2),
        ),
        'GasReading': lambda: swarm.GasReading(header=header('r0/gas'), raw=312, volts=1.52),
    }


def _best_us(function: Callable[[], Any], number: int, repeat: int) -> float:
    return min(timeit.repeat(function, number=number, repeat=repeat)) / number * 1e6


def measure(number: int, repeat: int) -> list[tuple[str, float, float, float, float]]:
    """(case, construct, serialize, deserialize, round trip) in microseconds per call."""
    from swarm_runtime.messages import (
        cdr_roundtrip,
        deserialize_cdr,
        message_typename,
        serialize_cdr,
    )

    rows = []
    for name, build in _cases().items():
        message = build()
        typename = message_typename(message)
        data = serialize_cdr(message)
        rows.append(
            (
                name,
                _best_us(build, number, repeat),
                _best_us(lambda message=message: serialize_cdr(message), number, repeat),
                _best_us(
                    lambda data=data, typename=typename: deserialize_cdr(data, typename),
                    number,
                    repeat,
                ),
                _best_us(lambda message=message: cdr_roundtrip(message), number, repeat),
            )
        )
    return rows


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='bench_messages', description=__doc__.split('\n', 1)[0])
    parser.add_argument('--number', type=int, default=5000, help='calls per timing run')
    parser.add_argument('--repeat', type=int, default=5, help='timing runs (best is kept)')
    parser.add_argument('--checks', choices=('both', 'on', 'off'), default='both')
    args = parser.parse_args(argv)
    if args.number < 1 or args.repeat < 1:
        raise UsageError('--number and --repeat must be >= 1')
    if args.checks == 'both':
        # ROS_PYTHON_CHECK_FIELDS is read once per process (as rclpy does): one child per setting.
        for setting in ('on', 'off'):
            subprocess.run(
                [
                    sys.executable,
                    __file__,
                    '--number',
                    str(args.number),
                    '--repeat',
                    str(args.repeat),
                    '--checks',
                    setting,
                ],
                check=True,
                env={**os.environ, 'ROS_PYTHON_CHECK_FIELDS': '1' if setting == 'on' else '0'},
            )
        return 0
    setting = os.environ.get('ROS_PYTHON_CHECK_FIELDS', '')
    print(f'field checks {args.checks} (ROS_PYTHON_CHECK_FIELDS={setting})')
    columns = ('construct', 'serialize', 'decode', 'roundtrip')
    print(f'{"message":44s} ' + ' '.join(f'{c:>10s}' for c in columns) + '  [us per call]')
    for name, *figures in measure(args.number, args.repeat):
        print(f'{name:44s} ' + ' '.join(f'{value:10.2f}' for value in figures))
    return 0


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; exit codes as every tool's (docs/conventions.md)."""
    return run_tool('bench_messages', _main, argv)


if __name__ == '__main__':
    sys.exit(main())
