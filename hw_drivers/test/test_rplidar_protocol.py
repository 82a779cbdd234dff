"""RPLidar codec: requests, descriptors, info/health, sample stream, revolutions, binning."""

import math

import numpy as np
import pytest
from hw_drivers.errors import ConfigurationError, ProtocolError
from hw_drivers.fakes.lidar import FakeRPLidar, RectangularRoom, encode_sample, revolution_bytes
from hw_drivers.rplidar_protocol import (
    HEALTH_DESCRIPTOR,
    INFO_DESCRIPTOR,
    MAX_BINS,
    SCAN_DESCRIPTOR,
    Command,
    HealthStatus,
    Revolution,
    RevolutionAssembler,
    SampleStreamDecoder,
    ScanBinning,
    SendMode,
    bin_revolution,
    check_descriptor,
    decode_descriptor,
    decode_health,
    decode_info,
    decode_samples,
    encode_request,
)


def test_requests_without_payload_are_two_bytes():
    assert encode_request(Command.STOP) == b'\xa5\x25'
    assert encode_request(Command.SCAN) == b'\xa5\x20'


def test_request_with_payload_carries_size_and_xor_checksum():
    # The documented legacy express-scan request.
    packet = encode_request(0x82, bytes(5))
    assert packet == bytes.fromhex('A582050000000000 22'.replace(' ', ''))


def test_scan_descriptor_decodes_length_mode_and_type():
    descriptor = decode_descriptor(bytes.fromhex('A55A0500004081'))
    assert descriptor == SCAN_DESCRIPTOR
    assert descriptor.send_mode is SendMode.MULTIPLE


@pytest.mark.parametrize(
    ('raw', 'expected'),
    [('A55A1400000004', INFO_DESCRIPTOR), ('A55A0300000006', HEALTH_DESCRIPTOR)],
)
def test_single_response_descriptors_are_recognised(raw, expected):
    assert check_descriptor(bytes.fromhex(raw), expected) == expected


@pytest.mark.parametrize(
    ('raw', 'match'),
    [
        ('A55A05000040', 'must be 7 bytes'),
        ('A5A50500004081', 'sync bytes'),
        ('A55A0500004082', 'unexpected descriptor'),
        ('A55A0400004081', 'unexpected descriptor'),
        ('A55A0500000081', 'unexpected descriptor'),
    ],
)
def test_wrong_descriptors_are_rejected(raw, match):
    data = bytes.fromhex(raw)
    with pytest.raises(ProtocolError, match=match):
        check_descriptor(data, SCAN_DESCRIPTOR)


def test_info_payload_decodes_model_firmware_hardware_and_serial():
    info = decode_info(bytes((0x18, 29, 1, 7)) + bytes(range(16)))
    assert (info.model, info.firmware, info.hardware) == (24, '1.29', 7)
    assert info.serial_number == '000102030405060708090A0B0C0D0E0F'


def test_health_error_code_is_little_endian():
    health = decode_health(bytes((2, 0x34, 0x12)))
    assert health.status is HealthStatus.ERROR
    assert health.error_code == 0x1234


def test_health_with_unknown_status_is_a_protocol_error():
    with pytest.raises(ProtocolError, match='unknown health status 7'):
        decode_health(bytes((7, 0, 0)))


def _run_from(first: bytes, count: int = 3) -> bytes:
    """``first`` followed by ``count`` samples that continue its rotation 1 deg at a time."""
    angle_q6 = (first[1] >> 1) | (first[2] << 7)
    distance_mm = (first[3] | first[4] << 8) / 4.0
    return first + b''.join(
        encode_sample(angle_q6 / 64.0 + k, distance_mm, first[0] >> 2, start=False)
        for k in range(1, count + 1)
    )


def test_documented_sample_decodes_to_90_degrees_and_one_metre():
    frame = bytes.fromhex('3D012DA00F')
    direct = decode_samples(np.frombuffer(frame, dtype=np.uint8).reshape(1, 5))
    samples = SampleStreamDecoder().feed(_run_from(frame, 11))
    for decoded in (direct, samples):
        assert bool(decoded.start[0])
        assert decoded.quality[0] == 15
        assert decoded.angle_deg[0] == pytest.approx(90.0)
        assert decoded.distance_mm[0] == pytest.approx(1000.0)
    assert len(samples) == 11  # the last one waits for its successor


def test_a_lone_window_that_passes_the_check_bits_is_not_a_sample():
    decoder = SampleStreamDecoder()
    assert len(decoder.feed(bytes.fromhex('3D012DA00F') + bytes(20))) == 0
    assert decoder.rejected_bytes == 25 - decoder.pending_bytes


@pytest.mark.parametrize(
    'corrupt',
    [
        bytes.fromhex('3F012DA00F'),  # S = !S = 1
        bytes.fromhex('3C012DA00F'),  # S = !S = 0
        bytes.fromhex('3D002DA00F'),  # check bit C = 0
        bytes.fromhex('3D01FFA00F'),  # angle beyond 360 degrees
        encode_sample(300.0, 1000.0, 15, start=False),  # angle far from its neighbours
    ],
)
def test_samples_failing_the_checks_are_rejected_and_their_neighbours_kept(corrupt):
    before = b''.join(encode_sample(80.0 + k, 1000.0, 15, start=False) for k in range(6))
    after = b''.join(encode_sample(87.0 + k, 1000.0, 15, start=False) for k in range(12))
    decoder = SampleStreamDecoder()
    out = decoder.feed(before + corrupt + after)
    np.testing.assert_allclose(out.angle_deg, [*range(80, 86), *range(87, 98)])
    assert decoder.rejected_bytes == 5


def test_decoder_resynchronises_after_junk_and_counts_dropped_bytes():
    good = revolution_bytes(FakeRPLidar(), 1)
    junk = bytes((0xFF, 0x00, 0xFF))
    decoder = SampleStreamDecoder()
    out = decoder.feed(good[:50] + junk + good[50:])
    # Every sample but the last, which waits for its successor.
    assert len(out) == 359
    assert decoder.pending_bytes == 5
    assert decoder.rejected_bytes == 3
    np.testing.assert_allclose(np.diff(out.angle_deg), 1.0)


def test_decoder_joins_samples_split_across_reads():
    data = revolution_bytes(FakeRPLidar(), 1)
    whole = SampleStreamDecoder().feed(data)
    decoder = SampleStreamDecoder()
    parts = [decoder.feed(data[i : i + 7]) for i in range(0, len(data), 7)]
    angles = np.concatenate([p.angle_deg for p in parts])
    np.testing.assert_array_equal(angles, whole.angle_deg)
    assert decoder.rejected_bytes == 0


def test_decoder_recovers_from_a_dropped_byte_within_a_few_samples():
    data = revolution_bytes(FakeRPLidar(), 2)
    damaged = data[:101] + data[102:]
    out = SampleStreamDecoder().feed(damaged)
    # The damaged sample is lost; at most a handful of neighbours with it.
    assert 720 - 5 <= len(out) <= 719
    assert np.all(out.distance_mm[-300:] > 0)


def test_revolutions_are_cut_at_start_flags_and_the_partial_first_one_dropped():
    device = FakeRPLidar()
    data = revolution_bytes(device, 3)
    samples = SampleStreamDecoder().feed(data[5 * 300 :])  # begins mid-revolution
    assembler = RevolutionAssembler()
    revolutions = assembler.add(samples, 1.0)
    # 60 samples of a revolution whose start was missed, one full, the last one still open.
    assert [len(r) for r in revolutions] == [360]
    assert revolutions[0].angle_deg[0] == pytest.approx(0.25)
    assert assembler.dropped_revolutions == 1


def test_partial_revolutions_below_min_points_are_dropped():
    # A revolution with only 20 samples left (the rest lost to noise) between two good ones.
    counts = (100, 20, 100, 50)
    out = bytearray()
    for count in counts:
        out += b''.join(
            encode_sample(k * 300.0 / count, 800.0, 9, start=k == 0) for k in range(count)
        )
    assembler = RevolutionAssembler(min_points=50)
    revolutions = assembler.add(SampleStreamDecoder().feed(bytes(out)), 0.0)
    assert [len(r) for r in revolutions] == [100, 100]
    assert assembler.dropped_revolutions == 1


def test_a_missed_start_flag_cuts_the_revolution_where_it_completed_a_turn():
    out = bytearray()
    for turn in range(3):
        for k in range(100):
            out += encode_sample(k * 3.6 + 0.5, 1000.0, 30, start=turn == 0 and k == 0)
    assembler = RevolutionAssembler()
    revolutions = assembler.add(SampleStreamDecoder().feed(bytes(out)), 0.0)
    assert [len(r) for r in revolutions] == [100, 100]


def test_revolution_period_comes_from_receive_times():
    data = revolution_bytes(FakeRPLidar(), 3)
    decoder = SampleStreamDecoder()
    assembler = RevolutionAssembler()
    revolutions = []
    for i, t in enumerate((0.0, 0.18, 0.36)):
        revolutions += assembler.add(decoder.feed(data[i * 1800 : (i + 1) * 1800]), t)
    assert [r.start_time_s for r in revolutions] == [0.0, 0.18]
    assert [r.period_s for r in revolutions] == pytest.approx([0.18, 0.18])


def _revolution(angles_deg, distances_mm):
    return Revolution(
        angle_deg=np.asarray(angles_deg, dtype=float),
        distance_mm=np.asarray(distances_mm, dtype=float),
        quality=np.full(len(angles_deg), 20, dtype=np.uint8),
        start_time_s=0.0,
        period_s=0.2,
    )


def test_default_binning_puts_device_180_degrees_straight_ahead_and_90_to_the_right():
    binning = ScanBinning(bins=360)
    ranges, _ = bin_revolution(_revolution([180.0, 90.0, 270.0], [1000, 2000, 3000]), binning)
    angles = binning.angle_min_rad + binning.angle_increment_rad * np.arange(360)
    assert ranges[np.argmin(np.abs(angles - 0.0))] == pytest.approx(1.0)
    # Device 90 deg (clockwise) -> ROS pi - pi/2 = +pi/2 (left).
    assert ranges[np.argmin(np.abs(angles - math.pi / 2))] == pytest.approx(2.0)
    assert ranges[np.argmin(np.abs(angles + math.pi / 2))] == pytest.approx(3.0)


def test_binning_direction_and_offset_are_parameters():
    binning = ScanBinning(bins=360, angle_direction=1, zero_offset_rad=0.0)
    ranges, _ = bin_revolution(_revolution([90.0], [1500]), binning)
    assert np.nanargmin(ranges) == 270  # +90 deg counter-clockwise = bin 270 from -180 deg


def test_invalid_samples_follow_rep_117():
    binning = ScanBinning(bins=8, angle_direction=1, zero_offset_rad=0.0, range_max_m=5.0)
    # bins at -180,-135,...,135 deg; device angle a maps to bin (a+180)/45.
    revolution = _revolution([0.0, 45.0, 90.0], [0.0, 100.0, 6000.0])
    ranges, _ = bin_revolution(revolution, binning)
    assert math.isinf(ranges[4])
    assert ranges[4] > 0
    assert ranges[5] == -math.inf  # closer than range_min
    assert math.isinf(ranges[6])  # beyond range_max
    assert math.isnan(ranges[0])  # no sample at all


def test_nearest_finite_range_wins_a_shared_bin():
    binning = ScanBinning(bins=4, angle_direction=1, zero_offset_rad=0.0)
    revolution = _revolution([0.0, 1.0, 2.0, 3.0], [0.0, 2500.0, 1200.0, 3000.0])
    ranges, intensities = bin_revolution(revolution, binning)
    assert ranges[2] == pytest.approx(1.2)
    assert intensities[2] == 20


def test_synthetic_room_scan_matches_the_room_geometry():
    room = RectangularRoom(width_m=4.0, depth_m=3.0, x_m=1.0, y_m=1.0, heading_rad=math.pi)
    data = revolution_bytes(FakeRPLidar(room, samples_per_revolution=720), 2)
    revolutions = RevolutionAssembler().add(SampleStreamDecoder().feed(data), 0.0)
    ranges, _ = bin_revolution(revolutions[0], ScanBinning(bins=360))
    # Device 0 deg points along room -x (heading pi); default mapping puts device 180 deg ahead,
    # i.e. laser +x = room +x: wall ahead at 3 m, left (room +y) at 2 m, right at 1 m, back 1 m.
    assert ranges[180] == pytest.approx(3.0, abs=0.01)
    assert ranges[270] == pytest.approx(2.0, abs=0.01)
    assert ranges[90] == pytest.approx(1.0, abs=0.01)
    assert ranges[0] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize(
    'kwargs',
    [
        {'bins': 2},
        {'bins': MAX_BINS + 1},
        {'bins': 1_000_000_000},
        {'angle_direction': 0},
        {'range_min_m': 5.0, 'range_max_m': 1.0},
    ],
)
def test_impossible_binning_is_refused(kwargs):
    with pytest.raises(ConfigurationError):
        ScanBinning(**kwargs)


def test_the_most_bins_allowed_still_bin_a_revolution():
    binning = ScanBinning(bins=MAX_BINS, angle_direction=1, zero_offset_rad=0.0)
    ranges, _ = bin_revolution(_revolution([90.0], [1500]), binning)
    assert ranges.shape == (MAX_BINS,)
    assert np.nanmin(ranges) == pytest.approx(1.5)
