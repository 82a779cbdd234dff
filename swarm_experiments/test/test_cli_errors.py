"""Bad input to every command-line tool: one stderr line, a documented exit code, no output.

Each row of :data:`ROWS` runs a tool's real ``main`` in-process (the rows in
:data:`SUBPROCESS_ROWS` run the installed command in a child process) in a fresh working
directory, and checks the exit code, that stderr is one line naming the tool and holding the
row's key words, that there is no traceback, and that nothing was written: neither in the
working directory (where default outputs such as ``oabug_results/`` would go) nor next to the
input files.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
OFFICE_PLAN = REPO / 'swarm_sim' / 'config' / 'sites' / 'office_plan.lay'

UNREACHABLE_ROOM = """\
format: swarm_site/1
name: sealed-room
bounds: {width_m: 4.0, height_m: 3.0}
departure_points:
  center: {x_m: 1.0, y_m: 1.5}
entrance:
  segment: [1.8, 0.0, 2.2, 0.0]
walls:
- [0.0, 0.0, 1.8, 0.0]
- [2.2, 0.0, 4.0, 0.0]
- [4.0, 0.0, 4.0, 3.0]
- [0.0, 3.0, 4.0, 3.0]
- [0.0, 0.0, 0.0, 3.0]
- [2.5, 1.5, 4.0, 1.5]
- [2.5, 1.5, 2.5, 3.0]
rooms:
- {id: 1, rects: [[2.5, 1.5, 4.0, 3.0]]}
"""


@dataclass(frozen=True)
class Row:
    """One bad input: the tool, its arguments, the exit code and the words of the message.

    ``{inputs}`` in an argument is the directory of the prepared bad files, ``{work}`` the
    row's working directory.
    """

    name: str
    tool: str
    argv: tuple[str, ...]
    words: tuple[str, ...]
    code: int = 2


def _row(name: str, tool: str, argv: str, *words: str, code: int = 2) -> Row:
    return Row(name, tool, tuple(argv.split()), words, code)


ROWS = [
    # Sites given to a spawner (the file, the line, what is wrong).
    _row('yaml syntax', 'spawn', '--site {inputs}/bad_syntax.yaml', 'bad_syntax.yaml:3', 'YAML'),
    _row('wrong type', 'spawn', '--site {inputs}/wrong_type.yaml', 'wrong_type.yaml:3', 'bounds'),
    _row('empty site file', 'spawn', '--site {inputs}/empty.yaml', 'empty.yaml', 'empty'),
    _row('unreachable room', 'spawn', '--site {inputs}/unreachable.yaml', ':17:', 'not reachable'),
    _row('garbage .yaml', 'spawn', '--site {inputs}/garbage.yaml', 'garbage.yaml:1', 'not UTF-8'),
    _row('garbage .lay', 'spawn', '--site {inputs}/garbage.lay', 'garbage.lay:1:1', 'not UTF-8'),
    _row('unclosed wall', 'spawn', '--site {inputs}/unclosed.lay', 'unclosed.lay:6:1', 'open'),
    _row('0 rooms (.yaml)', 'spawn', '--site {inputs}/no_rooms.yaml', 'no rooms'),
    _row('0 rooms (.lay)', 'spawn', '--site {inputs}/box_only.lay', 'box_only.lay', 'no rooms'),
    _row('no such site', 'spawn', '--site medum', "'medum'", 'neither a preset'),
    _row('site is a directory', 'spawn', '--site {inputs}', 'is a directory'),
    _row('unknown site type', 'spawn', '--site {inputs}/plain_file', 'unknown site file type'),
    _row('no such departure', 'spawn', '--departure roof', "'roof'", 'center, edge'),
    _row('site is a list', 'spawn', '--site {inputs}/list.yaml', 'list.yaml:1', 'mapping'),
    _row('missing key', 'spawn', '--site {inputs}/no_bounds.yaml', 'no_bounds.yaml:1', "'bounds'"),
    _row('site is a device', 'spawn', '--site /dev/null', "'/dev/null'", 'not a regular file'),
    # Outputs, checked before the run.
    _row('record into a bag', 'spawn', '--record {inputs}/old_bag', '--record', 'exists already'),
    _row('record under a file', 'spawn', '--record {inputs}/plain_file/bag', 'not a directory'),
    _row('out is a file', 'spawn', '--out {inputs}/plain_file', '--out', 'is a file'),
    _row('out unwritable', 'spawn', '--out {unwritable}/plots', '--out', 'cannot write in'),
    _row('out under a device', 'spawn', '--out /dev/null/plots', '--out', 'not a directory'),
    # Limits checked against the site, and plain bad values.
    _row('10000 robots', 'spawn', '--robots 10000', '10000 robots', '91 m^2', 'at most 2632'),
    _row('101 robots', 'spawn', '--robots 101', '--robots must be in 1..100'),
    _row('0 robots', 'spawn', '--robots 0', 'robots must be >= 1'),
    _row('robots not int', 'spawn', '--robots ten', "--robots: invalid int value: 'ten'"),
    _row('negative seed', 'spawn', '--seed -1', 'seeds must be >= 0'),
    _row('negative site seed', 'spawn', '--site-seed -2', 'site seed -2'),
    _row('negative actions', 'spawn', '--actions -5', 'actions must be >= 1'),
    _row('negative speed', 'spawn', '--speed -0.3', 'speed_mps must be positive'),
    _row('nan speed', 'spawn', '--speed nan', 'speed_mps must be positive'),
    _row('unknown variant', 'spawn', '--variant fast', '--variant', 'invalid choice'),
    _row('unknown option', 'spawn', '--robot 3', 'unrecognized arguments'),
    _row('bad --param value', 'spawn', '--param gas_threshold=high', 'gas_threshold'),
    _row('unknown --param', 'spawn', '--param warp=9', 'warp'),
    _row('--param no =', 'spawn', '--param gas_threshold', 'gas_threshold'),
    _row('spawner-set --param', 'spawn', '--param variant=gas', 'variant'),
    _row('MSC target outside', 'spawn_msc_pf', '--target-positions 5000,5000', '(5000, 5000)'),
    _row('MSC target negative', 'spawn_msc_pf', '--target-positions=-1,-1', '(-1, -1)', 'field'),
    _row('MSC bad points', 'spawn_msc_pf', '--target-positions 1,2;3', 'must look like'),
    _row('MSC nan point', 'spawn_msc_pf', '--target-positions nan,1', 'finite numbers'),
    _row('MSC 10000 robots', 'spawn_msc_pf', '--robots 10000', '--robots must be in 1..100'),
    _row('MSC 0 targets', 'spawn_msc_pf', '--targets 0', '--targets must be in 1..100'),
    _row('MSC 10000 targets', 'spawn_msc_pf', '--targets 10000', '--targets must be in 1..100'),
    _row(
        'MSC targets and positions disagree',
        'spawn_msc_pf',
        '--targets 3 --target-positions 1,1',
        '--targets 3 but --target-positions gives 1',
    ),
    _row('MSC negative T_max', 'spawn_msc_pf', '--t-max -5', '--t-max', '> 0'),
    _row('MSC inf T_max', 'spawn_msc_pf', '--t-max inf', '--t-max', 'finite'),
    _row('MSC negative seed', 'spawn_msc_pf', '--seed -1', '--seed must be >= 0'),
    _row('MSC loss 2', 'spawn_msc_pf', '--loss 2', '--loss', '[0, 1]'),
    _row('MSC comm range 0', 'spawn_msc_pf', '--comm-range 0', '--comm-range'),
    _row('MSC bad --param', 'spawn_msc_pf', '--param swarm.max_size=three', 'max_size'),
    _row('MSC record exists', 'spawn_msc_pf', '--record {inputs}/old_bag', 'exists already'),
    _row('MSC out unwritable', 'spawn_msc_pf', '--out {unwritable}/p', 'cannot write in'),
    _row('Bayes nan noise', 'spawn_bayes_swarm', '--noise nan', '--noise', 'finite'),
    _row('Bayes negative T_max', 'spawn_bayes_swarm', '--t-max -1', '--t-max'),
    _row('Bayes depot outside', 'spawn_bayes_swarm', '--depots 100,100', 'inside the arena'),
    _row('Bayes depot negative', 'spawn_bayes_swarm', '--depots=-1,0', 'inside the arena'),
    _row('Bayes bad depots', 'spawn_bayes_swarm', '--depots a,b', '--depots must look like'),
    _row('Bayes 10000 robots', 'spawn_bayes_swarm', '--robots 10000', '1..100'),
    _row('Bayes unknown case', 'spawn_bayes_swarm', '--case case9', '--case', 'invalid choice'),
    _row('Bayes loss -1', 'spawn_bayes_swarm', '--loss -1', '--loss'),
    _row('Bayes negative seed', 'spawn_bayes_swarm', '--seed -4', '--seed must be >= 0'),
    _row('Bayes spawner-set --param', 'spawn_bayes_swarm', '--param n_robots=4', 'n_robots'),
    _row('Bayes record under file', 'spawn_bayes_swarm', '--record {inputs}/plain_file/b', 'not a'),
    # site_tool.
    _row('validate yaml syntax', 'site_tool', 'validate {inputs}/bad_syntax.yaml', 'YAML'),
    _row('validate garbage', 'site_tool', 'validate {inputs}/garbage.yaml', 'not UTF-8'),
    _row('validate garbage .lay', 'site_tool', 'validate {inputs}/garbage.lay', 'not UTF-8'),
    _row('validate 0 rooms', 'site_tool', 'validate {inputs}/no_rooms.yaml', 'no rooms'),
    _row('validate 0 rooms .lay', 'site_tool', 'validate {inputs}/box_only.lay', 'no rooms'),
    _row('validate unreachable', 'site_tool', 'validate {inputs}/unreachable.yaml', 'reachable'),
    _row('validate a directory', 'site_tool', 'validate {inputs}', 'is a directory'),
    _row('validate missing', 'site_tool', 'validate {inputs}/missing.yaml', 'No such file'),
    _row('validate no argument', 'site_tool', 'validate', 'required: site'),
    _row(
        'generate 0 rooms', 'site_tool', 'generate --seed 1 --rooms 0 -o {work}/s.yaml', 'positive'
    ),
    _row('generate bad seed', 'site_tool', 'generate --seed -1 -o {work}/s.yaml', '--seed'),
    _row('generate -o dir', 'site_tool', 'generate --seed 1 -o {inputs}', 'is a directory'),
    _row(
        'generate png unwritable',
        'site_tool',
        'generate --seed 1 -o {work}/s.yaml --png {unwritable}/s.png',
        '--png',
        'cannot write in',
    ),
    _row('render under a file', 'site_tool', 'render x.lay -o {inputs}/plain_file/x.png', '-o'),
    _row(
        'import bad departure',
        'site_tool',
        'import-lay x.lay -o {work}/x.yaml --departure c',
        'NAME',
    ),
    # Reports from bags.
    _row('report missing bag', 'swarm_report', '{inputs}/nowhere', 'no such bag'),
    _row('report a file', 'swarm_report', '{inputs}/plain_file', 'not a bag directory'),
    _row('report empty dir', 'swarm_report', '{inputs}/old_bag', 'not a bag'),
    _row('report garbage mcap', 'swarm_report', '{inputs}/garbage_bag', '--recover'),
    _row('report unfinished bag', 'swarm_report', '{inputs}/unfinished', 'not closed', '--recover'),
    _row('report no mission', 'swarm_report', '{inputs}/counts', 'not a recorded simulation'),
    _row(
        'report out is a file', 'swarm_report', '{inputs}/counts --out {inputs}/plain_file', 'file'
    ),
    _row(
        'report out unwritable',
        'swarm_report',
        '{inputs}/counts --out {unwritable}/r',
        '--out',
        'cannot write in',
    ),
    _row('report both out', 'swarm_report', 'x --out a --out-dir b', 'give only --out'),
    _row('oabug_report missing', 'oabug_report', '{inputs}/nowhere', 'no such bag'),
    _row('oabug_report no topics', 'oabug_report', '{inputs}/counts', 'has no /sim/site'),
    # Studies, the robot, benchmarks.
    _row('study unknown', 'swarm_study', 'run nope --out {work}/out', "no study named 'nope'"),
    _row('study report missing', 'swarm_study', 'report {inputs}/nowhere', 'no such directory'),
    _row('study bad option', 'swarm_study', 'run', 'required: name'),
    _row(
        'study --set of the wrong type',
        'swarm_study',
        'run oabug-fig4 --set robots=abc --out {work}/out',
        '--set robots=abc: expected a whole number (like 2)',
    ),
    _row('bringup index', 'robot_bringup', '--robot-index 5 --robot-count 2', '--robot-index'),
    _row('bringup count', 'robot_bringup', '--robot-count 0', '--robot-count must be >= 1'),
    _row('bringup grace', 'robot_bringup', '--grace x', "invalid float value: 'x'"),
    _row('bringup params', 'robot_bringup', '--params-file {inputs}/none.yaml --fake', 'no such'),
    _row(
        'bringup params a list',
        'robot_bringup',
        '--params-file {inputs}/list.yaml --fake',
        'list.yaml',
        'node names',
    ),
    _row('bench_oabug sites', 'bench_oabug', '--sites 0', '--sites must be >= 1'),
    _row('bench_oabug out', 'bench_oabug', '--out {inputs}/plain_file/t.md', 'not a directory'),
    _row('bench_oabug param', 'bench_oabug', '--set gas_threshold=high', 'gas_threshold'),
    _row('bench_msc_pf T_max', 'bench_msc_pf', '--max-time -1', '--max-time'),
    _row('bench_msc_pf runs', 'bench_msc_pf', '--runs 0', '--runs must be >= 1'),
    _row('bench_bayes runs', 'bench_bayes_swarm', '--runs 0', '--runs must be >= 1'),
    _row('bench_bayes out', 'bench_bayes_swarm', '--out {inputs}', 'is a directory'),
    _row('bench_sites sites', 'bench_sites', '--sites 0', '--sites must be >= 1'),
    _row('bench_drivers output', 'bench_drivers', '--output {inputs}', 'is a directory'),
    _row('bench_runtime robots', 'bench_runtime', '--robots 0', '--robots must be >= 1'),
]

# Installed commands run in a child process: (command, module for ``python -m``).
SUBPROCESS_ROWS = {
    'garbage .yaml': ('spawn', 'swarm_experiments.spawn'),
    '10000 robots': ('spawn', 'swarm_experiments.spawn'),
    'MSC target outside': ('spawn_msc_pf', 'swarm_experiments.spawn_msc_pf'),
    'Bayes nan noise': ('spawn_bayes_swarm', 'swarm_experiments.spawn_bayes_swarm'),
    'validate garbage': ('site_tool', 'swarm_sim.sites.cli'),
    'report missing bag': ('swarm_report', 'swarm_analysis.cli'),
    'oabug_report missing': (None, 'swarm_analysis.oabug_report'),
    'bringup index': ('robot_bringup', 'hw_drivers.robot_bringup.cli'),
}

BENCHMARKS = ('bench_oabug', 'bench_msc_pf', 'bench_bayes_swarm', 'bench_sites', 'bench_drivers')


def _unwritable_directory(base: Path) -> Path:
    """A directory this process cannot create files in (root ignores permission bits)."""
    if os.geteuid() != 0:
        locked = base / 'locked'
        locked.mkdir()
        locked.chmod(0o500)
        return locked
    for candidate in (Path('/sys'), Path('/proc/sys')):
        try:
            (candidate / '.probe').touch()
        except OSError:
            return candidate
    pytest.skip('no unwritable directory on this machine')


@pytest.fixture(scope='module')
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The bad files every row refers to."""
    from swarm_runtime.bag import BagWriter
    from swarm_runtime.messages import get_message_module

    root = tmp_path_factory.mktemp('inputs')
    (root / 'bad_syntax.yaml').write_text('format: swarm_site/1\nname: [\n')
    (root / 'wrong_type.yaml').write_text(
        'format: swarm_site/1\nname: x\nbounds: 5\ndeparture_points: {c: {x_m: 1, y_m: 1}}\n'
        'walls: []\n'
    )
    (root / 'empty.yaml').write_text('')
    (root / 'list.yaml').write_text('- 1\n- 2\n')
    (root / 'no_bounds.yaml').write_text('format: swarm_site/1\nname: x\n')
    (root / 'unreachable.yaml').write_text(UNREACHABLE_ROOM)
    no_rooms = UNREACHABLE_ROOM.replace('rooms:\n- {id: 1, rects: [[2.5, 1.5, 4.0, 3.0]]}\n', '')
    (root / 'no_rooms.yaml').write_text(no_rooms)
    garbage = bytes(range(128, 256)) * 4
    (root / 'garbage.yaml').write_bytes(garbage)
    (root / 'garbage.lay').write_bytes(garbage)
    lines = OFFICE_PLAN.read_text().splitlines()
    lines[5] = ' ' + lines[5][1:]
    (root / 'unclosed.lay').write_text('\n'.join(lines) + '\n')
    (root / 'box_only.lay').write_text('%%%%%%%%\n%      %\n%   D  %\n%      %\n%%%/%%%%\n')
    (root / 'plain_file').write_text('not a site, not a bag\n')
    (root / 'old_bag').mkdir()
    (root / 'garbage_bag').mkdir()
    (root / 'garbage_bag' / 'garbage_bag.mcap').write_bytes(garbage)
    std_msgs = get_message_module('std_msgs')
    with BagWriter(root / 'counts') as writer:
        writer.write_message('/count', 1, std_msgs.Int32(data=1))
    unfinished = BagWriter(root / 'unfinished')
    unfinished.open()
    unfinished.write_message('/count', 1, std_msgs.Int32(data=1))
    unfinished.flush()  # never closed, like a killed recording
    (root / 'unwritable').symlink_to(_unwritable_directory(root))
    return root


def _tree(path: Path) -> dict[str, tuple[int, int]]:
    """Relative path -> (size, mtime ns) of everything under ``path``."""
    found = {}
    for entry in sorted(path.rglob('*')):
        if entry.is_symlink():
            continue
        stat = entry.stat()
        found[str(entry.relative_to(path))] = (
            stat.st_size if entry.is_file() else 0,
            stat.st_mtime_ns,
        )
    return found


def _main_of(tool: str, benchmark_script: Callable[[str], object]) -> Callable[[list[str]], int]:
    if tool in BENCHMARKS or tool == 'bench_runtime':
        return benchmark_script(tool).main  # type: ignore[attr-defined]
    if tool == 'robot_bringup':
        from hw_drivers.robot_bringup.cli import main as bringup

        def run_bringup(argv: list[str]) -> int:
            with pytest.raises(SystemExit) as stop:
                bringup(argv)
            return int(stop.value.code)

        return run_bringup
    modules = {
        'spawn': 'swarm_experiments.spawn',
        'spawn_msc_pf': 'swarm_experiments.spawn_msc_pf',
        'spawn_bayes_swarm': 'swarm_experiments.spawn_bayes_swarm',
        'site_tool': 'swarm_sim.sites.cli',
        'swarm_report': 'swarm_analysis.cli',
        'oabug_report': 'swarm_analysis.oabug_report',
        'swarm_study': 'swarm_experiments.study.cli',
    }
    import importlib

    return importlib.import_module(modules[tool]).main


def _argv(row: Row, inputs: Path, work: Path) -> list[str]:
    unwritable = str(inputs / 'unwritable')
    return [
        arg.format(inputs=inputs, work=work, unwritable=os.path.realpath(unwritable))
        for arg in row.argv
    ]


def _check(row: Row, code: int, err: str, inputs_before: dict, inputs: Path, work: Path) -> None:
    assert code == row.code, err
    assert 'Traceback' not in err, err
    assert err.count('\n') == 1, f'not one line:\n{err}'
    tool = 'oabug_report' if row.tool == 'oabug_report' else row.tool
    assert err.startswith(f'{tool}: '), err
    for word in row.words:
        assert word in err, f'{word!r} not in {err!r}'
    assert list(work.iterdir()) == [], f'left behind: {sorted(work.rglob("*"))}'
    assert _tree(inputs) == inputs_before, 'an input directory changed'


@pytest.mark.parametrize('row', ROWS, ids=[row.name for row in ROWS])
def test_bad_input_is_one_line_with_its_exit_code_and_leaves_nothing(
    row: Row,
    inputs: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    benchmark_script: Callable[[str], object],
) -> None:
    main = _main_of(row.tool, benchmark_script)
    work = tmp_path / 'work'
    work.mkdir()
    monkeypatch.chdir(work)
    before = _tree(inputs)
    capsys.readouterr()
    code = main(_argv(row, inputs, work))
    _check(row, code, capsys.readouterr().err, before, inputs, work)


def _command(name: str) -> list[str]:
    script, module = SUBPROCESS_ROWS[name]
    installed = Path(sys.executable).parent / script if script else None
    if installed is not None and installed.exists():
        return [str(installed)]
    return [sys.executable, '-m', module]


@pytest.mark.parametrize('name', sorted(SUBPROCESS_ROWS))
def test_the_installed_commands_fail_the_same_way(name: str, inputs: Path, tmp_path: Path) -> None:
    (row,) = [row for row in ROWS if row.name == name]
    work = tmp_path / 'work'
    work.mkdir()
    before = _tree(inputs)
    process = subprocess.run(
        [*_command(name), *_argv(row, inputs, work)],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    _check(row, process.returncode, process.stderr, before, inputs, work)


def test_debug_adds_the_traceback(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    from swarm_experiments.spawn import main

    assert main(['--debug', '--site', str(tmp_path / 'x.yaml')]) == 2
    err = capsys.readouterr().err
    assert err.startswith('Traceback')
    assert 'ConfigurationError' in err
    assert err.rstrip().splitlines()[-1].startswith('spawn: site ')


def test_every_tool_documents_its_exit_codes_and_debug(
    capsys: pytest.CaptureFixture[str], benchmark_script: Callable[[str], object]
) -> None:
    for tool in (
        'spawn',
        'spawn_msc_pf',
        'spawn_bayes_swarm',
        'site_tool',
        'swarm_report',
        'oabug_report',
        'swarm_study',
        *BENCHMARKS,
    ):
        assert _main_of(tool, benchmark_script)(['--help']) == 0, tool
        text = ' '.join(capsys.readouterr().out.split())
        assert 'exit codes: 0' in text, tool
        assert '--debug' in text, tool
    from hw_drivers.robot_bringup.cli import main as bringup

    with pytest.raises(SystemExit) as stop:
        bringup(['--help'])
    assert stop.value.code == 0
    text = ' '.join(capsys.readouterr().out.split())
    assert 'exit status: 0' in text
    assert '--debug' in text


def test_the_deprecated_out_dir_still_works_with_a_warning(tmp_path, capsys) -> None:
    from swarm_analysis.cli import build_parser, resolve_out_option

    args = build_parser().parse_args(['bag', '--out-dir', str(tmp_path)])
    resolve_out_option('swarm_report', args)
    assert args.out == tmp_path
    assert 'deprecated, use --out' in capsys.readouterr().err
    assert '--out-dir' not in build_parser().format_help()


# --- Ctrl-C ---------------------------------------------------------------------------------


def test_ctrl_c_stops_a_mission_at_the_next_step_and_closes_its_bag(tmp_path: Path) -> None:
    from sim_bridge.bouncer import WallBouncer
    from swarm_analysis.oabug_report import load_run
    from swarm_experiments.mission import (
        MissionSpec,
        RecordingSpec,
        RobotNodeSpec,
        StopReason,
        run_mission,
    )
    from swarm_sim.site_loading import load_site

    site = load_site(str(Path(__file__).parent / 'data' / 'five_rooms.lay'))
    bag = tmp_path / 'bag'
    spec = MissionSpec(
        site=site,
        initial_poses=[[2.8, 1.73, 0.0], [3.4, 1.73, 3.14]],
        robots=[RobotNodeSpec(WallBouncer), RobotNodeSpec(WallBouncer)],
        max_sim_time_s=600.0,
        recording=RecordingSpec(bag, ('/clock', '/sim/poses', '/sim/coverage', '/sim/site')),
        progress_period_s=1.0,
    )

    pressed = []

    def press_ctrl_c(report) -> None:
        # Once: the final report (after the handler is restored) must not press again.
        if report.sim_time_s >= 3.0 and not pressed:
            pressed.append(report.sim_time_s)
            os.kill(os.getpid(), signal.SIGINT)

    if threading.current_thread() is not threading.main_thread():
        pytest.skip('signal handlers can only be installed in the main thread')
    previous = signal.getsignal(signal.SIGINT)
    result = run_mission(spec, progress=press_ctrl_c)
    assert signal.getsignal(signal.SIGINT) is previous
    assert result.stop_reason == StopReason.INTERRUPTED
    assert 3.0 <= result.sim_time_s < 4.0
    assert result.bag_path == bag
    assert [p.name for p in tmp_path.iterdir()] == ['bag'], 'no partial directory is left'
    recorded = load_run(bag)
    assert recorded.times_s[-1] == pytest.approx(result.sim_time_s, abs=0.5)


def test_ctrl_c_keeps_the_finished_benchmark_runs(
    benchmark_script: Callable[[str], object],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    bench = benchmark_script('bench_oabug')
    calls = []

    def run_job(job):
        calls.append(job)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return bench.Outcome(job, 0.5, 300.0, 1.0, 1.0, 100.0)

    monkeypatch.setattr(bench, 'run_job', run_job)
    out = tmp_path / 'table.md'
    argv = ['--sites', '3', '--variants', 'gas', '--departures', 'edge', '--workers', '1']
    assert bench.main([*argv, '--out', str(out)]) == 130
    assert capsys.readouterr().err == (
        'bench_oabug: interrupted: the table covers the 2 of 3 runs that finished\n'
    )
    assert '| edge | gas | 2 |' in out.read_text()
    assert len(out.with_suffix('.csv').read_text().splitlines()) == 3


@pytest.mark.slow
def test_ctrl_c_in_a_spawner_prints_the_outcome_so_far_and_leaves_a_valid_bag(
    tmp_path: Path,
) -> None:
    from swarm_analysis.cct import cct_from_bag

    bag = tmp_path / 'bag'
    command = [sys.executable, '-m', 'swarm_experiments.spawn_msc_pf', '--robots', '3']
    command += ['--targets', '2', '--record', str(bag), '--out', str(tmp_path / 'plots')]
    process = subprocess.Popen(
        command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not list(tmp_path.glob('.bag.*.partial/*.mcap')):
        time.sleep(0.2)
    time.sleep(3.0)  # some sim time
    assert not bag.exists(), 'the bag has its final name only once it is complete'
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert 'Traceback' not in err
    assert err.strip().splitlines()[-1].startswith('spawn_msc_pf: interrupted at sim time')
    assert 'CCT: not every target captured by t = ' in out
    assert '(interrupted)' in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ['bag', 'plots']
    result = cct_from_bag(bag)
    assert result.n_targets == 2
    assert result.end_time_s > 0.0
