"""AoA locator input: JSON stream framing, report validation, sequence filter, TCP server."""

import json
import math
import socket
import threading
import time

import pytest
from hw_drivers.aoa_bearings import BearingCollector
from hw_drivers.aoa_protocol import (
    AzimuthMapping,
    JsonStreamDecoder,
    SequenceFilter,
    parse_angle_report,
    tag_emitter_id,
)
from hw_drivers.aoa_server import LocatorServer
from hw_drivers.errors import ConfigurationError, DeviceUnavailableError, ProtocolError
from hw_drivers.fakes.locator import FakeLocatorClient, authors_payload, ndjson_payload


def test_authors_multi_line_objects_decode():
    data = authors_payload(1, 'D2', 30.0) + authors_payload(2, 'AC', -45.5)
    objects = JsonStreamDecoder().feed(data)
    assert [o['tagId'] for o in objects] == ['D2', 'AC']
    assert objects[1]['azimuth'] == pytest.approx(-45.5)


def test_ndjson_decodes_the_same():
    objects = JsonStreamDecoder().feed(ndjson_payload(1, 'D2', 30.0) + ndjson_payload(2, 'C3', 5))
    assert [o['tagId'] for o in objects] == ['D2', 'C3']


def test_objects_split_at_every_byte_boundary_decode_once():
    data = authors_payload(7, '8B', 12.25) + ndjson_payload(8, '8B', 13.0)
    decoder = JsonStreamDecoder()
    out = []
    for i in range(len(data)):
        out += decoder.feed(data[i : i + 1])
    assert [o.get('timeStamp', o.get('sequence')) for o in out] == [7, 8]
    assert decoder.malformed == 0


def test_garbage_between_objects_is_skipped_and_counted():
    data = b'\x00\xffnoise' + ndjson_payload(1, 'D2', 1.0) + b'}}]] ' + ndjson_payload(2, 'D2', 2)
    decoder = JsonStreamDecoder()
    objects = decoder.feed(data)
    assert [o['sequence'] for o in objects] == [1, 2]
    assert decoder.garbage_chars > 0


def test_malformed_object_is_skipped_and_the_next_one_decodes():
    data = b'{"tagId": "D2", "azimuth": oops}\r\n' + ndjson_payload(3, 'AC', 3.0)
    decoder = JsonStreamDecoder()
    objects = decoder.feed(data)
    assert [o['tagId'] for o in objects] == ['AC']
    assert decoder.malformed == 1


def test_oversized_object_is_dropped_and_the_buffer_reset():
    decoder = JsonStreamDecoder(max_buffer_bytes=1024)
    decoder.feed(b'{"tagId": "' + b'A' * 2000)
    assert decoder.overflows == 1
    assert decoder.buffered_chars == 0
    assert decoder.feed(ndjson_payload(1, 'D2', 1.0))[0]['tagId'] == 'D2'


def test_slow_drip_without_a_closing_brace_stays_bounded():
    decoder = JsonStreamDecoder(max_buffer_bytes=1024)
    decoder.feed(b'{"tagId": "')
    for _ in range(5000):
        decoder.feed(b'x')
    assert decoder.buffered_chars <= 1024
    assert decoder.overflows >= 1


def test_authors_report_validates_with_all_fields():
    report = parse_angle_report(json.loads(authors_payload(70000, 'd2', 190.0, quality=4)))
    assert report.tag_id == 'D2'
    assert report.azimuth_deg == pytest.approx(-170.0)
    assert report.sequence == 70000 % 65536
    assert report.quality == 4
    assert report.distance_m == pytest.approx(1.5)
    assert math.isnan(report.rssi_dbm)


def test_objects_of_other_types_are_ignored():
    assert parse_angle_report({'type': 'motion', 'azimuth': {'yaw': 3}}) is None


@pytest.mark.parametrize(
    ('obj', 'match'),
    [
        ([1, 2], 'not a JSON object'),
        ({'azimuth': 1.0}, 'tagId'),
        ({'tagId': '  ', 'azimuth': 1.0}, 'tagId'),
        ({'tagId': 'D2'}, 'without "azimuth"'),
        ({'tagId': 'D2', 'azimuth': 'left'}, 'not a number'),
        ({'tagId': 'D2', 'azimuth': float('nan')}, 'not finite'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'quality': -1}, 'quality'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'sequence': 1.5}, 'sequence'),
        ({'tagId': 'D2', 'azimuth': True}, 'not a number'),
        ({'tagId': 'D2', 'azimuth': int('9' * 400)}, 'not finite'),
        ({'tagId': 'D2', 'azimuth': -(10**309)}, 'not finite'),
        ({'tagId': 'D2', 'azimuth': float('inf')}, 'not finite'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'elevation': int('9' * 400)}, 'not finite'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'distance': 1e300}, 'out of range'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'elevation': 10**39}, 'out of range'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'rssi': -1e39}, 'out of range'),
        ({'tagId': 'D2', 'azimuth': 1.0, 'quality': [[1]] * 100}, 'quality'),
    ],
)
def test_invalid_reports_raise_protocol_errors(obj, match):
    with pytest.raises(ProtocolError, match=match) as raised:
        parse_angle_report(obj)
    assert len(str(raised.value)) < 160  # one short line, whatever the value


def test_a_huge_integer_in_the_stream_is_an_invalid_report_then_the_next_one_decodes():
    decoder = JsonStreamDecoder()
    values = decoder.feed(
        b'{"tagId":"D2","azimuth":' + b'9' * 400 + b'}' + ndjson_payload(1, 'AC', 5.0)
    )
    assert len(values) == 2
    with pytest.raises(ProtocolError, match='not finite'):
        parse_angle_report(values[0])
    assert parse_angle_report(values[1]).azimuth_deg == 5.0


def test_an_integer_too_long_for_python_to_read_is_malformed_json():
    decoder = JsonStreamDecoder(max_buffer_bytes=16384)
    values = decoder.feed(
        b'{"tagId":"D2","azimuth":' + b'9' * 5000 + b'}' + ndjson_payload(1, 'AC', 5.0)
    )
    assert [parse_angle_report(v).tag_id for v in values] == ['AC']
    assert decoder.malformed == 1


def test_sequence_filter_drops_duplicates_and_old_reports_across_the_wrap():
    seq = SequenceFilter()
    assert seq.accept('D2', 65534)
    assert seq.accept('D2', 65535)
    assert not seq.accept('D2', 65535)  # duplicate
    assert seq.accept('D2', 0)  # wraps forward
    assert not seq.accept('D2', 65000)  # old
    assert seq.accept('AC', 65000)  # other tags are independent
    assert (seq.duplicates, seq.old) == (1, 1)


def test_sequence_filter_follows_a_restarted_locator():
    seq = SequenceFilter(resync_after=3)
    assert seq.accept('D2', 40000)
    assert not seq.accept('D2', 30000)  # looks old ...
    assert not seq.accept('D2', 30001)
    assert seq.accept('D2', 30002)  # ... three in a row: the counter was restarted
    assert seq.accept('D2', 30003)


def test_azimuth_mapping_sign_and_offset():
    assert AzimuthMapping().azimuth_rad(90.0) == pytest.approx(math.pi / 2)
    assert AzimuthMapping(sign=-1).azimuth_rad(90.0) == pytest.approx(-math.pi / 2)
    flipped = AzimuthMapping(offset_rad=math.pi)
    assert flipped.azimuth_rad(0.0) == pytest.approx(math.pi)
    assert flipped.azimuth_rad(-90.0) == pytest.approx(math.pi / 2)
    with pytest.raises(ConfigurationError):
        AzimuthMapping(sign=2)


@pytest.mark.parametrize(
    ('tag', 'emitter'),
    [('D2', 0xD2), ('BLE-PD-0123456789AB', 0x456789AB), ('AA:BB:CC:DD:EE:FF', 0xCCDDEEFF)],
)
def test_tag_ids_map_to_numeric_emitter_ids(tag, emitter):
    assert tag_emitter_id(tag) == emitter


def test_tag_id_without_hex_digits_has_no_emitter_id():
    assert tag_emitter_id('robot-seven') is None


def test_collector_drops_own_tag_and_keeps_the_latest_per_tag():
    collector = BearingCollector(own_tag_id='d2')
    objs = [authors_payload(1, 'D2', 5.0), authors_payload(1, 'AC', 5.0)]
    objs += [authors_payload(2, 'AC', -90.0), authors_payload(2, 'AC', 45.0)]
    for obj in objs:
        collector.add(parse_angle_report(json.loads(obj)), 1.0)
    bearings = collector.take()
    assert [b.tag_id for b in bearings] == ['AC']
    assert bearings[0].azimuth_rad == pytest.approx(-math.pi / 2)
    assert collector.own_reports == 1
    assert collector.sequence_filter.duplicates == 1
    assert collector.take() == []


def test_degraded_quality_is_kept_but_counted():
    collector = BearingCollector()
    collector.add(parse_angle_report(json.loads(authors_payload(1, 'AC', 5.0, quality=3))), 0.0)
    assert collector.take()[0].quality == 3
    assert collector.degraded_reports == 1


# Socket harness: a real server on an ephemeral loopback port.


@pytest.fixture
def server():
    reports = []
    srv = LocatorServer('127.0.0.1', 0, reports.append, max_buffer_bytes=2048)
    srv.reports_seen = reports
    yield srv
    srv.close()


def _pump(srv, until, timeout_s=2.0):
    deadline = time.monotonic() + timeout_s
    while not until() and time.monotonic() < deadline:
        srv.poll()
    return until()


def test_server_receives_the_authors_format_split_across_sends(server):
    client = FakeLocatorClient(server.port)
    data = b''.join(authors_payload(i, 'AC', float(i)) for i in range(5))
    for i in range(0, len(data), 37):
        client.send(data[i : i + 37])
    assert _pump(server, lambda: len(server.reports_seen) == 5)
    assert [r.azimuth_deg for r in server.reports_seen] == [0.0, 1.0, 2.0, 3.0, 4.0]
    client.close()


def test_server_counts_a_report_with_a_huge_number_as_invalid_and_keeps_the_client(server):
    client = FakeLocatorClient(server.port)
    client.send(b'{"tagId":"D2","azimuth":' + b'9' * 400 + b'}')
    assert _pump(server, lambda: server.invalid_reports == 1)
    client.send(ndjson_payload(1, 'C3', 9.0))
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    assert server.client_connected
    assert server.disconnects == 0
    assert 'not finite' in server.last_error
    client.close()


def test_a_closed_server_still_reports_its_port_and_closes_only_once():
    srv = LocatorServer('127.0.0.1', 0, print)
    port = srv.port
    srv.close()
    assert srv.closed
    assert srv.port == port  # no call on the closed socket (EBADF)
    srv.close()


def test_server_counts_malformed_and_invalid_reports_and_keeps_going(server):
    client = FakeLocatorClient(server.port)
    client.send(b'{"tagId": 5, "azimuth": 1}\r\n{bad json}\r\n' + ndjson_payload(1, 'C3', 9.0))
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    assert server.invalid_reports == 1
    assert server.decoder.malformed == 1
    client.close()


def test_oversized_json_from_a_client_resets_the_buffer(server):
    client = FakeLocatorClient(server.port)
    client.send(b'{"tagId": "' + b'x' * 10000)
    client.send(b'"}\n' + ndjson_payload(1, 'C3', 9.0))
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    assert server.decoder.overflows >= 1
    client.close()


def test_abrupt_disconnect_and_reconnect_continue(server):
    client = FakeLocatorClient(server.port)
    client.send(authors_payload(1, 'AC', 1.0) + b'{"tagId": "AC", "azi')
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    client.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b'\x01\x00\x00\x00\x00\x00\x00\x00')
    client.close()
    assert _pump(server, lambda: server.disconnects == 1)
    assert server.decoder.buffered_chars == 0  # the half object died with the connection
    client = FakeLocatorClient(server.port)
    client.send(authors_payload(2, 'AC', 2.0))
    assert _pump(server, lambda: len(server.reports_seen) == 2)
    client.close()


def test_a_second_client_replaces_the_first(server):
    first = FakeLocatorClient(server.port)
    first.send(ndjson_payload(1, 'AC', 1.0))
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    second = FakeLocatorClient(server.port)
    second.send(ndjson_payload(2, 'AC', 2.0))
    assert _pump(server, lambda: len(server.reports_seen) == 2)
    assert server.replaced_clients == 1
    first.close()
    second.close()


def test_slow_client_sending_byte_by_byte_is_served(server):
    client = FakeLocatorClient(server.port)
    for byte in authors_payload(1, 'D2', 33.0):
        client.send(bytes((byte,)))
        server.poll()
    assert _pump(server, lambda: len(server.reports_seen) == 1)
    client.close()


def test_flooding_client_is_read_in_bounded_slices(server):
    server.max_read_per_poll = 8192
    client = FakeLocatorClient(server.port)
    line = ndjson_payload(0, 'AC', 1.0)
    burst = b''.join(ndjson_payload(i, 'AC', 1.0) for i in range(3000))
    sender = threading.Thread(target=client.send, args=(burst,))
    sender.start()
    assert _pump(server, lambda: server.client_connected)
    time.sleep(0.05)
    per_poll = []
    while len(server.reports_seen) < 3000 and len(per_poll) < 1000:
        before = len(server.reports_seen)
        server.poll()
        per_poll.append(len(server.reports_seen) - before)
    sender.join(2.0)
    assert len(server.reports_seen) == 3000
    assert max(per_poll) <= 8192 // len(line) + 1
    client.close()


def test_port_in_use_is_recoverable():
    holder = LocatorServer('127.0.0.1', 0, print)
    try:
        with pytest.raises(DeviceUnavailableError, match='cannot listen'):
            LocatorServer('127.0.0.1', holder.port, print)
    finally:
        holder.close()
