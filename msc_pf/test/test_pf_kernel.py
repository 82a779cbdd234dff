"""The compiled particle-filter backend (msc_pf.pf_kernel) against the numpy reference.

The kernels repeat the numpy code's float32 operations in its order, so misfits, weights,
estimates, resampling indices and particles must be equal bit for bit, not merely close.
Skipped where numba is not installed (a robot).
"""

import math

import numpy as np
import pytest
from msc_pf.particle_filter import ParticleFilterBank, systematic_index
from msc_pf.settings import ParticleFilterConfig, RadioConfig

pytestmark = pytest.mark.runtime_independent(reason='the algorithm core')

pf_kernel = pytest.importorskip('msc_pf.pf_kernel')

RADIO = RadioConfig()
FIELD_M = 2000.0


def bank_pair(seed: int = 0, **overrides) -> tuple[ParticleFilterBank, ParticleFilterBank]:
    """A numpy and a numba bank with the same configuration and random seed."""
    return tuple(
        ParticleFilterBank(
            ParticleFilterConfig(backend=backend, **overrides),
            RADIO,
            FIELD_M,
            np.random.default_rng(seed),
        )
        for backend in ('numpy', 'numba')
    )


def assert_same_state(reference: ParticleFilterBank, compiled: ParticleFilterBank) -> None:
    assert reference.tracked_ids == compiled.tracked_ids
    for tid in reference.tracked_ids:
        a, b = reference.estimate(tid), compiled.estimate(tid)
        np.testing.assert_array_equal(reference.particles(tid), compiled.particles(tid))
        np.testing.assert_array_equal(a.position_m, b.position_m)
        np.testing.assert_array_equal(a.best_particle_m, b.best_particle_m)
        assert a.spread_m == b.spread_m
        assert (a.converged, a.n_updates) == (b.converged, b.n_updates)


def noisy_rssi(observer: np.ndarray, target: np.ndarray, rng: np.random.Generator) -> float:
    return RADIO.mean_rssi_dbm(float(np.hypot(*(target - observer)))) + rng.normal()


def test_auto_backend_picks_numba_where_it_is_installed():
    reference, compiled = bank_pair()
    assert reference.backend == 'numpy'
    assert compiled.backend == 'numba'
    auto = ParticleFilterBank(ParticleFilterConfig(), RADIO, FIELD_M, np.random.default_rng(0))
    assert auto.backend == 'numba'


@pytest.mark.filterwarnings('ignore:invalid value')
@pytest.mark.parametrize('gaussian', [False, True])
@pytest.mark.parametrize('censored', [False, True])
def test_misfits_equal_the_numpy_misfits(gaussian, censored):
    # First samples and later ones (uneven per filter, more than a block of work rows), over
    # distances from under 1 m to far past the censoring table, and non-finite particles.
    k, n = 6, 257
    reference, compiled = bank_pair(
        gaussian_likelihood=gaussian, censored_likelihood=censored, n_particles=n
    )
    rng = np.random.default_rng(1)
    x = rng.uniform(-2000.0, 4000.0, (k, n)).astype(np.float32)
    y = rng.uniform(-2000.0, 4000.0, (k, n)).astype(np.float32)
    x[0, :50] = np.float32(1000.0) + rng.uniform(-1.5, 1.5, 50).astype(np.float32)
    y[0, :50] = np.float32(1000.0)
    x[1, 7], y[2, 9], x[3, 11] = np.nan, np.inf, -np.inf
    first = np.column_stack((np.full(k, 1000.0), np.full(k, 1000.0), rng.uniform(-80, -60, k)))
    extra = np.array(
        [(row, *rng.uniform(500.0, 1500.0, 2), rng.uniform(-80.0, -60.0)) for row in range(k)] * 2
        + [(row, 1100.0, 900.0, -70.0) for row in (1, 4)] * 5
    )
    results = []
    for bank in (reference, compiled):
        q, dx, dy, d2 = (np.empty((k, n), np.float32) for _ in range(4))
        if bank is compiled:
            bank._misfits_compiled(x, y, first, extra, q, dx, dy, d2)
        else:
            first32 = first.astype(np.float32)
            np.subtract(x, first32[:, 0:1], out=dx)
            np.subtract(y, first32[:, 1:2], out=dy)
            np.add(dx * dx, dy * dy, out=d2)
            bank._misfit(d2, first[:, 2:], out=q)
            bank._add_extra_samples(q, x, y, extra)
        results.append((q, dx, dy, d2))
    for a, b in zip(*results, strict=True):
        np.testing.assert_array_equal(a, b)
    q = results[0][0]
    assert np.isnan(q[1, 7])
    assert np.isposinf(q[2, 9])
    assert np.isposinf(q[3, 11])
    assert np.all(np.isfinite(q[4]))


def test_censoring_is_looked_up_exactly_when_numpy_looks_it_up():
    # The table is used for a whole block once any particle reaches its first non-zero bin;
    # particles just inside and just at that distance decide it.
    reference, compiled = bank_pair(n_particles=4)
    start_m = 10.0 ** (reference._censor_from_log / 2.0)  # log10 d^2 at the first bin
    for far_m in (start_m * (1.0 - 1e-6), start_m, start_m * (1.0 + 1e-6), 250.0, 180.0):
        x = (1000.0 + np.array([[1.0, 20.0, 100.0, far_m]])).astype(np.float32)
        y = np.full_like(x, 1000.0)
        first = np.array([[1000.0, 1000.0, -95.0 - RADIO.rssi_at_1m_dbm]])
        q_ref, q_kernel = np.empty_like(x), np.empty_like(x)
        d2 = (x - np.float32(1000.0)) ** 2 + (y - np.float32(1000.0)) ** 2
        reference._misfit(d2, first[:, 2:], out=q_ref)
        scratch = [np.empty_like(x) for _ in range(3)]
        compiled._misfits_compiled(x, y, first, np.empty((0, 4)), q_kernel, *scratch)
        np.testing.assert_array_equal(q_ref, q_kernel)


def test_censoring_bins_equal_numpy_across_the_whole_table():
    # Particles every 2 cm from 1 m to 700 m: every 0.01 dB bin of the table, its first
    # non-zero one and its last (~450 m), and beyond.
    n = 35000
    reference, compiled = bank_pair(n_particles=n)
    x = (1000.0 + np.linspace(1.0, 700.0, n))[None, :].astype(np.float32)
    y = np.full_like(x, 1000.0)
    first = np.array([[1000.0, 1000.0, -100.5 - RADIO.rssi_at_1m_dbm]])
    d2 = (x - np.float32(1000.0)) ** 2 + (y - np.float32(1000.0)) ** 2
    q_ref, q_kernel = np.empty_like(x), np.empty_like(x)
    reference._misfit(d2, first[:, 2:], out=q_ref)
    scratch = [np.empty_like(x) for _ in range(3)]
    compiled._misfits_compiled(x, y, first, np.empty((0, 4)), q_kernel, *scratch)
    np.testing.assert_array_equal(q_ref, q_kernel)


def resampling_cases(n: int) -> np.ndarray:
    rng = np.random.default_rng(3)
    weights = np.zeros((7, n), np.float32)
    weights[0] = rng.random(n) ** 4
    weights[1] = 1.0
    weights[2, [0, n // 3, n - 2]] = (0.5, 0.25, 0.25)
    weights[3, -1] = 1.0  # everything on the last particle
    weights[4, 0] = 1.0  # everything on the first
    weights[5] = np.exp(-rng.uniform(0.0, 80.0, n))  # spans 35 decades
    weights[6] = rng.random(n).astype(np.float32) * np.float32(1e-30)
    return weights


@pytest.mark.parametrize('n', [5, 64, 5041])
def test_systematic_index_kernel_equals_the_numpy_index(n):
    weights = resampling_cases(n)
    k = len(weights)
    for u in (0.0, 0.5, float(np.nextafter(np.float32(1.0), np.float32(0.0))), None):
        if u is None:
            offsets = np.random.default_rng(n).random((k, 1), dtype=np.float32)
        else:
            offsets = np.full((k, 1), u, np.float32)
        expected = systematic_index(weights, offsets)
        got = np.empty((k, n), np.intp)
        pf_kernel.systematic_index_kernel(
            weights, offsets, np.empty(n, np.float32), np.empty(n + 1, np.int32), got
        )
        np.testing.assert_array_equal(got, expected)


def scripted_run(bank: ParticleFilterBank, seed: int, steps: int = 25) -> list[list[int]]:
    """Several filters heard unevenly by three observers; one forgotten half way (the
    updated rows are then not the first ones). Returns each step's re-initialised IDs."""
    rng = np.random.default_rng(100 + seed)
    targets = rng.uniform(800.0, 1200.0, (10, 2))
    reports = []
    for step in range(steps):
        observations = []
        for o in range(3):
            observer = np.array([900.0 + 6.0 * step + 20.0 * o, 1000.0 + 15.0 * o])
            heard = [t for t in range(10) if (t + o + step) % 3 and not (step > 12 and t == 4)]
            rssi = [noisy_rssi(observer, targets[t], rng) for t in heard]
            observations.append((observer, heard, rssi))
        if step == 12:
            bank.forget(4)
        reports.append(bank.update_joint(observations))
        bank.end_step()
    return reports


CONFIGS = [
    {},
    {'censored_likelihood': False},
    {'gaussian_likelihood': False},
    {'resampling': 'multinomial'},
    {'noise_pool_size': 0},
    {'initial_prior': 'field'},
    {'fusion': 'sequential', 'roughening_floor_m': 0.0},
]


@pytest.mark.parametrize('overrides', CONFIGS)
def test_bank_updates_equal_the_numpy_bank(overrides):
    reference, compiled = bank_pair(7, **overrides)
    assert scripted_run(reference, 7) == scripted_run(compiled, 7)
    assert_same_state(reference, compiled)


@pytest.mark.filterwarnings('ignore:invalid value')
def test_degenerate_filters_reinitialise_and_report_as_in_numpy():
    # Filter 4: no particle explains -30 dBm (all weights zero); filter 1: NaN particles;
    # filter 2 updates normally.
    reports = []
    banks = bank_pair(2)
    for bank in banks:
        for tid, where in ((4, (300.0, 300.0)), (1, (1000.0, 1000.0)), (2, (1200.0, 1000.0))):
            bank.track(tid, where)
        bank._x[bank._slot_of[1], ::3] = np.nan
        reports.append(bank.update((1500.0, 1500.0), [4, 2, 1], [-30.0, -80.0, -80.0]))
        reports.append(bank.update((1100.0, 1000.0), [2, 4], [-75.0, -85.0]))
    assert reports[0] == reports[2] == [4, 1]
    assert reports[1] == reports[3] == []
    assert_same_state(*banks)
    assert banks[1].estimate(1).n_updates == 0
    assert np.all(np.isfinite(banks[1].particles(1)))


def test_convergence_flags_switch_at_the_same_step():
    # Eqs. (6)-(7) are tested on the estimates and spreads; equal inputs, equal steps.
    banks = bank_pair(4)
    rng = np.random.default_rng(8)
    target = np.array([1000.0, 1040.0])
    flags = {0: [], 1: []}
    for step in range(60):
        samples = []
        for phase in (0.0, 2.1, 4.2):
            angle = 0.2 * step + phase
            observer = 1000.0 + 30.0 * np.array([math.cos(angle), math.sin(angle)])
            samples.append((observer, [1], [noisy_rssi(observer, target, rng)]))
        for i, bank in enumerate(banks):
            bank.update_joint(samples)
            bank.end_step()
            flags[i].append(bank.is_converged(1))
    assert flags[0] == flags[1]
    assert any(flags[1])
    assert not flags[1][0]
    assert_same_state(*banks)


@pytest.mark.parametrize('overrides', [{}, {'censored_likelihood': False}, {'noise_pool_size': 0}])
def test_bank_construction_compiles_every_kernel_the_updates_use(overrides):
    # warm_up covers the argument types of the real calls: no compilation on the first update.
    kernels = (
        pf_kernel.squared_distances,
        pf_kernel.add_misfit,
        pf_kernel.resample_roughen,
    )
    bank = bank_pair(1, **overrides)[1]
    before = [len(kernel.signatures) for kernel in kernels]
    scripted_run(bank, 1, steps=3)
    assert [len(kernel.signatures) for kernel in kernels] == before
