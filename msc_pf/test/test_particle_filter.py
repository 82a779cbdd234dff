"""Particle filter: convergence, its two tests at their thresholds, resampling, degeneracy.

These test the numpy code, the reference (``backend='numpy'``); test_pf_kernel.py checks
that the compiled backend gives the same results.
"""

import math

import numpy as np
import pytest
from msc_pf.errors import ConfigError, ObservationError
from msc_pf.particle_filter import (
    ParticleFilterBank,
    estimates_converged,
    lattice,
    resolve_backend,
    systematic_index,
)
from msc_pf.settings import ParticleFilterConfig, RadioConfig

from msc_pf import particle_filter

pytestmark = pytest.mark.runtime_independent(reason='the algorithm core')

RADIO = RadioConfig()
FIELD_M = 2000.0


def make_bank(seed: int = 0, **overrides) -> ParticleFilterBank:
    overrides.setdefault('backend', 'numpy')
    return ParticleFilterBank(
        ParticleFilterConfig(**overrides), RADIO, FIELD_M, np.random.default_rng(seed)
    )


def noisy_rssi(observer: np.ndarray, target: np.ndarray, rng: np.random.Generator) -> float:
    return RADIO.mean_rssi_dbm(float(np.hypot(*(target - observer)))) + rng.normal()


NEEDS_NUMBA = pytest.mark.skipif(
    resolve_backend('auto') != 'numba', reason='numba cannot be imported here'
)


@pytest.mark.parametrize('backend', ['numpy', pytest.param('numba', marks=NEEDS_NUMBA)])
@pytest.mark.parametrize('seed', [0, 1, 2])
def test_filter_converges_on_static_target_from_moving_observers(seed, backend):
    # Three robots abreast 20 m apart (the (b-1) formation) drive past a target ~190 m away.
    # The ring ambiguity of one RSSI sample is resolved after a few tens of metres of
    # baseline; the roughening keeps the spread above R_conv for a while longer, and eq. (7)
    # needs a window of 10 steps: expect 50-75 steps, allow 150.
    target = np.array([1150.0, 1120.0])
    rng = np.random.default_rng(100 + seed)
    bank = make_bank(seed, backend=backend)
    assert bank.backend == backend
    offsets = np.array([[0.0, 0.0], [0.0, 20.0], [0.0, -20.0]])
    for step in range(1, 151):
        for offset in offsets:
            observer = np.array([1000.0 + step, 1000.0]) + offset
            bank.update(observer, [3], [noisy_rssi(observer, target, rng)])
        bank.end_step()
        if bank.is_converged(3):
            break
    estimate = bank.estimate(3)
    assert estimate.converged, f'not converged after {step} steps'
    assert step >= bank_window()
    assert estimate.spread_m <= 20.0
    # 1 dB of noise is ~8 % of the range at 190 m: the estimate is good to a few tens of metres.
    assert np.hypot(*(estimate.position_m - target)) < 50.0


def bank_window() -> int:
    return ParticleFilterConfig().window


def test_convergence_needs_spread_at_most_r_conv():
    window = np.zeros((10, 2))
    assert estimates_converged(20.0, window, r_conv_m=20.0, r_err_m=10.0)
    assert not estimates_converged(20.001, window, r_conv_m=20.0, r_err_m=10.0)


def test_convergence_needs_every_recent_estimate_within_r_err_of_their_mean():
    # Two estimates at +-d around the mean: deviation exactly d.
    at_limit = np.array([[10.0, 0.0], [-10.0, 0.0]] * 5)
    beyond = np.array([[10.01, 0.0], [-10.01, 0.0]] * 5)
    assert estimates_converged(5.0, at_limit, r_conv_m=20.0, r_err_m=10.0)
    assert not estimates_converged(5.0, beyond, r_conv_m=20.0, r_err_m=10.0)


def test_filter_does_not_converge_before_its_window_is_full():
    bank = make_bank()
    target = np.array([1000.0, 1010.0])
    rng = np.random.default_rng(5)
    converged_at = None
    for step in range(1, 40):
        for dx in (-15.0, 0.0, 15.0):
            observer = np.array([1000.0 + dx, 1000.0 + 0.5 * step])
            bank.update(observer, [1], [noisy_rssi(observer, target, rng)])
        bank.end_step()
        if bank.is_converged(1) and converged_at is None:
            converged_at = step
    assert converged_at is not None
    assert converged_at >= ParticleFilterConfig().window


def test_filter_reinitialises_when_all_weights_vanish():
    bank = make_bank()
    bank.track(4, (300.0, 300.0))
    far_observer = np.array([1500.0, 1500.0])
    # -30 dBm means ~1 m away, but every particle is > 1000 m from this observer.
    reinitialised = bank.update(far_observer, [4], [-30.0])
    assert reinitialised == [4]
    particles = bank.particles(4)
    assert np.allclose(particles.mean(axis=0), far_observer, atol=1.0)
    assert not bank.estimate(4).converged
    assert bank.estimate(4).n_updates == 0


def test_update_rejects_non_finite_rssi_and_keeps_the_filter():
    bank = make_bank()
    bank.track(1, (1000.0, 1000.0))
    before = bank.particles(1)
    with pytest.raises(ObservationError, match='finite'):
        bank.update((1000.0, 1000.0), [1], [float('nan')])
    with pytest.raises(ObservationError, match='observer'):
        bank.update((float('inf'), 1000.0), [1], [-80.0])
    np.testing.assert_array_equal(bank.particles(1), before)


def test_initial_lattice_is_71_by_71_over_the_detection_square():
    x, y = lattice(np.array([1000.0, 1000.0]), RADIO.detection_range_m, FIELD_M, 5041)
    assert len(np.unique(x)) == 71
    assert len(np.unique(y)) == 71
    spacing = np.diff(np.unique(x))
    assert np.allclose(spacing, 2 * RADIO.detection_range_m / 70, atol=1e-3)


def test_initial_lattice_is_clipped_to_the_field():
    x, y = lattice(np.array([10.0, 1990.0]), 292.0, FIELD_M, 5041)
    assert x.min() == 0.0
    assert y.max() == FIELD_M
    assert x.max() == pytest.approx(302.0)
    assert y.min() == pytest.approx(1698.0)


def test_systematic_resampling_copies_in_proportion_to_weight():
    n = 5041
    weights = np.zeros((3, n), np.float32)
    weights[0, [10, 20]] = (0.75, 0.25)
    weights[1, :] = 1.0
    weights[2, :] = np.random.default_rng(0).random(n) ** 4  # unnormalised
    index = systematic_index(weights, np.array([[0.3], [0.999], [0.0]]))
    assert np.all(np.diff(index, axis=1) >= 0)
    rows = index // n
    assert np.all(rows == np.arange(3)[:, None])
    counts = np.stack([np.bincount(index[r] - r * n, minlength=n) for r in range(3)])
    assert counts.sum(axis=1).tolist() == [n, n, n]
    assert abs(int(counts[0, 10]) - 0.75 * n) <= 1
    assert abs(int(counts[0, 20]) - 0.25 * n) <= 1
    assert counts[0].sum() == counts[0, 10] + counts[0, 20]
    # Uniform weights: every particle survives once (up to float32 rounding of the sum).
    assert np.count_nonzero(counts[1] == 1) > 0.99 * n
    # Systematic resampling: each particle gets floor or ceil of its expected copies.
    expected = n * weights[2].astype(np.float64) / weights[2].sum(dtype=np.float64)
    assert np.all(np.abs(counts[2] - expected) < 1.0 + 1e-3)


def test_systematic_resampling_rejects_rows_without_weight():
    weights = np.ones((2, 8), np.float32)
    weights[1] = 0.0
    with pytest.raises(ValueError, match='positive'):
        systematic_index(weights, np.zeros((2, 1)))


def test_forgetting_a_target_leaves_the_other_filters_intact():
    bank = make_bank()
    for tid, where in ((1, (500.0, 500.0)), (2, (1000.0, 1000.0)), (3, (1500.0, 1500.0))):
        bank.track(tid, where)
    kept = {tid: bank.particles(tid) for tid in (1, 3)}
    bank.forget(2)
    assert bank.tracked_ids == (1, 3)
    for tid, particles in kept.items():
        np.testing.assert_array_equal(bank.particles(tid), particles)
    bank.update((520.0, 480.0), [3, 1], [-95.0, -60.0])
    assert bank.estimate(1).n_updates == 1
    assert bank.estimate(3).n_updates == 1


def ring_width_m(gaussian: bool) -> float:
    bank = make_bank(gaussian_likelihood=gaussian, init_half_width_m=150.0)
    observer = np.array([1000.0, 1000.0])
    bank.update(observer, [1], [RADIO.mean_rssi_dbm(100.0)])
    distances = np.hypot(*(bank.particles(1) - observer).T)
    return float(np.std(distances))


def test_paper_likelihood_keeps_a_thinner_ring_than_the_gaussian_flag():
    # exp(-e^2/sigma^2) is the Gaussian with variance sigma^2/2: width ratio 1/sqrt(2).
    paper, gaussian = ring_width_m(False), ring_width_m(True)
    assert paper < 0.85 * gaussian
    assert paper > 0.55 * gaussian


def test_batched_update_gives_each_target_the_same_estimate_as_a_lone_update():
    # The estimate comes from the pre-resampling weights, so the first update from the
    # deterministic lattice is free of randomness and must not depend on the batch.
    observer = np.array([1100.0, 900.0])
    together, alone = make_bank(1), make_bank(2)
    for bank in (together, alone):
        bank.track(1, (1000.0, 1000.0))
    together.track(2, (1500.0, 500.0))
    together.track(3, (200.0, 200.0))
    together.update(observer, [3, 1, 2], [-70.0, -80.0, -90.0])
    alone.update(observer, [1], [-80.0])
    a, b = together.estimate(1), alone.estimate(1)
    np.testing.assert_allclose(a.position_m, b.position_m, atol=1e-3)
    assert a.spread_m == pytest.approx(b.spread_m, abs=1e-3)


def lattice_posterior_mean(center, samples, gaussian=False):
    """Eq. (5) on the initial lattice in float64: the weights multiply over ``samples``."""
    x, y = (
        v.astype(np.float64)
        for v in lattice(
            np.array(center), RADIO.detection_range_m, FIELD_M, ParticleFilterConfig().n_particles
        )
    )
    log_w = np.zeros_like(x)
    denominator = 2.0 if gaussian else 1.0
    for (ox, oy), rssi in samples:
        d = np.maximum(np.hypot(x - ox, y - oy), 1.0)
        log_w -= (rssi - (RADIO.rssi_at_1m_dbm - 30.0 * np.log10(d))) ** 2 / denominator
    w = np.exp(log_w - log_w.max())
    w /= w.sum()
    return np.array([w @ x, w @ y])


# Which of ten observers hear target 1, 2, 3, 4: uneven (10, 5, 1 and 3 samples), or all.
UNEVEN_HEARING = {1: range(10), 2: range(0, 10, 2), 3: (4,), 4: (2, 5, 9)}
FULL_HEARING = dict.fromkeys((1, 2, 3, 4), range(10))


@pytest.mark.parametrize('hearing', [UNEVEN_HEARING, FULL_HEARING])
def test_joint_update_multiplies_every_sample_of_each_target(hearing):
    # Ten observers: more than one block of work rows. Filter 7 is tracked first but not
    # heard, so the updated filters are not the first rows of the bank, and target 1 (the
    # one with most samples) is the last of them.
    bank = make_bank(3, censored_likelihood=False, gaussian_likelihood=False)
    centers = {1: (1000.0, 1000.0), 2: (1100.0, 900.0), 3: (900.0, 1100.0), 4: (1000.0, 950.0)}
    bank.track(7, (400.0, 400.0))
    for tid in (2, 4, 3, 1):
        bank.track(tid, centers[tid])
    truth = {1: (1050.0, 1040.0), 2: (1150.0, 850.0), 3: (800.0, 1150.0), 4: (1000.0, 800.0)}
    rng = np.random.default_rng(9)
    observations, samples = [], {tid: [] for tid in truth}
    for i in range(10):
        observer = np.array([950.0 + 12.0 * i, 1000.0 - 7.0 * i])
        heard = [tid for tid in (1, 2, 3, 4) if i in hearing[tid]]
        rssi = [noisy_rssi(observer, np.array(truth[tid]), rng) for tid in heard]
        observations.append((observer, heard, rssi))
        for tid, value in zip(heard, rssi, strict=True):
            samples[tid].append((observer, value))
    assert bank.update_joint(observations) == []
    for tid, center in centers.items():
        estimate = bank.estimate(tid)
        assert estimate.n_updates == len(samples[tid])
        np.testing.assert_allclose(
            estimate.position_m, lattice_posterior_mean(center, samples[tid]), atol=0.05
        )
    assert bank.estimate(7).n_updates == 0


@pytest.mark.parametrize('gaussian', [False, True])
def test_censored_likelihood_divides_by_the_chance_of_being_heard(gaussian):
    # log w = -(P - R)^2 / sigma^2 - log Phi((R - gamma_D) / s), s = sqrt(denominator / 2).
    censored = make_bank(gaussian_likelihood=gaussian)
    plain = make_bank(gaussian_likelihood=gaussian, censored_likelihood=False)
    distances = np.array([[1.0, 100.0, 200.0, 260.0, 292.0, 330.0, 380.0]])
    d2 = (distances**2).astype(np.float32)
    got = -censored._misfit(d2, np.array([-100.0]), np.empty_like(d2))
    uncorrected = -plain._misfit(d2, np.array([-100.0]), np.empty_like(d2))
    s = math.sqrt((2.0 if gaussian else 1.0) / 2.0)
    mean = RADIO.rssi_at_1m_dbm - 30.0 * np.log10(distances)
    heard = np.array([0.5 * math.erfc(-u / math.sqrt(2.0)) for u in ((mean - -101.0) / s)[0]])
    np.testing.assert_allclose(got - uncorrected, -np.log(heard)[None, :], rtol=5e-3, atol=0.02)
    # Near the sensor the correction vanishes; beyond the detection range it favours particles.
    assert abs(got[0, 1] - uncorrected[0, 1]) < 1e-6
    assert got[0, -1] - uncorrected[0, -1] > 1.0


def test_censored_likelihood_removes_the_inward_bias_of_edge_samples():
    # Observers 300 m from a target hear it only when the noise lifts it above -101 dBm.
    # Those samples pull the range inward; with the correction the mean range is unbiased.
    rng = np.random.default_rng(4)
    target = np.array([1000.0, 1000.0])
    ranges = {}
    for censored in (False, True):
        bank = make_bank(5, censored_likelihood=censored, init_half_width_m=420.0)
        bank.track(0, target + np.array([0.0, -300.0]))
        heard = 0
        for i in range(400):
            angle = -math.pi / 2.0 + 0.02 * (i % 50 - 25)
            observer = target + 300.0 * np.array([math.cos(angle), math.sin(angle)])
            value = noisy_rssi(observer, target, rng)
            if value >= RADIO.detection_threshold_dbm:
                bank.update(observer, [0], [value])
                heard += 1
        assert 50 < heard < 350
        particles = bank.particles(0)
        ranges[censored] = float(np.mean(np.hypot(*(particles - (1000.0, 700.0)).T)))
    assert ranges[False] < 285.0
    assert abs(ranges[True] - 300.0) < abs(ranges[False] - 300.0)


@pytest.mark.parametrize('resampling', ['systematic', 'multinomial'])
def test_degenerate_filter_reinitialises_under_either_resampling(resampling):
    bank = make_bank(resampling=resampling)
    bank.track(4, (300.0, 300.0))
    bank.track(5, (1500.0, 1500.0))
    observer = np.array([1500.0, 1500.0])
    assert bank.update(observer, [4, 5], [-30.0, -80.0]) == [4]
    assert bank.estimate(4).n_updates == 0
    assert bank.estimate(5).n_updates == 1
    assert np.all(np.isfinite(bank.particles(4)))


@pytest.mark.filterwarnings('ignore:invalid value')
def test_filter_with_non_finite_particles_reinitialises_and_says_so():
    # Positions are validated, so non-finite weights can only come from corrupted particles;
    # the filter must not pass NaN on to the resampling or the estimate.
    bank = make_bank()
    bank.track(1, (1000.0, 1000.0))
    bank.track(2, (1200.0, 1000.0))
    bank._x[bank._slot_of[1], :] = np.nan
    observer = np.array([1100.0, 1000.0])
    assert bank.update(observer, [1, 2], [-80.0, -80.0]) == [1]
    assert np.allclose(bank.particles(1).mean(axis=0), observer, atol=1.0)
    assert bank.estimate(1).n_updates == 0
    assert np.all(np.isfinite(bank.estimate(1).position_m))
    assert bank.estimate(2).n_updates == 1
    assert np.all(np.isfinite(bank.particles(2)))


def test_end_step_tests_each_filter_on_its_own_window():
    # Target 1 is circled by three observers and converges; target 2 is heard only from one
    # fixed point, so its filter keeps a ring of possible positions and must not converge.
    bank = make_bank(4)
    rng = np.random.default_rng(8)
    near, far = np.array([1000.0, 1040.0]), np.array([1100.0, 1150.0])
    still = np.array([1000.0, 1000.0])
    for step in range(60):
        angle = 0.2 * step
        observations = [(still, [2], [noisy_rssi(still, far, rng)])]
        for phase in (0.0, 2.1, 4.2):
            observer = still + 30.0 * np.array([math.cos(angle + phase), math.sin(angle + phase)])
            observations.append((observer, [1], [noisy_rssi(observer, near, rng)]))
        bank.update_joint(observations)
        bank.end_step()
    assert bank.is_converged(1)
    assert np.hypot(*(bank.estimate(1).position_m - near)) < 10.0
    assert not bank.is_converged(2)
    assert bank.estimate(2).spread_m > ParticleFilterConfig().r_conv_m


def test_censoring_is_exactly_zero_well_inside_the_detection_range():
    # Phi((R - gamma_D) / s) > 1 - 1e-9 up to ~184 m: the correction (and its look-up) vanishes.
    censored = make_bank()
    plain = make_bank(censored_likelihood=False)
    for far_m in (180.0, 300.0):
        d2 = (np.array([[1.0, 50.0, 120.0, far_m]]) ** 2).astype(np.float32)
        got = censored._misfit(d2, np.array([-90.0]), np.empty_like(d2))
        uncorrected = plain._misfit(d2, np.array([-90.0]), np.empty_like(d2))
        np.testing.assert_array_equal(got[0, :3], uncorrected[0, :3])
        assert (got[0, 3] == uncorrected[0, 3]) == (far_m < 184.0)


def test_bank_grown_past_its_capacity_updates_like_a_large_one():
    # Tracking a ninth target reallocates the arrays; the filters must come through intact.
    config = ParticleFilterConfig(backend='numpy')
    grown = ParticleFilterBank(config, RADIO, FIELD_M, np.random.default_rng(6))
    large = ParticleFilterBank(config, RADIO, FIELD_M, np.random.default_rng(6), capacity=16)
    rng = np.random.default_rng(2)
    targets = rng.uniform(900.0, 1100.0, (12, 2))
    for step in range(3):
        observer = np.array([1000.0 + 10.0 * step, 1000.0])
        rssi = [noisy_rssi(observer, t, rng) for t in targets]
        for bank in (grown, large):
            bank.update(observer, list(range(12)), rssi)
            bank.end_step()
    for tid in range(12):
        np.testing.assert_array_equal(grown.particles(tid), large.particles(tid))
        np.testing.assert_array_equal(
            grown.estimate(tid).position_m, large.estimate(tid).position_m
        )
        assert grown.estimate(tid).n_updates == 3


def test_joint_update_of_a_full_bank_multiplies_every_sample():
    # Eight filters fill the bank's eight rows and every observer hears all of them: each
    # block of later samples is one whole level, evaluated without gathering rows.
    bank = make_bank(5, censored_likelihood=False)
    rng = np.random.default_rng(12)
    truth = rng.uniform(900.0, 1100.0, (8, 2))
    observers = [np.array([1000.0 + 15.0 * i, 990.0 + 9.0 * i]) for i in range(3)]
    observations, samples = [], {tid: [] for tid in range(8)}
    for observer in observers:
        rssi = [noisy_rssi(observer, target, rng) for target in truth]
        observations.append((observer, list(range(8)), rssi))
        for tid, value in enumerate(rssi):
            samples[tid].append((observer, value))
    assert bank.update_joint(observations) == []
    for tid in range(8):
        expected = lattice_posterior_mean(observers[0], samples[tid], gaussian=True)
        np.testing.assert_allclose(bank.estimate(tid).position_m, expected, atol=0.05)
        assert bank.estimate(tid).n_updates == 3


def test_unknown_backend_is_rejected():
    with pytest.raises(ConfigError, match="backend 'fortran' not in"):
        ParticleFilterConfig(backend='fortran')
    with pytest.raises(ConfigError, match="'auto', 'numpy' or 'numba', got 'fortran'"):
        resolve_backend('fortran')


def test_backend_without_numba(monkeypatch):
    # A robot without numba: 'auto' runs numpy, 'numba' is refused at construction, saying why.
    monkeypatch.setattr(
        particle_filter,
        '_compiled_kernel',
        lambda: (None, "ModuleNotFoundError: No module named 'numba'"),
    )
    assert make_bank(backend='auto').backend == 'numpy'
    assert make_bank(backend='numpy').backend == 'numpy'
    with pytest.raises(ConfigError, match=r"'numba' needs the numba package.*named 'numba'"):
        make_bank(backend='numba')


def test_miss_table_is_the_chance_of_not_hearing():
    # -log Phi((L - margin) / s): ~0 far beyond the detection range, huge near the sensor.
    bank = make_bank()
    table = bank._miss_table
    margin = RADIO.rssi_at_1m_dbm - RADIO.detection_threshold_dbm
    for loss_db in (30.0, 60.0, 70.0, margin, 76.0, 79.0):
        u = (loss_db - margin) / 1.0  # Gaussian likelihood of sigma^2 = 1: s = 1 dB
        expected = -math.log(0.5 * math.erfc(-u / math.sqrt(2.0))) if u > -30 else None
        got = float(table[int(loss_db / 0.01)])
        if expected is None:
            assert got > 400.0
        else:
            assert got == pytest.approx(expected, rel=2e-2, abs=2e-2)
    assert table[-1] == 0.0


def test_non_detection_removes_the_particles_the_observer_would_have_heard():
    bank = make_bank(seed=1)
    center = np.array([1000.0, 1000.0])
    bank.track(3, center)
    observer = center + np.array([250.0, 0.0])
    kept = bank.update_unheard(3, observer[None, :])
    # Some of the detection square lies within the observer's range, most of it not.
    assert 0.2 < kept < 0.95
    particles = bank.particles(3)
    distances = np.hypot(*(particles - observer).T)
    assert distances.min() > 220.0  # nothing survives where the target would be heard
    estimate = bank.estimate(3)
    assert estimate.position_m[0] < center[0] - 30.0  # pushed away from the observer
    assert np.hypot(*(estimate.best_particle_m - observer)) > 220.0


def test_non_detection_far_away_changes_nothing_and_covering_the_belief_is_reported():
    bank = make_bank(seed=2)
    bank.track(3, (1000.0, 1000.0))
    before = bank.estimate(3).position_m
    assert bank.update_unheard(3, np.array([[1900.0, 1900.0]])) == pytest.approx(1.0, abs=1e-6)
    assert np.hypot(*(bank.estimate(3).position_m - before)) < 5.0
    # A filter confined to 100 m around the observer cannot be right if nothing is heard.
    small = make_bank(seed=2, init_half_width_m=100.0)
    small.track(3, (1000.0, 1000.0))
    particles = small.particles(3)
    assert small.update_unheard(3, np.array([[1000.0, 1000.0]])) < 1e-12
    np.testing.assert_array_equal(small.particles(3), particles)  # left unchanged


def test_a_prior_moves_the_belief_to_where_it_weighs_more():
    bank = make_bank(seed=3)
    bank.track(5, (1000.0, 1000.0))
    particles = bank.particles(5)
    east = particles[:, 0] > 1000.0
    kept = bank.apply_prior(5, np.where(east, 1.0, 0.05))
    assert kept == pytest.approx(0.5 * 1.0 + 0.5 * 0.05, abs=0.02)
    after = bank.particles(5)
    assert np.mean(after[:, 0] > 1000.0) > 0.9
    estimate = bank.estimate(5)
    assert estimate.position_m[0] > 1100.0
    assert estimate.best_particle_m[0] > 1000.0


def test_a_prior_must_weigh_every_particle_and_a_zero_prior_changes_nothing():
    bank = make_bank(seed=3)
    bank.track(5, (1000.0, 1000.0))
    n = bank.particles(5).shape[0]
    with pytest.raises(ValueError, match='prior weights'):
        bank.apply_prior(5, np.ones(n - 1))
    with pytest.raises(ValueError, match='prior weights'):
        bank.apply_prior(5, np.full(n, -1.0))
    with pytest.raises(KeyError):
        bank.apply_prior(6, np.ones(n))
    before = bank.particles(5)
    assert bank.apply_prior(5, np.zeros(n)) == 0.0
    np.testing.assert_array_equal(bank.particles(5), before)
