"""Acquisition terms: Eq. 4, the path integral of Eq. 7 and the peers' planned points."""

import numpy as np
import pytest
from bayes_swarm.acquisition import (
    acquisition,
    omega,
    path_integral,
    path_points,
    planned_path_points,
    ray_integrals,
)
from bayes_swarm.gp import GaussianProcess, Hyperparameters
from bayes_swarm.settings import GpConfig
from scipy.integrate import quad


def smooth_std(points):
    return 0.3 + 0.2 * np.sin(points[:, 0]) * np.cos(0.5 * points[:, 1])


def reference_integral(std_fn, start, end):
    start, end = np.asarray(start, float), np.asarray(end, float)
    length = np.hypot(*(end - start))
    value, _ = quad(lambda u: std_fn((start + u * (end - start))[None])[0], 0.0, 1.0)
    return length * value


def test_source_seeking_term_is_one_at_the_expected_source_and_half_one_metre_away():
    values = omega(np.array([[1.0, 2.0], [2.0, 2.0], [1.0, 1.0]]), np.array([1.0, 2.0]))
    np.testing.assert_allclose(values, [1.0, 0.5, 0.5])


def test_path_integral_matches_a_numeric_reference():
    start, end = np.array([0.2, 0.1]), np.array([1.9, 1.4])
    value = path_integral(smooth_std, start, end, step_m=0.01)
    assert value == pytest.approx(reference_integral(smooth_std, start, end), rel=1e-4)


def test_path_integral_of_a_gp_std_matches_a_numeric_reference():
    rng = np.random.default_rng(2)
    gp = GaussianProcess(GpConfig())
    x = rng.uniform(0, 2.4, size=(15, 2))
    gp.fit(x, np.sin(x[:, 0]), hyperparameters=Hyperparameters(0.2, 0.5))
    std_fn = gp.extended_std(np.zeros((0, 2))).std
    start, end = np.array([0.5, 0.5]), np.array([1.3, 1.1])
    assert path_integral(std_fn, start, end, 0.005) == pytest.approx(
        reference_integral(std_fn, start, end), rel=1e-3
    )


def test_constant_std_integrates_to_std_times_length():
    assert path_integral(lambda p: np.full(len(p), 0.5), [0, 0], [0.3, 0.4], 0.1) == (
        pytest.approx(0.25)
    )


def test_ray_integrals_agree_with_the_single_path_integral():
    start = np.array([1.0, 1.0])
    headings = np.array([0.3, 2.0])
    candidates, integrals = ray_integrals(smooth_std, start, headings, 0.1, 10)
    for h in range(2):
        for k in (0, 4, 10):
            expected = path_integral(smooth_std, start, candidates[h, k], 0.1)
            assert integrals[h, k] == pytest.approx(expected, rel=1e-9, abs=1e-12)
    np.testing.assert_allclose(np.hypot(*(candidates[:, -1] - start).T), 1.0)


def test_origin_defect_measures_the_path_from_the_origin():
    pts = path_points([1.0, 1.0], [1.5, 1.0], 0.1, from_origin=True)
    np.testing.assert_allclose(pts[:, 1], 0.0)
    np.testing.assert_allclose(pts[:, 0], np.linspace(0.0, 0.5, 6))
    assert path_points([1.0, 1.0], [1.5, 1.0], 0.1)[0] == pytest.approx([1.0, 1.0])


def test_planned_path_points_skip_the_start_and_respect_the_cap():
    pts = planned_path_points(np.array([[0, 0], [5, 5]]), np.array([[1, 0], [5, 7]]), 0.5, 100)
    assert len(pts) == 2 + 4
    assert not np.any(np.all(pts == [0, 0], axis=1))
    capped = planned_path_points(np.array([[0, 0]]), np.array([[100, 0]]), 0.5, 50)
    assert len(capped) == 50
    assert capped[-1] == pytest.approx([100, 0])


def test_acquisition_combines_the_terms_as_eq_1():
    value = acquisition(0.25, np.array([0.8]), np.array([2.0]), np.array([0.5]))
    assert value[0] == pytest.approx((0.25 * 0.8 + 0.75 * 2.0) * 0.5)


def test_source_seeking_term_can_measure_distances_in_another_unit():
    points = np.array([[3.0, 4.0]])
    assert omega(points, np.zeros(2), distance_unit_m=5.0)[0] == pytest.approx(0.5)
    assert omega(points, np.zeros(2))[0] == pytest.approx(1.0 / 26.0)
