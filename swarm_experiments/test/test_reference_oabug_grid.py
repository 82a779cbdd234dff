"""benchmarks/reference_oabug_grid.py: the parts that do not need the authors' simulator."""

from __future__ import annotations

import pytest


@pytest.fixture
def grid(benchmark_script):
    return benchmark_script('reference_oabug_grid')


def test_seeds_follow_the_reference_protocol(grid):
    assert grid.site_seed(0) == 1000003
    assert grid.site_seed(4, attempt=1) == 5 * 1000003 + 1
    # site seed x 100 + algorithm index (Gas is the fourth, index 3) x 2 + edge
    assert grid.run_seed(1000003, 'gas', 'edge') == 100000300 + 6 + 1
    assert grid.run_seed(1000003, 'random', 'center') == 100000300


class _Robot:
    def __init__(self) -> None:
        self.turns: list[tuple[str, int]] = []

    def turn_right(self, degree: int) -> None:
        self.turns.append(('right', degree))

    def turn_left(self, degree: int) -> None:
        self.turns.append(('left', degree))


class _State:
    def __init__(self, robot: _Robot, nested: bool = False) -> None:
        self.robot, self.nested = robot, nested

    def get_robot(self) -> _Robot:
        return self.robot


def test_the_robot_hit_wrapper_turns_left_and_restores_the_right_turn(grid):
    def hit(state):
        if state.nested:
            state.nested = False
            wrapped(state)
        state.get_robot().turn_right(90)

    wrapped = grid._turning_left(hit)
    robot = _Robot()
    wrapped(_State(robot, nested=True))
    assert robot.turns == [('left', 90), ('left', 90)]
    robot.turn_right(90)
    assert robot.turns[-1] == ('right', 90), 'the right turn is back after the hit'


def test_summary_tabulates_coverage_and_pairs_the_scent_variants_by_site(grid):
    def run(site, variant, coverage, locked=0):
        return grid.GridRun(site, variant, 'edge', 'right', coverage, 1000, locked, 0.5)

    runs = [
        run(0, 'gas', 60.0, locked=8),
        run(1, 'gas', 100.0),
        run(0, 'gas_sound', 90.0),
        run(1, 'gas_sound', 100.0),
    ]
    lines = grid.summary(runs)
    assert '| edge | gas | 2 | 80.0 +- 20.0 | 80.0 | 1 | 4.00 | 0.50 |' in lines
    assert '| edge | gas_sound | 2 | 95.0 +- 5.0 | 95.0 | 1 | 0.00 | 0.50 |' in lines
    paired = [line for line in lines if 'Gas+Sound minus Gas' in line]
    assert len(paired) == 1
    assert '+15.0 +- 15.0 points' in paired[0]
    assert '1 sites better, 0 worse' in paired[0]


def test_a_missing_simulator_checkout_is_a_clear_usage_error(grid, tmp_path, capsys):
    assert grid.main(['--simulator', str(tmp_path / 'nowhere'), '--sites', '1']) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert 'no SwarmSearchSimulation checkout' in err


class _Layout:
    """Every room covered once ``covered_after`` actions have run."""

    def __init__(self, manager_box: list, covered_after: int) -> None:
        self.manager_box, self.covered_after = manager_box, covered_after

    def __bool__(self) -> bool:
        return self.manager_box[0].action_count >= self.covered_after

    def report(self) -> tuple[int, ...]:
        return (4 if self else 3,)


class _Manager:
    def __init__(self) -> None:
        self.action_count = 0
        self.robots = [_Robot()]
        self.robots[0].position = (0, 0)

    def update(self) -> None:
        self.action_count += 1


def _fake_simulator(grid, covered_after: int):
    """A GridSimulator whose modules are stand-ins: rooms all covered after N actions."""
    from types import SimpleNamespace

    simulator = object.__new__(grid.GridSimulator)
    simulator.config = grid.GridConfig(60, 30, 4, 0, 50)
    simulator.robot_hit_turn = 'right'
    simulator._sites = {0: (grid.site_seed(0), SimpleNamespace(room_cnt=4))}
    simulator._robots = dict.fromkeys(grid.VARIANTS)
    box: list = []

    def manager(*_args, **_kwargs):
        box.append(_Manager())
        return box[0]

    simulator._manager = manager
    simulator._layout = SimpleNamespace(
        from_generator=lambda *_args, **_kwargs: _Layout(box, covered_after)
    )
    return simulator


def test_a_run_ends_when_every_room_is_covered_unless_the_whole_budget_is_asked_for(grid):
    early = _fake_simulator(grid, covered_after=20).run(0, 'gas', 'edge', 1)
    assert (early.actions, early.coverage_pct) == (20, 100.0)
    whole = _fake_simulator(grid, covered_after=20).run(0, 'gas', 'edge', 1, full_budget=True)
    assert (whole.actions, whole.coverage_pct) == (50, 100.0)
    short = _fake_simulator(grid, covered_after=80).run(0, 'gas', 'edge', 1)
    assert (short.actions, short.coverage_pct) == (50, 75.0)
