"""benchmarks/bench_oabug.py: OA-Bug node parameters given on the command line (--set)."""

from __future__ import annotations

import pytest


@pytest.fixture
def bench(benchmark_script):
    return benchmark_script('bench_oabug')


def test_set_parameters_reach_every_mission(bench, monkeypatch):
    pytest.importorskip('oabug_robot.node')
    import sim_bridge.oabug_batch

    seen = []

    def fake_run(config):
        seen.append(config)
        raise RuntimeError('stop here')

    monkeypatch.setattr(sim_bridge.oabug_batch, 'run_spawn_batch', fake_run)
    job = bench.Job('small', 3, 'gas_sound', 'edge', 4, 10, 0.3, 'batch', (('gas_threshold', 300),))
    with pytest.raises(RuntimeError, match='stop here'):
        bench.run_job(job)
    assert seen[0].robot_parameters == {'gas_threshold': 300}
    assert (seen[0].site_seed, seen[0].variant, seen[0].robots) == (3, 'gas_sound', 4)


def test_bad_set_parameters_stop_the_benchmark_before_any_run(bench, capsys, monkeypatch):
    pytest.importorskip('oabug_robot.node')
    monkeypatch.setattr(bench, 'run', lambda **_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as exit_info:
        bench.main(['--set', 'gas_threshold=high'])
    assert exit_info.value.code == 2
    assert 'gas_threshold' in capsys.readouterr().err
