"""Per-type CDR codecs (what publishers and subscriptions use) and the keyword constructors."""

from __future__ import annotations

import pytest
from rosbags.typesys import get_types_from_msg
from swarm_runtime.messages import (
    DeserializationError,
    MessageRegistry,
    SerializationError,
    default_registry,
    deserialize_cdr,
    get_cdr_codec,
    get_message_module,
    serialize_cdr,
)
from swarm_runtime.messages.codegen import class_source
from swarm_runtime.messages.typestore import jazzy_typestore

sensor_msgs = get_message_module('sensor_msgs')


def _scan() -> object:
    scan = sensor_msgs.LaserScan(ranges=[1.0, 2.5, 0.1], angle_max=0.5)
    scan.header.frame_id = 'laser'
    return scan


def test_codec_gives_the_bytes_and_messages_of_serialize_and_deserialize_cdr() -> None:
    codec = get_cdr_codec('sensor_msgs/msg/LaserScan')
    scan = _scan()
    data = codec.serialize(scan)
    assert data == serialize_cdr(scan)
    assert codec.deserialize(data) == deserialize_cdr(data, 'sensor_msgs/msg/LaserScan')
    assert codec.deserialize(bytearray(data)) == codec.deserialize(data)
    # float32 fields come back rounded, as from another process.
    assert codec.deserialize(data).ranges[2] != 0.1
    assert codec.typename == 'sensor_msgs/msg/LaserScan'


def test_codec_is_one_per_type_and_accepts_short_names() -> None:
    assert get_cdr_codec('sensor_msgs/LaserScan') is not None
    assert get_cdr_codec('sensor_msgs/msg/Imu') is get_cdr_codec('sensor_msgs/msg/Imu')
    assert get_cdr_codec('sensor_msgs/LaserScan').typename == 'sensor_msgs/msg/LaserScan'


def test_codec_reports_bad_values_and_bad_bytes_like_the_functions() -> None:
    codec = get_cdr_codec('sensor_msgs/msg/LaserScan')
    header = get_message_module('std_msgs').Header(check_fields=False)
    header.frame_id = 7
    scan = sensor_msgs.LaserScan(header=header, check_fields=False)
    with pytest.raises(SerializationError, match=r"'header\.frame_id' holds int 7"):
        codec.serialize(scan)
    data = codec.serialize(_scan())
    with pytest.raises(DeserializationError, match='LaserScan'):
        codec.deserialize(data[:-5])
    with pytest.raises(DeserializationError, match='LaserScan'):
        codec.deserialize(b'\x00\x01')


def test_codec_decodes_big_endian_data_through_the_general_path() -> None:
    registry = default_registry()
    scan = _scan()
    to_rosbags, _ = registry.converters('sensor_msgs/msg/LaserScan')
    big_endian = bytes(
        registry.typestore.serialize_cdr(
            to_rosbags(scan), 'sensor_msgs/msg/LaserScan', little_endian=False
        )
    )
    assert get_cdr_codec('sensor_msgs/msg/LaserScan').deserialize(big_endian) == scan


def test_codec_compiles_its_functions_at_first_use_only() -> None:
    registry = MessageRegistry(check_fields=True)
    codec = registry.codec('sensor_msgs/msg/Imu')
    assert 'sensor_msgs/msg/Imu' not in registry._cdr
    codec.deserialize(codec.serialize(registry.get_class('sensor_msgs/msg/Imu')()))
    assert 'sensor_msgs/msg/Imu' in registry._cdr


def test_strings_are_written_and_checked_when_read() -> None:
    codec = get_cdr_codec('std_msgs/msg/Header')
    header = get_message_module('std_msgs').Header(frame_id='bäse_link')
    data = codec.serialize(header)
    assert codec.deserialize(data).frame_id == 'bäse_link'
    unterminated = bytearray(data)
    unterminated[-1] = ord('x')
    with pytest.raises(DeserializationError, match='invalid string'):
        codec.deserialize(bytes(unterminated))
    too_long = bytearray(data)
    too_long[12:16] = (200).to_bytes(4, 'little')
    with pytest.raises(DeserializationError, match='invalid string'):
        codec.deserialize(bytes(too_long))


def test_constructor_takes_keywords_only_and_checks_them() -> None:
    checked = MessageRegistry(check_fields=True)
    unchecked = MessageRegistry(check_fields=False)
    time_checked = checked.get_class('builtin_interfaces/msg/Time')
    with pytest.raises(TypeError):
        time_checked(1, 2)
    with pytest.raises(AssertionError, match='Invalid arguments passed to constructor: a, b'):
        time_checked(sec=1, b=2, a=3)
    with pytest.raises(AssertionError, match="The 'sec' field must be an integer"):
        time_checked(sec=2**31)
    assert time_checked(sec=1, check_fields=False, bogus=2).sec == 1
    assert unchecked.get_class('builtin_interfaces/msg/Time')(nanosec=5, bogus=1).nanosec == 5


def test_fields_named_like_builtins_work_as_constructor_keywords() -> None:
    registry = MessageRegistry(check_fields=True)
    range_msg = registry.get_class('sensor_msgs/msg/Range')(range=1.5, min_range=0.1)
    assert (range_msg.range, range_msg.min_range) == (1.5, 0.1)
    with pytest.raises(AssertionError, match="The 'range' field must be of type 'float'"):
        registry.get_class('sensor_msgs/msg/Range')(range=1)
    marker = registry.get_class('visualization_msgs/msg/Marker')(type=2, id=7, text='x')
    assert (marker.type, marker.id, marker.text) == (2, 7, 'x')


def test_fields_named_like_python_keywords_fall_back_to_a_kwargs_constructor() -> None:
    typestore = jazzy_typestore()
    typestore.register(get_types_from_msg('float64 lambda\nint32 data\n', 'probe_msgs/msg/Odd'))
    registry = MessageRegistry(typestore, check_fields=True)
    odd = registry.get_class('probe_msgs/msg/Odd')(**{'lambda': 2.0, 'data': 3})
    assert (getattr(odd, 'lambda'), odd.data) == (2.0, 3)
    assert 'def __init__(self, **kwargs):' in class_source(registry.spec('probe_msgs/msg/Odd'))
    with pytest.raises(AssertionError, match='Invalid arguments passed to constructor: x'):
        registry.get_class('probe_msgs/msg/Odd')(x=1)


def test_default_fixed_arrays_are_fresh_zero_arrays_of_their_dtype() -> None:
    registry = MessageRegistry(check_fields=True)
    imu_class = registry.get_class('sensor_msgs/msg/Imu')
    first = imu_class()
    first.orientation_covariance[0] = 5.0
    first.angular_velocity_covariance[:] = 1.0
    for imu in (imu_class(), imu_class._new_default(), imu_class(check_fields=False)):
        assert imu.orientation_covariance.dtype == 'float64'
        assert imu.orientation_covariance.shape == (9,)
        assert not imu.orientation_covariance.any()
        assert not imu.angular_velocity_covariance.any()
        assert imu.orientation_covariance is not first.orientation_covariance
