"""Hypothesis fuzzing of every parser: only documented exceptions escape, state stays sound."""

import itertools
import json
import math

import numpy as np
import pytest
from hw_drivers.aoa_protocol import JsonStreamDecoder, SequenceFilter, parse_angle_report
from hw_drivers.errors import DeviceIdentityError, DeviceTimeoutError, ProtocolError
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.fakes.i2c import FakeSMBus
from hw_drivers.fakes.lidar import encode_sample
from hw_drivers.fakes.locator import authors_payload, ndjson_payload
from hw_drivers.gas_device import AdsGasBackend, GroveHatGasBackend, XiaoGasBackend
from hw_drivers.gas_protocol import (
    AdsChip,
    AdsConfig,
    decode_ads_conversion,
    decode_xiao_reply,
    grove_ratio_to_raw10,
)
from hw_drivers.mpu6050_device import Mpu6050
from hw_drivers.mpu6050_protocol import Mpu6050Config, decode_data_block
from hw_drivers.pump_control import PumpController, PumpLimits
from hw_drivers.rplidar_protocol import (
    HEALTH_DESCRIPTOR,
    Revolution,
    RevolutionAssembler,
    SampleStreamDecoder,
    ScanBinning,
    bin_revolution,
    check_descriptor,
    decode_health,
    decode_info,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

FUZZ = settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])

chunks = st.lists(st.binary(max_size=64), max_size=20)


def _only_protocol_errors(function, *args):
    try:
        return function(*args)
    except ProtocolError:
        return None


@FUZZ
@given(st.binary(max_size=40))
def test_lidar_response_decoders_raise_only_protocol_errors(data):
    _only_protocol_errors(check_descriptor, data, HEALTH_DESCRIPTOR)
    _only_protocol_errors(decode_info, data)
    _only_protocol_errors(decode_health, data)


@FUZZ
@given(chunks)
def test_sample_decoder_accounts_for_every_byte_and_emits_only_valid_samples(parts):
    decoder = SampleStreamDecoder()
    total = 0
    accepted = 0
    for part in parts:
        out = decoder.feed(part)
        total += len(part)
        accepted += len(out)
        assert np.all(out.quality <= 63)
        assert np.all((out.angle_deg >= 0.0) & (out.angle_deg < 360.0))
        assert np.all(out.distance_mm >= 0.0)
    pending = total - 5 * accepted - decoder.rejected_bytes
    assert pending == decoder.pending_bytes
    config = decoder.config
    assert 0 <= pending <= 5 * config.compare_samples + config.compare_offsets - 2


@FUZZ
@given(chunks, st.data())
def test_sample_decoder_gives_the_same_samples_whatever_the_read_boundaries(parts, data):
    stream = b''.join(parts)
    whole = SampleStreamDecoder().feed(stream)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=10)))
    decoder = SampleStreamDecoder()
    pieces = [
        decoder.feed(stream[a:b]) for a, b in zip([0, *cuts], [*cuts, len(stream)], strict=False)
    ]
    angles = np.concatenate([p.angle_deg for p in pieces])
    np.testing.assert_array_equal(angles, whole.angle_deg)


@FUZZ
@given(st.binary(max_size=200), st.binary(max_size=200))
def test_valid_samples_after_junk_are_all_recovered_once_in_sync(junk, more_junk):
    good = b''.join(encode_sample(k * 10.0 + 1.0, 1000.0 + k, 20, start=k == 0) for k in range(36))
    decoder = SampleStreamDecoder()
    decoder.feed(junk)
    out = decoder.feed(good * 3 + more_junk)
    # Junk may swallow or fake a few samples at the start, never more than a handful.
    assert len(out) >= 3 * 36 - 4


@FUZZ
@given(
    st.lists(
        st.tuples(st.booleans(), st.floats(0.0, 359.98), st.floats(0.0, 16000.0)), max_size=300
    ),
    st.integers(1, 100),
)
def test_assembler_never_invents_samples(samples, min_points):
    stream = b''.join(encode_sample(a, d, 10, start=s) for s, a, d in samples)
    decoded = SampleStreamDecoder().feed(stream)
    revolutions = RevolutionAssembler(min_points=min_points).add(decoded, 0.0)
    assert sum(len(r) for r in revolutions) <= len(decoded)
    assert all(len(r) >= min_points for r in revolutions)


@FUZZ
@given(
    st.lists(st.tuples(st.floats(0.0, 359.99), st.floats(0.0, 20000.0)), min_size=1, max_size=50),
    st.integers(4, 720),
    st.sampled_from([-1, 1]),
    st.floats(-10.0, 10.0),
)
def test_binning_yields_valid_ranges_or_rep117_markers(samples, bins, direction, offset):
    binning = ScanBinning(bins=bins, angle_direction=direction, zero_offset_rad=offset)
    revolution = Revolution(
        angle_deg=np.array([a for a, _ in samples]),
        distance_mm=np.array([d for _, d in samples]),
        quality=np.full(len(samples), 5, dtype=np.uint8),
        start_time_s=0.0,
        period_s=0.2,
    )
    ranges, intensities = bin_revolution(revolution, binning)
    assert ranges.shape == intensities.shape == (bins,)
    finite = ranges[np.isfinite(ranges)]
    assert np.all((finite >= binning.range_min_m - 1e-6) & (finite <= binning.range_max_m + 1e-3))
    # -inf (REP 117: closer than range_min) only where such a sample exists.
    too_close = [d for _, d in samples if d > 0.0 and d / 1000.0 < binning.range_min_m]
    assert np.count_nonzero(np.isneginf(ranges)) <= len(too_close)
    assert np.count_nonzero(~np.isnan(ranges)) <= len(samples)


@FUZZ
@given(st.binary(min_size=2, max_size=2), st.sampled_from(list(AdsChip)))
def test_any_ads_conversion_decodes_within_the_full_scale(data, chip):
    config = AdsConfig(chip=chip, data_rate_sps=128 if chip is AdsChip.ADS1115 else 1600)
    counts, volts = decode_ads_conversion(data, config)
    assert 0.0 <= volts <= config.full_scale_v
    assert isinstance(counts, int)


@FUZZ
@given(st.binary(max_size=120))
def test_gas_reply_decoder_raises_only_protocol_errors_on_bytes(data):
    sample = _only_protocol_errors(decode_xiao_reply, data)
    if sample is not None:
        assert 0 <= sample.value <= 1023


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda children: (
        st.lists(children, max_size=4)
        | st.dictionaries(
            st.sampled_from(['type', 'value', 'timeStamp', 'tagId', 'azimuth', 'quality', 'x']),
            children,
            max_size=5,
        )
    ),
    max_leaves=12,
)


@FUZZ
@given(json_values)
def test_gas_reply_decoder_on_any_json(value):
    data = json.dumps(value, allow_nan=True).encode()
    _only_protocol_errors(decode_xiao_reply, data)


@FUZZ
@given(json_values)
def test_angle_report_parser_on_any_json(value):
    report = _only_protocol_errors(parse_angle_report, value)
    if report is not None:
        assert -180.0 < report.azimuth_deg <= 180.0
        assert report.tag_id == report.tag_id.strip().upper()
        assert report.sequence is None or 0 <= report.sequence <= 0xFFFF


@FUZZ
@given(st.binary(min_size=14, max_size=14))
def test_any_mpu_data_block_decodes(data):
    raw = decode_data_block(data)
    assert all(-32768 <= v <= 32767 for v in (*raw.accel, raw.temperature, *raw.gyro))


@FUZZ
@given(st.binary(max_size=30).filter(lambda b: len(b) != 14))
def test_mpu_blocks_of_the_wrong_size_are_protocol_errors(data):
    assert _only_protocol_errors(decode_data_block, data) is None


@FUZZ
@given(chunks)
def test_json_stream_decoder_survives_any_bytes_within_its_buffer_cap(parts):
    decoder = JsonStreamDecoder(max_buffer_bytes=256)
    for part in parts:
        decoder.feed(part)
        assert decoder.buffered_chars <= 256


garbage = st.binary(max_size=30).filter(lambda b: b'{' not in b and b'"' not in b)


@FUZZ
@given(st.lists(st.tuples(garbage, st.booleans()), min_size=1, max_size=8), st.data())
def test_json_stream_decoder_recovers_every_object_between_garbage(items, data):
    stream = b''
    for i, (junk, authors) in enumerate(items):
        payload = authors_payload(i, 'AC', 1.0) if authors else ndjson_payload(i, 'AC', 1.0)
        stream += junk + payload
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=12)))
    decoder = JsonStreamDecoder()
    objects = []
    for a, b in zip([0, *cuts], [*cuts, len(stream)], strict=False):
        objects += decoder.feed(stream[a:b])
    numbers = [o.get('timeStamp', o.get('sequence')) for o in objects if isinstance(o, dict)]
    assert numbers == list(range(len(items)))


@FUZZ
@given(st.lists(st.tuples(st.text('ABCD', min_size=1, max_size=1), st.integers(0, 65535))))
def test_sequence_filter_never_accepts_an_exact_repeat(reports):
    seq = SequenceFilter()
    last = {}
    for tag, number in reports:
        accepted = seq.accept(tag, number)
        if last.get(tag) == number:
            assert not accepted
        if accepted:
            last[tag] = number


@FUZZ
@given(
    st.lists(st.tuples(st.floats(0.0, 0.3), st.booleans()), max_size=60),
    st.floats(0.05, 2.0),
    st.floats(0.0, 2.0),
    st.floats(0.05, 1.0),
)
def test_pump_never_breaks_its_limits_whatever_the_commands(steps, max_on, min_off, timeout):
    limits = PumpLimits(max_on_s=max_on, min_off_s=min_off, command_timeout_s=timeout)
    controller = PumpController(limits)
    t = 0.0
    on_since = None
    off_since = -math.inf
    last_command = -math.inf
    tick = 0.01
    for gap, level in steps:
        end = t + gap
        while t < end:
            t += tick
            out = controller.update(t)
            if out and on_since is None:
                assert t - off_since >= min_off - 1e-9
                assert t - last_command <= timeout + 1e-9
                on_since = t
            if not out and on_since is not None:
                off_since, on_since = t, None
            if on_since is not None:
                assert t - on_since <= max_on + tick + 1e-9
        out = controller.command(level, t)
        last_command = t
        if out and on_since is None:
            assert t - off_since >= min_off - 1e-9
            on_since = t
        if not out and on_since is not None:
            off_since, on_since = t, None


@FUZZ
@given(st.integers(-(2**16), 2**16))
def test_grove_ratio_register_maps_or_raises_only_protocol_errors(word):
    raw10 = _only_protocol_errors(grove_ratio_to_raw10, word)
    assert raw10 is None or 0 <= raw10 <= 1023


# --- devices answering junk: only documented, recoverable errors, and no reading ---------


class _JunkPort:
    """A serial port that answers anything with random bytes (a wrong or noisy device)."""

    def __init__(self, seed, max_chunk):
        self._rng = np.random.default_rng(seed)
        self._max_chunk = max_chunk
        self.reads = 0

    @property
    def in_waiting(self):
        return int(self._rng.integers(0, self._max_chunk + 1))

    def read(self, size=1):
        self.reads += 1
        count = int(self._rng.integers(0, min(size, self._max_chunk) + 1))
        return self._rng.integers(0, 256, count, dtype=np.uint8).tobytes()

    def write(self, data):
        return len(data)

    def reset_input_buffer(self):
        pass

    def close(self):
        pass


class _JunkRegisters:
    """An I2C device whose every register reads as random bytes."""

    def __init__(self, seed):
        self._rng = np.random.default_rng(seed)

    def read(self, register, length):
        return self._rng.integers(0, 256, length).tolist()

    def write(self, register, data):
        pass


def _ticking_clock():
    clock = FakeClock()

    def now():
        clock.advance(0.001)
        return clock()

    return now


@FUZZ
@given(st.integers(0, 2**31), st.integers(1, 64))
def test_a_gas_board_sending_random_bytes_yields_no_reading(seed, max_chunk):
    backend = XiaoGasBackend(_JunkPort(seed, max_chunk), clock=_ticking_clock())
    for _ in range(20):
        with pytest.raises((ProtocolError, DeviceTimeoutError)):
            backend.read()


@FUZZ
@given(st.integers(0, 2**31))
def test_random_register_contents_are_never_taken_for_an_mpu6050(seed):
    bus = FakeSMBus({0x68: _JunkRegisters(seed)})
    device = Mpu6050(bus, Mpu6050Config(), sleep=lambda _s: None)
    with pytest.raises((DeviceIdentityError, ProtocolError)):
        device.initialise()


@FUZZ
@given(st.integers(0, 2**31), st.sampled_from(list(AdsChip)))
def test_random_register_contents_are_never_taken_for_an_ads1x15(seed, chip):
    config = AdsConfig(chip=chip, data_rate_sps=128 if chip is AdsChip.ADS1115 else 1600)
    bus = FakeSMBus({0x48: _JunkRegisters(seed)})
    with pytest.raises(DeviceIdentityError):
        AdsGasBackend(bus, config=config, sleep=lambda _s: None, clock=_ticking_clock())


@FUZZ
@given(st.integers(0, 2**31))
def test_random_register_contents_are_never_taken_for_a_grove_hat(seed):
    bus = FakeSMBus({0x04: _JunkRegisters(seed)})
    with pytest.raises(DeviceIdentityError):
        GroveHatGasBackend(bus)


@FUZZ
@given(st.integers(0, 2**31), st.integers(1, 20_000), st.lists(st.integers(0, 20_000)))
def test_random_bytes_from_the_locator_yield_no_report(seed, size, cuts):
    junk = np.random.default_rng(seed).integers(0, 256, size, dtype=np.uint8).tobytes()
    decoder = JsonStreamDecoder()
    reports = []
    bounds = [0, *sorted(c for c in cuts if c <= size), size]
    for a, b in itertools.pairwise(bounds):
        for value in decoder.feed(junk[a:b]):
            report = _only_protocol_errors(parse_angle_report, value)
            if report is not None:
                reports.append(report)
    assert reports == []
    assert decoder.buffered_chars <= 16 * 1024
