"""Building the rosbags typestore: the ROS 2 Jazzy types plus swarm_interfaces."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rosbags.typesys import Stores, TypesysError, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from .errors import InterfaceDefinitionError
from .fields import referenced_types
from .interface_paths import INTERFACES_PACKAGE

__all__ = ['jazzy_typestore', 'load_msg_directory']


def jazzy_typestore() -> Typestore:
    """Return a new typestore holding the standard ROS 2 Jazzy message types."""
    return get_typestore(Stores.ROS2_JAZZY)


def load_msg_directory(
    typestore: Typestore, msg_dir: Path, package: str = INTERFACES_PACKAGE
) -> tuple[str, ...]:
    """Register every ``msg_dir/*.msg`` as ``<package>/msg/<stem>`` in ``typestore``.

    Returns:
        The registered type names, sorted.

    Raises:
        InterfaceDefinitionError: a file cannot be read or parsed, refers to a type that does
            not exist, or clashes with a type already registered; the message names the file.
    """
    types: dict[str, Any] = {}
    files: dict[str, Path] = {}
    for path in sorted(msg_dir.glob('*.msg')):
        typename = f'{package}/msg/{path.stem}'
        try:
            text = path.read_text(encoding='utf-8')
            types.update(get_types_from_msg(text, typename))
        except (OSError, UnicodeDecodeError, TypesysError) as err:
            msg = f'cannot load {typename} from {path}: {err}'
            raise InterfaceDefinitionError(msg) from err
        files[typename] = path
    for typename, (_, fielddefs) in types.items():
        unknown = referenced_types(fielddefs) - types.keys() - typestore.fielddefs.keys()
        if unknown:
            msg = (
                f'{files.get(typename, msg_dir)}: unknown message type {", ".join(sorted(unknown))}'
            )
            raise InterfaceDefinitionError(msg)
    try:
        typestore.register(types)  # type: ignore[arg-type]
    except TypesysError as err:
        msg = f'cannot register the {package} definitions from {msg_dir}: {err}'
        raise InterfaceDefinitionError(msg) from err
    return tuple(sorted(types))
