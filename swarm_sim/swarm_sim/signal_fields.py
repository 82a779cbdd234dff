"""Scalar signal fields of the Bayes-Swarm-P study and their mission settings (pure numpy).

Cases 1-3 are the Gaussian mixtures of the paper's Appendix C (Eqs. 19-21); the avalanche
field is the magnitude of a buried beacon's dipole field (Eqs. 13-14) on a 40 x 40 m area.
Each :class:`SignalCase` bundles the field with the settings the paper uses for it (Table 3
caption, Table 4, Table 8, Table 10): arena, depots, V, T, eps, T_max, M, L, delta theta and
the observation rate.

Choices where the paper is silent or inconsistent (see docs/bayes_swarm.md):

* Case 3: the text gives -24 <= x_i <= 24, but its bumps lie up to 125 m out and its depots
  at the arena corners (+-120, +-120), so the arena is taken as [-120, 120]^2 (the bump c6 at
  x = 125 m lies just outside and still shapes the field). The main bump is so wide (divisor
  6500 m^2) that the weaker bumps shift the global maximum from c1 = (55, 45) to
  (65.52, 44.31); the source to find is that maximum, what Bayes-Swarm seeks.
* Avalanche: the beacon lies flat (moment along world x) ``depth_m`` = 6 m below the UAVs'
  sensing plane at (20, 20); the moment is scaled so that the maximum |H| directly above the
  beacon is the paper's 47. The paper gives no depth, but it chose the 40 x 40 m area
  "given the limited range within which the beacon signal can be registered": from the
  depot at the corner (0, 0), 28.3 m from the beacon, the signal must exceed the paper's
  noise (std 47 / 100 = 0.47). That needs at least 5.4 m; at 6 m |H| exceeds 0.47 within
  27 m of the beacon in every direction (32 m along the diagonal; 0.66 at the depot), at
  2 m only within 9-11 m. The depot gives the paper's t_idealized = 56.57 s at 0.5 m/s.
  The planners see the signal in units of the beacon's known peak (``signal_scale`` 47),
  for which the paper's M = 1.2 and L = 2 are what Sec. 2.5 asks of them (M >= max f,
  L >= max |grad f|: 1 and 0.14 /m at 6 m); they are the values the paper gives for Case 1,
  whose field peaks at 1. Read for |H| itself (M = 47), L = 2 is no Lipschitz constant of
  the field (its largest gradient is 6.7 at 6 m) and the exclusion ball (M - mu) / L around
  every peer's waypoint is about 23 m wide, the whole reachable area; that never showed in
  the authors' code because their penalty is inert.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from swarm_sim.errors import SimulationError

__all__ = [
    'AVALANCHE_DEPTH_M',
    'CASE_NAMES',
    'DipoleField',
    'GaussianMixtureField',
    'SignalCase',
    'SignalField',
    'UnknownCaseError',
    'avalanche_case',
    'get_case',
]


class UnknownCaseError(SimulationError, ValueError):
    """A case name that is not one of :data:`CASE_NAMES`."""


class SignalField(Protocol):
    """A scalar field: (q, 2) world points [m] -> (q,) signal values."""

    def __call__(self, points_m: np.ndarray) -> np.ndarray: ...

    def translated(self, offset_m: np.ndarray) -> SignalField:
        """The same field moved by (2,) ``offset_m`` [m]."""
        ...


@dataclass(frozen=True)
class GaussianMixtureField:
    """f(x) = sum_i weight_i exp(-|x - centre_i|^2 / divisor_i) (Appendix C form).

    Attributes:
        centres_m: (k, 2) bump centres [m].
        divisors_m2: (k,) divisors of the squared distance [m^2].
        weights: (k,) bump amplitudes.
    """

    centres_m: np.ndarray
    divisors_m2: np.ndarray
    weights: np.ndarray

    def translated(self, offset_m: np.ndarray) -> GaussianMixtureField:
        """The same field moved by (2,) ``offset_m`` [m]."""
        return replace(self, centres_m=self.centres_m + np.asarray(offset_m, dtype=float))

    def __call__(self, points_m: np.ndarray) -> np.ndarray:
        pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
        diff = pts[:, None, :] - self.centres_m[None, :, :]
        sq = np.einsum('qkj,qkj->qk', diff, diff)
        return np.exp(-sq / self.divisors_m2) @ self.weights


@dataclass(frozen=True)
class DipoleField:
    """|H| of a magnetic dipole (Eqs. 13-14) sensed on a plane ``depth_m`` above it.

    H = A m / (4 pi r^5) with r the vector from the beacon to the receiver.

    Attributes:
        beacon_m: (2,) horizontal beacon position [m].
        depth_m: vertical distance between the sensing plane and the beacon [m].
        moment: (3,) magnetic moment [A m^2].
    """

    beacon_m: np.ndarray
    depth_m: float
    moment: np.ndarray

    def translated(self, offset_m: np.ndarray) -> DipoleField:
        """The same field moved by (2,) ``offset_m`` [m]."""
        return replace(self, beacon_m=self.beacon_m + np.asarray(offset_m, dtype=float))

    def __call__(self, points_m: np.ndarray) -> np.ndarray:
        pts = np.asarray(points_m, dtype=float).reshape(-1, 2)
        r = np.empty((pts.shape[0], 3))
        r[:, :2] = pts - self.beacon_m
        r[:, 2] = self.depth_m
        r2 = np.einsum('qj,qj->q', r, r)
        # A m = 3 r (r . m) - r^2 m, the expanded form of Eq. 14 times m.
        r_dot_m = r @ self.moment
        h = (3.0 * r * r_dot_m[:, None] - r2[:, None] * self.moment) / (
            4.0 * math.pi * r2[:, None] ** 2.5
        )
        return np.linalg.norm(h, axis=1)

    @classmethod
    def with_peak(
        cls,
        beacon_m: tuple[float, float],
        depth_m: float,
        peak: float,
        direction: tuple[float, float, float] = (1.0, 0.0, 0.0),
    ) -> DipoleField:
        """Dipole whose |H| directly above a horizontal moment equals ``peak``."""
        unit = np.asarray(direction, dtype=float)
        unit = unit / np.linalg.norm(unit)
        magnitude = peak * 4.0 * math.pi * depth_m**3
        return cls(np.asarray(beacon_m, dtype=float), float(depth_m), magnitude * unit)


@dataclass(frozen=True)
class SignalCase:
    """A search mission: field, true source and the paper's settings for it.

    Attributes:
        name: case name ('case1', 'case2', 'case3', 'avalanche').
        field: the signal field.
        source_m: (2,) location of the global maximum [m].
        arena_m: (x_min, x_max, y_min, y_max) [m].
        depots_m: (d, 2) start points; robots are dealt to them in turn.
        velocity_mps, horizon_s, detection_radius_m, max_mission_time_s: V, T, eps, T_max.
        signal_scale: the planners' unit of the signal: they divide samples by it, and M, L
            are in these units (the avalanche: its peak 47, see the module docstring).
        max_signal, lipschitz: M and L of the local penalty.
        direction_range_deg: delta theta of the first decision.
        observation_rate_hz: f_Hz.
        default_robots: swarm size used in the paper for this case.
        dimensionless_acquisition: the planners' acquisition terms in [0, 1] (see
            BayesSwarmConfig); on for the avalanche, whose signal reaches 47.
    """

    name: str
    field: SignalField
    source_m: np.ndarray
    arena_m: tuple[float, float, float, float]
    depots_m: np.ndarray
    velocity_mps: float
    horizon_s: float
    detection_radius_m: float
    max_mission_time_s: float
    max_signal: float
    lipschitz: float
    direction_range_deg: float
    observation_rate_hz: float = 1.0
    default_robots: int = 5
    depot_direction_offsets_deg: tuple[float, ...] = (0.0,)
    dimensionless_acquisition: bool = False
    signal_scale: float = 1.0

    def with_source_moved(self, offset_m: np.ndarray) -> SignalCase:
        """The case with its field and source moved by (2,) ``offset_m`` [m].

        Arena, depots and every setting stay. Used to check that a result does not hinge on
        the exact source position (the benchmark's shifted Case 2) and, in the tests, that the
        robots' decisions follow the samples.
        """
        offset = np.asarray(offset_m, dtype=float).reshape(2)
        return replace(self, field=self.field.translated(offset), source_m=self.source_m + offset)

    def ideal_time_s(self, start_m: np.ndarray) -> float:
        """t_idealized of Eq. 12 for a robot starting at (2,) ``start_m`` [s]."""
        return float(np.hypot(*(self.source_m - np.asarray(start_m)))) / self.velocity_mps


def _case1() -> SignalCase:
    return SignalCase(
        name='case1',
        field=GaussianMixtureField(
            np.array([[1.0, 2.0], [2.0, 0.5]]), np.array([3.0, 0.5]), np.array([1.0, 0.5])
        ),
        source_m=np.array([1.0, 2.0]),
        arena_m=(0.0, 2.4, 0.0, 2.4),
        depots_m=np.array([[0.0, 0.0]]),
        velocity_mps=0.1,
        horizon_s=10.0,
        detection_radius_m=0.05,
        max_mission_time_s=100.0,
        max_signal=1.2,
        lipschitz=2.0,
        direction_range_deg=90.0,
        default_robots=5,
    )


_CASE2_CENTRES = [(21, 19), (21, -19), (0, -15), (0, 15), (-19, 10), (21, 19), (-15, -15)]
_CASE3_CENTRES = [(55, 45), (105, -95), (0, -75), (-25, 100), (-95, 50), (125, 40), (-75, -75)]


def _mixture(centres: list[tuple[int, int]], main: float, weak: float) -> GaussianMixtureField:
    divisors = np.array([main] + [weak] * (len(centres) - 1))
    weights = np.array([1.0] + [0.4] * (len(centres) - 1))
    return GaussianMixtureField(np.array(centres, dtype=float), divisors, weights)


def _case2() -> SignalCase:
    return SignalCase(
        name='case2',
        field=_mixture(_CASE2_CENTRES, 130.0, 40.0),
        source_m=np.array([21.0, 19.0]),
        arena_m=(-24.0, 24.0, -24.0, 24.0),
        depots_m=np.array([[0.0, 0.0]]),
        velocity_mps=1.0,
        horizon_s=20.0,
        detection_radius_m=0.2,
        max_mission_time_s=1000.0,
        max_signal=1.2,
        lipschitz=100.0,
        direction_range_deg=360.0,
        default_robots=10,
    )


def _case3() -> SignalCase:
    return SignalCase(
        name='case3',
        field=_mixture(_CASE3_CENTRES, 6500.0, 1600.0),
        source_m=np.array([65.5195, 44.3059]),  # numerical argmax of Eq. 21
        arena_m=(-120.0, 120.0, -120.0, 120.0),
        depots_m=np.array([[-120.0, -120.0], [120.0, -120.0], [120.0, 120.0], [-120.0, 120.0]]),
        velocity_mps=1.0,
        horizon_s=100.0,
        detection_radius_m=0.2,
        max_mission_time_s=1000.0,
        max_signal=1.2,
        lipschitz=480.0,
        direction_range_deg=90.0,
        default_robots=48,
        depot_direction_offsets_deg=(0.0, 90.0, 180.0, 270.0),
    )


AVALANCHE_DEPTH_M = 6.0


def avalanche_case(depth_m: float = AVALANCHE_DEPTH_M) -> SignalCase:
    """The avalanche case with the beacon ``depth_m`` below the sensing plane.

    The peak stays 47 and the field's largest gradient scales as 1 / depth (6.7 at the
    default 6 m, 20 at 2 m), so the paper's L = 2 for |H| / 47 is a valid Lipschitz constant
    at any depth above about 0.43 m. The beacon rises above noise of 1 % of its peak within 27 m of
    it in every direction at 6 m, 23 m at 5 m and 9 m at 2 m.
    """
    if not depth_m > 0.0:
        msg = f'depth_m must be > 0, got {depth_m}'
        raise ValueError(msg)
    return SignalCase(
        name='avalanche',
        field=DipoleField.with_peak((20.0, 20.0), depth_m=depth_m, peak=47.0),
        source_m=np.array([20.0, 20.0]),
        arena_m=(0.0, 40.0, 0.0, 40.0),
        depots_m=np.array([[0.0, 0.0]]),
        velocity_mps=0.5,
        horizon_s=10.0,
        detection_radius_m=0.15,
        max_mission_time_s=100.0,
        signal_scale=47.0,  # the beacon's known peak; M and L are read for |H| / 47
        max_signal=1.2,
        lipschitz=2.0,
        direction_range_deg=90.0,
        observation_rate_hz=0.5,
        default_robots=6,
    )


_FACTORIES = {'case1': _case1, 'case2': _case2, 'case3': _case3, 'avalanche': avalanche_case}
CASE_NAMES = tuple(_FACTORIES)


def get_case(name: str) -> SignalCase:
    """The mission settings of case ``name`` (one of :data:`CASE_NAMES`)."""
    try:
        return _FACTORIES[name]()
    except KeyError:
        msg = f'unknown case {name!r}; choose one of {", ".join(CASE_NAMES)}'
        raise UnknownCaseError(msg) from None
