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


@pytest.mark.slow
def test_full_budget_runs_past_the_last_room_to_the_end_of_the_budget(bench):
    # Small site 2, Gas+Sound from the centre, 10 robots: every room is covered before the
    # budget's 333 s (with the messages' float32 rounding or without).
    early = bench._ours(2, 'small', 'gas_sound', 'center', 10, 'paper')
    whole = bench._ours(2, 'small', 'gas_sound', 'center', 10, 'paper', full_budget=True)
    assert early.mission.stop_reason == 'all_rooms_covered'
    assert whole.mission.stop_reason == 'budget'
    assert early.coverage == whole.coverage == 1.0
    assert early.mission.sim_time_s < whole.mission.sim_time_s
    assert whole.mission.sim_time_s == pytest.approx(early.settings.budget_s, abs=0.2)
    # Up to the early end the two missions are the same run (the early one's last sample is
    # its final pose, off the sampling period).
    n = len(early.mission.trajectory_times_s) - 1
    assert (early.mission.trajectory_times_s[:n] == whole.mission.trajectory_times_s[:n]).all()
    assert (early.mission.trajectories[:n] == whole.mission.trajectories[:n]).all()
