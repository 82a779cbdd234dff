"""The repository is self-contained: no tracked file points at a document it does not hold.

Two checks over every tracked text file: no mention of the design documents the project was
written from (they are not part of it: what users need from them is in docs/), and no
upper-case ``NAME.md`` that is not a tracked file; and in every Markdown file, every relative
link resolves to a tracked file or folder.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path
from urllib.parse import unquote

import pytest

pytestmark = pytest.mark.runtime_independent(reason='reads docs')

ROOT = Path(__file__).resolve().parents[1]

# Spelt in pieces so that this file does not name them itself.
OUTSIDE_DOCUMENTS = tuple(
    ''.join(parts)
    for parts in (
        ('HARD', 'WARE.md'),
        ('REFERENCE', '_OABUG_SIM'),
        ('REFERENCE', '_BAYES'),
        ('ALGORITHM', '_SPECS'),
        ('ROS', '_FACTS'),
        ('STYLE', '.md'),
        ('ARCHITECTURE', '.md'),
        ('shared', '/docs'),
        ('shared', '/papers'),
        ('design', ' folder'),
    )
)
UPPER_CASE_DOC = re.compile(r'\b[A-Z][A-Z0-9_]{2,}\.md\b')
# [text](target) and [text]: target, the target without a title.
INLINE_LINK = re.compile(r'\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
REFERENCE_LINK = re.compile(r'^\s*\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+"[^"]*")?\s*$', re.MULTILINE)
EXTERNAL = re.compile(r'^(?:[a-z][a-z0-9+.-]*:|#|//)', re.IGNORECASE)


def tracked_files() -> list[Path]:
    try:
        out = subprocess.run(
            ['git', 'ls-files', '-z'], cwd=ROOT, check=True, capture_output=True
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip('not a git checkout: the tracked files are unknown')
    return [ROOT / name for name in out.decode().split('\0') if name]


def text_of(path: Path) -> str | None:
    try:
        data = path.read_bytes()
    except OSError:  # tracked but deleted in the work tree
        return None
    if b'\0' in data[:8192]:
        return None
    try:
        return data.decode('utf-8')
    except UnicodeDecodeError:
        return None


def markdown_links(text: str) -> list[str]:
    # Code spans and fenced blocks are examples, not links.
    text = re.sub(r'```.*?```', '', text, flags=re.DOTALL)
    text = re.sub(r'`[^`\n]*`', '', text)
    return INLINE_LINK.findall(text) + REFERENCE_LINK.findall(text)


def test_no_file_names_a_document_outside_the_repository() -> None:
    files = tracked_files()
    names = {path.name for path in files}
    found = []
    for path in files:
        text = None if path == Path(__file__).resolve() else text_of(path)
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), start=1):
            where = f'{path.relative_to(ROOT)}:{number}'
            found += [f'{where}: {name}' for name in OUTSIDE_DOCUMENTS if name in line]
            found += [
                f'{where}: {name}' for name in UPPER_CASE_DOC.findall(line) if name not in names
            ]
    assert not found, 'references to documents the repository does not hold:\n' + '\n'.join(found)


def test_relative_markdown_links_resolve() -> None:
    files = tracked_files()
    existing = {path.relative_to(ROOT).as_posix() for path in files}
    folders = {parent.as_posix() for name in existing for parent in Path(name).parents}
    broken = []
    for path in files:
        if path.suffix != '.md':
            continue
        text = text_of(path)
        if text is None:
            continue
        for target in markdown_links(text):
            if EXTERNAL.match(target):
                continue
            relative = unquote(target.split('#', 1)[0])
            if not relative:
                continue
            base = Path('.') if relative.startswith('/') else path.parent.relative_to(ROOT)
            resolved = (ROOT / base / relative.lstrip('/')).resolve()
            try:
                key = resolved.relative_to(ROOT).as_posix()
            except ValueError:
                broken.append(f'{path.relative_to(ROOT)}: {target} (outside the repository)')
                continue
            if key not in existing and key not in folders:
                broken.append(f'{path.relative_to(ROOT)}: {target}')
    assert not broken, 'Markdown links that do not resolve:\n' + '\n'.join(broken)


def test_the_checks_catch_what_they_are_for(tmp_path: Path) -> None:
    """The patterns find an outside document, an unknown NAME.md and a link target."""
    line = f'see {OUTSIDE_DOCUMENTS[0]} and NOTES_X.md, [a](docs/missing.md "t") [b](#top)'
    assert OUTSIDE_DOCUMENTS[0] in line
    assert UPPER_CASE_DOC.findall(line) == [OUTSIDE_DOCUMENTS[0], 'NOTES_X.md']
    assert markdown_links(line) == ['docs/missing.md', '#top']
    assert markdown_links('`[a](b.md)` and\n```\n[c](d.md)\n```\n[e]: f.md') == ['f.md']
