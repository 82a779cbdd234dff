"""The mission end and trajectory sampling rules every engine runner shares."""

from types import SimpleNamespace

import numpy as np
import pytest
from swarm_sim.mission_rules import (
    ALL_ROOMS_COVERED,
    BUDGET,
    EXTENSION_DONE,
    TrajectorySampler,
    end_reason,
)


def _engine(time_s: float, complete: bool):
    return SimpleNamespace(time_s=time_s, coverage=SimpleNamespace(complete=complete))


@pytest.mark.parametrize(
    ('time_s', 'complete', 'stop_on_rooms', 'extensions', 'expected'),
    [
        (10.0, False, True, None, ''),
        (10.0, True, True, None, ALL_ROOMS_COVERED),
        (10.0, True, False, None, ''),  # rooms covered, but the mission goes on to the budget
        (100.0, True, False, None, BUDGET),
        (100.0 - 1e-12, False, True, None, BUDGET),  # reached up to rounding
        (10.0, False, True, lambda: True, EXTENSION_DONE),
        (10.0, False, True, lambda: False, ''),
        (100.0, False, True, lambda: True, EXTENSION_DONE),  # the extension before the budget
        (100.0, True, True, lambda: True, ALL_ROOMS_COVERED),  # the rooms before both
    ],
)
def test_the_first_condition_that_holds_names_the_end(
    time_s, complete, stop_on_rooms, extensions, expected
):
    reason = end_reason(
        _engine(time_s, complete),
        stop_when_all_rooms_covered=stop_on_rooms,
        max_sim_time_s=100.0,
        extensions_done=extensions,
    )
    assert reason == expected


def test_extensions_are_not_asked_when_the_rooms_end_the_mission():
    def ask() -> bool:
        raise AssertionError('asked')

    reason = end_reason(
        _engine(1.0, True),
        stop_when_all_rooms_covered=True,
        max_sim_time_s=9.0,
        extensions_done=ask,
    )
    assert reason == ALL_ROOMS_COVERED


def test_samples_keep_their_period_whatever_the_step():
    sampler = TrajectorySampler.starting_at(np.zeros((2, 3)), period_s=1.0)
    for k in range(1, 36):  # steps of 0.3 s, the last at 10.5 s
        sampler.offer(0.3 * k, np.full((2, 3), float(k)))
    # The first step at or after each whole second, and no drift: 1.2, 2.1, 3.0 (in
    # rounding), 4.2, ...
    assert sampler.times_s[0] == 0.0
    assert len(sampler.times_s) == 11
    for n, t in enumerate(sampler.times_s[1:], start=1):
        assert n - 1e-9 <= t < n + 0.3
    assert sampler.poses[0].sum() == 0.0
    assert sampler.poses[1][0, 0] == 4.0  # the step at 1.2 s
