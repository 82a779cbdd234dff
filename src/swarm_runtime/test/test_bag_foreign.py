"""Bags written by other MCAP writers, laid out like a robot's ``ros2 bag record -s mcap``.

The bag is written with Foxglove's mcap-ros2 writer (zstd-compressed chunks with CRCs, as
rosbag2's MCAP plugin can write) next to a rosbag2 metadata.yaml of the Jazzy layout.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from mcap.writer import CompressionType
from mcap_ros2.writer import Writer as McapRos2Writer
from swarm_runtime.bag import BagTypeError, TruncatedBagWarning, read_bag_info, read_messages
from swarm_runtime.messages import get_message_class, get_typestore

CUSTOM_STATUS = 'uint8 battery_percent\nstring mode\n'
# An older swarm_interfaces GasReading: same name, different fields.
OLD_GAS_READING = 'std_msgs/Header header\nuint16 raw\n'


def _definition(typename: str) -> str:
    """The ros2msg schema text rosbag2 stores: the type plus its dependencies."""
    text, _ = get_typestore().generate_msgdef(typename, ros_version=2)
    return text


def _header_definition() -> str:
    return _definition('std_msgs/msg/Header')


def _write_robot_bag(path: Path, compression: CompressionType) -> None:
    path.mkdir()
    storage = path / f'{path.name}_0.mcap'
    with storage.open('wb') as stream:
        writer = McapRos2Writer(stream, compression=compression, chunk_size=256)
        scan = writer.register_msgdef(
            'sensor_msgs/msg/LaserScan', _definition('sensor_msgs/msg/LaserScan')
        )
        status = writer.register_msgdef('robot_msgs/msg/Status', CUSTOM_STATUS)
        old_gas = writer.register_msgdef(
            'swarm_interfaces/msg/GasReading',
            OLD_GAS_READING + '\n' + '=' * 80 + '\nMSG: std_msgs/Header\n' + _header_definition(),
        )
        header = {'stamp': {'sec': 1, 'nanosec': 0}, 'frame_id': 'laser'}
        for step in range(3):
            log_time = 1_700_000_000_000_000_000 + step * 100_000_000
            writer.write_message(
                '/scan',
                scan,
                {
                    'header': header,
                    'angle_min': -1.0,
                    'angle_max': 1.0,
                    'angle_increment': 0.5,
                    'time_increment': 0.0,
                    'scan_time': 0.1,
                    'range_min': 0.1,
                    'range_max': 12.0,
                    'ranges': [1.0, 2.0, float(step)],
                    'intensities': [],
                },
                log_time=log_time,
            )
            writer.write_message(
                '/status', status, {'battery_percent': 90 - step, 'mode': 'explore'}, log_time + 1
            )
            writer.write_message(
                '/gas', old_gas, {'header': header, 'raw': 200 + step}, log_time + 2
            )
        writer.finish()
    topics = [
        (
            '/scan',
            'sensor_msgs/msg/LaserScan',
            get_typestore().hash_rihs01('sensor_msgs/msg/LaserScan'),
        ),
        ('/status', 'robot_msgs/msg/Status', ''),
        ('/gas', 'swarm_interfaces/msg/GasReading', ''),
    ]
    metadata = {
        'rosbag2_bagfile_information': {
            'version': 9,
            'storage_identifier': 'mcap',
            'duration': {'nanoseconds': 200_000_002},
            'starting_time': {'nanoseconds_since_epoch': 1_700_000_000_000_000_000},
            'message_count': 9,
            'topics_with_message_count': [
                {
                    'topic_metadata': {
                        'name': name,
                        'type': typename,
                        'serialization_format': 'cdr',
                        'offered_qos_profiles': [],
                        'type_description_hash': digest,
                    },
                    'message_count': 3,
                }
                for name, typename, digest in topics
            ],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [storage.name],
            'files': [
                {
                    'path': storage.name,
                    'starting_time': {'nanoseconds_since_epoch': 1_700_000_000_000_000_000},
                    'duration': {'nanoseconds': 200_000_002},
                    'message_count': 9,
                }
            ],
            'custom_data': {},
            'ros_distro': 'jazzy',
        }
    }
    (path / 'metadata.yaml').write_text(yaml.safe_dump(metadata))


@pytest.fixture(params=[CompressionType.ZSTD, CompressionType.LZ4, CompressionType.NONE])
def robot_bag(request: pytest.FixtureRequest, tmp_path: Path) -> Path:
    """A robot-style bag, once per chunk compression."""
    path = tmp_path / 'robot_run'
    _write_robot_bag(path, request.param)
    return path


def test_standard_types_decode_into_the_shared_classes(robot_bag: Path) -> None:
    scans = list(read_messages(robot_bag, topics=['/scan']))
    assert [list(m.message.ranges) for m in scans] == [[1.0, 2.0, float(i)] for i in range(3)]
    assert all(type(m.message) is get_message_class('sensor_msgs/msg/LaserScan') for m in scans)
    assert scans[0].message.header.frame_id == 'laser'


def test_custom_types_decode_from_the_bags_own_definitions(robot_bag: Path) -> None:
    status = [m.message for m in read_messages(robot_bag, topics=['/status'])]
    assert [s.battery_percent for s in status] == [90, 89, 88]
    assert status[0].mode == 'explore'
    assert status[0].get_fields_and_field_types() == {'battery_percent': 'uint8', 'mode': 'string'}


def test_a_type_defined_differently_in_the_bag_uses_the_bag_definition(robot_bag: Path) -> None:
    gas = [m.message for m in read_messages(robot_bag, topics=['/gas'])]
    assert [g.raw for g in gas] == [200, 201, 202]
    assert 'volts' not in gas[0].get_fields_and_field_types()
    assert type(gas[0]) is not get_message_class('swarm_interfaces/msg/GasReading')


def test_all_topics_come_in_log_time_order(robot_bag: Path) -> None:
    read = list(read_messages(robot_bag))
    assert len(read) == 9
    assert [m.log_time_ns for m in read] == sorted(m.log_time_ns for m in read)
    assert [m.topic for m in read[:3]] == ['/scan', '/status', '/gas']


def test_bag_info_of_a_robot_bag(robot_bag: Path) -> None:
    info = read_bag_info(robot_bag)
    assert info.message_count == 9
    assert info.topics['/status'].typename == 'robot_msgs/msg/Status'
    assert info.storage_files == (robot_bag / 'robot_run_0.mcap',)


def test_cut_robot_bag_recovers_through_compressed_chunks(robot_bag: Path) -> None:
    storage = robot_bag / 'robot_run_0.mcap'
    data = storage.read_bytes()
    storage.write_bytes(data[: len(data) // 2])
    with pytest.warns(TruncatedBagWarning):
        recovered = list(read_messages(robot_bag, allow_truncated=True))
    assert recovered
    assert [m.log_time_ns for m in recovered] == sorted(m.log_time_ns for m in recovered)
    assert recovered[0].topic == '/scan'
    assert list(recovered[0].message.ranges) == [1.0, 2.0, 0.0]


def _set_recorded_hash(bag: Path, topic: str, digest: str) -> None:
    path = bag / 'metadata.yaml'
    metadata = yaml.safe_load(path.read_text())
    for entry in metadata['rosbag2_bagfile_information']['topics_with_message_count']:
        if entry['topic_metadata']['name'] == topic:
            entry['topic_metadata']['type_description_hash'] = digest
    path.write_text(yaml.safe_dump(metadata))


def test_a_definition_matching_its_recorded_hash_is_used(robot_bag: Path) -> None:
    from swarm_runtime.bag.decoding import definition_hash

    old_hash = definition_hash(
        'swarm_interfaces/msg/GasReading',
        OLD_GAS_READING + '\n' + '=' * 80 + '\nMSG: std_msgs/Header\n' + _header_definition(),
    )
    assert old_hash != get_typestore().hash_rihs01('swarm_interfaces/msg/GasReading')
    _set_recorded_hash(robot_bag, '/gas', old_hash)
    assert [m.message.raw for m in read_messages(robot_bag, topics=['/gas'])] == [200, 201, 202]


def test_a_definition_that_contradicts_its_recorded_hash_is_not_used(robot_bag: Path) -> None:
    _set_recorded_hash(robot_bag, '/gas', 'RIHS01_' + '00' * 32)
    with pytest.raises(
        BagTypeError, match=r'/gas: the definition of .*GasReading.* does not match'
    ):
        list(read_messages(robot_bag, topics=['/gas']))
    # The other topics still read; with recovery the bad topic is skipped with a warning.
    assert len(list(read_messages(robot_bag, topics=['/scan', '/status']))) == 6
    with pytest.warns(TruncatedBagWarning, match='cannot be decoded; skipped'):
        recovered = list(read_messages(robot_bag, allow_truncated=True))
    assert {m.topic for m in recovered} == {'/scan', '/status'}


def test_a_recorded_hash_that_matches_the_workspace_type_rescues_a_wrong_definition() -> None:
    """A recorder that stored a stale definition but the publishers' real type hash."""
    from swarm_runtime.bag.decoding import Decoder

    decision = Decoder().decision(
        '/n',
        'std_msgs/msg/Int32',
        'ros2msg',
        'int16 data\n',
        get_typestore().hash_rihs01('std_msgs/msg/Int32'),
    )
    assert decision.source == 'workspace'
    assert decision.verified
    assert decision.decode(b'\x00\x01\x00\x00\x07\x00\x00\x00').data == 7


def test_a_type_without_stored_definition_needs_a_matching_hash() -> None:
    from swarm_runtime.bag.decoding import Decoder

    decoder = Decoder()
    ours = get_typestore().hash_rihs01('std_msgs/msg/Int32')
    assert decoder.decision('/n', 'std_msgs/msg/Int32', '', '', ours).verified
    assert not decoder.decision('/n', 'std_msgs/msg/Int32', '', '', '').verified
    with pytest.raises(BagTypeError, match='stores no definition'):
        decoder.decision('/n', 'std_msgs/msg/Int32', '', '', 'RIHS01_' + 'ab' * 32)
    with pytest.raises(BagTypeError, match='not known here'):
        decoder.decision('/n', 'robot_msgs/msg/Unknown', '', '', '')


def test_messages_decode_to_the_same_classes_on_either_runtime(robot_bag: Path) -> None:
    """Analysis code gets generated classes whatever runtime the process selected."""
    from swarm_runtime.messages import is_message

    read = list(read_messages(robot_bag))
    assert all(is_message(m.message) for m in read)
