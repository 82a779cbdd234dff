"""Outputs of the command-line tools: checked before a run, never left half-written.

- :func:`check_output_directory` and :func:`check_new_output` say before a long run whether
  the directory (``--out``) or the new file or directory (``--record``) can be written,
  without creating anything;
- :func:`atomic_output` and :func:`write_text_atomic` write a file under a temporary name
  in the same directory and rename it into place when it is complete, so a reader (or a
  crash) never sees a partial plot or report under the final name;
- :func:`staging_path` is the temporary sibling a directory (a bag) is written into before
  it is renamed to its final name.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import tempfile
from collections.abc import Iterator
from pathlib import Path

from swarm_common.errors import OutputError

__all__ = [
    'atomic_output',
    'check_new_output',
    'check_output_directory',
    'check_output_file',
    'staging_path',
    'write_text_atomic',
]


def _label(path: Path, option: str | None) -> str:
    return f'{option} {path}' if option else str(path)


def _nearest_existing(path: Path) -> Path:
    current = path
    while not os.path.lexists(current):
        parent = current.parent
        if parent == current:
            break
        current = parent
    return current


def _check_can_create_in(path: Path, label: str) -> None:
    """``path`` (not existing yet) can be created: its nearest existing ancestor is a
    directory this process can write in (tried with a temporary file, which works for root
    and read-only mounts where ``os.access`` does not)."""
    ancestor = _nearest_existing(path.parent)
    if not ancestor.is_dir():
        msg = f'{label}: {ancestor} is not a directory'
        raise OutputError(msg)
    _probe(ancestor, label)


def _probe(directory: Path, label: str) -> None:
    try:
        handle, name = tempfile.mkstemp(prefix='.write-check-', dir=directory)
    except OSError as err:
        reason = err.strerror or str(err)
        msg = f'{label}: cannot write in {directory}: {reason}'
        raise OutputError(msg) from None
    os.close(handle)
    with contextlib.suppress(OSError):
        os.unlink(name)


def check_output_directory(path: str | Path, *, option: str | None = None) -> Path:
    """Check that files can be written into directory ``path`` (existing or not).

    Nothing is created; the directory is made when the first output is written.

    Args:
        path: the directory.
        option: the command-line option that named it, quoted in the message.

    Raises:
        OutputError: ``path`` is a file, lies under a file, or cannot be written in.
    """
    path = Path(path)
    label = _label(path, option)
    if path.exists():
        if not path.is_dir():
            raise OutputError(f'{label}: is a file, not a directory')
        _probe(path, label)
    else:
        _check_can_create_in(path / 'file', label)
    return path


def check_output_file(path: str | Path, *, option: str | None = None) -> Path:
    """Check that file ``path`` can be written (created, or replaced if it exists).

    Raises:
        OutputError: ``path`` is a directory, lies under a file, or its directory cannot be
            written in.
    """
    path = Path(path)
    label = _label(path, option)
    if path.is_dir():
        raise OutputError(f'{label}: is a directory, not a file')
    _check_can_create_in(path, label)
    return path


def check_new_output(path: str | Path, *, option: str | None = None, what: str = 'output') -> Path:
    """Check that ``path`` does not exist yet and can be created (a bag directory, say).

    Raises:
        OutputError: ``path`` exists, lies under a file, or its directory cannot be written in.
    """
    path = Path(path)
    label = _label(path, option)
    if os.path.lexists(path):
        kind = 'a directory' if path.is_dir() else 'a file'
        msg = f'{label}: {kind} of that name exists already; a {what} is never overwritten'
        raise OutputError(msg)
    _check_can_create_in(path, label)
    return path


def staging_path(path: str | Path) -> Path:
    """The hidden sibling ``.<name>.<pid>.partial`` a directory is written into before it is
    renamed to ``path``; a run that is killed leaves it under this name only."""
    path = Path(path)
    return path.with_name(f'.{path.name}.{os.getpid()}.partial')


@contextlib.contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it to ``path`` when the block ends.

    The temporary name keeps the suffix (matplotlib picks the format from it). If the block
    raises, the temporary file is removed and ``path`` is left as it was. The directory is
    created if needed.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    while True:
        temporary = path.with_name(f'.{path.stem}.{secrets.token_hex(4)}.tmp{path.suffix}')
        try:
            # Created like an ordinary file (0666 less the umask), unlike mkstemp's 0600.
            os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        break
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            temporary.unlink()
        raise


def write_text_atomic(path: str | Path, text: str, *, encoding: str = 'utf-8') -> Path:
    """Write ``text`` to ``path`` through :func:`atomic_output`; return the path."""
    with atomic_output(path) as temporary:
        temporary.write_text(text, encoding=encoding)
    return Path(path)
