"""benchmarks/bench_oabug.py: OA-Bug node parameters given on the command line (--set)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / 'benchmarks' / 'bench_oabug.py'


def _load_bench():
    spec = importlib.util.spec_from_file_location('bench_oabug', SCRIPT)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


BENCH = _load_bench()


def test_set_parameters_reach_every_mission(monkeypatch):
    pytest.importorskip('oabug_robot.node')
    import sim_bridge.oabug_batch

    seen = []

    def fake_run(config):
        seen.append(config)
        raise RuntimeError('stop here')

    monkeypatch.setattr(sim_bridge.oabug_batch, 'run_spawn_batch', fake_run)
    job = BENCH.Job('small', 3, 'gas_sound', 'edge', 4, 10, 0.3, 'batch', (('gas_threshold', 300),))
    with pytest.raises(RuntimeError, match='stop here'):
        BENCH.run_job(job)
    assert seen[0].robot_parameters == {'gas_threshold': 300}
    assert (seen[0].site_seed, seen[0].variant, seen[0].robots) == (3, 'gas_sound', 4)


def test_bad_set_parameters_stop_the_benchmark_before_any_run(capsys, monkeypatch):
    pytest.importorskip('oabug_robot.node')
    monkeypatch.setattr(BENCH, 'run', lambda **_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as exit_info:
        BENCH.main(['--set', 'gas_threshold=high'])
    assert exit_info.value.code == 2
    assert 'gas_threshold' in capsys.readouterr().err
