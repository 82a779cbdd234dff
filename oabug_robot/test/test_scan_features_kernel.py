"""The compiled scan features of many robots equal the robots' numpy extractor, bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.errors import ScanError
from oabug_robot.scan_features import (
    MIN_FIT_SPREAD_M,
    LaserScanData,
    ScanFeatureExtractor,
    ScanFeatures,
)
from oabug_robot.scan_features_kernel import (
    extract_held,
    extract_many,
    extract_many_flat,
    pairwise_sum,
    side_wall_fit,
)
from oabug_robot.settings import PerceptionConfig
from oabug_robot.sound import PeerBearings

pytestmark = pytest.mark.runtime_independent(reason='the algorithm core')


def _scan(
    ranges: np.ndarray, *, angle_min: float = -math.pi, range_min: float = 0.15
) -> LaserScanData:
    return LaserScanData(
        ranges_m=ranges,
        angle_min_rad=angle_min,
        angle_increment_rad=2.0 * math.pi / max(len(ranges), 1),
        range_min_m=range_min,
        range_max_m=12.0,
    )


def _room_ranges(rng: np.random.Generator, rays: int) -> np.ndarray:
    """Ranges inside a rotated rectangular room, with peer discs, noise and bad readings."""
    angles = rng.uniform(-math.pi, math.pi) + np.arange(rays) * (2.0 * math.pi / rays)
    c, s = np.cos(angles), np.sin(angles)
    ahead, left, behind, right = rng.uniform(0.12, 1.5, 4)
    with np.errstate(divide='ignore'):
        tx = np.where(c > 0, ahead / c, np.where(c < 0, -behind / c, np.inf))
        ty = np.where(s > 0, left / s, np.where(s < 0, -right / s, np.inf))
    ranges = np.minimum(tx, ty)
    for _ in range(rng.integers(0, 3)):
        x, y = rng.uniform(-0.8, 0.8, 2)
        proj = c * x + s * y
        perp_sq = x * x + y * y - proj**2
        hit = (perp_sq <= 0.01) & (proj > 0)
        t = proj - np.sqrt(np.maximum(0.01 - perp_sq, 0.0))
        ranges = np.where(hit & (t < ranges), t, ranges)
    ranges = ranges * (1.0 + 0.01 * rng.standard_normal(rays))
    for value, share in ((math.nan, 0.03), (math.inf, 0.05), (-math.inf, 0.02)):
        ranges[rng.random(rays) < share] = value
    return ranges.astype(np.float32).astype(float)


def _peers(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray | None]:
    count = int(rng.integers(0, 5))
    azimuths = rng.uniform(-4.0, 4.0, count)
    distances = rng.uniform(0.05, 2.5, count)
    azimuths[rng.random(count) < 0.15] = math.nan
    distances[rng.random(count) < 0.2] = math.nan
    return azimuths, None if rng.random() < 0.1 else distances


def _exact(features: ScanFeatures) -> str:
    """Every field, floats to the last bit (repr round-trips and shows -0.0)."""
    return repr(features)


def _numpy_features(extractor, scans, peers, sides) -> list[str]:
    return [
        _exact(extractor.extract(scan, a, d, sides=(side,) if side else ()))
        for scan, (a, d), side in zip(scans, peers, sides, strict=True)
    ]


@pytest.mark.parametrize(
    ('rays', 'config'),
    [
        (360, PerceptionConfig()),
        (90, PerceptionConfig()),
        (360, PerceptionConfig(lidar_yaw_offset_rad=0.3, feature_range_m=2.0)),
        (360, PerceptionConfig(robot_contact_in_path=False)),
    ],
)
def test_the_kernel_gives_the_numpy_features_on_random_scans(rays, config) -> None:
    rng = np.random.default_rng(rays)
    extractor = ScanFeatureExtractor(config)
    checked = 0
    for _ in range(60):
        k = int(rng.integers(1, 12))
        scans = [_scan(_room_ranges(rng, rays)) for _ in range(k)]
        peers = [_peers(rng) for _ in range(k)]
        sides = [int(s) for s in rng.integers(-1, 2, k)]
        got = [_exact(f) for f in extract_many(extractor, scans, peers, sides)]
        assert got == _numpy_features(extractor, scans, peers, sides)
        checked += k
    assert checked > 300


def test_the_kernel_sees_peers_and_side_walls_where_the_extractor_does() -> None:
    """The random scans above do exercise every feature (so equality means something)."""
    rng = np.random.default_rng(7)
    extractor = ScanFeatureExtractor(PerceptionConfig())
    scans = [_scan(_room_ranges(rng, 360)) for _ in range(200)]
    peers = [_peers(rng) for _ in range(200)]
    sides = [int(s) for s in rng.integers(-1, 2, 200)]
    features = extract_many(extractor, scans, peers, sides)
    assert sum(f.peer_returns > 0 for f in features) > 10
    assert sum(math.isfinite(f.front_robot_m) for f in features) > 5
    assert sum(f.left.found and f.left.angle_rad != 0.0 for f in features) > 10
    assert sum(f.right.found and f.right.angle_rad != 0.0 for f in features) > 10
    assert sum(math.isfinite(f.front_wall_m) for f in features) > 50


def test_empty_and_unreadable_scans_give_empty_features_like_the_extractor() -> None:
    extractor = ScanFeatureExtractor(PerceptionConfig())
    rays = 360
    scans = [
        _scan(np.full(rays, math.inf)),
        _scan(np.full(rays, math.nan)),
        _scan(np.full(rays, -math.inf)),  # every ray too close: obstacles at range_min
        _scan(np.full(rays, 20.0)),
    ]
    peers = [(np.array([0.0, math.nan]), np.array([0.3, math.nan]))] * len(scans)
    for sides in ([0] * 4, [1] * 4, [-1] * 4):
        got = [_exact(f) for f in extract_many(extractor, scans, peers, sides)]
        assert got == _numpy_features(extractor, scans, peers, sides)
    # A negative range_min counts as 0: -inf rays become returns at 0 m.
    scans = [_scan(np.full(rays, -math.inf), range_min=-1.0)]
    got = [_exact(f) for f in extract_many(extractor, scans, peers[:1], [1])]
    assert got == _numpy_features(extractor, scans, peers[:1], [1])
    assert extract_many(extractor, [], [], []) == []


def test_bad_batches_are_refused() -> None:
    extractor = ScanFeatureExtractor(PerceptionConfig())
    good = _scan(np.ones(360))
    with pytest.raises(ScanError):
        extract_many(extractor, [_scan(np.zeros(0))], [(np.zeros(0), None)], [0])
    bad_angles = good._replace(angle_min_rad=math.nan)
    with pytest.raises(ScanError):
        extract_many(extractor, [bad_angles], [(np.zeros(0), None)], [0])
    other = good._replace(range_max_m=6.0)
    with pytest.raises(ValueError, match='share'):
        extract_many(extractor, [good, other], [(np.zeros(0), None)] * 2, [0, 0])
    with pytest.raises(ValueError, match='sides'):
        extract_many(extractor, [good], [(np.zeros(0), None)], [0, 1])
    with pytest.raises(ValueError, match='peers'):
        extract_many_flat(extractor, [good], np.array([0, 2]), np.zeros(1), np.zeros(2), [0])
    with pytest.raises(ValueError, match='sides'):
        extract_many_flat(extractor, [good], np.array([0]), np.zeros(0), np.zeros(0), [0])


def test_flat_peers_give_the_features_of_the_per_scan_peers() -> None:
    """extract_many_flat (the batch path's call) with the peers of all scans in one array."""
    rng = np.random.default_rng(11)
    extractor = ScanFeatureExtractor(PerceptionConfig())
    for _ in range(40):
        k = int(rng.integers(1, 12))
        scans = [_scan(_room_ranges(rng, 360)) for _ in range(k)]
        peers = [_peers(rng) for _ in range(k)]
        sides = [int(s) for s in rng.integers(-1, 2, k)]
        start = np.concatenate(([0], np.cumsum([len(a) for a, _ in peers])))
        azimuths = np.concatenate([a for a, _ in peers])
        distances = np.concatenate(
            [np.full(len(a), math.nan) if d is None else d for a, d in peers]
        )
        flat = extract_many_flat(extractor, scans, start, azimuths, distances, sides)
        assert [_exact(f) for f in flat] == _numpy_features(extractor, scans, peers, sides)


def _held(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, float, float] | None:
    """Held bearings as a robot loop keeps them (NaN and inf distances, NaN bearings,
    near and far peers), the yaw they were heard at and the yaw now; None: none held."""
    if rng.random() < 0.2:
        return None
    count = int(rng.integers(0, 9))
    azimuths = rng.uniform(-4.0, 4.0, count)
    distances = rng.uniform(0.05, 4.0, count)
    distances[rng.random(count) < 0.2] = math.nan
    distances[rng.random(count) < 0.1] = math.inf
    azimuths[rng.random(count) < 0.1] = math.nan
    azimuths[rng.random(count) < 0.05] = -0.0
    stamp_yaw, yaw = rng.uniform(-math.pi, math.pi, 2)
    if rng.random() < 0.1:
        yaw = stamp_yaw  # no rotation since: -0.0 bearings stay -0.0
    return azimuths, distances, float(stamp_yaw), float(yaw)


def test_held_bearings_give_each_robots_own_features() -> None:
    """extract_held (the batch path's call) equals, scan by scan, the extractor on the
    near peers PeerBearings.near_peers_now selects from the held bearings."""
    rng = np.random.default_rng(13)
    extractor = ScanFeatureExtractor(PerceptionConfig())
    peers_seen = 0
    for _ in range(60):
        k = int(rng.integers(1, 12))
        scans = [_scan(_room_ranges(rng, 360)) for _ in range(k)]
        held = [_held(rng) for _ in range(k)]
        sides = [int(s) for s in rng.integers(-1, 2, k)]
        want = []
        for scan, h, side in zip(scans, held, sides, strict=True):
            near: tuple[np.ndarray, np.ndarray | None] = (np.zeros(0), None)
            if h is not None:
                near = PeerBearings(h[0], h[1], 0.0, h[2]).near_peers_now(
                    h[3], extractor.config.peer_bearing_max_distance_m
                )
            want.append(_exact(extractor.extract(scan, *near, sides=(side,) if side else ())))
        loops_held = [None if h is None else (h[0], h[1], h[2] - h[3]) for h in held]
        got = extract_held(extractor, scans, loops_held, sides)
        assert [_exact(f) for f in got] == want
        peers_seen += sum(f.peer_returns for f in got)
    assert peers_seen > 100
    with pytest.raises(ValueError, match='sides'):
        extract_held(extractor, scans, loops_held, [*sides, 1])


def test_the_pairwise_sum_adds_in_numpys_order() -> None:
    """Bit for bit numpy's sum, on lengths across its unrolled (8) and split (128) limits,
    with magnitudes far apart (where the order of the additions shows) and signed zeros."""
    rng = np.random.default_rng(5)
    differs_from_sequential = 0
    for n in [*range(0, 40), 127, 128, 129, 135, 255, 256, 257, 300, 777]:
        for _ in range(20):
            values = rng.standard_normal(n) * 10.0 ** rng.integers(-8, 9, n)
            lo = int(rng.integers(0, 3))
            padded = np.concatenate((rng.standard_normal(lo), values, [1e300]))
            expected = float(np.sum(values))
            assert repr(float(pairwise_sum(padded, lo, n))) == repr(expected)
            differs_from_sequential += sum(values.tolist()) != expected
    assert differs_from_sequential > 0  # the test inputs do tell the orders apart
    assert repr(float(pairwise_sum(np.array([-0.0, -0.0]), 0, 2))) == repr(
        float(np.sum([-0.0, -0.0]))
    )


def _wall_points(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Side window returns: a noisy straight wall, a corner (a second wall through the
    window), a short wall or a few scattered returns."""
    kind = int(rng.integers(0, 4))
    n = int(rng.integers(1, 6)) if kind == 3 else int(rng.integers(3, 140))
    xs = np.sort(rng.uniform(-0.3, 0.6, n))
    if kind == 2:
        xs = rng.uniform(0.0, MIN_FIT_SPREAD_M * 1.2, n)
    ls = rng.uniform(0.1, 0.8) + math.tan(rng.uniform(-1.2, 1.2)) * xs
    if kind == 1:
        corner = xs > rng.uniform(0.0, 0.5)
        if corner.any():
            ls[corner] += rng.uniform(-2.0, 2.0) * (xs[corner] - xs[corner].min())
    ls += rng.normal(0.0, rng.choice([0.0, 0.003, 0.03]), n)
    return xs, np.abs(ls)


def test_the_compiled_wall_fit_gives_the_extractors_wall() -> None:
    """side_wall_fit equals ScanFeatureExtractor.wall_from_points bit for bit, including the
    refit without the returns off the first line and the windows too short to fit."""
    rng = np.random.default_rng(11)
    extractor = ScanFeatureExtractor(PerceptionConfig())
    tolerance = extractor.config.side_wall_fit_tolerance_m
    refits = unfitted = 0
    for _ in range(3000):
        xs, ls = _wall_points(rng)
        n = xs.size
        expected = extractor.wall_from_points(xs.copy(), ls.copy(), False)
        scratch = np.full((4, n + 3), np.nan)
        padded_x = np.concatenate((xs, [7.0, 8.0, 9.0]))
        padded_l = np.concatenate((ls, [7.0, 8.0, 9.0]))
        distance, angle = side_wall_fit(padded_x, padded_l, n, tolerance, MIN_FIT_SPREAD_M, scratch)
        assert repr((float(distance), float(angle))) == repr(
            (expected.distance_m, expected.angle_rad)
        )
        unfitted += angle == 0.0
        if n >= 3 and xs.max() - xs.min() >= MIN_FIT_SPREAD_M:
            # Returns off the final line: the first fit's outliers, left out of a refit.
            residual = np.abs(xs * math.sin(angle) - ls * math.cos(angle) + distance)
            refits += bool(np.count_nonzero(residual > tolerance))
    assert unfitted > 100
    assert refits > 100


def test_without_numba_the_module_imports_and_gives_the_same_features() -> None:
    """A robot install has no numba: the kernels then run as plain Python, bit for bit."""
    import subprocess
    import sys

    script = '\n'.join(
        [
            'import sys',
            "sys.modules['numba'] = None",
            'import math',
            'import numpy as np',
            'from oabug_robot import scan_features_kernel as kernel',
            'from oabug_robot.scan_features import LaserScanData, ScanFeatureExtractor',
            'from oabug_robot.settings import PerceptionConfig',
            'assert not kernel.HAVE_NUMBA',
            'rng = np.random.default_rng(3)',
            'extractor = ScanFeatureExtractor(PerceptionConfig())',
            'step = 2 * math.pi / 90',
            'scans = [LaserScanData(rng.uniform(0.2, 4.0, 90), -math.pi, step, 0.15, 12.0)',
            '         for _ in range(3)]',
            'peers = [(np.array([0.5]), np.array([1.0])), (np.zeros(0), None),',
            '         (np.array([2.0]), None)]',
            'got = kernel.extract_many(extractor, scans, peers, [1, -1, 0])',
            'want = [extractor.extract(s, p[0], p[1], sides=(d,) if d else ())',
            '        for s, p, d in zip(scans, peers, [1, -1, 0])]',
            'assert repr(got) == repr(want), (got, want)',
        ]
    )
    done = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
