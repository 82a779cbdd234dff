"""Behaviour of the generated message classes, checked against Jazzy's rosidl classes."""

from __future__ import annotations

import copy
import pickle
from array import array

import numpy as np
import pytest
from swarm_runtime.messages import (
    MessageRegistry,
    UnknownMessageTypeError,
    UnknownPackageError,
    get_message_class,
    get_message_module,
    message_typename,
)


@pytest.fixture(scope='module')
def checked() -> MessageRegistry:
    """A registry whose messages check every field, as under ROS_PYTHON_CHECK_FIELDS=1."""
    return MessageRegistry(check_fields=True)


@pytest.fixture(scope='module')
def unchecked() -> MessageRegistry:
    """A registry whose messages do not check fields (Jazzy's default)."""
    return MessageRegistry(check_fields=False)


def test_defaults_match_rosidl(checked: MessageRegistry) -> None:
    sensor_msgs = checked.get_module('sensor_msgs')
    scan = sensor_msgs.LaserScan()
    assert scan.angle_min == 0.0
    assert isinstance(scan.angle_min, float)
    assert scan.header.frame_id == ''
    assert scan.header.stamp.sec == 0
    assert isinstance(scan.ranges, array)
    assert scan.ranges.typecode == 'f'
    assert len(scan.ranges) == 0
    imu = sensor_msgs.Imu()
    assert isinstance(imu.orientation_covariance, np.ndarray)
    assert imu.orientation_covariance.dtype == np.float64
    assert imu.orientation_covariance.shape == (9,)
    assert not imu.orientation_covariance.any()


def test_nested_defaults_are_independent_objects(checked: MessageRegistry) -> None:
    sensor_msgs = checked.get_module('sensor_msgs')
    first, second = sensor_msgs.LaserScan(), sensor_msgs.LaserScan()
    first.header.frame_id = 'laser'
    first.ranges.append(1.0)
    assert second.header.frame_id == ''
    assert len(second.ranges) == 0


def test_unknown_keyword_fails_only_with_checks(
    checked: MessageRegistry, unchecked: MessageRegistry
) -> None:
    with pytest.raises(AssertionError, match='Invalid arguments passed to constructor: bogus'):
        checked.get_module('std_msgs').Bool(bogus=1)
    assert unchecked.get_module('std_msgs').Bool(bogus=1).data is False


@pytest.mark.parametrize(
    ('value', 'message'),
    [
        (1, "The 'angle_min' field must be of type 'float'"),
        (np.float32(1.0), "The 'angle_min' field must be of type 'float'"),
        (1e39, "The 'angle_min' field must be a float in"),
    ],
)
def test_float_field_rejects_what_jazzy_rejects(
    checked: MessageRegistry, value: object, message: str
) -> None:
    scan = checked.get_module('sensor_msgs').LaserScan()
    with pytest.raises(AssertionError, match=message):
        scan.angle_min = value


def test_float_field_accepts_float_and_numpy_float64(checked: MessageRegistry) -> None:
    scan = checked.get_module('sensor_msgs').LaserScan()
    scan.angle_min = 1.5
    scan.angle_max = np.float64(2.5)
    scan.range_max = float('inf')
    assert (scan.angle_min, scan.angle_max) == (1.5, 2.5)


def test_integer_field_checks_type_and_range(checked: MessageRegistry) -> None:
    status = checked.get_module('sensor_msgs').NavSatStatus()
    status.status = -128
    with pytest.raises(AssertionError, match=r'must be an integer in \[-128, 127\]'):
        status.status = 128
    with pytest.raises(AssertionError, match="The 'status' field must be of type 'int'"):
        status.status = np.int8(1)


def test_string_and_nested_fields_are_checked(checked: MessageRegistry) -> None:
    std_msgs = checked.get_module('std_msgs')
    header = std_msgs.Header()
    with pytest.raises(AssertionError, match="The 'frame_id' field must be of type 'str'"):
        header.frame_id = b'map'
    scan = checked.get_module('sensor_msgs').LaserScan()
    with pytest.raises(AssertionError, match="must be a sub message of type 'Header'"):
        scan.header = {'frame_id': 'map'}


def test_numeric_sequence_assignment_follows_rosidl(checked: MessageRegistry) -> None:
    scan = checked.get_module('sensor_msgs').LaserScan()
    scan.ranges = [1.0, 2.0]
    assert scan.ranges == array('f', [1.0, 2.0])
    scan.ranges = (3.0,)
    assert isinstance(scan.ranges, array)
    with pytest.raises(AssertionError, match="The 'ranges' field must be a set or sequence"):
        scan.ranges = np.array([1.0, 2.0], dtype=np.float32)
    with pytest.raises(AssertionError, match="each value of type 'float'"):
        scan.ranges = [1, 2]
    with pytest.raises(AssertionError, match="must have the type code of 'f'"):
        scan.ranges = array('d', [1.0])


def test_fixed_array_needs_exact_length(checked: MessageRegistry) -> None:
    imu = checked.get_module('sensor_msgs').Imu()
    imu.orientation_covariance = [float(i) for i in range(9)]
    assert isinstance(imu.orientation_covariance, np.ndarray)
    assert imu.orientation_covariance[8] == 8.0
    with pytest.raises(AssertionError, match='with length 9'):
        imu.orientation_covariance = [0.0] * 8
    with pytest.raises(AssertionError, match='must have a size of 9'):
        imu.orientation_covariance = np.zeros(8)


def test_unchecked_messages_store_wrong_types_as_given(unchecked: MessageRegistry) -> None:
    scan = unchecked.get_module('sensor_msgs').LaserScan(angle_min=1)
    scan.range_max = 'far'
    assert scan.angle_min == 1
    assert scan.range_max == 'far'


def test_constants_are_class_attributes(checked: MessageRegistry) -> None:
    gas = checked.get_module('swarm_interfaces').GasReading
    assert gas.RAW_MAX == 1023
    assert gas().RAW_MAX == 1023
    status = checked.get_module('diagnostic_msgs').DiagnosticStatus
    assert status.ERROR == b'\x02'


def test_equality_is_field_wise_and_compares_arrays_by_value(checked: MessageRegistry) -> None:
    sensor_msgs = checked.get_module('sensor_msgs')
    first = sensor_msgs.Imu()
    second = sensor_msgs.Imu()
    assert first == second
    second.orientation_covariance = [1.0] + [0.0] * 8
    assert first != second
    assert sensor_msgs.LaserScan(ranges=[1.0]) == sensor_msgs.LaserScan(ranges=[1.0])
    assert sensor_msgs.LaserScan(ranges=[1.0]) != sensor_msgs.LaserScan(ranges=[2.0])
    assert sensor_msgs.LaserScan() != checked.get_module('std_msgs').Header()


def test_repr_reads_like_rosidl(checked: MessageRegistry) -> None:
    sensor_msgs = checked.get_module('sensor_msgs')
    text = repr(sensor_msgs.LaserScan(ranges=[1.0, 2.5]))
    assert text.startswith(
        'sensor_msgs.msg.LaserScan(header=std_msgs.msg.Header('
        'stamp=builtin_interfaces.msg.Time(sec=0, nanosec=0), '
        "frame_id=''), angle_min=0.0"
    )
    assert text.endswith('ranges=[1.0, 2.5], intensities=[])')


def test_fields_and_field_types_use_rosidl_spelling(checked: MessageRegistry) -> None:
    fields = checked.get_module('sensor_msgs').Imu.get_fields_and_field_types()
    assert fields['header'] == 'std_msgs/Header'
    assert fields['orientation_covariance'] == 'double[9]'
    scan_fields = checked.get_module('sensor_msgs').LaserScan.get_fields_and_field_types()
    assert scan_fields['ranges'] == 'sequence<float>'
    fields['header'] = 'changed'
    assert checked.get_module('sensor_msgs').Imu.get_fields_and_field_types()['header'] != 'changed'


def test_messages_have_slots_and_no_instance_dict(checked: MessageRegistry) -> None:
    header = checked.get_module('std_msgs').Header()
    assert '_frame_id' in type(header).__slots__
    with pytest.raises(AttributeError):
        header.not_a_field = 1


def test_copy_deepcopy_and_pickle_preserve_equality() -> None:
    sensor_msgs = get_message_module('sensor_msgs')
    scan = sensor_msgs.LaserScan(ranges=[1.0, 2.0])
    scan.header.frame_id = 'laser'
    deep = copy.deepcopy(scan)
    assert deep == scan
    deep.ranges[0] = 5.0
    assert scan.ranges[0] == 1.0
    shallow = copy.copy(scan)
    assert shallow.header is scan.header
    assert pickle.loads(pickle.dumps(scan)) == scan


def test_class_lookup_accepts_short_and_full_names() -> None:
    full = get_message_class('sensor_msgs/msg/LaserScan')
    assert get_message_class('sensor_msgs/LaserScan') is full
    assert get_message_module('sensor_msgs').LaserScan is full
    assert message_typename(full()) == 'sensor_msgs/msg/LaserScan'
    assert message_typename(full) == 'sensor_msgs/msg/LaserScan'


def test_unknown_types_and_packages_raise_precise_errors() -> None:
    with pytest.raises(UnknownMessageTypeError, match='unknown message type'):
        get_message_class('sensor_msgs/msg/NoSuchThing')
    with pytest.raises(UnknownPackageError, match='no_such_msgs'):
        get_message_module('no_such_msgs')
    with pytest.raises(AttributeError, match='NoSuchThing'):
        _ = get_message_module('sensor_msgs').NoSuchThing
    with pytest.raises(UnknownMessageTypeError, match='not a ROS message class'):
        message_typename(3.0)
