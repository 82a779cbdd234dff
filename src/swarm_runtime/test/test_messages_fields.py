"""Every kind of field rosidl knows, on a probe message type that holds one of each."""

from __future__ import annotations

from array import array
from pathlib import Path

import numpy as np
import pytest
from rosbags.typesys import get_types_from_msg
from swarm_runtime.messages import MessageRegistry, definition
from swarm_runtime.messages.typestore import jazzy_typestore

PROBE_DEFINITION = (Path(__file__).parent / 'data' / 'AllKinds.msg').read_text()


def _registry(*, check_fields: bool | None) -> MessageRegistry:
    typestore = jazzy_typestore()
    typestore.register(get_types_from_msg(PROBE_DEFINITION, 'probe_msgs/msg/AllKinds'))
    return MessageRegistry(typestore, check_fields=check_fields)


@pytest.fixture(scope='module')
def probe() -> type:
    """The probe class with field checks on."""
    return _registry(check_fields=True).get_class('probe_msgs/msg/AllKinds')


@pytest.fixture(scope='module')
def probe_unchecked() -> type:
    """The probe class with field checks off."""
    return _registry(check_fields=False).get_class('probe_msgs/msg/AllKinds')


def test_defaults_of_every_field_kind(probe: type) -> None:
    msg = probe()
    assert msg.flag is False
    assert msg.octet == b'\x00'
    assert msg.letter == 0
    assert msg.name == ''
    assert msg.floats == array('f')
    assert msg.raw == array('B')
    assert msg.octets == []
    assert msg.flags == []
    assert msg.few == array('h')
    assert msg.triple.dtype == np.float64
    assert msg.triple.shape == (3,)
    assert msg.pair == ['', '']
    assert msg.flag_pair == [False, False]
    assert msg.octet_pair == [b'\x00', b'\x00']
    assert msg.header_pair[0] == msg.header_pair[1]
    assert msg.header_pair[0] is not msg.header_pair[1]


def test_constants_have_rosidl_python_types(probe: type) -> None:
    assert probe.ANSWER == 42
    assert probe.GREETING == 'hello'
    assert probe.OCTET_CONSTANT == b'\x07'


def test_bool_field_takes_only_bool(probe: type) -> None:
    msg = probe(flag=True)
    assert msg.flag is True
    with pytest.raises(AssertionError, match="The 'flag' field must be of type 'bool'"):
        msg.flag = 1


def test_byte_field_takes_one_byte_bytes(probe: type) -> None:
    msg = probe(octet=b'\xff')
    msg.octet = bytearray(b'a')
    with pytest.raises(AssertionError, match="'bytes' or 'ByteString' with length 1"):
        msg.octet = b'ab'
    with pytest.raises(AssertionError, match="The 'octet' field"):
        msg.octet = 3


def test_char_field_is_an_unsigned_8_bit_integer(probe: type) -> None:
    msg = probe(letter=255)
    with pytest.raises(AssertionError, match=r'unsigned integer in \[0, 255\]'):
        msg.letter = 256
    with pytest.raises(AssertionError, match="must be of type 'int'"):
        msg.letter = 'a'


def test_uint64_field_accepts_its_full_range(probe: type) -> None:
    msg = probe(big=2**64 - 1)
    with pytest.raises(AssertionError, match=r'\[0, 18446744073709551615\]'):
        msg.big = 2**64
    with pytest.raises(AssertionError, match=r'\[0, 18446744073709551615\]'):
        msg.big = -1


def test_float32_field_allows_infinity_and_nan(probe: type) -> None:
    msg = probe()
    msg.single = float('inf')
    msg.single = float('nan')
    msg.double_value = 1e300
    with pytest.raises(AssertionError, match=r"'single' field must be a float in \[-3.4"):
        msg.single = 1e300


def test_bounded_string_checks_its_length(probe: type) -> None:
    msg = probe(short_name='abcd')
    with pytest.raises(AssertionError, match='must be string value not longer than 4'):
        msg.short_name = 'abcde'


def test_uint8_sequence_accepts_bytes_and_stores_an_array(probe: type) -> None:
    msg = probe()
    msg.raw = b'\x01\x02\xff'
    assert msg.raw == array('B', [1, 2, 255])
    with pytest.raises(AssertionError, match=r'each unsigned integer in \[0, 255\]'):
        msg.raw = [1, 256]


def test_byte_sequence_is_a_list_of_one_byte_bytes(probe: type) -> None:
    msg = probe(octets=[b'a', b'b'])
    assert msg.octets == [b'a', b'b']
    with pytest.raises(AssertionError, match="each value of type 'bytes'"):
        msg.octets = b'ab'
    with pytest.raises(AssertionError, match="each value of type 'bytes'"):
        msg.octets = [1, 2]


def test_string_sequences_check_elements_and_bounds(probe: type) -> None:
    msg = probe(names=['a', 'b'], short_names=('abc',))
    assert msg.short_names == ('abc',)
    with pytest.raises(AssertionError, match="each value of type 'str'"):
        msg.names = ['a', 1]
    with pytest.raises(AssertionError, match='each string value not longer than 3'):
        msg.short_names = ['abcd']
    with pytest.raises(AssertionError, match="The 'names' field must be a set or sequence"):
        msg.names = 'ab'


def test_bounded_numeric_sequence_checks_its_size(probe: type) -> None:
    msg = probe(few=[1, 2])
    with pytest.raises(AssertionError, match='with length <= 2'):
        msg.few = [1, 2, 3]
    with pytest.raises(AssertionError, match=r'must have a size <= 2'):
        msg.few = array('h', [1, 2, 3])
    with pytest.raises(AssertionError, match=r'must have a size <= 2'):
        probe(few=[1, 2, 3])


def test_constructor_converts_numeric_sequences_before_checking(probe: type) -> None:
    msg = probe(floats=[1, 2], raw=np.array([3, 4], dtype=np.uint8))
    assert msg.floats == array('f', [1.0, 2.0])
    assert msg.raw == array('B', [3, 4])


def test_fixed_arrays_of_other_types_check_length_and_elements(probe: type) -> None:
    msg = probe(pair=['x', 'y'], flag_pair=[True, False], octet_pair=[b'a', b'b'])
    with pytest.raises(AssertionError, match='with length 2'):
        msg.pair = ['x']
    with pytest.raises(AssertionError, match="each value of type 'bool'"):
        msg.flag_pair = [1, 0]


def test_nested_sequence_elements_must_be_that_message(probe: type) -> None:
    header_cls = type(probe().header)
    msg = probe(headers=[header_cls(frame_id='a')])
    assert msg.headers[0].frame_id == 'a'
    with pytest.raises(AssertionError, match="each value of type 'Header'"):
        msg.headers = [{'frame_id': 'a'}]


def test_check_fields_keyword_overrides_the_default(probe: type, probe_unchecked: type) -> None:
    loose = probe(check_fields=False, single=1)
    assert loose.single == 1
    strict = probe_unchecked(check_fields=True)
    with pytest.raises(AssertionError):
        strict.single = 1


def test_unchecked_setters_still_convert_numeric_arrays(probe_unchecked: type) -> None:
    msg = probe_unchecked()
    msg.floats = np.array([1.5, 2.5])
    assert msg.floats == array('f', [1.5, 2.5])
    msg.triple = [1, 2, 3]
    assert msg.triple.dtype == np.float64
    msg.names = 'not a list'
    assert msg.names == 'not a list'


def test_check_fields_default_is_read_from_the_environment(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv('ROS_PYTHON_CHECK_FIELDS', '1')
    checked = _registry(check_fields=None).get_class('probe_msgs/msg/AllKinds')
    monkeypatch.setenv('ROS_PYTHON_CHECK_FIELDS', '0')
    unchecked = _registry(check_fields=None).get_class('probe_msgs/msg/AllKinds')
    with pytest.raises(AssertionError):
        checked(single=1)
    assert unchecked(single=1).single == 1


def test_slot_types_mirror_rosidl_definitions(probe: type) -> None:
    slot_types = dict(zip(probe.get_fields_and_field_types(), probe.SLOT_TYPES, strict=True))
    assert slot_types['single'] == definition.BasicType('float')
    assert slot_types['letter'] == definition.BasicType('uint8')
    assert slot_types['short_name'] == definition.BoundedString(4)
    assert slot_types['few'] == definition.BoundedSequence(definition.BasicType('int16'), 2)
    assert slot_types['triple'] == definition.Array(definition.BasicType('double'), 3)
    assert slot_types['header'] == definition.NamespacedType(('std_msgs', 'msg'), 'Header')
    assert isinstance(slot_types['floats'], definition.AbstractSequence)


def test_field_types_text_follows_rosidl(probe: type) -> None:
    fields = probe.get_fields_and_field_types()
    assert fields['few'] == 'sequence<int16, 2>'
    assert fields['short_names'] == 'sequence<string<3>>'
    assert fields['octet_pair'] == 'octet[2]'
    assert fields['headers'] == 'sequence<std_msgs/Header>'
