"""Locating the project's own message definitions (swarm_interfaces/msg/*.msg).

Searched in this order, first hit wins:

1. the directory named by the environment variable ``SWARM_INTERFACES_MSG_DIR``;
2. ``<prefix>/share/swarm_interfaces/msg`` for each prefix of ``AMENT_PREFIX_PATH``
   (a colcon install or a sourced ROS workspace);
3. the source tree this package was installed from in development mode: the
   ``swarm_interfaces/msg`` directory of the first ancestor directory holding one.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from .errors import InterfacesNotFoundError

__all__ = [
    'INTERFACES_PACKAGE',
    'MSG_DIR_ENV_VAR',
    'find_interface_msg_dir',
]

INTERFACES_PACKAGE = 'swarm_interfaces'
MSG_DIR_ENV_VAR = 'SWARM_INTERFACES_MSG_DIR'

# How many directories above this file the source-tree search looks.
_MAX_SOURCE_TREE_DEPTH = 6


def _has_msg_files(directory: Path) -> bool:
    return directory.is_dir() and any(directory.glob('*.msg'))


def find_interface_msg_dir(
    environ: Mapping[str, str] | None = None,
    *,
    source_anchor: Path | None = None,
) -> Path:
    """Return the directory holding swarm_interfaces' .msg files.

    Args:
        environ: Environment to read (default ``os.environ``).
        source_anchor: File or directory from which the source tree is searched upwards
            (default: this module).

    Raises:
        InterfacesNotFoundError: no candidate holds .msg files; the message lists every
            place that was tried. An explicit ``SWARM_INTERFACES_MSG_DIR`` that is wrong is
            an error even if another location would work.
    """
    env = os.environ if environ is None else environ
    explicit = env.get(MSG_DIR_ENV_VAR, '').strip()
    if explicit:
        path = Path(explicit).expanduser()
        if _has_msg_files(path):
            return path
        msg = f'{MSG_DIR_ENV_VAR}={explicit!r} is not a directory holding .msg files'
        raise InterfacesNotFoundError(msg)

    tried: list[str] = []
    for prefix in env.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if not prefix:
            continue
        candidate = Path(prefix) / 'share' / INTERFACES_PACKAGE / 'msg'
        if _has_msg_files(candidate):
            return candidate
        tried.append(str(candidate))

    anchor = (source_anchor or Path(__file__)).resolve()
    for parent in list(anchor.parents)[:_MAX_SOURCE_TREE_DEPTH]:
        candidate = parent / INTERFACES_PACKAGE / 'msg'
        if _has_msg_files(candidate):
            return candidate
        tried.append(str(candidate))

    msg = (
        f'cannot find the {INTERFACES_PACKAGE} message definitions; set {MSG_DIR_ENV_VAR} to '
        f'the directory holding its .msg files, or source a workspace that installs '
        f'{INTERFACES_PACKAGE} (tried: {", ".join(tried) or "nothing"})'
    )
    raise InterfacesNotFoundError(msg)
