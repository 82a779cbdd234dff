"""benchmarks/bench_oabug_cpu.py: bad options and a missing grid simulator are one-line errors."""

from __future__ import annotations

import pytest


@pytest.fixture
def bench(benchmark_script):
    return benchmark_script('bench_oabug_cpu')


@pytest.mark.parametrize(
    ('argv', 'message'),
    [
        (['--ours-only', '--sites', '0'], 'at least 1'),
        (['--ours-only', '--repeat', '0'], 'at least 1'),
        ([], '--simulator'),
    ],
)
def test_bad_options_stop_before_any_run(bench, capsys, monkeypatch, argv, message):
    monkeypatch.setattr(bench, '_ours', lambda *_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as stop:
        bench.main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert message in err


def test_a_missing_simulator_checkout_is_one_line(bench, capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(bench, '_ours', lambda *_: pytest.fail('a run started'))
    with pytest.raises(SystemExit) as stop:
        bench.main(['--simulator', str(tmp_path / 'nowhere')])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert 'Traceback' not in err
    assert 'no SwarmSearchSimulation checkout' in err.splitlines()[-1]
