"""Make the test fixtures importable here and in every worker process the tests start."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent


def _with_path(value: str | None) -> str:
    parts = [str(HERE), *(value.split(os.pathsep) if value else [])]
    return os.pathsep.join(dict.fromkeys(parts))


if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))


@pytest.fixture(autouse=True)
def _fixture_path_for_workers(monkeypatch: pytest.MonkeyPatch) -> None:
    """Spawned pool and Dask worker processes import the fixtures through PYTHONPATH."""
    monkeypatch.setenv('PYTHONPATH', _with_path(os.environ.get('PYTHONPATH')))
