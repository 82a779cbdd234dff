"""The code version a study's rows record."""

from __future__ import annotations

import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

__all__ = ['code_version']

_PACKAGE = 'swarm_experiments'


def code_version(source: Path | None = None) -> str:
    """``git describe --always --dirty --tags`` of the checkout holding ``source``.

    Outside a git checkout (an installed wheel, a worker without the repository) it is the
    installed package's version, and ``unknown`` when neither can be found.
    """
    source = Path(source) if source is not None else Path(__file__).resolve().parent
    try:
        described = subprocess.run(
            ['git', 'describe', '--always', '--dirty', '--tags'],
            cwd=source,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        described = ''
    if described:
        return described
    try:
        return f'{_PACKAGE} {version(_PACKAGE)}'
    except PackageNotFoundError:
        return 'unknown'
