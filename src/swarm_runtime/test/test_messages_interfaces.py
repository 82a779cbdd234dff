"""Locating and loading swarm_interfaces/msg, and what happens when that goes wrong."""

from __future__ import annotations

from pathlib import Path

import pytest
from swarm_runtime.messages import (
    InterfaceDefinitionError,
    InterfacesNotFoundError,
    MessageRegistry,
    get_message_module,
)
from swarm_runtime.messages.interface_paths import find_interface_msg_dir
from swarm_runtime.messages.typestore import jazzy_typestore, load_msg_directory


def _msg_dir(root: Path, files: dict[str, str]) -> Path:
    directory = root / 'share' / 'swarm_interfaces' / 'msg'
    directory.mkdir(parents=True)
    for name, text in files.items():
        (directory / name).write_text(text)
    return directory


def test_environment_variable_wins(tmp_path: Path) -> None:
    chosen = _msg_dir(tmp_path / 'chosen', {'A.msg': 'int32 a\n'})
    ament = _msg_dir(tmp_path / 'ament', {'B.msg': 'int32 b\n'})
    environ = {
        'SWARM_INTERFACES_MSG_DIR': str(chosen),
        'AMENT_PREFIX_PATH': str(ament.parents[2]),
    }
    assert find_interface_msg_dir(environ) == chosen


def test_a_wrong_environment_variable_is_an_error_not_a_fallback(tmp_path: Path) -> None:
    _msg_dir(tmp_path / 'ament', {'B.msg': 'int32 b\n'})
    environ = {
        'SWARM_INTERFACES_MSG_DIR': str(tmp_path / 'nowhere'),
        'AMENT_PREFIX_PATH': str(tmp_path / 'ament'),
    }
    with pytest.raises(InterfacesNotFoundError, match='SWARM_INTERFACES_MSG_DIR'):
        find_interface_msg_dir(environ)


def test_ament_prefix_path_is_searched_in_order(tmp_path: Path) -> None:
    second = _msg_dir(tmp_path / 'second', {'B.msg': 'int32 b\n'})
    environ = {'AMENT_PREFIX_PATH': f'{tmp_path / "first"}:{tmp_path / "second"}'}
    assert find_interface_msg_dir(environ, source_anchor=tmp_path / 'x' / 'y') == second


def test_source_tree_is_found_from_an_anchor_inside_it(tmp_path: Path) -> None:
    interfaces = tmp_path / 'repo' / 'swarm_interfaces' / 'msg'
    interfaces.mkdir(parents=True)
    (interfaces / 'A.msg').write_text('int32 a\n')
    anchor = tmp_path / 'repo' / 'src' / 'swarm_runtime' / 'swarm_runtime' / 'messages' / 'x.py'
    assert find_interface_msg_dir({}, source_anchor=anchor) == interfaces


def test_not_found_lists_every_place_tried(tmp_path: Path) -> None:
    environ = {'AMENT_PREFIX_PATH': str(tmp_path / 'prefix')}
    with pytest.raises(InterfacesNotFoundError) as caught:
        find_interface_msg_dir(environ, source_anchor=tmp_path / 'a' / 'b.py')
    text = str(caught.value)
    assert 'SWARM_INTERFACES_MSG_DIR' in text
    assert str(tmp_path / 'prefix' / 'share' / 'swarm_interfaces' / 'msg') in text


def test_the_workspace_definitions_are_loaded() -> None:
    swarm = get_message_module('swarm_interfaces')
    assert swarm.GasReading().RAW_MAX == 1023
    assert 'PeerBearingArray' in dir(swarm)


def test_a_broken_definition_names_its_file(tmp_path: Path) -> None:
    directory = _msg_dir(tmp_path, {'Good.msg': 'int32 a\n', 'Bad.msg': 'int32[ a\n'})
    with pytest.raises(InterfaceDefinitionError, match=r'Bad\.msg'):
        load_msg_directory(jazzy_typestore(), directory)


def test_a_reference_to_a_missing_type_names_its_file(tmp_path: Path) -> None:
    directory = _msg_dir(tmp_path, {'Uses.msg': 'Missing thing\nstd_msgs/Header header\n'})
    with pytest.raises(InterfaceDefinitionError, match=r'Uses\.msg: unknown message type'):
        load_msg_directory(jazzy_typestore(), directory)


def test_missing_interfaces_only_break_swarm_interfaces(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv('SWARM_INTERFACES_MSG_DIR', str(tmp_path / 'nowhere'))
    registry = MessageRegistry()
    assert registry.get_module('std_msgs').Bool(data=True).data is True
    with pytest.raises(InterfacesNotFoundError, match='SWARM_INTERFACES_MSG_DIR'):
        registry.get_module('swarm_interfaces')
    with pytest.raises(InterfacesNotFoundError):
        registry.require_interfaces()
