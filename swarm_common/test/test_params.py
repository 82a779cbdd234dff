"""Parameter specs from dataclass fields: names, types, checks, flattening, renderings."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from enum import Enum
from typing import Literal

import pytest
import yaml
from swarm_common.params import (
    ParameterError,
    ParameterSpec,
    SpecError,
    parameter,
    render_value,
    section,
)


class Mode(Enum):
    FAST = 'fast'
    SLOW = 'slow'


class DemoError(ValueError):
    """A package's own configuration error."""


class DemoParameterError(DemoError, ParameterError):
    """The package's parameter error: both a DemoError and a ParameterError."""


@dataclass(frozen=True)
class Sensor:
    rate_hz: float = parameter(10.0, 'sample rate', unit='Hz', gt=0.0)
    ids: tuple[int, ...] = parameter((-1,), 'accepted ids; [-1] takes all')
    weight: float | None = parameter(None, 'weight; unset uses 1', ge=0.0)
    window: int | None = parameter(None, 'window; -1: whole history', ge=1, none=-1)
    bounds_m: tuple[float, float] = parameter((0.0, 1.0), 'lower and upper bound', unit='m')
    hidden: int = 7  # no metadata: not a parameter

    def __post_init__(self) -> None:
        if self.bounds_m[0] > self.bounds_m[1]:
            raise DemoError('bounds_m must be ordered')


@dataclass(frozen=True)
class Robot:
    speed_mps: float = parameter(0.3, 'cruise speed', unit='m/s', gt=0.0, le=2.0)
    bias_rad: float = parameter(math.radians(45.0), 'fan bias', unit='deg', degrees=True)
    mode: Mode = parameter(Mode.FAST, 'how to drive', read_only=False)
    shape: Literal['disc', 'box'] = parameter('disc', 'body shape')
    name: str = parameter('r0', 'robot name')
    count: int = parameter(3, 'robots', ge=1, le=10)
    flag: bool = parameter(True, 'a switch')
    range_m: float = parameter(math.inf, 'radio range', unit='m', gt=0.0, finite=False)
    legacy: float = parameter(1.0, 'kept under its old name', name='old_legacy_name')
    sensor: Sensor = section(Sensor)
    flat: Sensor = section(Sensor, prefix='flat_')

    def __post_init__(self) -> None:
        if self.count > 5 and self.mode is Mode.FAST:
            raise DemoError('count above 5 needs mode slow')


SPEC = ParameterSpec(Robot, error=DemoParameterError)


def test_names_follow_sections_prefixes_degrees_and_explicit_names() -> None:
    assert SPEC.names == (
        'speed_mps',
        'bias_deg',
        'mode',
        'shape',
        'name',
        'count',
        'flag',
        'range_m',
        'old_legacy_name',
        'sensor.rate_hz',
        'sensor.ids',
        'sensor.weight',
        'sensor.window',
        'sensor.bounds_m',
        'flat_rate_hz',
        'flat_ids',
        'flat_weight',
        'flat_window',
        'flat_bounds_m',
    )
    assert 'sensor.hidden' not in SPEC


def test_defaults_come_from_the_dataclass_as_parameter_values() -> None:
    defaults = SPEC.defaults()
    assert defaults['bias_deg'] == pytest.approx(45.0)
    assert defaults['mode'] == 'fast'
    assert defaults['sensor.ids'] == [-1]
    assert math.isnan(defaults['sensor.weight'])
    assert defaults['sensor.window'] == -1
    assert defaults['sensor.bounds_m'] == [0.0, 1.0]
    assert SPEC['mode'].choices == ('fast', 'slow')
    assert SPEC['shape'].choices == ('disc', 'box')
    assert SPEC['sensor.ids'].kind == 'int[]'


def test_a_different_base_gives_its_values_as_defaults() -> None:
    base = Robot(speed_mps=1.5, sensor=Sensor(rate_hz=4.0))
    assert SPEC.defaults(base)['speed_mps'] == 1.5
    assert SPEC.defaults(base)['sensor.rate_hz'] == 4.0
    assert SPEC.build({'count': 2}, base) == dataclasses.replace(base, count=2)


def test_flattening_and_unflattening_round_trip() -> None:
    config = Robot(
        speed_mps=0.5,
        bias_rad=0.25,
        mode=Mode.SLOW,
        count=6,
        sensor=Sensor(ids=(3, 4), weight=0.5, window=4, bounds_m=(-1.0, 2.0)),
    )
    values = SPEC.values_of(config)
    rebuilt = SPEC.build(values)
    assert rebuilt == dataclasses.replace(config, bias_rad=math.radians(math.degrees(0.25)))
    assert SPEC.build(SPEC.defaults()) == Robot()


def test_values_are_converted_to_field_values() -> None:
    config = SPEC.build(
        {'mode': 'SLOW', 'count': 6, 'bias_deg': 90.0, 'sensor.weight': math.nan, 'flat_window': 5}
    )
    assert config.mode is Mode.SLOW
    assert config.bias_rad == pytest.approx(math.pi / 2)
    assert config.sensor.weight is None
    assert config.flat.window == 5
    assert SPEC.build({'speed_mps': 1}).speed_mps == 1.0
    assert isinstance(SPEC.build({'speed_mps': 1}).speed_mps, float)


@pytest.mark.parametrize(
    ('values', 'message'),
    [
        ({'speed_mps': 0.0}, 'parameter speed_mps: must be > 0 m/s, got 0 m/s'),
        ({'speed_mps': 2.5}, 'parameter speed_mps: must be <= 2 m/s, got 2.5 m/s'),
        ({'speed_mps': math.nan}, 'parameter speed_mps: must be a finite number'),
        ({'speed_mps': 'fast'}, "speed_mps: expected a floating-point number, got a string 'fast'"),
        ({'count': 2.0}, 'parameter count: expected an integer, got a floating-point number 2.0'),
        ({'count': True}, 'parameter count: expected an integer, got a boolean True'),
        ({'flag': 1}, 'parameter flag: expected true or false, got an integer 1'),
        ({'mode': 'fsat'}, "'fsat' is not one of fast, slow \\(did you mean fast\\?\\)"),
        ({'shape': 'Disc'}, "shape: 'Disc' is not one of disc, box"),
        ({'sensor.ids': [1.5]}, 'sensor.ids: expected a list of integers, got \\[1.5\\]'),
        ({'sensor.bounds_m': [1.0]}, 'sensor.bounds_m: expected 2 values'),
        ({'sensor.window': 0}, 'sensor.window: must be >= 1, got 0'),
        ({'sensor.weight': -1.0}, 'sensor.weight: must be >= 0, got -1'),
    ],
)
def test_bad_values_name_the_parameter_and_the_problem(values, message) -> None:
    with pytest.raises(DemoParameterError, match=message) as caught:
        SPEC.build(values)
    assert caught.value.name == next(iter(values))
    assert isinstance(caught.value, DemoError)


def test_strict_checks_refuse_an_integer_for_a_float_as_ros_does() -> None:
    with pytest.raises(ParameterError, match=r'got the integer 1 \(write 1.0\)'):
        SPEC.build({'speed_mps': 1}, strict=True)


def test_an_unknown_name_gets_did_you_mean_suggestions() -> None:
    with pytest.raises(DemoParameterError) as caught:
        SPEC.build({'sped_mps': 1.0})
    error = caught.value
    assert error.unknown
    assert error.suggestions == ('speed_mps',)
    assert str(error) == "unknown parameter 'sped_mps' (did you mean speed_mps?)"
    # A misplaced section still finds the field by its name.
    assert 'sensor.rate_hz' in SPEC.unknown('lidar.rate_hz').suggestions


def test_cross_field_rules_of_the_dataclass_still_apply() -> None:
    with pytest.raises(DemoError, match='count above 5 needs mode slow'):
        SPEC.build({'count': 6})
    with pytest.raises(DemoError, match='bounds_m must be ordered'):
        SPEC.build({'sensor.bounds_m': [2.0, 1.0]})


def test_text_is_parsed_as_the_parameters_type() -> None:
    assert SPEC.parse_text('speed_mps', '2') == 2.0
    assert SPEC.parse_text('count', '4') == 4
    assert SPEC.parse_text('flag', 'false') is False
    assert SPEC.parse_text('name', '17') == '17'
    assert SPEC.parse_text('sensor.ids', '[1, 2]') == [1, 2]
    assert math.isnan(SPEC.parse_text('sensor.weight', 'nan'))
    assert SPEC.parse_text('range_m', '.inf') == math.inf
    assert SPEC.parse_text('bias_deg', '30') == pytest.approx(30.0)
    with pytest.raises(ParameterError, match="count: expected an integer, got a string 'abc'"):
        SPEC.parse_text('count', 'abc')
    with pytest.raises(ParameterError, match='must be <= 10'):
        SPEC.parse_text('count', '11')


def test_the_yaml_file_reads_back_as_the_defaults() -> None:
    text = SPEC.render_yaml('/**/robot', header=['a header line'])
    assert text.startswith('# a header line\n/**/robot:\n  ros__parameters:\n')
    loaded = yaml.safe_load(text)['/**/robot']['ros__parameters']
    flat = {}
    for key, value in loaded.items():
        if isinstance(value, dict):
            flat.update({f'{key}.{k}': v for k, v in value.items()})
        else:
            flat[key] = value
    defaults = SPEC.defaults()
    assert flat.keys() == defaults.keys()
    for key, value in defaults.items():
        if isinstance(value, float) and math.isnan(value):
            assert math.isnan(flat[key])
        else:
            assert flat[key] == value, key
            assert type(flat[key]) is type(value), key
    assert '# cruise speed [m/s] (range (0, 2])' in text
    assert 'Can be changed while the node runs.' in text


@pytest.mark.parametrize(
    ('value', 'text'),
    [
        (True, 'true'),
        (3, '3'),
        (0.1, '0.1'),
        (1e-05, '1.0e-05'),
        (2e20, '2.0e+20'),
        (math.inf, '.inf'),
        (-math.inf, '-.inf'),
        ('', "''"),
        ('on', "'on'"),
        ('17', "'17'"),
        ('127.0.0.1', "'127.0.0.1'"),
        ('/dev/ttyUSB0', '/dev/ttyUSB0'),
        ("it's", "'it''s'"),
        ([1, 2], '[1, 2]'),
    ],
)
def test_values_render_as_yaml_that_reads_back_the_same(value, text) -> None:
    assert render_value(value) == text
    assert yaml.safe_load(f'v: {text}')['v'] == value


def test_the_markdown_table_has_a_row_per_parameter() -> None:
    table = SPEC.render_markdown()
    rows = table.strip().splitlines()
    assert rows[0].startswith('| parameter | default | unit |')
    assert len(rows) == 2 + len(SPEC.parameters)
    assert '| `mode` | `fast` |  | one of fast, slow | yes | how to drive |' in rows
    assert '| `speed_mps` | `0.3` | m/s | (0, 2] | no | cruise speed |' in rows


def test_specs_refuse_fields_they_cannot_carry() -> None:
    @dataclass(frozen=True)
    class Mixed:
        pair: tuple[int, str] = parameter((1, 'a'), 'a mixed tuple')

    with pytest.raises(SpecError, match='mixed types'):
        ParameterSpec(Mixed)

    @dataclass(frozen=True)
    class OptionalInt:
        count: int | None = parameter(None, 'an optional integer')

    with pytest.raises(SpecError, match='none='):
        ParameterSpec(OptionalInt)

    @dataclass(frozen=True)
    class BadDefault:
        rate_hz: float = parameter(-1.0, 'a rate', gt=0.0)

    with pytest.raises(SpecError, match='default of parameter rate_hz'):
        ParameterSpec(BadDefault)

    @dataclass(frozen=True)
    class Twice:
        a_b: int = parameter(1, 'first')
        a: Sensor = section(Sensor, prefix='a_')
        b: int = parameter(2, 'second', name='a_b')

    with pytest.raises(SpecError, match='used twice: a_b'):
        ParameterSpec(Twice)

    with pytest.raises(SpecError, match='description'):
        parameter(1, '')
