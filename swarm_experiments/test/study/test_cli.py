"""The swarm_study command line: exit codes, one-line errors, resume after Ctrl-C."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from study_fixtures import studies
from study_helpers import comparable
from swarm_experiments.study import StudyRegistry, read_rows
from swarm_experiments.study.cli import main
from swarm_experiments.study.results import read_manifest


@pytest.fixture
def registry() -> StudyRegistry:
    return StudyRegistry(studies())


def _run(registry: StudyRegistry, *argv: str) -> int:
    return main(list(argv), registry=registry)


def test_list_names_each_study_with_its_run_count(
    registry: StudyRegistry, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _run(registry, 'list') == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith('synthetic-search: 9 configurations x 4 sites = 36 runs')
    assert out[1].startswith('synthetic-slow: 4 configurations x 6 sites = 24 runs')


def test_list_without_studies_says_how_to_add_some(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(['list'], registry=StudyRegistry()) == 0
    assert 'no studies registered' in capsys.readouterr().out


def test_run_then_rerun_skips_everything(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ['run', 'synthetic-search', '--smoke', '--engine', 'serial', '--out', str(tmp_path)]
    assert _run(registry, *argv, '--quiet') == 0
    assert 'synthetic-search: 6 ok, 0 failed, 0 already stored' in capsys.readouterr().out
    assert _run(registry, *argv, '--quiet') == 0
    assert '0 ok, 0 failed, 6 already stored, 0 not run of 6' in capsys.readouterr().out
    assert len(read_rows(tmp_path / 'synthetic-search-smoke')) == 6


def test_a_study_resumed_under_another_blas_kernel_warns_in_one_line(
    registry: StudyRegistry,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    kernel = ['openblas 0.3.30 Haswell']
    monkeypatch.setattr('swarm_experiments.study.results.blas_kernels', lambda: kernel[0])
    argv = ['run', 'synthetic-search', '--engine', 'serial', '--quiet', '--out', str(tmp_path)]
    assert _run(registry, *argv, '--sites', '1') == 0
    assert 'BLAS' not in capsys.readouterr().err
    kernel[0] = 'openblas 0.3.30 Sandybridge'
    assert _run(registry, *argv, '--sites', '2') == 0
    (warning,) = capsys.readouterr().err.splitlines()
    assert warning.startswith('swarm_study: warning: the rows in ')
    assert 'ran on 2 BLAS setups (openblas 0.3.30 Haswell | openblas 0.3.30 Sandybridge)' in warning


def test_sites_and_set_shape_the_study(registry: StudyRegistry, tmp_path: Path) -> None:
    argv = [
        'run',
        'synthetic-search',
        '--sites',
        '2',
        '--set',
        'robots=4',
        '--set',
        'sim.steps=10',
        '--engine',
        'serial',
        '--out',
        str(tmp_path),
        '--quiet',
    ]
    assert _run(registry, *argv) == 0
    rows = read_rows(tmp_path / 'synthetic-search')
    assert len(rows) == 3 * 2
    assert set(rows['config.robots']) == {4}
    assert set(rows['param.sim.steps']) == {10}
    assert set(rows['seed']) == {0, 1}


def test_first_site_moves_the_sites_to_held_out_indices(
    registry: StudyRegistry, tmp_path: Path
) -> None:
    argv = ['run', 'synthetic-search', '--sites', '2', '--first-site', '300', '--set', 'robots=4']
    assert _run(registry, *argv, '--engine', 'serial', '--out', str(tmp_path), '--quiet') == 0
    rows = read_rows(tmp_path / 'synthetic-search')
    assert set(rows['seed']) == {300, 301}
    manifest = read_manifest(tmp_path / 'synthetic-search')
    assert manifest['seeds'] == [300, 301]


def test_failed_runs_exit_1_and_the_report_lists_them(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [
        'run',
        'synthetic-search',
        '--smoke',
        '--set',
        'fail_seeds=[1]',
        '--engine',
        'serial',
        '--out',
        str(tmp_path),
        '--quiet',
    ]
    assert _run(registry, *argv) == 1
    assert '3 ok, 3 failed' in capsys.readouterr().out
    assert _run(registry, 'report', str(tmp_path)) == 1
    page = (tmp_path / 'synthetic-search-smoke' / 'report.md').read_text()
    assert '3 ok, 3 failed, 0 not run of 6 planned' in page
    assert 'ValueError: seed 1 fails on purpose' in page


@pytest.mark.parametrize(
    ('argv', 'message'),
    [
        (['run', 'nope'], "no study named 'nope'"),
        (['run', 'synthetic-search', '--set', 'steps=3'], "no parameter 'steps'"),
        (['run', 'synthetic-search', '--set', 'oops'], 'expected PARAM=VALUE'),
        (['run', 'synthetic-search', '--runs', '0'], '>= 1'),
        (['run', 'synthetic-search', '--runs', '2', '--sites', '2'], 'not allowed with'),
        (['run', 'synthetic-search', '--first-site', '-1'], 'first seed must be >= 0'),
        (['run', 'synthetic-search', '--first-site', '1', '--first-seed', '1'], 'not allowed'),
        (['run', 'synthetic-search', '--engine', 'spark'], 'invalid choice'),
        (['run', 'synthetic-search', '--workers', '0'], '--workers must be >= 1'),
        (['report', '/nonexistent/dir'], 'no such directory'),
        (['frobnicate'], 'invalid choice'),
        (['--studies', 'no_module_x:f', 'list'], 'cannot import'),
    ],
)
def test_usage_errors_exit_2_with_one_line(
    argv: list[str],
    message: str,
    registry: StudyRegistry,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    full = list(argv)
    if full[0] == 'run':
        full += ['--out', str(tmp_path), '--quiet']
        if '--engine' not in full:
            full += ['--engine', 'serial']
    assert main(full, registry=registry) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1, err
    assert err.startswith('swarm_study: ')
    assert message in err
    assert 'Traceback' not in err


def test_debug_shows_the_traceback(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert _run(registry, '--debug', 'run', 'nope', '--out', str(tmp_path)) == 2
    err = capsys.readouterr().err
    assert 'Traceback' in err
    assert err.rstrip().endswith(
        "swarm_study: no study named 'nope' (known: synthetic-search, synthetic-slow)"
    )


def test_an_unreachable_cluster_is_a_one_line_error(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = _run(
        registry,
        'run',
        'synthetic-search',
        '--smoke',
        '--engine',
        'dask',
        '--address',
        'tcp://127.0.0.1:9',
        '--connect-timeout-s',
        '2',
        '--out',
        str(tmp_path),
        '--quiet',
    )
    assert code == 1
    err = capsys.readouterr().err
    assert err.startswith('swarm_study: cannot reach the Dask scheduler at tcp://127.0.0.1:9')
    assert err.count('\n') == 1


def test_project_reads_measured_rows_and_prints_the_wall_time(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        _run(
            registry,
            'run',
            'synthetic-search',
            '--runs',
            '1',
            '--engine',
            'serial',
            '--out',
            str(tmp_path),
            '--quiet',
        )
        == 0
    )
    capsys.readouterr()
    assert (
        _run(
            registry,
            'project',
            'synthetic-search',
            '--runs',
            '100',
            '--from',
            str(tmp_path / 'synthetic-search'),
            '--cores',
            '32',
        )
        == 0
    )
    out = capsys.readouterr().out
    assert out.startswith('synthetic-search: 900 runs on 32 cores: ')
    code = _run(
        registry,
        'project',
        'synthetic-search',
        '--set',
        'robots=8',
        '--from',
        str(tmp_path / 'synthetic-search'),
        '--cores',
        '4',
    )
    assert code == 2
    assert 'no measured run for 3 configurations: variant=gas, robots=8' in capsys.readouterr().err


def _default_sigint() -> None:
    # A shell without job control starts background jobs with SIGINT ignored, and a Python
    # started with SIGINT ignored never raises KeyboardInterrupt: give the child the
    # disposition a terminal's Ctrl-C meets, whatever launched the test run.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _cli(tmp_path: Path, *argv: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [
            sys.executable,
            '-m',
            'swarm_experiments.study.cli',
            '--studies',
            'study_fixtures:studies',
            *argv,
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_sigint,
    )


@pytest.mark.slow
def test_ctrl_c_keeps_the_finished_runs_and_the_same_command_resumes(tmp_path: Path) -> None:
    out = tmp_path / 'out'
    # 0.4 s a run keeps the study going for about 5 s on two workers, so the Ctrl-C below
    # lands mid-study even when a loaded machine starves this test's polling for seconds.
    argv = [
        'run',
        'synthetic-slow',
        '--set',
        'sleep_s=0.4',
        '--engine',
        'pool',
        '--workers',
        '2',
        '--out',
        str(out),
        '--batch-rows',
        '1',
    ]
    process = _cli(tmp_path, *argv)
    study_dir = out / 'synthetic-slow'
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(study_dir.glob('part-*.parquet'))) < 3:
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert 'interrupted; run the same command again to resume' in err
    assert 'Traceback' not in err
    kept = read_rows(study_dir)
    assert 3 <= len(kept) < 24
    assert set(kept['status']) == {'ok'}, 'runs cut short by Ctrl-C leave no row'
    resumed = _cli(tmp_path, *argv, '--quiet')
    stdout, err = resumed.communicate(timeout=120)
    assert resumed.returncode == 0, err
    assert f'{24 - len(kept)} ok, 0 failed, {len(kept)} already stored' in stdout
    serial = _cli(
        tmp_path,
        'run',
        'synthetic-slow',
        '--set',
        'sleep_s=0.4',
        '--engine',
        'serial',
        '--out',
        str(tmp_path / 'serial'),
        '--quiet',
    )
    serial.communicate(timeout=120)
    assert comparable(read_rows(study_dir)) == comparable(
        read_rows(tmp_path / 'serial' / 'synthetic-slow')
    )


def test_help_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(['--help'], registry=StudyRegistry()) == 0
    assert 'usage: swarm_study' in capsys.readouterr().out


def test_the_module_runs_as_a_script(tmp_path: Path) -> None:
    process = _cli(tmp_path, 'list')
    stdout, _ = process.communicate(timeout=60)
    assert process.returncode == 0
    assert 'synthetic-slow' in stdout


@pytest.mark.parametrize(
    ('setting', 'message'),
    [
        ('sim.steps=-1', 'sim.steps=-1: must be >= 1'),
        ('sleep_s=-0.5', 'sleep_s=-0.5: must be >= 0'),
    ],
)
def test_a_value_the_study_rejects_is_exit_2_and_nothing_runs_or_is_written(
    registry: StudyRegistry,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    setting: str,
    message: str,
) -> None:
    out = tmp_path / 'out'
    argv = ['run', 'synthetic-search', '--smoke', '--engine', 'serial', '--out', str(out)]
    assert _run(registry, *argv, '--set', setting) == 2
    captured = capsys.readouterr()
    assert captured.err == f'swarm_study: {message}\n'
    assert 'ok' not in captured.out
    assert not out.exists()


def test_report_of_a_manifest_that_is_not_an_object_is_exit_2_naming_the_file(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / 'study.json').write_text('[1, 2]\n')
    assert _run(registry, 'report', str(tmp_path)) == 2
    err = capsys.readouterr().err
    assert err == (
        f'swarm_study: {tmp_path / "study.json"}: not a study manifest (a JSON object), '
        'found list\n'
    )


def test_report_with_a_foreign_parquet_file_is_exit_2_naming_the_file(
    registry: StudyRegistry, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ['run', 'synthetic-search', '--smoke', '--engine', 'serial', '--out', str(tmp_path)]
    assert _run(registry, *argv, '--quiet') == 0
    study_dir = tmp_path / 'synthetic-search-smoke'
    foreign = study_dir / 'part-zzz-foreign.parquet'
    pd.DataFrame({'x': [1.0]}).to_parquet(foreign)
    capsys.readouterr()
    assert _run(registry, 'report', str(study_dir)) == 2
    err = capsys.readouterr().err
    assert err.startswith(f'swarm_study: {foreign}: not a part file of a study')
    assert err.count('\n') == 1
    assert 'unexpected error' not in err


@pytest.mark.slow
@pytest.mark.parametrize('engine', ['serial', 'pool'])
def test_sigterm_keeps_the_finished_runs_exits_143_and_the_same_command_resumes(
    tmp_path: Path, engine: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / 'out'
    markers = tmp_path / 'markers'
    markers.mkdir()
    monkeypatch.setenv('STUDY_TEST_MARKERS', str(markers))
    argv = ['run', 'synthetic-slow', '--set', 'sleep_s=0.4', '--engine', engine]
    argv += ['--workers', '2'] if engine == 'pool' else []
    argv += ['--out', str(out), '--quiet']
    process = _cli(tmp_path, *argv)
    study_dir = out / 'synthetic-slow'
    # Three runs started: at least one finished (two workers at most). Its row is only in
    # memory (a part is written every 50 rows or 30 s) until the stop writes it.
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(list(markers.iterdir())) < 3:
        time.sleep(0.05)
    assert not list(study_dir.glob('part-*.parquet'))
    process.send_signal(signal.SIGTERM)
    stdout, err = process.communicate(timeout=60)
    assert process.returncode == 143, err
    assert 'stopped by SIGTERM; run the same command again to resume' in err
    assert 'Traceback' not in err
    kept = read_rows(study_dir)
    assert 1 <= len(kept) < 24, stdout
    assert set(kept['status']) == {'ok'}, 'runs cut short by SIGTERM leave no row'
    resumed = _cli(tmp_path, *argv)
    stdout, err = resumed.communicate(timeout=120)
    assert resumed.returncode == 0, err
    assert f'{24 - len(kept)} ok, 0 failed, {len(kept)} already stored' in stdout
