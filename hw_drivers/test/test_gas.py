"""Gas sensor: ADC codecs, the 10-bit mapping, three backends with fakes, warm-up."""

import errno
import itertools
import math
import os
import threading

import pytest
import serial
from hw_drivers.errors import (
    ConfigurationError,
    DeviceIdentityError,
    DeviceTimeoutError,
    DeviceUnavailableError,
    ProtocolError,
)
from hw_drivers.fakes.clock import FakeClock
from hw_drivers.fakes.gas_mcu import FakeGasMcu, FakeGasMcuPort, xiao_reply
from hw_drivers.fakes.i2c import FakeAds1115, FakeGroveHat, FakeSMBus
from hw_drivers.gas_device import (
    AdsGasBackend,
    GasSession,
    GroveHatGasBackend,
    WarmUp,
    XiaoGasBackend,
)
from hw_drivers.gas_protocol import (
    AdsChip,
    AdsConfig,
    ads_config_matches,
    decode_ads_conversion,
    decode_xiao_reply,
    encode_ads_config,
    grove_ratio_to_raw10,
    volts_to_raw10,
)
from hw_drivers.worker import DeviceWorker


def test_ads_config_word_matches_the_datasheet_example():
    # Single-shot AIN0 vs GND, +-4.096 V, 128 SPS, comparator off.
    assert encode_ads_config(AdsConfig()) == 0xC383
    assert encode_ads_config(AdsConfig(), start=False) == 0x4383


def test_ads_config_read_back_ignores_the_os_bit_only():
    config = AdsConfig(channel=2, full_scale_v=2.048)
    word = encode_ads_config(config, start=False)
    assert ads_config_matches(word | 0x8000, config)
    assert not ads_config_matches(word ^ 0x0200, config)


@pytest.mark.parametrize(
    ('data', 'counts', 'volts'),
    [
        ([0x00, 0x00], 0, 0.0),
        ([0x7F, 0xFF], 32767, 4.096 * 32767 / 32768),
        ([0x40, 0x00], 16384, 2.048),
        ([0xFF, 0xF0], -16, 0.0),  # slightly negative near 0 V clamps to 0 V
    ],
)
def test_ads1115_conversion_to_volts_at_edge_values(data, counts, volts):
    assert decode_ads_conversion(data, AdsConfig()) == (counts, pytest.approx(volts))


def test_ads1015_result_is_left_justified_12_bit():
    config = AdsConfig(chip=AdsChip.ADS1015, data_rate_sps=1600)
    assert decode_ads_conversion([0x7F, 0xF0], config) == (2047, pytest.approx(4.094))


@pytest.mark.parametrize(
    ('volts', 'supply', 'raw10'),
    [(0.0, 3.3, 0), (3.3, 3.3, 1023), (5.0, 3.3, 1023), (-0.2, 3.3, 0), (0.645, 3.3, 200)],
)
def test_volts_map_to_the_paper_10_bit_scale(volts, supply, raw10):
    assert volts_to_raw10(volts, supply) == raw10


def test_non_positive_supply_is_a_configuration_error():
    with pytest.raises(ConfigurationError, match='supply voltage'):
        volts_to_raw10(1.0, 0.0)


@pytest.mark.parametrize(('ratio', 'raw10'), [(0, 0), (1000, 1023), (500, 512)])
def test_grove_ratio_maps_to_10_bits(ratio, raw10):
    assert grove_ratio_to_raw10(ratio) == raw10


def test_grove_ratio_out_of_range_is_a_protocol_error():
    with pytest.raises(ProtocolError, match='out of range'):
        grove_ratio_to_raw10(1001)


@pytest.mark.parametrize('kwargs', [{'channel': 4}, {'full_scale_v': 3.3}, {'data_rate_sps': 100}])
def test_impossible_ads_settings_are_refused(kwargs):
    with pytest.raises(ConfigurationError):
        AdsConfig(**kwargs)


def test_xiao_multi_line_reply_decodes():
    sample = decode_xiao_reply(xiao_reply(17, 84).rstrip(b'\r\n'))
    assert (sample.counter, sample.value) == (17, 84)


@pytest.mark.parametrize(
    ('reply', 'match'),
    [
        (b'{"timeStamp": 1, "type": "olfactory", "val', 'not JSON'),
        (b'[1, 2]', 'not a JSON object'),
        (b'{"timeStamp": 1, "type": "motion", "value": 3}', 'expected "olfactory"'),
        (b'{"timeStamp": 1, "type": "olfactory", "value": 2000}', '0..1023'),
        (b'{"timeStamp": 1, "type": "olfactory", "value": 3.5}', '0..1023'),
        (b'{"timeStamp": -1, "type": "olfactory", "value": 3}', 'unsigned'),
        (b'\xff\xfe', 'not JSON'),
        (b'[' * 100000, 'longer than 1024 bytes'),
        (b'[' * 1000, 'not JSON'),  # nesting past the recursion limit, within the length
        (b'{"timeStamp": 1, "type": "olfactory", "value": ' + b'9' * 400 + b'}', '0..1023'),
        (b'{"timeStamp": ' + b'9' * 400 + b', "type": "olfactory", "value": 3}', 'unsigned'),
        (b'{"timeStamp": 1, "type": "olfactory", "value": NaN}', '0..1023'),
        (b'{"timeStamp": 1, "type": "olfactory", "value": -Infinity}', '0..1023'),
        (b'{"timeStamp": 1, "type": "olfactory", "value": 1e999}', '0..1023'),
    ],
)
def test_bad_xiao_replies_are_protocol_errors(reply, match):
    with pytest.raises(ProtocolError, match=match) as raised:
        decode_xiao_reply(reply)
    assert len(str(raised.value)) < 160
    assert '\n' not in str(raised.value)


def _ads(volts=0.645, **kwargs):
    clock = FakeClock()
    chip = FakeAds1115(clock, volts=volts)
    bus = FakeSMBus({0x48: chip})
    backend = AdsGasBackend(bus, sleep=clock.sleep, clock=clock, **kwargs)
    return backend, chip, bus, clock


def test_ads_backend_averages_single_shot_conversions_onto_the_10_bit_scale():
    backend, chip, _, _ = _ads(volts=0.645, averaging=4)
    sample = backend.read()
    assert chip.conversions_started == 4
    assert sample.raw10 == 200
    assert sample.volts == pytest.approx(0.645, abs=2e-4)
    assert not sample.pinned


def test_ads_backend_flags_a_reading_pinned_at_zero():
    backend, _, _, _ = _ads(volts=0.0)
    assert backend.read().pinned


def test_ads_conversion_that_never_completes_times_out():
    backend, chip, _, _ = _ads()
    chip.never_completes = True
    with pytest.raises(DeviceTimeoutError, match='OS stayed 0'):
        backend.read()


def test_ads_nack_is_a_recoverable_unavailable_error():
    backend, _, bus, _ = _ads()
    bus.fail_next(errno.EREMOTEIO)
    with pytest.raises(DeviceUnavailableError, match='NACK'):
        backend.read()
    assert backend.read().raw10 == 200  # the next transfer works again


def test_ads_bus_timeout_is_a_timeout_error():
    backend, _, bus, _ = _ads()
    bus.fail_next(errno.ETIMEDOUT)
    with pytest.raises(DeviceTimeoutError, match='bus timeout'):
        backend.read()


def test_wrong_chip_at_the_ads_address_fails_the_config_read_back():
    clock = FakeClock()
    bus = FakeSMBus({0x48: FakeGroveHat()})
    with pytest.raises(DeviceIdentityError, match='config read back'):
        AdsGasBackend(bus, sleep=clock.sleep, clock=clock)


def test_grove_hat_backend_reads_the_ratio_register():
    hat = FakeGroveHat(supply_mv=3300)
    hat.channel_mv[0] = 645
    backend = GroveHatGasBackend(FakeSMBus({0x04: hat}), channel=0)
    sample = backend.read()
    # The ratio register has 0.1 % resolution: within one count of 1023 * 0.645 / 3.3.
    assert abs(sample.raw10 - 1023 * 0.645 / 3.3) <= 1.0
    assert sample.volts == pytest.approx(0.645)


def test_grove_hat_backend_refuses_an_unknown_product_id():
    with pytest.raises(DeviceIdentityError, match='product id 0x0099'):
        GroveHatGasBackend(FakeSMBus({0x04: FakeGroveHat(product_id=0x99)}))


def test_xiao_backend_requests_and_decodes_one_reply():
    port = FakeGasMcuPort(FakeGasMcu(lambda: 312))
    backend = XiaoGasBackend(port)
    sample = backend.read()
    assert sample.raw10 == 312
    assert sample.volts == pytest.approx(312 * 3.3 / 1023)
    assert backend.read().raw10 == 312


def test_xiao_garbage_and_truncated_replies_are_skipped_not_fatal():
    mcu = FakeGasMcu(lambda: 99)
    replies = iter([b'\x00\xffgarbage\r\n', b'{"timeStamp": 4, "ty\r\n', None, None])
    mcu.mangle = lambda reply: next(replies) or reply
    clock = FakeClock()
    samples = []
    session = GasSession(
        XiaoGasBackend(FakeGasMcuPort(mcu)),
        lambda s, w: samples.append(s),
        sleep=clock.sleep,
        clock=clock,
    )
    for _ in range(8):
        session.poll()
    assert session.skipped == 2
    assert [s.raw10 for s in samples] == [99, 99]


def test_xiao_repeated_counter_is_a_duplicate():
    mcu = FakeGasMcu()
    mcu.mangle = lambda reply: xiao_reply(7, 50)
    backend = XiaoGasBackend(FakeGasMcuPort(mcu))
    backend.read()
    with pytest.raises(ProtocolError, match='repeats counter 7'):
        backend.read()


def test_silent_xiao_times_out():
    mcu = FakeGasMcu()
    mcu.mangle = lambda reply: b''
    clock = FakeClock()
    port = FakeGasMcuPort(mcu)
    original_read = port.read

    def slow_read(size=1):
        clock.advance(0.05)
        return original_read(size)

    port.read = slow_read
    with pytest.raises(DeviceTimeoutError, match='silent'):
        XiaoGasBackend(port, clock=clock).read()


def test_endless_reply_without_cr_is_bounded():
    mcu = FakeGasMcu()
    mcu.mangle = lambda reply: b'x' * 1000
    with pytest.raises(ProtocolError, match='longer than 256'):
        XiaoGasBackend(FakeGasMcuPort(mcu)).read()


def test_session_samples_at_the_rate_and_flags_warm_up():
    backend, _, _, clock = _ads()
    out = []
    session = GasSession(
        backend,
        lambda s, w: out.append((clock(), w)),
        rate_hz=10.0,
        warm_up=WarmUp(duration_s=0.5),
        sleep=clock.sleep,
        clock=clock,
    )
    while len(out) < 10:
        session.poll()
    times = [t for t, _ in out]
    assert len(out) == 10
    assert all(0.09 < b - a < 0.11 for a, b in itertools.pairwise(times))
    assert [w for _, w in out] == [True] * 5 + [False] * 5


def test_unplugged_gas_board_is_reopened_by_the_worker():
    clock = FakeClock()
    mcu = FakeGasMcu()
    ports = []

    def connect():
        ports.append(FakeGasMcuPort(mcu))
        return GasSession(XiaoGasBackend(ports[-1]), print, sleep=clock.sleep, clock=clock)

    worker = DeviceWorker('gas', connect, clock=clock)
    worker.run_once()
    ports[-1].unplugged = True
    worker.run_once()
    assert ports[0].closed
    assert not worker.connected
    clock.advance(1.0)
    worker.run_once()
    assert worker.connected
    assert len(ports) == 2


def _fake_mcu_on_pty(master_fd, mcu, stop):
    os.set_blocking(master_fd, False)
    while not stop.is_set():
        try:
            data = os.read(master_fd, 64)
        except BlockingIOError:
            data = b''
        except OSError:
            return
        if data:
            os.write(master_fd, mcu.handle(data))
        stop.wait(0.002)


def test_xiao_backend_over_a_pty_with_a_multi_line_fake():
    master, slave = os.openpty()
    mcu = FakeGasMcu(lambda: 150)
    stop = threading.Event()
    thread = threading.Thread(target=_fake_mcu_on_pty, args=(master, mcu, stop))
    thread.start()
    try:
        port = serial.Serial(os.ttyname(slave), 115200, timeout=0.05)
        backend = XiaoGasBackend(port, reply_timeout_s=1.0)
        values = [backend.read().raw10 for _ in range(3)]
        port.close()
    finally:
        stop.set()
        thread.join(2.0)
        os.close(master)
        os.close(slave)
    assert values == [150, 150, 150]
    assert math.isclose(mcu.counter, 3)
