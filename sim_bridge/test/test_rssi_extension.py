"""RSSI extension: what it publishes to the robots and to /sim/targets."""

import math

import numpy as np
from sim_bridge.extensions import RobotStates, SimExtension
from sim_bridge.rssi_extension import RssiExtension
from swarm_sim.rssi_targets import RssiTargetConfig, RssiTargetField


class RecordingPublisher:
    def __init__(self, topic):
        self.topic = topic
        self.messages = []

    def publish(self, msg):
        self.messages.append(msg)


class FakeNode:
    def __init__(self):
        self.publishers = {}

    def create_publisher(self, msg_type, topic, qos):
        pub = RecordingPublisher(topic)
        self.publishers[topic] = pub
        return pub


def make_extension(positions):
    field = RssiTargetField(
        RssiTargetConfig(n_targets=len(positions)), np.array(positions, dtype=float)
    )
    ext = RssiExtension(field, seed=3)
    node = FakeNode()
    ext.attach(node, ('r0', 'r1'))
    return ext, node


def states(poses, speeds):
    return RobotStates(
        ('r0', 'r1'),
        np.array(poses, dtype=float),
        np.column_stack([speeds, np.zeros(len(speeds))]),
    )


def test_extension_satisfies_the_protocol():
    ext, _ = make_extension([(100.0, 100.0)])
    assert isinstance(ext, SimExtension)


def test_rssi_is_published_once_per_period_with_only_detectable_targets():
    ext, node = make_extension([(100.0, 100.0), (1900.0, 1900.0)])
    poses = [[150.0, 100.0, 0.0], [1000.0, 1000.0, 0.0]]
    for k in range(1, 31):  # 3 s at 10 Hz
        ext.on_step(0.1 * k, states(poses, [1.0, 1.0]))
    r0 = node.publishers['/r0/rssi'].messages
    r1 = node.publishers['/r1/rssi'].messages
    assert [m.header.stamp.sec for m in r0] == [1, 2, 3]
    assert [[e.emitter_id for e in m.readings] for m in r0] == [[0], [0], [0]]
    assert all(len(m.readings) == 0 for m in r1)  # both targets > 1000 m away
    expected = 13.0 - 40.046 - 30.0 * math.log10(50.0)
    assert abs(r0[0].readings[0].rssi_dbm - expected) < 5.0


def test_still_robots_within_d_th_capture_and_are_told_so():
    ext, node = make_extension([(100.0, 100.0)])
    poses = [[102.0, 100.0, 0.0], [100.0, 104.0, 0.0]]
    done_at = None
    for k in range(1, 201):
        t = 0.1 * k
        ext.on_step(t, states(poses, [0.0, 0.0]))
        if ext.is_done() and done_at is None:
            done_at = t
    # Two robots at 5 load/s each: 100 load in 10 s (the first step has no elapsed time);
    # done is reported one step after the capture.
    assert done_at is not None
    assert abs(done_at - 10.2) < 1e-6
    for name in ('r0', 'r1'):
        notes = node.publishers[f'/{name}/captured'].messages
        assert [list(m.target_ids) for m in notes] == [[0]]
    truth = node.publishers['/sim/targets'].messages[-1]
    assert truth.all_captured
    assert truth.targets[0].captured
    assert abs(truth.capture_completion_time_s - 10.1) < 1e-9


def test_a_captured_target_is_no_longer_heard():
    ext, node = make_extension([(100.0, 100.0)])
    poses = [[102.0, 100.0, 0.0], [130.0, 100.0, 0.0]]
    for k in range(1, 251):
        ext.on_step(0.1 * k, states(poses, [0.0, 1.0]))
    r1 = node.publishers['/r1/rssi'].messages
    heard = [len(m.readings) for m in r1]
    assert heard[0] == 1
    assert heard[-1] == 0
