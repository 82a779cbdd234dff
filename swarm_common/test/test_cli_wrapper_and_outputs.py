"""The entry-point wrapper (one line per error, exit codes, --debug) and the output checks."""

from __future__ import annotations

import io
import os
from pathlib import Path

import pytest
from swarm_common.cli import (
    EXIT_INTERRUPTED,
    EXIT_SUCCESS,
    EXIT_UNFINISHED,
    EXIT_USAGE,
    ToolParser,
    describe_os_error,
    run_tool,
)
from swarm_common.errors import OutputError, SwarmError, UsageError
from swarm_common.jobs import map_jobs
from swarm_common.outputs import (
    atomic_output,
    check_new_output,
    check_output_directory,
    check_output_file,
    staging_path,
    write_text_atomic,
)


class _UnfinishedError(SwarmError):
    exit_code = EXIT_UNFINISHED


def _run(body, argv=()):
    err = io.StringIO()
    code = run_tool('tool', body, list(argv), stderr=err)
    return code, err.getvalue()


def _raise(error):
    def body(_argv):
        raise error

    return body


@pytest.mark.parametrize(
    ('error', 'code', 'text'),
    [
        (
            SwarmError('site.yaml:3: not valid YAML'),
            EXIT_USAGE,
            'tool: site.yaml:3: not valid YAML',
        ),
        (_UnfinishedError('no capture'), EXIT_UNFINISHED, 'tool: no capture'),
        (
            FileNotFoundError(2, 'No such file or directory', 'x.yaml'),
            EXIT_USAGE,
            'x.yaml: No such',
        ),
        (KeyboardInterrupt(), EXIT_INTERRUPTED, 'tool: interrupted'),
        (ZeroDivisionError('division by zero'), EXIT_UNFINISHED, 'unexpected error: Zero'),
    ],
)
def test_every_error_becomes_one_line_and_its_exit_code(error, code, text):
    got, err = _run(_raise(error))
    assert got == code
    assert err.count('\n') == 1
    assert text in err
    assert 'Traceback' not in err


def test_an_unexpected_error_points_to_debug_and_debug_prints_the_traceback():
    _, plain = _run(_raise(ValueError('boom')))
    assert '--debug' in plain
    code, debug = _run(_raise(ValueError('boom')), ['--debug'])
    assert code == EXIT_UNFINISHED
    assert debug.startswith('Traceback')
    assert debug.rstrip().splitlines()[-1] == 'tool: unexpected error: ValueError: boom'
    _, after_separator = _run(_raise(ValueError('boom')), ['--', '--debug'])
    assert 'Traceback' not in after_separator


def test_a_multi_line_message_is_folded_into_one_line():
    _, err = _run(_raise(SwarmError('first\nsecond')))
    assert err == 'tool: first second\n'


def test_the_body_return_value_is_the_exit_code_and_help_exits_0(capsys):
    assert _run(lambda argv: 1)[0] == 1
    assert _run(lambda argv: None)[0] == EXIT_SUCCESS
    parser = ToolParser(prog='tool')
    code, _ = _run(lambda argv: parser.parse_args(argv), ['--help'])
    assert code == 0
    out = capsys.readouterr().out
    assert '--debug' in out
    assert 'exit codes: 0 done' in out


@pytest.mark.parametrize(
    ('argv', 'words'),
    [
        (['--count', 'x'], "argument --count: invalid int value: 'x'"),
        (['a', '--nope'], 'unrecognized arguments: --nope'),
        ([], 'the following arguments are required: name'),
        (['a', 'sub', '--level', '9'], 'invalid choice'),
    ],
)
def test_argument_errors_are_one_line_usage_errors(argv, words):
    parser = ToolParser(prog='tool')
    parser.add_argument('name')
    parser.add_argument('--count', type=int)
    commands = parser.add_subparsers(dest='command')
    sub = commands.add_parser('sub')
    sub.add_argument('--level', type=int, choices=(1, 2))
    code, err = _run(lambda args: parser.parse_args(args) and 0, argv)
    assert code == EXIT_USAGE
    assert err.count('\n') == 1
    assert words in err
    assert err.rstrip().endswith('--help)')


def test_debug_after_a_subcommand_is_accepted_and_not_reset():
    parser = ToolParser(prog='tool')
    commands = parser.add_subparsers(dest='command')
    commands.add_parser('sub')
    assert parser.parse_args(['sub', '--debug']).debug is True
    assert parser.parse_args(['--debug', 'sub']).debug is True
    assert parser.parse_args(['sub']).debug is False
    with pytest.raises(UsageError):
        parser.parse_args(['sub', '--bogus'])


def test_os_errors_name_the_file():
    assert describe_os_error(PermissionError(13, 'Permission denied', '/x')) == (
        '/x: Permission denied'
    )
    assert describe_os_error(OSError('disk on fire')) == 'disk on fire'


def _unwritable_directory(tmp_path: Path) -> Path:
    """A directory this process cannot create files in (root ignores permission bits)."""
    if os.geteuid() != 0:
        locked = tmp_path / 'locked'
        locked.mkdir()
        locked.chmod(0o500)
        return locked
    for candidate in (Path('/sys'), Path('/proc/sys')):
        try:
            (candidate / '.probe').touch()
        except OSError:
            return candidate
    pytest.skip('no unwritable directory on this machine')


def test_output_checks_name_the_option_and_what_is_in_the_way(tmp_path):
    afile = tmp_path / 'afile'
    afile.write_text('x')
    existing = tmp_path / 'bag'
    existing.mkdir()
    cases = [
        (lambda: check_output_directory(afile, option='--out'), '--out', 'is a file'),
        (lambda: check_output_directory(afile / 'x', option='--out'), 'not a directory'),
        (lambda: check_new_output(existing, option='--record', what='bag'), 'exists already'),
        (lambda: check_new_output(afile / 'bag', option='--record'), 'not a directory'),
        (lambda: check_output_file(tmp_path, option='-o'), 'is a directory'),
        (
            lambda: check_output_directory(_unwritable_directory(tmp_path) / 'x', option='--out'),
            'cannot write in',
        ),
    ]
    for check, *words in cases:
        with pytest.raises(OutputError) as info:
            check()
        assert all(word in str(info.value) for word in words), str(info.value)
    before = sorted(tmp_path.rglob('*'))
    check_output_directory(tmp_path / 'new' / 'deeper', option='--out')
    check_new_output(tmp_path / 'new' / 'bag', option='--record')
    check_output_file(afile, option='-o')
    assert sorted(tmp_path.rglob('*')) == before, 'a check created something'


def test_atomic_output_renames_a_complete_file_and_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / 'plots' / 'figure.png'
    with atomic_output(target) as partial:
        assert partial.suffix == '.png'
        assert partial.parent == target.parent
        assert not target.exists()
        partial.write_bytes(b'complete')
    assert target.read_bytes() == b'complete'

    def crash_while_writing() -> None:
        with atomic_output(target) as partial:
            partial.write_bytes(b'half')
            raise RuntimeError('crash while writing')

    with pytest.raises(RuntimeError):
        crash_while_writing()
    assert target.read_bytes() == b'complete'
    assert sorted(p.name for p in target.parent.iterdir()) == ['figure.png']
    write_text_atomic(tmp_path / 'table.md', 'row\n')
    assert (tmp_path / 'table.md').read_text() == 'row\n'
    assert (tmp_path / 'table.md').stat().st_mode & 0o777 == 0o666 & ~_umask()


def _umask() -> int:
    current = os.umask(0)
    os.umask(current)
    return current


def test_staging_paths_are_hidden_siblings_named_after_the_process(tmp_path):
    staged = staging_path(tmp_path / 'run' / 'bag')
    assert staged.parent == tmp_path / 'run'
    assert staged.name == f'.bag.{os.getpid()}.partial'


def _square(value: int) -> int:
    return value * value


def test_jobs_run_in_order_here_and_in_workers():
    assert list(map_jobs(_square, range(5))) == [0, 1, 4, 9, 16]
    assert list(map_jobs(_square, range(5), workers=2)) == [0, 1, 4, 9, 16]
    assert sorted(map_jobs(_square, range(5), workers=2, ordered=False)) == [0, 1, 4, 9, 16]


def test_a_serial_interrupt_keeps_the_results_already_yielded():
    def job(value: int) -> int:
        if value == 3:
            raise KeyboardInterrupt
        return value

    done: list[int] = []

    def consume() -> None:
        for result in map_jobs(job, range(6)):
            done.append(result)

    with pytest.raises(KeyboardInterrupt):
        consume()
    assert done == [0, 1, 2]
