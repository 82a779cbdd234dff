"""benchmarks/bench_sites.py runs headless and reports what it measured."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / 'benchmarks' / 'bench_sites.py'


@pytest.fixture(scope='module')
def bench() -> Iterator[ModuleType]:
    spec = importlib.util.spec_from_file_location('bench_sites', SCRIPT)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.modules.pop(spec.name, None)


def test_the_site_benchmark_measures_and_writes_its_table(
    bench: ModuleType, tmp_path: Path
) -> None:
    out = tmp_path / 'sites.md'
    results = bench.run(['small'], sites=3, out=out)
    (small,) = results
    assert small.sites == 3
    assert small.rooms_met == 1.0
    assert small.horizontal_corridors == (1, 1)
    assert small.corridor_doors + small.inner_doors == pytest.approx(30)  # one door per room
    table = out.read_text()
    assert '| small | 3 |' in table
    assert '(18.9)' in table  # the authors' figure next to ours
