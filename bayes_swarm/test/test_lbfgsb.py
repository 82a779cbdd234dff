"""The box-constrained L-BFGS-B driver returns what scipy's minimize returns."""

import numpy as np
import pytest
from bayes_swarm.gp import GaussianProcess
from bayes_swarm.planner import _negated_gradient_norm, _negated_mean
from bayes_swarm.settings import GpConfig
from scipy.optimize import minimize

from bayes_swarm import lbfgsb


def fitted_gp(seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(0.0, 2.4, (40, 2))
    values = np.exp(-((points - [1.0, 2.0]) ** 2).sum(1) / 3.0) + 0.5 * np.exp(
        -2.0 * ((points - [2.0, 0.5]) ** 2).sum(1)
    )
    gp = GaussianProcess(GpConfig())
    gp.fit(points, values)
    return gp


@pytest.mark.parametrize('objective', [_negated_mean, _negated_gradient_norm])
def test_the_driver_gives_scipys_point_and_value_bit_for_bit(objective):
    assert lbfgsb._driver_matches_scipy()
    rng = np.random.default_rng(7)
    on_bound = 0
    # The whole arena, and a box that cuts the field's maximum at (1, 2) off.
    for seed, top in ((0, 2.4), (1, 2.4), (2, 1.6)):
        gp = fitted_gp(seed)
        lower, upper = np.zeros(2), np.array([2.4, top])
        for start in rng.uniform(-0.2, 2.6, (10, 2)):  # some outside the box: clipped
            x, value = lbfgsb.minimize_box(objective, start, lower, upper, args=(gp,))
            result = minimize(
                objective,
                start,
                args=(gp,),
                jac=True,
                method='L-BFGS-B',
                bounds=list(zip(lower, upper, strict=True)),
            )
            np.testing.assert_array_equal(x, result.x)
            assert value == result.fun
            on_bound += bool(np.any((x == lower) | (x == upper)))
    assert on_bound > 0  # the projected steps were exercised too


def test_a_driver_that_disagrees_with_scipy_is_not_used(monkeypatch):
    real = lbfgsb._setulb_driver

    def off_by_a_bit(*args):
        x, value = real(*args)
        return x + 1e-12, value

    lbfgsb._driver_matches_scipy.cache_clear()
    monkeypatch.setattr(lbfgsb, '_setulb_driver', off_by_a_bit)
    try:
        assert not lbfgsb._driver_matches_scipy()
        gp = fitted_gp(0)
        start, lower, upper = np.array([0.5, 0.5]), np.zeros(2), np.full(2, 2.4)
        x, _ = lbfgsb.minimize_box(_negated_mean, start, lower, upper, args=(gp,))
        expected = minimize(
            _negated_mean, start, args=(gp,), jac=True, method='L-BFGS-B', bounds=[(0, 2.4)] * 2
        )
        np.testing.assert_array_equal(x, expected.x)
    finally:
        lbfgsb._driver_matches_scipy.cache_clear()
