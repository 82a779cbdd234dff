"""Scan latency over real DDS: sim bridge publish -> subscriber callback, in two processes.

The sim bridge (its real node, ``sim_bridge.bridge_node.SimBridgeNode``) runs in one process
and a subscriber node in another, both on real rclpy (the installed RMW, Fast DDS by default)
in a domain of their own with discovery kept on this host, as the tests run
(``swarm_runtime.dds_isolation``). The subscriber takes every ``/r<i>/scan`` with the OA-Bug
node's QoS (``qos_profile_sensor_data``).

What is measured: for every scan, the wall time from just before the bridge's ``publish()``
call (so serialization counts) to the start of the subscriber's callback. Both processes read
``time.monotonic_ns()``, one clock for the whole machine on Linux, so the times compare
directly; a scan is matched across the processes by its topic and header stamp (the bridge's
sim time, unique per robot and step), which is the sequence id. The bridge paces its physics
on wall time (``real_time_factor`` = ``--time-scale`` sim seconds per wall second), so the
scan rate is 5.5 Hz x robots x time scale.

Usage::

    python benchmarks/bench_dds_latency.py                       # 1 and 10 robots
    python benchmarks/bench_dds_latency.py --robots 1 10 --messages 1000 --time-scale 4

Needs real rclpy (``make bootstrap`` installs it where wheels exist); exits 2 without it.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROLE_BRIDGE = 'bridge'
ROLE_LISTENER = 'listener'
# Scans sent in the first second after the match are left out (warm-up).
WARMUP_S = 1.0
MATCH_TIMEOUT_S = 60.0
# The listener keeps taking scans this long after the bridge has stopped.
DRAIN_S = 1.0


def _bridge(robots: int, time_scale: float, out: Path, run_s: float) -> int:
    """Run the sim bridge for ``run_s`` wall seconds; write topic, stamp and send time."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sim_bridge.bridge_node import SimBridgeNode
    from swarm_sim.departure import place_starts
    from swarm_sim.site_loading import load_site

    site = load_site('small', seed=0)
    poses = place_starts(site, 'center', robots, seed=0).poses
    rclpy.init(args=[])
    bridge = SimBridgeNode(
        site=site,
        initial_poses=poses,
        parameter_overrides=[Parameter('real_time_factor', value=float(time_scale))],
    )
    sent: list[tuple[str, int, int]] = []
    # The bridge's scan publishers, wrapped to note the send time (the bridge offers no hook).
    bridge._scan_pubs = [_TimedPublisher(p, sent) for p in bridge._scan_pubs]
    executor = SingleThreadedExecutor()
    executor.add_node(bridge)
    try:
        # The measured run starts once discovery has matched every scan with the listener.
        deadline = time.monotonic() + MATCH_TIMEOUT_S
        while min(p.get_subscription_count() for p in bridge._scan_pubs) < 1:
            if time.monotonic() > deadline:
                print('bench_dds_latency: the listener never matched', file=sys.stderr)
                return 1
            executor.spin_once(timeout_sec=0.05)
        end = time.monotonic() + run_s
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.remove_node(bridge)
        bridge.destroy_node()
        rclpy.try_shutdown()
    out.write_text(json.dumps(sent))
    return 0


class _TimedPublisher:
    """Forwards to a publisher and notes (topic, stamp [ns], monotonic ns before publish)."""

    def __init__(self, publisher: Any, sent: list[tuple[str, int, int]]) -> None:
        self._publisher = publisher
        self._sent = sent

    def get_subscription_count(self) -> int:
        return int(self._publisher.get_subscription_count())

    def publish(self, msg: Any) -> None:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self._sent.append((self._publisher.topic_name, stamp, time.monotonic_ns()))
        self._publisher.publish(msg)


def _listener(robots: int, out: Path, stop_file: Path) -> int:
    """Subscribe every robot's scan until ``stop_file`` exists; write the receive times."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan

    rclpy.init(args=[])
    node = Node('scan_listener')
    received: list[tuple[str, int, int]] = []

    def callback_for(topic: str) -> Any:
        def on_scan(msg: Any) -> None:
            now = time.monotonic_ns()
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            received.append((topic, stamp, now))

        return on_scan

    for i in range(robots):
        topic = f'/r{i}/scan'
        node.create_subscription(LaserScan, topic, callback_for(topic), qos_profile_sensor_data)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        while not stop_file.exists():
            executor.spin_once(timeout_sec=0.05)
    finally:
        executor.remove_node(node)
        node.destroy_node()
        rclpy.try_shutdown()
    out.write_text(json.dumps(received))
    return 0


def _measure(robots: int, messages: int, time_scale: float, workdir: Path) -> dict[str, Any]:
    """Start both processes, wait for them, match the scans; the figures of one run."""
    import numpy as np
    from swarm_runtime.dds_isolation import dds_test_environment, reserve_test_domain

    scans_per_s = 5.5 * robots * time_scale
    run_s = WARMUP_S + messages / scans_per_s * 1.1 + 1.0
    reservation = reserve_test_domain()
    env = {**os.environ, **dds_test_environment(reservation.domain_id)}
    sent_file = workdir / f'sent_{robots}.json'
    received_file = workdir / f'received_{robots}.json'
    stop_file = workdir / f'stop_{robots}'
    script = str(Path(__file__).resolve())
    common = ['--robots', str(robots), '--run-s', f'{run_s:.3f}']
    try:
        listener = subprocess.Popen(
            [
                sys.executable,
                script,
                '--role',
                ROLE_LISTENER,
                '--out',
                str(received_file),
                '--stop-file',
                str(stop_file),
                *common,
            ],
            env=env,
        )
        bridge = subprocess.Popen(
            [
                sys.executable,
                script,
                '--role',
                ROLE_BRIDGE,
                '--out',
                str(sent_file),
                '--time-scale',
                str(time_scale),
                *common,
            ],
            env=env,
        )
        bridge_code = bridge.wait()
        time.sleep(DRAIN_S)
        stop_file.touch()
        codes = (bridge_code, listener.wait())
    finally:
        reservation.release()
    if any(codes):
        msg = f'a benchmark process failed (bridge exit {codes[0]}, listener exit {codes[1]})'
        raise RuntimeError(msg)
    sent = {(t, s): ns for t, s, ns in json.loads(sent_file.read_text())}
    received = json.loads(received_file.read_text())
    first_ns = min(sent.values()) if sent else 0
    latencies = [
        (ns - sent[(t, s)]) / 1e6
        for t, s, ns in received
        if (t, s) in sent and sent[(t, s)] - first_ns >= WARMUP_S * 1e9
    ]
    after_warmup = sum(1 for ns in sent.values() if ns - first_ns >= WARMUP_S * 1e9)
    lat = np.array(latencies)
    return {
        'robots': robots,
        'time_scale': time_scale,
        'scans_sent': after_warmup,
        'scans_matched': len(lat),
        'lost': after_warmup - len(lat),
        'median_ms': float(np.median(lat)) if len(lat) else float('nan'),
        'p99_ms': float(np.percentile(lat, 99)) if len(lat) else float('nan'),
        'max_ms': float(lat.max()) if len(lat) else float('nan'),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--robots', type=int, nargs='+', default=[1, 10])
    parser.add_argument('--messages', type=int, default=1000, help='scans to measure per run')
    parser.add_argument('--time-scale', type=float, default=4.0, help='sim seconds per wall second')
    parser.add_argument('--role', choices=(ROLE_BRIDGE, ROLE_LISTENER), help=argparse.SUPPRESS)
    parser.add_argument('--out', type=Path, help=argparse.SUPPRESS)
    parser.add_argument('--run-s', type=float, help=argparse.SUPPRESS)
    parser.add_argument('--stop-file', type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.role == ROLE_BRIDGE:
        return _bridge(args.robots[0], args.time_scale, args.out, args.run_s)
    if args.role == ROLE_LISTENER:
        return _listener(args.robots[0], args.out, args.stop_file)
    try:
        import rclpy  # noqa: F401
    except ImportError:
        print('bench_dds_latency: needs real rclpy (make bootstrap installs it)', file=sys.stderr)
        return 2
    rmw = os.environ.get('RMW_IMPLEMENTATION', 'rmw_fastrtps_cpp (default)')
    print(f'scan latency, bridge publish -> subscriber callback, two processes, {rmw}')
    print('| robots | time scale | scans | lost | median [ms] | p99 [ms] | max [ms] |')
    print('|---|---|---|---|---|---|---|')
    with tempfile.TemporaryDirectory() as tmp:
        for robots in args.robots:
            r = _measure(robots, args.messages, args.time_scale, Path(tmp))
            print(
                f'| {r["robots"]} | {r["time_scale"]:g} | {r["scans_matched"]} | {r["lost"]} '
                f'| {r["median_ms"]:.2f} | {r["p99_ms"]:.2f} | {r["max_ms"]:.2f} |',
                flush=True,
            )
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
