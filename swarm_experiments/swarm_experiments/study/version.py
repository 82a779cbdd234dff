"""What a study's rows record of the code that ran them and the BLAS it linked."""

from __future__ import annotations

import contextlib
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

__all__ = ['blas_kernels', 'code_version']

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


def blas_kernels() -> str:
    """The BLAS libraries loaded in this process, with the kernels they chose for this CPU.

    Each library as ``<implementation> <version> <kernel>`` (e.g. ``openblas 0.3.30
    Haswell``), distinct entries sorted and joined by ``; ``, and ``unknown`` when none is
    found. numpy and scipy each bundle an OpenBLAS that picks its kernel from the CPU at load
    time (``OPENBLAS_CORETYPE`` overrides it); another kernel rounds the last bits of linear
    algebra differently, which can turn a close decision of a run. scipy's library is loaded
    first when scipy is installed, so every process of one environment reports the same set
    whatever its run function imported.
    """
    with contextlib.suppress(ImportError):
        import scipy.linalg  # noqa: F401  (loads scipy's BLAS)
    from threadpoolctl import threadpool_info

    entries = {
        ' '.join(
            str(library[key])
            for key in ('internal_api', 'version', 'architecture')
            if library.get(key)
        )
        for library in threadpool_info()
        if library.get('user_api') == 'blas'
    }
    return '; '.join(sorted(entries)) or 'unknown'
