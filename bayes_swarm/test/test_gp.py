"""GP belief: closed-form posteriors, likelihood gradient, downsampling, recovery."""

import numpy as np
import pytest
from bayes_swarm.errors import ObservationError
from bayes_swarm.gp import (
    GaussianProcess,
    Hyperparameters,
    _likelihood_derivatives,
    _minimise_likelihood,
    _squared_distances,
    downsample_indices,
)
from bayes_swarm.settings import GpConfig
from scipy.optimize import approx_fprime, minimize
from scipy.stats import multivariate_normal

HYPER = Hyperparameters(signal_variance=0.7, length_scale_m=0.4)
NOISE_STD = 0.05


def closed_form(x, y, q, hyper, noise_var):
    def k(a, b):
        d2 = ((a[:, None, :] - b[None, :, :]) ** 2).sum(-1)
        return hyper.signal_variance * np.exp(-0.5 * d2 / hyper.length_scale_m**2)

    k_inv = np.linalg.inv(k(x, x) + noise_var * np.eye(len(x)))
    kq = k(x, q)
    mean = kq.T @ k_inv @ y
    var = hyper.signal_variance - np.einsum('ij,ik,kj->j', kq, k_inv, kq)
    return mean, np.sqrt(var)


@pytest.fixture
def data():
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 2, size=(12, 2))
    y = np.sin(2 * x[:, 0]) + x[:, 1] ** 2
    q = rng.uniform(-0.5, 2.5, size=(9, 2))
    return x, y, q


def test_posterior_mean_and_std_match_the_closed_form(data):
    x, y, q = data
    gp = GaussianProcess(GpConfig(noise_std=NOISE_STD))
    gp.fit(x, y, hyperparameters=HYPER)
    mean, std = gp.predict(q)
    ref_mean, ref_std = closed_form(x, y, q, HYPER, NOISE_STD**2)
    np.testing.assert_allclose(mean, ref_mean, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(std, ref_std, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(gp.predict_mean(q), ref_mean, rtol=1e-8, atol=1e-10)


def test_extended_std_equals_a_gp_conditioned_on_the_extra_locations(data):
    x, y, q = data
    extra = np.array([[0.3, 0.3], [1.7, 0.2], [2.2, 2.2]])
    gp = GaussianProcess(GpConfig(noise_std=NOISE_STD))
    gp.fit(x, y, hyperparameters=HYPER)
    x_all = np.vstack([x, extra])
    _, ref_std = closed_form(x_all, np.zeros(len(x_all)), q, HYPER, NOISE_STD**2)
    np.testing.assert_allclose(gp.extended_std(extra).std(q), ref_std, rtol=1e-7, atol=1e-9)
    # Extra observation locations can only reduce the uncertainty.
    assert np.all(gp.extended_std(extra).std(q) <= gp.predict(q)[1] + 1e-12)


def test_mean_gradient_matches_finite_differences(data):
    x, y, _ = data
    gp = GaussianProcess(GpConfig(noise_std=NOISE_STD))
    gp.fit(x, y, hyperparameters=HYPER)
    point = np.array([0.9, 1.1])
    _, grad = gp.mean_and_gradient(point)
    numeric = approx_fprime(point, lambda p: gp.mean_and_gradient(p)[0], 1e-7)
    np.testing.assert_allclose(grad, numeric, rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize('noise_var', [1e-6, 1e-2])
def test_likelihood_gradient_and_hessian_match_finite_differences(data, noise_var):
    x, y, _ = data
    sq = _squared_distances(x, x)
    theta = np.log([0.8, 0.6])

    def nll(t):
        return _likelihood_derivatives(t, sq, y, noise_var)[0]

    def grad(t, axis):
        return _likelihood_derivatives(t, sq, y, noise_var)[1][axis]

    _, g, h = _likelihood_derivatives(theta, sq, y, noise_var)
    np.testing.assert_allclose(g, approx_fprime(theta, nll, 1e-7), rtol=1e-4, atol=1e-5)
    for axis in range(2):
        numeric = approx_fprime(theta, grad, 1e-6, axis)
        np.testing.assert_allclose(h[axis], numeric, rtol=1e-4, atol=1e-4)
    assert h[0, 1] == h[1, 0]


def test_likelihood_value_is_the_negative_gaussian_log_density_of_the_data(data):
    x, y, _ = data
    s2, ell, noise_var = 0.8, 0.6, 1e-3
    d2 = ((x[:, None, :] - x[None, :, :]) ** 2).sum(-1)
    cov = s2 * np.exp(-0.5 * d2 / ell**2) + noise_var * np.eye(len(x))
    expected = multivariate_normal(mean=np.zeros(len(x)), cov=cov).logpdf(y)
    nll, _, _ = _likelihood_derivatives(np.log([s2, ell]), _squared_distances(x, x), y, noise_var)
    assert nll == pytest.approx(-expected, rel=1e-9)


@pytest.mark.parametrize('start', [(0.0, 0.0), (3.0, -4.0), (-8.0, 4.0)])
def test_newton_likelihood_fit_reaches_the_optimum_a_general_solver_finds(data, start):
    x, y, _ = data
    sq = _squared_distances(x, x)
    lower, upper = (np.log(1e-5), np.log(1e-3)), (np.log(1e5), np.log(500.0))

    def nll(t):
        return _likelihood_derivatives(t, sq, y, 1e-6)[:2]

    bounds = list(zip(lower, upper, strict=True))
    reference = minimize(nll, start, jac=True, method='L-BFGS-B', bounds=bounds)
    found = _minimise_likelihood(sq, y, 1e-6, start, lower, upper, max_iterations=50)
    assert found is not None
    # As good as the general solver (which may stop in a worse local optimum from a far
    # start), and a stationary point.
    assert nll(found)[0] <= reference.fun + 1e-6
    assert np.hypot(*nll(found)[1]) < 1e-3


def test_newton_likelihood_fit_stops_at_a_bound_when_the_optimum_lies_beyond(data):
    x, y, _ = data
    sq = _squared_distances(x, x)
    # The fitted length scale of this field is about 0.5 m: an upper bound of 0.2 m binds.
    lower, upper = (np.log(1e-5), np.log(1e-3)), (np.log(1e5), np.log(0.2))
    found = _minimise_likelihood(sq, y, 1e-6, (0.0, -2.0), lower, upper, max_iterations=50)
    assert found is not None
    assert found[1] == pytest.approx(upper[1])
    assert _likelihood_derivatives(found, sq, y, 1e-6)[1][1] < 0.0  # would grow further


def test_mean_derivatives_agree_with_the_mean_its_gradient_and_finite_differences(data):
    x, y, q = data
    gp = GaussianProcess(GpConfig(noise_std=NOISE_STD))
    gp.fit(x, y, hyperparameters=HYPER)
    mean, grad, hess = gp.mean_derivatives(q)
    np.testing.assert_allclose(mean, gp.predict_mean(q), rtol=1e-12, atol=1e-12)
    for point, g, h in zip(q, grad, hess, strict=True):
        np.testing.assert_allclose(g, gp.mean_and_gradient(point)[1], rtol=1e-12, atol=1e-12)
        for axis in range(2):
            numeric = approx_fprime(point, lambda p, a=axis: gp.mean_and_gradient(p)[1][a], 1e-7)
            np.testing.assert_allclose(h[axis], numeric, rtol=1e-4, atol=1e-5)
        assert h[0, 1] == pytest.approx(h[1, 0], rel=1e-12)


def test_fit_recovers_the_length_scale_of_a_smooth_field():
    rng = np.random.default_rng(0)
    x = rng.uniform(0, 10, size=(120, 2))
    y = np.exp(-((x - 5.0) ** 2).sum(1) / (2 * 2.0**2))  # a bump with width 2 m
    gp = GaussianProcess(GpConfig(noise_std=1e-3))
    gp.fit(x, y)
    assert 1.0 < gp.hyperparameters.length_scale_m < 4.0
    mean, _ = gp.predict(np.array([[5.0, 5.0], [1.0, 9.0]]))
    np.testing.assert_allclose(mean, [1.0, np.exp(-32 / 8)], atol=0.02)


def test_refit_happens_only_after_the_data_grew_by_the_growth_factor():
    rng = np.random.default_rng(1)
    x = rng.uniform(0, 3, size=(40, 2))
    y = np.cos(x[:, 0])
    gp = GaussianProcess(GpConfig(refit_growth_factor=1.5))
    gp.fit(x[:20], y[:20])
    first = gp.hyperparameters
    gp.fit(x[:25], y[:25])
    assert gp.hyperparameters == first
    gp.fit(x[:30], y[:30])
    assert gp.hyperparameters != first


def test_ceil_downsampling_keeps_the_first_and_every_dth_sample_in_time_order():
    kept = downsample_indices(2500, 1000)
    assert kept[0] == 0
    assert np.all(np.diff(kept) == 3)  # ceil(2500 / 1000)
    assert len(kept) <= 1000


def test_floor_downsampling_reproduces_the_authors_missing_reduction():
    assert len(downsample_indices(1999, 1000, floor_rule=True)) == 1999
    assert len(downsample_indices(1999, 1000)) == 1000


def test_downsampling_rejects_n_max_below_one():
    with pytest.raises(ObservationError, match='n_max'):
        downsample_indices(10, 0)


def test_duplicated_samples_with_a_tiny_noise_term_still_factor():
    x = np.repeat(np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 0.2]]), 20, axis=0)
    y = np.repeat(np.array([0.1, 0.4, 0.3]), 20)
    gp = GaussianProcess(GpConfig(noise_std=1e-9))
    gp.fit(x, y, hyperparameters=Hyperparameters(1.0, 5.0))
    mean, std = gp.predict(np.array([[0.5, 0.5]]))
    assert np.isfinite(mean).all()
    assert np.isfinite(std).all()
    assert mean[0] == pytest.approx(0.4, abs=0.05)


def test_non_finite_training_data_is_rejected():
    gp = GaussianProcess(GpConfig())
    with pytest.raises(ObservationError, match='non-finite'):
        gp.fit(np.array([[0.0, 0.0], [1.0, np.nan]]), np.array([1.0, 2.0]))
    with pytest.raises(ObservationError, match=r'\(n, 2\)'):
        gp.fit(np.zeros((3, 3)), np.zeros(3))


def test_the_default_refits_the_hyperparameters_at_every_fit_as_the_paper():
    rng = np.random.default_rng(4)
    x = rng.uniform(0, 3, size=(30, 2))
    y = np.cos(x[:, 0])
    gp = GaussianProcess(GpConfig())
    gp.fit(x[:20], y[:20])
    first = gp.hyperparameters
    gp.fit(x[:21], y[:21])
    assert gp.hyperparameters != first


def test_a_refit_follows_a_jump_in_the_signal_scale_before_the_data_doubles():
    rng = np.random.default_rng(4)
    x = rng.uniform(0, 3, size=(30, 2))
    faint = 0.01 * np.cos(x[:, 0])
    gp = GaussianProcess(GpConfig(refit_growth_factor=2.0))
    gp.fit(x[:20], faint[:20])
    first = gp.hyperparameters
    gp.fit(x[:25], faint[:25])
    assert gp.hyperparameters == first  # 25 < 2 x 20 samples, same scale: no refit
    strong = faint.copy()
    strong[24] = 0.5  # one sample 50 times stronger than the rest
    gp.fit(x[:25], strong[:25])
    assert gp.hyperparameters != first
