"""Mission progress off a terminal: a plain line per tenth of the budget, nothing if quiet."""

from __future__ import annotations

import io

from swarm_experiments.mission import MissionProgress
from swarm_experiments.progress import MissionProgressBar, progress_wanted


def _reports(times_s: list[float]) -> list[MissionProgress]:
    return [MissionProgress(t, 0.5 * t, int(t // 100), 30) for t in times_s]


def test_a_log_gets_one_line_per_tenth_of_the_budget() -> None:
    stream = io.StringIO()
    bar = MissionProgressBar('OA-Bug gas', 1000.0, enabled=False, lines=True, stream=stream)
    with bar:
        for report in _reports([0.0, 10.0, 99.0, 100.0, 150.0, 420.0, 1000.0]):
            bar(report)
    lines = stream.getvalue().splitlines()
    # 100 s, then 420 s (it passes 200, 300 and 400 at once), then the end.
    assert lines == [
        'OA-Bug gas: sim 100/1000 s (10 %), rooms 1/30, wall 50.0 s',
        'OA-Bug gas: sim 420/1000 s (42 %), rooms 4/30, wall 210.0 s',
        'OA-Bug gas: sim 1000/1000 s (100 %), rooms 10/30, wall 500.0 s',
    ]


def test_an_empty_detail_leaves_no_empty_field_and_quiet_prints_nothing() -> None:
    stream = io.StringIO()
    bar = MissionProgressBar(
        'msc', 50.0, enabled=False, lines=True, stream=stream, detail=lambda report: ''
    )
    bar(_reports([5.0])[0])
    assert stream.getvalue() == 'msc: sim 5/50 s (10 %), wall 2.5 s\n'
    quiet = io.StringIO()
    silent = MissionProgressBar('msc', 50.0, enabled=False, lines=False, stream=quiet)
    for report in _reports([5.0, 50.0]):
        silent(report)
    assert quiet.getvalue() == ''


def test_the_bar_is_only_for_terminals_and_not_when_quiet() -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    assert progress_wanted(False, Terminal())
    assert not progress_wanted(True, Terminal())
    assert not progress_wanted(False, io.StringIO())
    # With the bar drawn there are no extra lines.
    assert not MissionProgressBar('x', 10.0, enabled=True, lines=True).lines
