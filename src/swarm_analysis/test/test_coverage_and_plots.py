"""Coverage summary arithmetic and the two figures of an OA-Bug run."""

import numpy as np
import pytest
from swarm_analysis.coverage import CoverageSummary, RoomFirstVisit
from swarm_analysis.plots import plot_coverage_curves, plot_site_paths


def summary():
    visits = [RoomFirstVisit(2, 'r1', 30.0), RoomFirstVisit(0, 'r0', 10.0)]
    return CoverageSummary.build(4, visits, 100.0, ('r0', 'r1', 'r2'))


def test_summary_orders_visits_and_credits_first_visitors():
    s = summary()
    assert [v.room_index for v in s.visits] == [0, 2]
    assert s.coverage == pytest.approx(0.5)
    assert s.first_visits_per_robot() == {'r0': 1, 'r1': 1, 'r2': 0}
    assert s.first_visitor_by_room() == {0: 'r0', 2: 'r1'}
    assert not s.complete


def test_curve_steps_up_at_each_first_visit_and_ends_at_the_run_end():
    times, fraction = summary().curve()
    assert times.tolist() == [0.0, 10.0, 30.0, 100.0]
    assert fraction.tolist() == [0.0, 0.25, 0.5, 0.5]
    assert summary().coverage_at(20.0) == pytest.approx(0.25)


def test_report_names_coverage_rooms_and_every_robot():
    text = summary().format_report()
    assert '50.0 %' in text
    assert '(2/4 rooms)' in text
    assert 'r2: 0' in text


def test_figures_are_written_as_png(tmp_path):
    walls = np.array([[0.0, 0.0, 4.0, 0.0], [4.0, 0.0, 4.0, 2.0], [4.0, 2.0, 0.0, 2.0]])
    rooms = [np.array([[0.0, 0.0, 2.0, 2.0]]), np.array([[2.0, 0.0, 4.0, 2.0]])]
    traj = np.cumsum(np.full((20, 2, 2), 0.1), axis=0)
    fig6 = plot_site_paths(
        tmp_path / 'paths.png',
        walls=walls,
        room_rects=rooms,
        robot_names=['r0', 'r1'],
        trajectories=traj,
        first_visitor={0: 'r1'},
        title='test',
    )
    curve = plot_coverage_curves(tmp_path / 'cov.png', {'run': summary().curve()})
    for path in (fig6, curve):
        assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
