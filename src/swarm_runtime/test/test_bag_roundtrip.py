"""Bags written by BagWriter read back identically, also with rosbags' and Foxglove's readers."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
import yaml
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability
from rosbags.interfaces import QosTime as Time
from swarm_runtime.bag import BagWriteError, BagWriter, read_bag_info, read_messages
from swarm_runtime.messages import get_message_module, get_typestore, serialize_cdr
from swarm_runtime.ros import using_real_rclpy

SENSOR_QOS = Qos(
    history=QosHistory.KEEP_LAST,
    depth=5,
    reliability=QosReliability.BEST_EFFORT,
    durability=QosDurability.VOLATILE,
    deadline=Time(sec=2147483647, nsec=4294967295),
    lifespan=Time(sec=2147483647, nsec=4294967295),
    liveliness=QosLiveliness.AUTOMATIC,
    liveliness_lease_duration=Time(sec=2147483647, nsec=4294967295),
    avoid_ros_namespace_conventions=False,
)


def _messages() -> list[tuple[str, int, object]]:
    """(topic, log time [ns], message) of a short two-robot recording."""
    sensor_msgs = get_message_module('sensor_msgs')
    swarm = get_message_module('swarm_interfaces')
    std_msgs = get_message_module('std_msgs')
    recorded: list[tuple[str, int, object]] = []
    for step in range(4):
        stamp_ns = 1_000_000_000 + step * 100_000_000
        recorded.append(
            (
                '/r0/scan',
                stamp_ns,
                sensor_msgs.LaserScan(
                    header=std_msgs.Header(frame_id='r0/laser'),
                    angle_increment=0.5,
                    ranges=[1.0 + step, 2.5, float('inf')],
                ),
            )
        )
        recorded.append(
            ('/r1/gas', stamp_ns + 1, swarm.GasReading(raw=100 + step, volts=0.25 * step))
        )
        bearing = swarm.PeerBearing(tag_id='R0', azimuth=0.5, quality=swarm.PeerBearing.QUALITY_OK)
        recorded.append(('/r1/bearings', stamp_ns + 2, swarm.PeerBearingArray(bearings=[bearing])))
    return recorded


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    """A bag holding :func:`_messages`, the scan topic with the sensor-data QoS."""
    path = tmp_path / 'run'
    with BagWriter(path) as writer:
        writer.add_topic('/r0/scan', 'sensor_msgs/msg/LaserScan', offered_qos_profiles=[SENSOR_QOS])
        for topic, log_time, message in _messages():
            writer.write_message(topic, log_time, message)
    return path


def test_bag_directory_has_metadata_and_one_mcap(bag: Path) -> None:
    assert sorted(p.name for p in bag.iterdir()) == ['metadata.yaml', 'run.mcap']
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['version'] == 9
    assert info['storage_identifier'] == 'mcap'
    assert info['relative_file_paths'] == ['run.mcap']
    assert info['message_count'] == 12


def test_metadata_records_offered_qos_and_type_hash(bag: Path) -> None:
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    scan = topics['/r0/scan']['topic_metadata']
    assert scan['serialization_format'] == 'cdr'
    assert scan['type_description_hash'] == get_typestore().hash_rihs01('sensor_msgs/msg/LaserScan')
    assert scan['type_description_hash'].startswith('RIHS01_')
    (profile,) = scan['offered_qos_profiles']
    assert profile['reliability'] == 'best_effort'
    assert profile['history'] == 'keep_last'
    assert profile['depth'] == 5
    gas = topics['/r1/gas']['topic_metadata']
    assert gas['type'] == 'swarm_interfaces/msg/GasReading'
    assert gas['type_description_hash'] == get_typestore().hash_rihs01(
        'swarm_interfaces/msg/GasReading'
    )


def test_read_messages_returns_what_was_written(bag: Path) -> None:
    read = [(m.topic, m.log_time_ns, m.message) for m in read_messages(bag)]
    assert read == _messages()


def test_read_bag_info_summarizes_topics(bag: Path) -> None:
    info = read_bag_info(bag)
    assert info.message_count == 12
    assert info.start_time_ns == 1_000_000_000
    assert info.end_time_ns == 1_300_000_002
    assert info.topics['/r1/gas'].message_count == 4
    assert info.topics['/r0/scan'].offered_qos_profiles == (SENSOR_QOS,)
    assert info.topics['/r1/bearings'].typename == 'swarm_interfaces/msg/PeerBearingArray'


def test_topics_filter_by_name_and_glob(bag: Path) -> None:
    assert {m.topic for m in read_messages(bag, topics=['/r1/gas'])} == {'/r1/gas'}
    assert {m.topic for m in read_messages(bag, topics=['/r1/*'])} == {'/r1/gas', '/r1/bearings'}
    assert list(read_messages(bag, topics=['/nothing'])) == []


def test_raw_reading_returns_the_cdr_bytes(bag: Path) -> None:
    first = next(read_messages(bag, raw=True))
    assert first.message == serialize_cdr(_messages()[0][2])


def test_messages_come_in_log_time_order_whatever_the_write_order(tmp_path: Path) -> None:
    std_msgs = get_message_module('std_msgs')
    with BagWriter(tmp_path / 'shuffled') as writer:
        for log_time in (30, 10, 40, 20):
            writer.write_message('/a', log_time, std_msgs.Int32(data=log_time))
        writer.flush()
        for log_time in (15, 35, 5):
            writer.write_message('/b', log_time, std_msgs.Int32(data=log_time))
    times = [m.log_time_ns for m in read_messages(tmp_path / 'shuffled')]
    assert times == sorted(times) == [5, 10, 15, 20, 30, 35, 40]
    assert [m.message.data for m in read_messages(tmp_path / 'shuffled')] == times


def test_rosbags_anyreader_decodes_our_bag(bag: Path) -> None:
    with AnyReader([bag], default_typestore=get_typestore()) as reader:
        decoded = [
            (c.topic, t, reader.deserialize(data, c.msgtype))
            for c, t, data in reader.messages(reader.connections)
        ]
    expected = _messages()
    assert [(topic, t) for topic, t, _ in decoded] == [(topic, t) for topic, t, _ in expected]
    scan = decoded[0][2]
    assert scan.header.frame_id == 'r0/laser'
    assert list(scan.ranges) == [1.0, 2.5, float('inf')]
    assert decoded[1][2].raw == 100
    assert decoded[2][2].bearings[0].tag_id == 'R0'


def test_mcap_ros2_decoder_reads_our_mcap(bag: Path) -> None:
    with warnings.catch_warnings():
        # mcap_ros2.reader warns about its ROS 1 sibling when imported.
        warnings.simplefilter('ignore', DeprecationWarning)
        from mcap_ros2.reader import read_ros2_messages

    decoded = list(read_ros2_messages(bag / 'run.mcap'))
    assert [m.channel.topic for m in decoded] == [topic for topic, _, _ in _messages()]
    assert [m.log_time_ns for m in decoded] == [t for _, t, _ in _messages()]
    assert decoded[0].schema.name == 'sensor_msgs/msg/LaserScan'
    assert list(decoded[0].ros_msg.ranges) == [1.0, 2.5, float('inf')]
    assert decoded[1].ros_msg.raw == 100
    assert decoded[1].ros_msg.volts == 0.0
    assert decoded[5].ros_msg.bearings[0].azimuth == 0.5


def test_writer_refuses_to_overwrite_and_to_change_a_topic_type(tmp_path: Path) -> None:
    (tmp_path / 'exists').mkdir()
    with pytest.raises(BagWriteError, match='exists already'):
        BagWriter(tmp_path / 'exists')
    with BagWriter(tmp_path / 'new') as writer:
        writer.add_topic('/x', 'std_msgs/msg/Int32')
        with pytest.raises(BagWriteError, match="'/x' is recorded as std_msgs/msg/Int32"):
            writer.add_topic('/x', 'std_msgs/msg/String')
        with pytest.raises(BagWriteError, match='unknown'):
            writer.add_topic('/y', 'nowhere_msgs/msg/Nothing')
        with pytest.raises(BagWriteError, match='was not added'):
            writer.write('/z', 1, b'')


def _record_then_crash(path: Path) -> None:
    std_msgs = get_message_module('std_msgs')
    with BagWriter(path) as writer:
        writer.write_message('/x', 1, std_msgs.Int32(data=7))
        raise RuntimeError('recording crashed')


def test_error_inside_the_with_block_still_closes_the_bag(tmp_path: Path) -> None:
    with pytest.raises(RuntimeError, match='recording crashed'):
        _record_then_crash(tmp_path / 'b')
    assert (tmp_path / 'b' / 'metadata.yaml').is_file()
    assert [m.message.data for m in read_messages(tmp_path / 'b')] == [7]


def test_chunks_carry_crcs_and_channels_the_type_hash(bag: Path) -> None:
    from mcap.records import Channel, Chunk
    from mcap.stream_reader import StreamReader

    with (bag / 'run.mcap').open('rb') as stream:
        records = list(StreamReader(stream, emit_chunks=True).records)
        stream.seek(0)
        records += list(StreamReader(stream).records)  # the records inside the chunks
    chunks = [r for r in records if isinstance(r, Chunk)]
    assert chunks
    assert all(chunk.uncompressed_crc != 0 for chunk in chunks)
    channels = {r.topic: r for r in records if isinstance(r, Channel)}
    assert channels['/r1/gas'].metadata['topic_type_hash'] == get_typestore().hash_rihs01(
        'swarm_interfaces/msg/GasReading'
    )
    assert 'best_effort' in channels['/r0/scan'].metadata['offered_qos_profiles']


def test_a_type_given_by_its_definition_is_written_and_read_back(tmp_path: Path) -> None:
    with BagWriter(tmp_path / 'custom') as writer:
        writer.add_topic(
            '/status', 'robot_msgs/msg/Status', definition='uint8 battery_percent\nstring mode\n'
        )
        writer.write('/status', 5, b'\x00\x01\x00\x00\x5a\x00\x00\x00\x04\x00\x00\x00abc\x00')
        digest = writer.type_hash('/status')
    assert digest.startswith('RIHS01_')
    (message,) = read_messages(tmp_path / 'custom')
    assert message.message.battery_percent == 90
    assert message.message.mode == 'abc'
    assert read_bag_info(tmp_path / 'custom').topics['/status'].type_hash == digest


@pytest.mark.skipif(
    not using_real_rclpy(), reason='real rclpy message classes exist with SWARM_RUNTIME=rclpy'
)
def test_real_rclpy_messages_are_written_like_generated_ones(tmp_path: Path) -> None:
    import sensor_msgs.msg

    scan = sensor_msgs.msg.LaserScan(angle_increment=0.5, ranges=[1.0, 2.5])
    scan.header.frame_id = 'r0/laser'
    with BagWriter(tmp_path / 'real') as writer:
        writer.write_message('/r0/scan', 1, scan)
    (message,) = read_messages(tmp_path / 'real')
    assert message.typename == 'sensor_msgs/msg/LaserScan'
    assert list(message.message.ranges) == [1.0, 2.5]
    assert message.message.header.frame_id == 'r0/laser'


def test_a_bag_from_rosbags_own_writer_reads_without_chunk_crcs(tmp_path: Path) -> None:
    """rosbags' MCAP writer stores CRC 0 ("none"): such bags read, checked by CDR alone."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    std_msgs = get_message_module('std_msgs')
    with Writer(tmp_path / 'plain', version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection('/n', 'std_msgs/msg/Int32', typestore=get_typestore())
        for value in range(3):
            writer.write(connection, value, serialize_cdr(std_msgs.Int32(data=value)))
    assert [m.message.data for m in read_messages(tmp_path / 'plain')] == [0, 1, 2]
