"""The two-variable projected trust-region Newton step shared by the GP solvers."""

import math

import numpy as np
import pytest
from bayes_swarm.trust_region import projected_newton_step

LOWER, UPPER = (-10.0, -10.0), (10.0, 10.0)


def test_inside_the_box_a_convex_quadratic_is_minimised_in_one_step():
    hess = np.array([[2.0, 0.5], [0.5, 1.0]])
    centre = np.array([1.0, -2.0])
    x = np.array([3.0, 1.0])
    step = projected_newton_step(x, hess @ (x - centre), hess, LOWER, UPPER, radius=100.0)
    np.testing.assert_allclose(x + np.array(step), centre, atol=1e-12)


def test_the_step_is_clipped_to_the_trust_radius():
    hess = np.eye(2)
    step = projected_newton_step((0.0, 0.0), np.array([-3.0, -4.0]), hess, LOWER, UPPER, 0.5)
    assert math.hypot(*step) == pytest.approx(0.5)
    assert step[0] / step[1] == pytest.approx(3.0 / 4.0)


def test_without_curvature_the_step_is_steepest_descent_of_the_radius():
    hess = np.array([[-1.0, 0.0], [0.0, 2.0]])
    step = projected_newton_step((0.0, 0.0), np.array([0.0, 2.0]), hess, LOWER, UPPER, 0.3)
    np.testing.assert_allclose(step, [0.0, -0.3], atol=1e-15)


def test_a_coordinate_pressed_against_its_bound_stays_and_the_other_takes_a_newton_step():
    hess = np.array([[1.0, 0.9], [0.9, 1.0]])
    # At x0 = upper bound, descent would push x0 further up: it is held.
    step = projected_newton_step((10.0, 0.0), np.array([-5.0, 2.0]), hess, LOWER, UPPER, 100.0)
    assert step[0] == 0.0
    assert step[1] == pytest.approx(-2.0)
    # Pointing back inside, the bound does not hold the coordinate.
    step = projected_newton_step((10.0, 0.0), np.array([5.0, 2.0]), hess, LOWER, UPPER, 100.0)
    assert step[0] < 0.0
