"""The named parameter profiles: paper (Table I read literally) and tuned (the defaults)."""

from __future__ import annotations

import pytest
from oabug_robot.errors import ConfigError
from oabug_robot.node_settings import OABUG_PARAMETERS
from oabug_robot.profiles import PROFILES, TUNED_DEPARTURES, profile_parameters
from oabug_robot.settings import SoundTurnRule, SoundWallSide


def test_the_paper_profile_is_table_one_read_literally():
    config = OABUG_PARAMETERS.build(profile_parameters('paper')).controller
    assert config.gas_sound_wall_side is SoundWallSide.EVERY_CONTACT
    assert config.sound_turn_rule is SoundTurnRule.AWAY
    assert config.gas_sound_side_deadband_rad == 0.0
    assert config.robot_hit_repeat_s == 0.0


def test_both_profiles_take_inner_corners_on_an_arc_and_count_contacts_in_the_path():
    for name in PROFILES:
        config = OABUG_PARAMETERS.build(profile_parameters(name)).controller
        assert config.motion.inner_corner_arc_radius_m == 0.15, name
        assert config.perception.robot_contact_in_path, name


def test_the_tuned_profile_is_the_defaults_and_its_departures_are_listed():
    defaults = OABUG_PARAMETERS.defaults()
    assert profile_parameters('tuned') == {}
    for name, (tuned, paper, why) in TUNED_DEPARTURES.items():
        assert defaults[name] == tuned
        assert PROFILES['paper'][name] == paper
        assert why
    # Every parameter where the profiles differ is listed as a departure.
    differing = {k for k, v in PROFILES['paper'].items() if defaults[k] != v}
    assert differing == set(TUNED_DEPARTURES)


def test_an_unknown_profile_is_an_error():
    with pytest.raises(ConfigError, match='paper, tuned'):
        profile_parameters('fast')
