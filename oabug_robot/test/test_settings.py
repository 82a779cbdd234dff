"""Configuration validation: bad values fail at start with a message naming them."""

from __future__ import annotations

import math

import pytest
from oabug_robot.errors import ConfigError
from oabug_robot.settings import (
    Departure,
    MotionConfig,
    OABugConfig,
    PerceptionConfig,
    Variant,
)


def test_defaults_are_the_papers_parameters() -> None:
    config = OABugConfig()
    assert config.variant is Variant.GAS_SOUND
    assert config.gas_threshold == 200
    assert config.pump_on_s == 0.5
    assert config.pump_period_s == 5.0
    assert config.revisit_flip_count == 3
    assert config.motion.random_step_m == pytest.approx(0.1)


@pytest.mark.parametrize('name', [v.value for v in Variant])
def test_every_table_one_variant_parses_by_name(name: str) -> None:
    assert Variant.parse(name.upper()).value == name


def test_an_unknown_variant_is_rejected_with_the_valid_names() -> None:
    with pytest.raises(ConfigError, match='gas_sound'):
        Variant.parse('oabug')


def test_an_unknown_departure_is_rejected() -> None:
    with pytest.raises(ConfigError, match='center or edge'):
        Departure.parse('middle')


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'robot_count': 0}, 'robot_count'),
        ({'robot_index': 3, 'robot_count': 3}, 'robot_index'),
        ({'robot_index': -1}, 'robot_index'),
        ({'gas_threshold': 1024}, '10-bit'),
        ({'pump_on_s': 6.0}, 'pump_on_s'),
        ({'pump_period_s': 0.0}, 'pump_period_s'),
        ({'revisit_flip_count': 0}, 'revisit_flip_count'),
        ({'heading_bias_rad': math.nan}, 'heading_bias_rad'),
        ({'scent_window_s': -1.0}, 'scent_window_s'),
        ({'seed': -2}, 'seed'),
    ],
)
def test_inconsistent_configuration_is_rejected(overrides: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        OABugConfig(**overrides)


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'forward_speed_mps': 0.0}, 'forward_speed_mps'),
        ({'turn_rate_radps': math.inf}, 'turn_rate_radps'),
        ({'min_turn_rate_radps': 3.0}, 'min_turn_rate_radps'),
        ({'random_turn_probability': 1.5}, 'random_turn_probability'),
    ],
)
def test_bad_motion_settings_are_rejected(overrides: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        MotionConfig(**overrides)


def test_a_hit_distance_inside_the_body_is_rejected() -> None:
    with pytest.raises(ConfigError, match='wall_hit_distance_m'):
        PerceptionConfig(robot_radius_m=0.2, wall_hit_distance_m=0.1)


def test_config_is_immutable() -> None:
    config = OABugConfig()
    with pytest.raises(AttributeError):
        config.robot_count = 4  # type: ignore[misc]
