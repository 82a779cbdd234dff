"""CDR serialization of the generated classes, cross-checked against rosbags' own objects."""

from __future__ import annotations

import struct
from array import array
from pathlib import Path

import numpy as np
import pytest
from rosbags.typesys import get_types_from_msg
from swarm_runtime.messages import (
    DeserializationError,
    MessageRegistry,
    SerializationError,
    cdr,
    cdr_roundtrip,
    deserialize_cdr,
    get_message_module,
    get_typestore,
    serialize_cdr,
)
from swarm_runtime.messages.typestore import jazzy_typestore

PROBE_DEFINITION = (Path(__file__).parent / 'data' / 'AllKinds.msg').read_text()


@pytest.fixture(scope='module')
def unchecked() -> MessageRegistry:
    """A registry whose messages do not check fields, so wrong types can get in."""
    return MessageRegistry(check_fields=False)


@pytest.fixture(scope='module')
def probe_registry() -> MessageRegistry:
    """A registry that knows the probe type with one field of every kind."""
    typestore = jazzy_typestore()
    typestore.register(get_types_from_msg(PROBE_DEFINITION, 'probe_msgs/msg/AllKinds'))
    return MessageRegistry(typestore, check_fields=True)


def _scan() -> object:
    sensor_msgs = get_message_module('sensor_msgs')
    std_msgs = get_message_module('std_msgs')
    builtin_interfaces = get_message_module('builtin_interfaces')
    return sensor_msgs.LaserScan(
        header=std_msgs.Header(stamp=builtin_interfaces.Time(sec=3, nanosec=5), frame_id='laser'),
        angle_min=-3.0,
        angle_max=3.0,
        angle_increment=0.0174,
        range_max=12.0,
        ranges=[1.0, 2.5, float('inf')],
        intensities=[7.0, 8.0, 9.0],
    )


def test_bytes_equal_what_rosbags_writes_for_the_same_message() -> None:
    typestore = get_typestore()
    types = typestore.types
    expected = typestore.serialize_cdr(
        types['sensor_msgs/msg/LaserScan'](
            header=types['std_msgs/msg/Header'](
                stamp=types['builtin_interfaces/msg/Time'](sec=3, nanosec=5), frame_id='laser'
            ),
            angle_min=-3.0,
            angle_max=3.0,
            angle_increment=0.0174,
            time_increment=0.0,
            scan_time=0.0,
            range_min=0.0,
            range_max=12.0,
            ranges=np.array([1.0, 2.5, np.inf], dtype=np.float32),
            intensities=np.array([7.0, 8.0, 9.0], dtype=np.float32),
        ),
        'sensor_msgs/msg/LaserScan',
    )
    assert serialize_cdr(_scan()) == bytes(expected)


def test_cdr_starts_with_the_little_endian_encapsulation_header() -> None:
    data = serialize_cdr(get_message_module('std_msgs').UInt32(data=0x01020304))
    assert data[:4] == b'\x00\x01\x00\x00'
    assert struct.unpack('<I', data[4:8]) == (0x01020304,)


def test_roundtrip_rounds_float32_fields_like_a_real_subscriber() -> None:
    sent = _scan()
    received = cdr_roundtrip(sent)
    assert received.angle_increment == 0.017400000244379044
    assert received != sent
    received.angle_increment = sent.angle_increment
    assert received == sent


def test_roundtrip_returns_fresh_arrays() -> None:
    sent = _scan()
    received = cdr_roundtrip(sent)
    assert isinstance(received.ranges, array)
    received.ranges[0] = 42.0
    assert sent.ranges[0] == 1.0
    imu = get_message_module('sensor_msgs').Imu()
    received_imu = cdr_roundtrip(imu)
    received_imu.orientation_covariance[0] = 1.0
    assert imu.orientation_covariance[0] == 0.0


def test_deserialize_accepts_short_type_names() -> None:
    data = serialize_cdr(_scan())
    assert deserialize_cdr(data, 'sensor_msgs/LaserScan') == deserialize_cdr(
        data, 'sensor_msgs/msg/LaserScan'
    )


@pytest.mark.parametrize(
    'typename',
    sorted(
        t
        for t in get_typestore().fielddefs
        if t.split('/')[0] in ('std_msgs', 'sensor_msgs', 'geometry_msgs', 'nav_msgs')
        or t.startswith('swarm_interfaces/')
    ),
)
def test_default_messages_survive_the_roundtrip(typename: str) -> None:
    from swarm_runtime.messages import get_message_class

    message = get_message_class(typename)()
    assert cdr_roundtrip(message) == message


def test_every_field_kind_survives_the_roundtrip(probe_registry: MessageRegistry) -> None:
    probe = probe_registry.get_class('probe_msgs/msg/AllKinds')
    header_cls = type(probe().header)
    sent = probe(
        flag=True,
        octet=b'\xff',
        letter=200,
        small=-100,
        big=2**64 - 1,
        single=0.5,
        double_value=0.1,
        name='ünïcode',
        short_name='abcd',
        floats=[1.5, -2.25],
        raw=b'\x00\x7f\xff',
        octets=[b'\x00', b'\xfe'],
        flags=[True, False, True],
        names=['x', ''],
        short_names=['abc'],
        few=[-3, 3],
        triple=[1.0, 2.0, 3.0],
        pair=['p', 'q'],
        flag_pair=[False, True],
        octet_pair=[b'a', b'\x80'],
        headers=[header_cls(frame_id='h0'), header_cls(frame_id='h1')],
    )
    received = cdr.cdr_roundtrip(sent, probe_registry)
    assert received == sent
    assert received.octets == [b'\x00', b'\xfe']
    assert received.flags == [True, False, True]


def test_wrong_type_in_a_float_field_names_type_and_field(unchecked: MessageRegistry) -> None:
    scan = unchecked.get_class('sensor_msgs/msg/LaserScan')(angle_min='wide')
    with pytest.raises(SerializationError, match=r"LaserScan: field 'angle_min' holds str"):
        cdr.serialize_cdr(scan, unchecked)


def test_wrong_nested_message_names_the_path(unchecked: MessageRegistry) -> None:
    scan = unchecked.get_class('sensor_msgs/msg/LaserScan')()
    scan.header.stamp = {'sec': 1}
    with pytest.raises(SerializationError, match=r"field 'header\.stamp' holds dict"):
        cdr.cdr_roundtrip(scan, unchecked)


def test_wrong_element_in_a_nested_sequence_is_reported(unchecked: MessageRegistry) -> None:
    bearing_array = unchecked.get_class('swarm_interfaces/msg/PeerBearingArray')
    bearing = unchecked.get_class('swarm_interfaces/msg/PeerBearing')
    message = bearing_array(bearings=[bearing(), bearing(azimuth=None)])
    with pytest.raises(SerializationError, match=r"field 'bearings\[1\]\.azimuth' holds NoneType"):
        cdr.serialize_cdr(message, unchecked)


def test_out_of_range_integer_is_reported(unchecked: MessageRegistry) -> None:
    gas = unchecked.get_class('swarm_interfaces/msg/GasReading')(raw=70000)
    with pytest.raises(SerializationError, match=r"field 'raw' holds int 70000"):
        cdr.serialize_cdr(gas, unchecked)


def test_convertible_wrong_types_are_converted_like_rclpy(unchecked: MessageRegistry) -> None:
    gas = unchecked.get_class('swarm_interfaces/msg/GasReading')(raw=np.int64(300), volts=1)
    received = cdr.cdr_roundtrip(gas, unchecked)
    assert received.raw == 300
    assert received.volts == 1.0
    assert isinstance(received.volts, float)


def test_garbage_bytes_raise_a_deserialization_error() -> None:
    with pytest.raises(DeserializationError, match='sensor_msgs/msg/LaserScan'):
        deserialize_cdr(b'\x00\x01\x00\x00\x01', 'sensor_msgs/msg/LaserScan')
    with pytest.raises(DeserializationError, match='std_msgs/msg/String'):
        deserialize_cdr(b'\x07\x07', 'std_msgs/msg/String')
