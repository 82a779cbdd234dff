"""The generated CDR codec writes exactly rosbags' bytes and decodes them back."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rosbags.typesys import get_types_from_msg
from swarm_runtime.messages import (
    DeserializationError,
    MessageRegistry,
    cdr,
    default_registry,
    deserialize_cdr,
    get_message_module,
    get_typestore,
    serialize_cdr,
)
from swarm_runtime.messages.typestore import jazzy_typestore

PROBE_DEFINITION = (Path(__file__).parent / 'data' / 'AllKinds.msg').read_text()
PROBE = 'probe_msgs/msg/AllKinds'


def _rosbags_bytes(registry: MessageRegistry, message: Any, typename: str) -> bytes:
    """The reference encoding: through rosbags' own message objects and serializer."""
    to_rosbags, _ = registry.converters(typename)
    return bytes(registry.typestore.serialize_cdr(to_rosbags(message), typename))


@pytest.mark.parametrize('typename', sorted(get_typestore().fielddefs))
def test_default_message_of_every_known_type_matches_rosbags(typename: str) -> None:
    registry = default_registry()
    message = registry.get_class(typename)()
    data = serialize_cdr(message)
    assert data == _rosbags_bytes(registry, message, typename)
    assert deserialize_cdr(data, typename) == message


@functools.cache
def _probe_registry() -> MessageRegistry:
    """One registry that knows the probe type, shared by every hypothesis example."""
    typestore = jazzy_typestore()
    typestore.register(get_types_from_msg(PROBE_DEFINITION, PROBE))
    return MessageRegistry(typestore, check_fields=True)


_TEXT = st.text(st.characters(exclude_categories=('Cs',), exclude_characters='\x00'), max_size=9)
# rosidl's float32 bound (3.402823466e+38) is a little below the largest float32, which its
# check therefore rejects; infinities pass the check.
_FLOAT32 = st.floats(
    width=32, min_value=-3.3999999521443642e38, max_value=3.3999999521443642e38
) | st.sampled_from([float('inf'), float('-inf')])
_FLOAT64 = st.floats(allow_nan=False)
_OCTET = st.binary(min_size=1, max_size=1)


@st.composite
def _headers(draw: st.DrawFn) -> Any:
    registry = _probe_registry()
    header = registry.get_class('std_msgs/msg/Header')
    time = registry.get_class('builtin_interfaces/msg/Time')
    return header(
        stamp=time(
            sec=draw(st.integers(-(2**31), 2**31 - 1)), nanosec=draw(st.integers(0, 2**32 - 1))
        ),
        frame_id=draw(_TEXT),
    )


@st.composite
def _probes(draw: st.DrawFn) -> Any:
    probe = _probe_registry().get_class(PROBE)
    return probe(
        flag=draw(st.booleans()),
        octet=draw(_OCTET),
        letter=draw(st.integers(0, 255)),
        small=draw(st.integers(-128, 127)),
        big=draw(st.integers(0, 2**64 - 1)),
        single=draw(_FLOAT32),
        double_value=draw(_FLOAT64),
        name=draw(_TEXT),
        short_name=draw(
            st.text(st.characters(codec='ascii', exclude_characters='\x00'), max_size=4)
        ),
        header=draw(_headers()),
        floats=draw(st.lists(_FLOAT32, max_size=5)),
        raw=draw(st.binary(max_size=7)),
        octets=draw(st.lists(_OCTET, max_size=5)),
        flags=draw(st.lists(st.booleans(), max_size=5)),
        names=draw(st.lists(_TEXT, max_size=3)),
        short_names=draw(
            st.lists(
                st.text(st.characters(codec='ascii', exclude_characters='\x00'), max_size=3),
                max_size=3,
            )
        ),
        few=draw(st.lists(st.integers(-(2**15), 2**15 - 1), max_size=2)),
        triple=draw(st.lists(_FLOAT64, min_size=3, max_size=3)),
        pair=draw(st.lists(_TEXT, min_size=2, max_size=2)),
        flag_pair=draw(st.lists(st.booleans(), min_size=2, max_size=2)),
        octet_pair=draw(st.lists(_OCTET, min_size=2, max_size=2)),
        headers=draw(st.lists(_headers(), max_size=3)),
        header_pair=draw(st.lists(_headers(), min_size=2, max_size=2)),
    )


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(message=_probes())
def test_random_messages_of_every_field_kind_match_rosbags(message: Any) -> None:
    registry = _probe_registry()
    data = cdr.serialize_cdr(message, registry)
    assert data == _rosbags_bytes(registry, message, PROBE)
    assert cdr.deserialize_cdr(data, PROBE, registry) == message


def test_big_endian_data_decodes_through_rosbags() -> None:
    registry = default_registry()
    scan = get_message_module('sensor_msgs').LaserScan(ranges=[1.0, 2.0], angle_max=0.5)
    scan.header.frame_id = 'laser'
    to_rosbags, _ = registry.converters('sensor_msgs/msg/LaserScan')
    big_endian = bytes(
        registry.typestore.serialize_cdr(
            to_rosbags(scan), 'sensor_msgs/msg/LaserScan', little_endian=False
        )
    )
    assert big_endian[:2] == b'\x00\x00'
    assert deserialize_cdr(big_endian, 'sensor_msgs/msg/LaserScan') == scan


def test_truncated_and_overlong_data_are_rejected() -> None:
    scan = get_message_module('sensor_msgs').LaserScan(ranges=[1.0, 2.0, 3.0])
    data = serialize_cdr(scan)
    for cut in (len(data) - 1, len(data) - 5, 30, 6):
        with pytest.raises(DeserializationError, match='LaserScan'):
            deserialize_cdr(data[:cut], 'sensor_msgs/msg/LaserScan')
    with pytest.raises(DeserializationError, match='bytes left after the message'):
        deserialize_cdr(data + bytes(8), 'sensor_msgs/msg/LaserScan')
    deserialize_cdr(data + bytes(3), 'sensor_msgs/msg/LaserScan')  # padding rmw may add


def test_a_huge_sequence_length_is_rejected_without_allocating() -> None:
    data = bytearray(serialize_cdr(get_message_module('std_msgs').Float64MultiArray()))
    data[-4:] = (2**31).to_bytes(4, 'little')
    with pytest.raises(DeserializationError, match='exceeds the data'):
        deserialize_cdr(bytes(data), 'std_msgs/msg/Float64MultiArray')
