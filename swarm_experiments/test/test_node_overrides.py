"""NAME=VALUE overrides of node parameters: typed, ranged and named as the node's spec says."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from swarm_common.params import ParameterSpec, parameter
from swarm_experiments.node_overrides import OverrideError, parse_overrides
from swarm_sim.errors import ConfigurationError


@dataclass(frozen=True)
class Demo:
    gas_threshold: int = parameter(200, 'scent threshold', ge=0, le=1023)
    scent_window_s: float = parameter(2.0, 'scent window', unit='s', ge=0.0)
    sound_updates_at_corner: bool = parameter(True, 'update at corners')
    sound_turn_rule: str = parameter('away', 'turn rule', choices=('away', 'toward'))
    robot_index: int = parameter(0, 'index', ge=0)
    target_ids: tuple[int, ...] = parameter((-1,), 'targets')

    def __post_init__(self) -> None:
        if self.scent_window_s > 10.0:
            raise ValueError('scent_window_s must be at most 10 s')


SPEC = ParameterSpec(Demo)


def test_values_take_the_parameters_type() -> None:
    values = parse_overrides(
        [
            'gas_threshold=300',
            'scent_window_s:=1',
            'sound_updates_at_corner=false',
            'sound_turn_rule = toward',
            'target_ids=[1, 2]',
        ],
        SPEC,
    )
    assert values == {
        'gas_threshold': 300,
        'scent_window_s': 1.0,
        'sound_updates_at_corner': False,
        'sound_turn_rule': 'toward',
        'target_ids': [1, 2],
    }
    assert isinstance(values['scent_window_s'], float)


def test_a_later_override_of_the_same_name_wins() -> None:
    assert parse_overrides(['gas_threshold=250', 'gas_threshold=300'], SPEC) == {
        'gas_threshold': 300
    }


@pytest.mark.parametrize(
    ('item', 'message'),
    [
        ('gas_threshold=2.5', 'parameter gas_threshold: expected an integer, got a floating'),
        ('gas_threshold=true', 'parameter gas_threshold: expected an integer, got a boolean'),
        ('gas_threshold=abc', "parameter gas_threshold: expected an integer, got a string 'abc'"),
        ('gas_threshold=2000', 'parameter gas_threshold: must be <= 1023, got 2000'),
        ('scent_window_s=.inf', 'parameter scent_window_s: must be a finite number'),
        ('scent_window_s=fast', 'parameter scent_window_s: expected a floating-point number'),
        ('scent_window_s=-1', 'parameter scent_window_s: must be >= 0 s, got -1 s'),
        ('sound_updates_at_corner=1', 'parameter sound_updates_at_corner: expected true or false'),
        ('sound_turn_rule=left', "sound_turn_rule: 'left' is not one of away, toward"),
        ('target_ids=3', 'parameter target_ids: expected a list of integers'),
        ('gas_threshold', 'must look like NAME=VALUE'),
        ('=3', 'must look like NAME=VALUE'),
    ],
)
def test_malformed_or_mistyped_overrides_are_one_line_naming_the_parameter(item, message):
    with pytest.raises(OverrideError, match=message) as caught:
        parse_overrides([item], SPEC)
    assert '\n' not in str(caught.value)
    assert isinstance(caught.value, ConfigurationError)
    assert caught.value.item == item


def test_an_unknown_name_is_rejected_with_the_close_matches() -> None:
    message = r"unknown parameter 'gas_treshold' \(did you mean gas_threshold\?\)"
    with pytest.raises(OverrideError, match=message) as caught:
        parse_overrides(['gas_treshold=300'], SPEC)
    assert caught.value.suggestions == ('gas_threshold',)


def test_a_parameter_the_caller_sets_itself_cannot_be_overridden() -> None:
    with pytest.raises(OverrideError, match="'robot_index' is set by the spawner"):
        parse_overrides(['robot_index=3'], SPEC, reserved=('robot_index',))


def test_the_configurations_own_checks_see_all_overrides() -> None:
    assert parse_overrides(['scent_window_s=4'], SPEC) == {'scent_window_s': 4.0}
    with pytest.raises(OverrideError, match='scent_window_s must be at most 10 s'):
        parse_overrides(['scent_window_s=12'], SPEC)


def test_the_spawners_read_their_nodes_specs() -> None:
    from swarm_experiments.spawn import oabug_parameter_overrides
    from swarm_experiments.spawn_bayes_swarm import node_parameter_overrides
    from swarm_experiments.spawn_msc_pf import controller_parameter_overrides

    assert oabug_parameter_overrides(['sound_side_deadband_deg=10']) == {
        'sound_side_deadband_deg': 10.0
    }
    with pytest.raises(OverrideError, match='sound_side_deadband_deg: must be <= 90 deg'):
        oabug_parameter_overrides(['sound_side_deadband_deg=120'])
    assert node_parameter_overrides(['horizon_s=20']) == {'horizon_s': 20.0}
    assert controller_parameter_overrides(['msc.leader_rule=pbest']) == {'msc.leader_rule': 'pbest'}
    with pytest.raises(OverrideError, match=r'did you mean msc\.leader_rule'):
        controller_parameter_overrides(['msc.leader_rul=pbest'])
    with pytest.raises(OverrideError, match='thresholds must satisfy gamma1 < gamma2 < gamma3'):
        controller_parameter_overrides(['phases.gamma2_dbm=-90'])
