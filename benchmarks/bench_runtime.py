"""Real-time factor of the built-in runtime under a swarm's sensor traffic.

Each simulated robot has a sensor node publishing the contract's streams at realistic rates
(``scan`` 10 Hz with 360 ranges, ``imu`` 50 Hz, ``gas``/``bearings``/``rssi`` 5 Hz,
``cmd_vel`` 10 Hz) on sim-time timers, and a subscriber node taking all of them; a clock node
publishes ``/clock`` at 100 Hz from a wall timer, as the sim bridge does. The real-time
factor is simulated seconds per real second of spinning (setup excluded).

The goal (the foundation issue): at least 100x real time without the CDR round trip and 50x
with it. On a machine shared with other work the wall-clock factor depends on the load, so the
factor per CPU second of the benchmark process is the primary figure; both are printed, with
the command line that produced them.

Field checks (``ROS_PYTHON_CHECK_FIELDS``) are fixed when message classes are generated, so
each configuration runs in its own process, one after the other::

    python benchmarks/bench_runtime.py                    # the four configurations, best of 3
    python benchmarks/bench_runtime.py --configs current  # this process's environment only
    python benchmarks/bench_runtime.py --configs current --profile runtime.prof
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import json
import math
import os
import pstats
import shlex
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from typing import Any

from swarm_common.cli import ToolParser, run_tool
from swarm_common.errors import UsageError

#: Real-time factor goals (per CPU second) without and with the CDR round trip.
GOAL_WITHOUT_CDR = 100.0
GOAL_WITH_CDR = 50.0

CONFIGURATIONS = (
    (
        'no CDR round trip, field checks off',
        {'SWARM_RUNTIME_CDR_ROUNDTRIP': '0', 'ROS_PYTHON_CHECK_FIELDS': '0'},
    ),
    (
        'no CDR round trip, field checks on',
        {'SWARM_RUNTIME_CDR_ROUNDTRIP': '0', 'ROS_PYTHON_CHECK_FIELDS': '1'},
    ),
    (
        'CDR round trip, field checks off',
        {'SWARM_RUNTIME_CDR_ROUNDTRIP': '1', 'ROS_PYTHON_CHECK_FIELDS': '0'},
    ),
    (
        'CDR round trip, field checks on',
        {'SWARM_RUNTIME_CDR_ROUNDTRIP': '1', 'ROS_PYTHON_CHECK_FIELDS': '1'},
    ),
)

#: Stream name -> publishing rate in Hz, per robot.
STREAM_RATES_HZ = {
    'scan': 10.0,
    'imu': 50.0,
    'gas': 5.0,
    'bearings': 5.0,
    'rssi': 5.0,
    'cmd_vel': 10.0,
}


@dataclass(frozen=True)
class BenchResult:
    """One benchmark run."""

    robots: int
    sim_seconds: float
    wall_seconds: float
    cpu_seconds: float
    messages_received: int
    prebuilt_messages: bool
    cdr_roundtrip: bool
    field_checks: bool

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per real (wall-clock) second."""
        return self.sim_seconds / self.wall_seconds

    @property
    def cpu_real_time_factor(self) -> float:
        """Simulated seconds per second of this process's CPU time (load-independent)."""
        return self.sim_seconds / self.cpu_seconds


def _build_nodes(
    context: Any, robots: int, clock_hz: float, prebuilt: bool
) -> tuple[list[Any], list[Any]]:
    """Create the clock node and, per robot, a sensor node and a subscriber node.

    With ``prebuilt``, each stream republishes one message built up front, which leaves
    only the runtime's own work (and the CDR round trip, if on) in the measurement.
    """
    from swarm_runtime.builtin.node import Node
    from swarm_runtime.builtin.parameter import Parameter
    from swarm_runtime.builtin.qos import qos_profile_sensor_data
    from swarm_runtime.messages import get_message_module

    sensor_msgs = get_message_module('sensor_msgs')
    std_msgs = get_message_module('std_msgs')
    geometry_msgs = get_message_module('geometry_msgs')
    rosgraph_msgs = get_message_module('rosgraph_msgs')
    builtin_interfaces = get_message_module('builtin_interfaces')
    swarm_interfaces = get_message_module('swarm_interfaces')
    sim_time = [Parameter('use_sim_time', value=True)]
    ranges = [2.0 + math.sin(i * math.pi / 180.0) for i in range(360)]

    class ClockNode(Node):
        def __init__(self) -> None:
            super().__init__('clock', context=context)
            self.step_ns = round(1e9 / clock_hz)
            self.sim_ns = 0
            self.pub = self.create_publisher(rosgraph_msgs.Clock, '/clock', 10)
            self.create_timer(1.0 / clock_hz, self.tick)

        def tick(self) -> None:
            self.sim_ns += self.step_ns
            sec, nanosec = divmod(self.sim_ns, 1_000_000_000)
            stamp = builtin_interfaces.Time(sec=sec, nanosec=nanosec)
            self.pub.publish(rosgraph_msgs.Clock(clock=stamp))

    class SensorNode(Node):
        """One robot's sensor streams; message construction is part of the measured work."""

        def __init__(self, index: int) -> None:
            super().__init__(
                'sensors', namespace=f'r{index}', context=context, parameter_overrides=sim_time
            )
            qos = qos_profile_sensor_data
            self.peers = [f'tag{peer}' for peer in range(robots) if peer != index]
            streams = {
                'scan': (sensor_msgs.LaserScan, qos, self.make_scan),
                'imu': (sensor_msgs.Imu, qos, self.make_imu),
                'gas': (swarm_interfaces.GasReading, qos, self.make_gas),
                'bearings': (swarm_interfaces.PeerBearingArray, qos, self.make_bearings),
                'rssi': (swarm_interfaces.RssiArray, qos, self.make_rssi),
                'cmd_vel': (geometry_msgs.Twist, 10, self.make_cmd_vel),
            }
            for stream, (msg_type, stream_qos, make) in streams.items():
                publisher = self.create_publisher(msg_type, stream, stream_qos)
                if prebuilt:
                    prebuilt_msg = make()
                    callback = functools.partial(publisher.publish, prebuilt_msg)
                else:
                    callback = functools.partial(self.publish_new, publisher, make)
                self.create_timer(1.0 / STREAM_RATES_HZ[stream], callback)

        @staticmethod
        def publish_new(publisher: Any, make: Any) -> None:
            publisher.publish(make())

        def header(self, frame_id: str) -> Any:
            return std_msgs.Header(stamp=self.get_clock().now().to_msg(), frame_id=frame_id)

        def make_scan(self) -> Any:
            return sensor_msgs.LaserScan(
                header=self.header('laser'),
                angle_min=-math.pi,
                angle_max=math.pi,
                angle_increment=math.pi / 180.0,
                range_min=0.15,
                range_max=12.0,
                ranges=ranges,
            )

        def make_imu(self) -> Any:
            msg = sensor_msgs.Imu(header=self.header('imu'))
            msg.orientation.z = 0.3826834323650898
            msg.orientation.w = 0.9238795325112867
            msg.angular_velocity.z = 0.1
            msg.linear_acceleration.z = 9.81
            return msg

        def make_gas(self) -> Any:
            return swarm_interfaces.GasReading(header=self.header('gas'), raw=512, volts=1.65)

        def make_bearings(self) -> Any:
            bearings = [
                swarm_interfaces.PeerBearing(tag_id=tag, azimuth=0.5, elevation=0.0, distance=2.0)
                for tag in self.peers
            ]
            return swarm_interfaces.PeerBearingArray(header=self.header('ble'), bearings=bearings)

        def make_rssi(self) -> Any:
            readings = [
                swarm_interfaces.EmitterRssi(emitter_id=emitter, rssi_dbm=-60.0)
                for emitter in range(3)
            ]
            return swarm_interfaces.RssiArray(header=self.header('ble'), readings=readings)

        def make_cmd_vel(self) -> Any:
            msg = geometry_msgs.Twist()
            msg.linear.x = 0.2
            msg.angular.z = 0.1
            return msg

    class SubscriberNode(Node):
        def __init__(self, index: int) -> None:
            super().__init__('consumer', namespace=f'r{index}', context=context)
            self.received = 0
            qos = qos_profile_sensor_data
            self.create_subscription(sensor_msgs.LaserScan, 'scan', self.count, qos)
            self.create_subscription(sensor_msgs.Imu, 'imu', self.count, qos)
            self.create_subscription(swarm_interfaces.GasReading, 'gas', self.count, qos)
            self.create_subscription(swarm_interfaces.PeerBearingArray, 'bearings', self.count, qos)
            self.create_subscription(swarm_interfaces.RssiArray, 'rssi', self.count, qos)
            self.create_subscription(geometry_msgs.Twist, 'cmd_vel', self.count, 10)

        def count(self, msg: Any) -> None:
            self.received += 1

    nodes: list[Any] = [ClockNode()]
    consumers = [SubscriberNode(index) for index in range(robots)]
    nodes.extend(SensorNode(index) for index in range(robots))
    nodes.extend(consumers)
    return nodes, consumers


def run(
    robots: int = 10,
    sim_seconds: float = 20.0,
    *,
    clock_hz: float = 100.0,
    prebuilt: bool = False,
    profile_path: str | None = None,
) -> BenchResult:
    """Run one configuration in this process (CDR and field checks from the environment)."""
    from swarm_runtime.builtin._messages import cdr_roundtrip_enabled
    from swarm_runtime.builtin.context import Context
    from swarm_runtime.builtin.executors import SingleThreadedExecutor
    from swarm_runtime.messages.registry import check_fields_from_environment
    from swarm_runtime.simulation import spin_until_time

    context = Context()
    context.init(['bench_runtime'], initialize_logging=False)
    try:
        nodes, consumers = _build_nodes(context, robots, clock_hz, prebuilt)
        executor = SingleThreadedExecutor(context=context)
        for node in nodes:
            executor.add_node(node)
        profiler = cProfile.Profile() if profile_path else None
        start_wall = time.perf_counter()
        start_cpu = time.process_time()
        if profiler is not None:
            profiler.enable()
        spin_until_time(executor, sim_seconds)
        if profiler is not None:
            profiler.disable()
        cpu_seconds = time.process_time() - start_cpu
        wall_seconds = time.perf_counter() - start_wall
        if profiler is not None and profile_path is not None:
            profiler.dump_stats(profile_path)
        return BenchResult(
            robots=robots,
            sim_seconds=sim_seconds,
            wall_seconds=wall_seconds,
            cpu_seconds=cpu_seconds,
            messages_received=sum(consumer.received for consumer in consumers),
            prebuilt_messages=prebuilt,
            cdr_roundtrip=cdr_roundtrip_enabled(),
            field_checks=check_fields_from_environment(),
        )
    finally:
        context.try_shutdown()


def _run_configuration(args: argparse.Namespace, env_overrides: dict[str, str]) -> dict[str, Any]:
    """Run one configuration in a fresh process (field checks are fixed at import)."""
    command = [
        sys.executable,
        __file__,
        '--configs',
        'current',
        '--robots',
        str(args.robots),
        '--sim-seconds',
        str(args.sim_seconds),
        '--clock-hz',
        str(args.clock_hz),
        '--json',
    ]
    if args.prebuilt:
        command.append('--prebuilt')
    env = {**os.environ, **env_overrides}
    completed = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    return json.loads(completed.stdout.strip().splitlines()[-1])


def _describe(result: dict[str, Any]) -> str:
    return (
        f'{result["real_time_factor"]:7.1f}x real time ({result["wall_seconds"]:.2f} s wall), '
        f'{result["cpu_real_time_factor"]:7.1f}x per CPU second ({result["cpu_seconds"]:.2f} s), '
        f'{result["messages_received"]} messages received'
    )


def _main(argv: list[str]) -> int:
    parser = ToolParser(prog='bench_runtime', description=__doc__.splitlines()[0])
    parser.add_argument('--robots', type=int, default=10)
    parser.add_argument('--sim-seconds', type=float, default=20.0)
    parser.add_argument('--clock-hz', type=float, default=100.0)
    parser.add_argument(
        '--configs',
        choices=('all', 'current'),
        default='all',
        help="'all': the four CDR/field-check configurations, each in its own process; "
        "'current': this process's environment",
    )
    parser.add_argument(
        '--prebuilt',
        action='store_true',
        help='republish messages built once (measures the runtime without message building)',
    )
    parser.add_argument(
        '--repeat',
        type=int,
        default=5,
        help='runs per configuration (with all); the fastest is reported, as with timeit',
    )
    parser.add_argument('--profile', metavar='PATH', help='write cProfile stats (with current)')
    parser.add_argument('--json', action='store_true', help='print the result as JSON')
    args = parser.parse_args(argv)
    if args.robots < 1 or not args.sim_seconds > 0.0 or not args.clock_hz > 0.0:
        raise UsageError('--robots must be >= 1, --sim-seconds and --clock-hz > 0')
    command = shlex.join(['python', 'benchmarks/bench_runtime.py', *argv])

    if args.configs == 'current':
        result = run(
            args.robots,
            args.sim_seconds,
            clock_hz=args.clock_hz,
            prebuilt=args.prebuilt,
            profile_path=args.profile,
        )
        summary = {
            **asdict(result),
            'real_time_factor': result.real_time_factor,
            'cpu_real_time_factor': result.cpu_real_time_factor,
        }
        if args.json:
            print(json.dumps(summary))
            return 0
        print(f'$ {command}')
        print(
            f'CDR round trip {"on" if result.cdr_roundtrip else "off"}, field checks '
            f'{"on" if result.field_checks else "off"}: {_describe(summary)}'
        )
        if args.profile:
            pstats.Stats(args.profile).sort_stats('tottime').print_stats(25)
        return 0

    print(f'$ {command}')
    print(
        f'{args.robots} robots, {args.sim_seconds:g} s of sim time, /clock at {args.clock_hz:g} Hz'
        + (', prebuilt messages' if args.prebuilt else '')
        + f'; best of {max(args.repeat, 1)} runs per configuration (by CPU factor)'
    )
    for label, env_overrides in CONFIGURATIONS:
        runs = [_run_configuration(args, env_overrides) for _ in range(max(args.repeat, 1))]
        best = max(runs, key=lambda result: result['cpu_real_time_factor'])
        goal = GOAL_WITH_CDR if best['cdr_roundtrip'] else GOAL_WITHOUT_CDR
        verdict = 'meets' if best['cpu_real_time_factor'] >= goal else 'misses'
        print(f'  {label:<37} {_describe(best)}; {verdict} the {goal:g}x goal')
    print(
        'The factor per CPU second is the primary figure: the wall-clock factor also counts '
        'the time other processes hold the CPU.'
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; prints the real-time factor of each configuration (exit codes
    as every tool's, docs/conventions.md)."""
    return run_tool('bench_runtime', _main, argv)


if __name__ == '__main__':
    sys.exit(main())
