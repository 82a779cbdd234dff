"""NAME=VALUE overrides of node parameters: typed like the defaults, bad ones named."""

import pytest
from swarm_experiments.node_overrides import parse_overrides
from swarm_sim.errors import ConfigurationError

DECLARED = {
    'gas_threshold': 200,
    'scent_window_s': 2.0,
    'sound_updates_at_corner': True,
    'sound_turn_rule': 'toward',
    'robot_index': 0,
}


def test_values_take_the_type_of_the_declared_default() -> None:
    values = parse_overrides(
        [
            'gas_threshold=300',
            'scent_window_s:=1',
            'sound_updates_at_corner=false',
            'sound_turn_rule = away',
        ],
        DECLARED,
    )
    assert values == {
        'gas_threshold': 300,
        'scent_window_s': 1.0,
        'sound_updates_at_corner': False,
        'sound_turn_rule': 'away',
    }
    assert isinstance(values['scent_window_s'], float)


def test_a_later_override_of_the_same_name_wins() -> None:
    assert parse_overrides(['gas_threshold=250', 'gas_threshold=300'], DECLARED) == {
        'gas_threshold': 300
    }


@pytest.mark.parametrize(
    ('item', 'message'),
    [
        ('gas_threshold=2.5', 'expected an integer'),
        ('gas_threshold=true', 'expected an integer'),
        ('gas_threshold=abc', 'expected an integer'),
        ('scent_window_s=.inf', 'expected a finite number'),
        ('scent_window_s=fast', 'expected a finite number'),
        ('sound_updates_at_corner=1', 'expected true or false'),
        ('gas_threshold', 'must look like NAME=VALUE'),
        ('=3', 'must look like NAME=VALUE'),
    ],
)
def test_malformed_or_mistyped_overrides_are_rejected(item: str, message: str) -> None:
    with pytest.raises(ConfigurationError, match=message):
        parse_overrides([item], DECLARED)


def test_an_unknown_name_is_rejected_with_the_close_matches() -> None:
    message = r"unknown parameter 'gas_treshold' \(did you mean gas_threshold\?\)"
    with pytest.raises(ConfigurationError, match=message):
        parse_overrides(['gas_treshold=300'], DECLARED)


def test_a_parameter_the_caller_sets_itself_cannot_be_overridden() -> None:
    with pytest.raises(ConfigurationError, match="'robot_index' is set by the spawner"):
        parse_overrides(['robot_index=3'], DECLARED, reserved=('robot_index',))


def test_the_nodes_own_check_sees_defaults_and_overrides_and_its_error_is_reported() -> None:
    seen = []

    def check(values):
        seen.append(values)
        if values['scent_window_s'] > 10.0:
            raise ValueError('scent_window_s must be at most 10 s')

    assert parse_overrides(['scent_window_s=4'], DECLARED, check=check) == {'scent_window_s': 4.0}
    assert seen == [{**DECLARED, 'scent_window_s': 4.0}]
    with pytest.raises(ConfigurationError, match='scent_window_s must be at most 10 s'):
        parse_overrides(['scent_window_s=12'], DECLARED, check=check)


def test_a_parameter_of_a_type_the_command_line_cannot_express_is_refused() -> None:
    with pytest.raises(ConfigurationError, match=r'target_ids \(list\) cannot be set'):
        parse_overrides(['target_ids=[1, 2]'], {'target_ids': [-1]})
