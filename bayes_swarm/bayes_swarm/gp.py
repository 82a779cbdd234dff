"""Gaussian-process belief of the signal field (paper Sec. 2.3, Appendix A).

Zero prior mean, squared-exponential kernel

    k(x, x') = s2 * exp(-|x - x'|^2 / (2 l^2)),   K_eps = K + noise_std^2 I,

hyperparameters (s2, l) by maximum marginal likelihood within bounds (a projected
trust-region Newton method on their logarithms with the analytic gradient and Hessian; the
authors use L-BFGS-B, which reaches the same optimum with about twice the likelihood
evaluations and a costly set-up per call). The posterior is kept as a Cholesky factor; if it
fails the diagonal receives growing jitter, and if even ``max_jitter`` fails the
hyperparameters are reset and refitted once before :class:`~bayes_swarm.errors.GpFitError` is
raised.

Posterior variance does not depend on the observed values, so the "extended" variance of
Eq. 7 (observations plus the peers' planned path points) reuses the same hyperparameters and
extends the Cholesky factor block-wise instead of fitting a second GP.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgError, cholesky, solve_triangular
from scipy.linalg.blas import dtrsm
from scipy.linalg.lapack import dpotrf, dpotri, dpotrs, dtrtri
from scipy.spatial.distance import cdist

from bayes_swarm.errors import GpFitError, ObservationError
from bayes_swarm.settings import GpConfig
from bayes_swarm.trust_region import projected_newton_step

__all__ = [
    'GaussianProcess',
    'Hyperparameters',
    'downsample_indices',
    'se_kernel',
]


@dataclass(frozen=True)
class Hyperparameters:
    """Kernel hyperparameters: signal variance [signal^2] and length scale [m]."""

    signal_variance: float
    length_scale_m: float


def se_kernel(a: np.ndarray, b: np.ndarray, hyper: Hyperparameters) -> np.ndarray:
    """Squared-exponential covariance between (n, 2) points ``a`` and (m, 2) points ``b``.

    Returns an (n, m) array.
    """
    # In place, in the order of s2 * exp(-0.5 * d2 / l^2): same values without four temporaries.
    k = _squared_distances(a, b)
    np.multiply(k, -0.5, out=k)
    np.divide(k, hyper.length_scale_m**2, out=k)
    np.exp(k, out=k)
    np.multiply(k, hyper.signal_variance, out=k)
    return k


def _squared_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return cdist(a, b, 'sqeuclidean')


def downsample_indices(n: int, n_max: int, *, floor_rule: bool = False) -> np.ndarray:
    """Indices kept when ``n`` time-ordered samples are compressed to at most ``n_max``.

    The paper (Sec. 2.6) keeps the first sample and every d-th after it with
    d = ceil(n / N_max). ``floor_rule`` reproduces the authors' code, d = floor(n / N_max),
    which keeps up to about 2 N_max samples.
    """
    if n_max < 1:
        msg = f'n_max must be >= 1, got {n_max}'
        raise ObservationError(msg)
    if n <= n_max:
        return np.arange(n)
    step = n // n_max if floor_rule else math.ceil(n / n_max)
    return np.arange(0, n, max(step, 1))


class GaussianProcess:
    """GP regression on 2-D inputs with a Cholesky-factored posterior.

    Typical use::

        gp = GaussianProcess(GpConfig())
        gp.fit(x_m, values)                 # (n, 2), (n,)
        mean, std = gp.predict(query_m)     # (q,), (q,)
    """

    def __init__(self, config: GpConfig) -> None:
        self._config = config
        self._hyper = Hyperparameters(config.initial_signal_variance, config.initial_length_scale_m)
        self._fitted_hyper: Hyperparameters | None = None
        self._n_at_last_fit = 0
        self._scale_at_last_fit = 0.0
        self._x = np.zeros((0, 2))
        self._y = np.zeros(0)
        self._chol = np.zeros((0, 0))
        self._weights = np.zeros(0)
        self._jitter = 0.0
        self._chol_inv: np.ndarray | None = None

    @property
    def hyperparameters(self) -> Hyperparameters:
        """Current kernel hyperparameters."""
        return self._hyper

    @property
    def noise_variance(self) -> float:
        """Observation noise variance on the kernel diagonal [signal^2] (without jitter)."""
        return self._config.noise_std**2

    @property
    def n_samples(self) -> int:
        """Number of samples the posterior is conditioned on."""
        return int(self._x.shape[0])

    @property
    def training_inputs(self) -> np.ndarray:
        """(n, 2) array of the conditioning locations [m] (read-only view)."""
        view = self._x.view()
        view.flags.writeable = False
        return view

    # ------------------------------------------------------------------ fitting
    def fit(
        self,
        x_m: np.ndarray,
        values: np.ndarray,
        *,
        optimise: bool | None = None,
        hyperparameters: Hyperparameters | None = None,
    ) -> None:
        """Condition the GP on (n, 2) locations ``x_m`` and (n,) ``values``.

        ``optimise`` None applies the refit policy (first fit, or data grown by
        ``refit_growth_factor`` in size or largest |value| since the last fit); True/False
        force it. Explicit ``hyperparameters`` skip the likelihood fit.
        """
        x = np.ascontiguousarray(x_m, dtype=float)
        y = np.ascontiguousarray(values, dtype=float)
        if x.ndim != 2 or x.shape[1] != 2 or y.shape != (x.shape[0],):
            msg = f'expected (n, 2) locations and (n,) values, got {x.shape} and {y.shape}'
            raise ObservationError(msg)
        if x.shape[0] == 0:
            msg = 'cannot fit a GP on zero samples'
            raise ObservationError(msg)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            msg = 'GP training data contains non-finite values'
            raise ObservationError(msg)
        if hyperparameters is not None:
            self._hyper = hyperparameters
        else:
            if optimise is None:
                optimise = self._needs_refit(y)
            if optimise:
                self._refit(x, y)
        self._x, self._y = x, y
        try:
            self._chol, self._jitter = self._factor(x, self._hyper)
        except GpFitError:
            # Recover once: restart the hyperparameters from their initial values and refit.
            self._refit(x, y, warm=False)
            self._chol, self._jitter = self._factor(x, self._hyper)
        self._weights, _ = dpotrs(self._chol, y, lower=1)
        self._chol_inv = None

    def _needs_refit(self, y: np.ndarray) -> bool:
        """Refit policy: first fit, or the data grew by the growth factor in size or in scale.

        The scale (largest |value|) matters where the signal rises steeply toward the source:
        hyperparameters fitted on the faint tail of a field extrapolate wildly once samples
        near the peak arrive.
        """
        if self._fitted_hyper is None:
            return True
        growth = self._config.refit_growth_factor
        scale = float(np.max(np.abs(y)))
        return y.shape[0] >= math.ceil(growth * self._n_at_last_fit) or (
            scale > growth * self._scale_at_last_fit
        )

    def _refit(self, x: np.ndarray, y: np.ndarray, *, warm: bool = True) -> None:
        self._hyper = self._maximise_likelihood(x, y, warm=warm)
        self._fitted_hyper = self._hyper
        self._n_at_last_fit = x.shape[0]
        self._scale_at_last_fit = float(np.max(np.abs(y)))

    def _factor(self, x: np.ndarray, hyper: Hyperparameters) -> tuple[np.ndarray, float]:
        """Lower Cholesky factor of K + (noise + jitter) I with escalating jitter."""
        k = se_kernel(x, x, hyper)
        base = self.noise_variance
        jitter = 0.0
        while True:
            k_eps = k.copy()
            k_eps.flat[:: k.shape[0] + 1] += base + jitter
            try:
                return cholesky(k_eps, lower=True, check_finite=False), jitter
            except LinAlgError:
                jitter = max(jitter * 10.0, 1e-10 * hyper.signal_variance)
                if jitter > self._config.max_jitter * max(hyper.signal_variance, 1.0):
                    msg = (
                        f'covariance of {x.shape[0]} samples is not positive definite even with '
                        f'jitter {jitter:.1e} (signal variance {hyper.signal_variance:.3g}, '
                        f'length scale {hyper.length_scale_m:.3g} m)'
                    )
                    raise GpFitError(msg) from None

    def _maximise_likelihood(
        self, x: np.ndarray, y: np.ndarray, *, warm: bool = True
    ) -> Hyperparameters:
        keep = downsample_indices(x.shape[0], self._config.max_fit_points)
        xs, ys = x[keep], y[keep]
        sq = _squared_distances(xs, xs)
        cfg = self._config
        lower = (math.log(cfg.signal_variance_bounds[0]), math.log(cfg.length_scale_bounds_m[0]))
        upper = (math.log(cfg.signal_variance_bounds[1]), math.log(cfg.length_scale_bounds_m[1]))
        start = (cfg.initial_signal_variance, cfg.initial_length_scale_m)
        if warm and self._fitted_hyper is not None:
            # Warm start: the previous optimum is close once data accumulates.
            start = (self._fitted_hyper.signal_variance, self._fitted_hyper.length_scale_m)
        best = _minimise_likelihood(
            sq,
            ys,
            self.noise_variance,
            (math.log(start[0]), math.log(start[1])),
            lower,
            upper,
            max_iterations=cfg.max_fit_iterations,
        )
        if best is None:
            return Hyperparameters(cfg.initial_signal_variance, cfg.initial_length_scale_m)
        return Hyperparameters(math.exp(best[0]), math.exp(best[1]))

    # --------------------------------------------------------------- prediction
    def predict(self, query_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Posterior mean (q,) and standard deviation (q,) at (q, 2) query points [m]."""
        q = np.asarray(query_m, dtype=float).reshape(-1, 2)
        k_q = se_kernel(self._x, q, self._hyper)
        mean = k_q.T @ self._weights
        if self._chol_inv is None and 4 * q.shape[0] < self._chol.shape[0]:
            # A few queries: two triangular solves are cheaper than forming the inverse.
            v = solve_triangular(self._chol, k_q, lower=True, check_finite=False)
        else:
            if self._chol_inv is None:
                self._chol_inv = _inverse_factor(self._chol)
            v = self._chol_inv @ k_q
        var = self._hyper.signal_variance - np.einsum('ij,ij->j', v, v)
        return mean, np.sqrt(np.maximum(var, 0.0))

    def predict_mean(self, query_m: np.ndarray) -> np.ndarray:
        """Posterior mean (q,) at (q, 2) query points [m]."""
        q = np.asarray(query_m, dtype=float).reshape(-1, 2)
        return se_kernel(q, self._x, self._hyper) @ self._weights

    def mean_and_gradient(self, point_m: np.ndarray) -> tuple[float, np.ndarray]:
        """Posterior mean at one (2,) point and its (2,) gradient [signal / m]."""
        p = np.asarray(point_m, dtype=float).reshape(1, 2)
        k = se_kernel(p, self._x, self._hyper)[0] * self._weights
        diff = self._x - p
        grad = (k @ diff) / self._hyper.length_scale_m**2
        return float(k.sum()), grad

    def mean_derivatives(self, points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Posterior mean (s,), its gradient (s, 2) and Hessian (s, 2, 2) at (s, 2) points."""
        p = np.asarray(points_m, dtype=float).reshape(-1, 2)
        ell2 = self._hyper.length_scale_m**2
        kw = se_kernel(p, self._x, self._hyper)
        kw *= self._weights  # (s, n)
        diff = self._x[None, :, :] - p[:, None, :]  # (s, n, 2)
        mean = kw.sum(axis=1)
        grad = np.einsum('sn,snj->sj', kw, diff) / ell2
        # Two-operand contraction of the pre-weighted differences: half the time of the
        # three-operand einsum with the same products and sums.
        hess = np.einsum('sni,snj->sij', kw[:, :, None] * diff, diff) / (ell2 * ell2)
        hess -= (mean / ell2)[:, None, None] * np.eye(2)
        return mean, grad, hess

    def extended_std(self, extra_m: np.ndarray) -> ExtendedVariance:
        """Posterior std model conditioned on the data plus (k, 2) extra locations.

        The extra points are the peers' planned observation locations of Eq. 7; their values
        are not needed because the posterior variance does not depend on them.
        """
        return ExtendedVariance(self, np.asarray(extra_m, dtype=float).reshape(-1, 2))


class ExtendedVariance:
    """Posterior standard deviation of a GP conditioned on extra, unobserved locations."""

    def __init__(self, gp: GaussianProcess, extra_m: np.ndarray) -> None:
        hyper = gp.hyperparameters
        self._hyper = hyper
        self._chol_f: np.ndarray | None = None
        x = gp._x
        chol = gp._chol
        if extra_m.shape[0] == 0:
            self._x, self._chol = x, chol
            return
        noise = gp.noise_variance + gp._jitter
        k_xe = se_kernel(x, extra_m, hyper)
        b = solve_triangular(chol, k_xe, lower=True, check_finite=False)
        schur = se_kernel(extra_m, extra_m, hyper) - b.T @ b
        schur.flat[:: schur.shape[0] + 1] += noise
        jitter = 0.0
        while True:
            try:
                shifted = schur.copy()
                shifted.flat[:: schur.shape[0] + 1] += jitter
                c = cholesky(shifted, lower=True, check_finite=False)
                break
            except LinAlgError:
                jitter = max(10.0 * jitter, 1e-10 * hyper.signal_variance)
                if jitter > 1e-2 * max(hyper.signal_variance, 1.0):
                    # Extra points add nothing numerically usable: fall back to the data only.
                    self._x, self._chol = x, chol
                    return
        n, k = x.shape[0], extra_m.shape[0]
        full = np.zeros((n + k, n + k))
        full[:n, :n] = chol
        full[n:, :n] = b.T
        full[n:, n:] = c
        self._x = np.vstack([x, extra_m])
        self._chol = full

    @property
    def hyperparameters(self) -> Hyperparameters:
        """Kernel hyperparameters (those of the belief GP)."""
        return self._hyper

    @property
    def n_points(self) -> int:
        """Number of conditioning locations (data plus extra points)."""
        return int(self._x.shape[0])

    def std(self, query_m: np.ndarray) -> np.ndarray:
        """Posterior std (q,) at (q, 2) query points [m].

        One triangular solve L v = k(X, q) per call (BLAS trsm on column-major operands,
        no copies): half the operations of a product with the inverse factor, and no
        inverse to form per decision.
        """
        q = np.asarray(query_m, dtype=float).reshape(-1, 2)
        if self._chol_f is None:
            self._chol_f = np.asfortranarray(self._chol)
        # k(q, X) transposed is k(X, q) in column-major order, as trsm takes it.
        k = se_kernel(q, self._x, self._hyper).T
        v = dtrsm(1.0, self._chol_f, k, lower=1, overwrite_b=1)
        var = np.einsum('ij,ij->j', v, v)
        np.subtract(self._hyper.signal_variance, var, out=var)
        np.maximum(var, 0.0, out=var)
        return np.sqrt(var, out=var)


def _inverse_factor(chol: np.ndarray) -> np.ndarray:
    """Inverse of a lower Cholesky factor: std queries then cost one matrix product."""
    inverse, info = dtrtri(chol, lower=1)
    if info != 0:
        return solve_triangular(chol, np.eye(chol.shape[0]), lower=True, check_finite=False)
    return np.tril(inverse)


def _likelihood_derivatives(
    log_params: Sequence[float] | np.ndarray,
    sq: np.ndarray,
    y: np.ndarray,
    noise_variance: float,
) -> tuple[float, np.ndarray, np.ndarray] | None:
    """Negative log marginal likelihood, its gradient (2,) and Hessian (2, 2).

    Derivatives are with respect to (log s2, log l); ``sq`` is the (n, n) matrix of squared
    distances [m^2]. Returns None if the covariance cannot be factored. With W = a a^T - K^-1,
    a = K^-1 y and K_i = dK / d theta_i, the log likelihood has the gradient 0.5 tr(W K_i)
    and the Hessian 0.5 tr(W K_ij) - (K_i a)^T K^-1 (K_j a) + 0.5 tr(K^-1 K_i K^-1 K_j).
    For the SE kernel K_s = K - noise I, K_l = K_s * sq / l^2, K_ss = K_s, K_sl = K_l and
    K_ll = K_l * (sq / l^2 - 2); K^-1 K_s = I - noise K^-1 needs no product, so the Hessian
    costs one matrix product more than the gradient.

    LAPACK is called directly (potrf/potrs/potri, as scipy's wrappers do) because at n <= 100
    the wrappers' argument checks cost more than the factorisation.
    """
    s2 = math.exp(log_params[0])
    ell2 = math.exp(2.0 * log_params[1])
    scaled_sq = sq / ell2
    k_s = np.exp(-0.5 * scaled_sq)
    k_s *= s2  # dK / d log s2: K without the noise
    k = k_s.copy()
    n = y.shape[0]
    k.flat[:: n + 1] += noise_variance
    chol, info = dpotrf(k, lower=1, clean=1)
    noise = noise_variance
    if info != 0:
        noise += 1e-8 * s2
        k.flat[:: n + 1] += 1e-8 * s2
        chol, info = dpotrf(k, lower=1, clean=1)
        if info != 0:
            return None
    a, info = dpotrs(chol, y, lower=1)
    if info != 0:
        return None
    nll = 0.5 * float(y @ a) + float(np.log(np.diag(chol)).sum()) + 0.5 * n * math.log(2 * math.pi)
    k_inv, info = dpotri(chol, lower=1, overwrite_c=1)
    if info != 0:
        return None
    # potri fills the lower triangle and leaves the (clean, zero) upper one alone: adding the
    # transpose and halving the doubled diagonal gives the full symmetric inverse exactly.
    k_inv += k_inv.T
    k_inv.flat[:: n + 1] *= 0.5
    k_l = k_s * scaled_sq  # dK / d log l
    w = np.outer(a, a)
    w -= k_inv
    g_s = 0.5 * float(np.vdot(w, k_s))
    g_l = 0.5 * float(np.vdot(w, k_l))
    scaled_sq -= 2.0
    scaled_sq *= k_l  # d2K / d (log l)^2
    w_ll = 0.5 * float(np.vdot(w, scaled_sq))
    # K^-1 K_s = I - noise K^-1 (symmetric) and K^-1 K_l.
    a_s = k_inv * -noise
    a_s.flat[:: n + 1] += 1.0
    a_l = k_inv @ k_l
    ka_s = y - noise * a  # K_s a
    ka_l = k_l @ a
    kinv_ka_s = a_s @ a  # K^-1 K_s a
    kinv_ka_l = a_l @ a
    h_ss = g_s - float(ka_s @ kinv_ka_s) + 0.5 * float(np.vdot(a_s, a_s))
    h_sl = g_l - float(ka_s @ kinv_ka_l) + 0.5 * float(np.vdot(a_s, a_l))
    h_ll = w_ll - float(ka_l @ kinv_ka_l) + 0.5 * float(np.vdot(a_l, a_l.T))
    grad = np.array([-g_s, -g_l])
    hess = np.array([[-h_ss, -h_sl], [-h_sl, -h_ll]])
    return nll, grad, hess


def _minimise_likelihood(
    sq: np.ndarray,
    y: np.ndarray,
    noise_variance: float,
    start: tuple[float, float],
    lower: tuple[float, float],
    upper: tuple[float, float],
    *,
    max_iterations: int,
    tolerance: float = 1e-4,
) -> tuple[float, float] | None:
    """Minimise the negative log likelihood over (log s2, log l) within box bounds.

    A projected trust-region Newton method on the two log-parameters: a Newton step where the
    Hessian (restricted to the coordinates not held at a bound) is positive definite, else a
    steepest-descent step of the trust radius; steps are clipped to the trust radius and the
    box and kept only if the likelihood improves. Stops when a step is shorter than
    ``tolerance`` (relative change of the hyperparameters) or after ``max_iterations``
    evaluations. Returns the best (log s2, log l), or None if no start value was finite.

    With its analytic Hessian it needs a handful of evaluations from a warm start, and two
    parameters make every step a few float operations (no optimiser set-up per fit).
    """
    x = [min(max(start[0], lower[0]), upper[0]), min(max(start[1], lower[1]), upper[1])]
    current = _likelihood_derivatives(x, sq, y, noise_variance)
    if current is None or not math.isfinite(current[0]):
        return None
    radius = 1.0
    for _ in range(max_iterations):
        value, grad, hess = current
        step = projected_newton_step(x, grad, hess, lower, upper, radius)
        candidate = [
            min(max(x[0] + step[0], lower[0]), upper[0]),
            min(max(x[1] + step[1], lower[1]), upper[1]),
        ]
        length = math.hypot(candidate[0] - x[0], candidate[1] - x[1])
        if length < tolerance:
            break
        trial = _likelihood_derivatives(candidate, sq, y, noise_variance)
        if trial is not None and trial[0] < value:
            x, current = candidate, trial
            radius = min(2.0 * radius, 4.0)
        else:
            radius = 0.25 * length
    return x[0], x[1]
