"""MP503 gas sensor model on the paper's 10-bit scale.

The MP503 (Grove Air Quality v1.3) responds slowly: the datasheet gives a response time of
about 10 s and a recovery time of about 30 s. The model is a first-order lag with separate
rise and fall time constants on the sensed concentration x [ppm],

    dx/dt = (c - x) / tau,  tau = tau_rise if c > x else tau_fall,

followed by a saturating transfer to counts on the paper's scale and Gaussian noise:

    raw = clip(round(baseline + (RAW_MAX - baseline) x / (x + half_response_ppm) + noise))

With the defaults, clean air reads about 60 (the paper: background below 100) and the
paper's threshold 200 corresponds to about 68 ppm of sensed ethanol.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors_kernel import gas_update_kernel

__all__ = ['RAW_MAX', 'GasSensorConfig', 'Mp503Model']

RAW_MAX = 1023
_NO_NOISE = np.zeros(0)


@dataclass(frozen=True)
class GasSensorConfig:
    """Parameters of the gas sensor model.

    Attributes:
        rate_hz: sample rate [Hz] (the authors polled every 100 ms).
        rise_time_constant_s: lag time constant while the concentration rises [s].
        fall_time_constant_s: lag time constant while it falls [s].
        baseline_raw: clean-air reading on the 10-bit scale.
        half_response_ppm: sensed concentration giving half of the span above baseline [ppm].
        noise_std_raw: standard deviation of the reading noise [counts].
        sensor_offset_m: sensor position ahead of the robot's centre [m].
    """

    rate_hz: float = parameter(10.0, 'Gas sensor sample rate.', unit='Hz', gt=0.0)
    rise_time_constant_s: float = parameter(3.0, 'MP503 rise lag.', unit='s', gt=0.0)
    fall_time_constant_s: float = parameter(5.0, 'MP503 fall lag.', unit='s', gt=0.0)
    baseline_raw: float = parameter(60.0, 'Clean-air reading on the 10-bit scale.', unit='counts')
    half_response_ppm: float = 400.0
    noise_std_raw: float = parameter(4.0, 'Gas reading noise std.', unit='counts', ge=0.0)
    sensor_offset_m: float = parameter(0.08, 'Gas sensor distance ahead of centre.', unit='m')

    def __post_init__(self) -> None:
        positive = ('rate_hz', 'rise_time_constant_s', 'fall_time_constant_s', 'half_response_ppm')
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigurationError(msg)
        if not 0.0 <= self.baseline_raw < RAW_MAX:
            msg = f'baseline_raw must be in [0, {RAW_MAX}), got {self.baseline_raw}'
            raise ConfigurationError(msg)
        if self.noise_std_raw < 0.0:
            raise ConfigurationError('noise_std_raw must be >= 0')

    def raw_for_ppm(self, sensed_ppm: float) -> float:
        """Noise-free reading for a settled sensed concentration [ppm]."""
        x = max(sensed_ppm, 0.0)
        span = RAW_MAX - self.baseline_raw
        return self.baseline_raw + span * x / (x + self.half_response_ppm)

    def ppm_for_raw(self, raw: float) -> float:
        """Settled concentration [ppm] that reads ``raw`` without noise."""
        span = RAW_MAX - self.baseline_raw
        fraction = (raw - self.baseline_raw) / span
        if not 0.0 <= fraction < 1.0:
            msg = f'raw {raw} is outside the sensor span ({self.baseline_raw}, {RAW_MAX})'
            raise ConfigurationError(msg)
        return self.half_response_ppm * fraction / (1.0 - fraction)


class Mp503Model:
    """Slow-responding gas sensors of N robots."""

    def __init__(self, num_robots: int, config: GasSensorConfig, rng: np.random.Generator) -> None:
        self.config = config
        self._rng = rng
        self._sensed_ppm = np.zeros(num_robots)
        # Per sample period [s], the rise and fall gains 1 - exp(-dt / tau).
        self._gains: dict[float, list[float]] = {}

    @property
    def sensed_ppm(self) -> np.ndarray:
        """(N,) lagged concentration inside each sensor [ppm]."""
        return self._sensed_ppm.copy()

    def update(self, concentration_ppm: np.ndarray, dt_s: float) -> np.ndarray:
        """Expose the sensors to (N,) concentrations [ppm] for ``dt_s`` seconds.

        The arithmetic runs in the compiled :func:`swarm_sim.sensors_kernel.gas_update_kernel`
        (the same readings as :meth:`update_reference` from the same random state).

        Returns:
            (N,) int readings on the 10-bit scale, 0..1023.
        """
        cfg = self.config
        c = np.asarray(concentration_ppm, dtype=float).reshape(len(self._sensed_ppm))
        gains = self._gains.get(dt_s)
        if gains is None:
            # The same every period (numpy's exp, as update_reference computes it).
            gains = self._gains[dt_s] = (
                1.0 - np.exp(-dt_s / np.array([cfg.rise_time_constant_s, cfg.fall_time_constant_s]))
            ).tolist()
        gain_rise, gain_fall = gains
        noise = _NO_NOISE
        if cfg.noise_std_raw > 0.0:
            noise = self._rng.normal(0.0, cfg.noise_std_raw, len(c))
        return gas_update_kernel(
            self._sensed_ppm,
            c,
            gain_rise,
            gain_fall,
            noise,
            float(cfg.baseline_raw),
            float(RAW_MAX - cfg.baseline_raw),
            float(cfg.half_response_ppm),
            float(RAW_MAX),
        )

    def update_reference(self, concentration_ppm: np.ndarray, dt_s: float) -> np.ndarray:
        """:meth:`update` in numpy, the reference of the compiled kernel."""
        cfg = self.config
        c = np.asarray(concentration_ppm, dtype=float)
        if not np.isfinite(c).all():
            c = np.nan_to_num(c)
        c = np.maximum(c, 0.0)
        tau = np.where(c > self._sensed_ppm, cfg.rise_time_constant_s, cfg.fall_time_constant_s)
        self._sensed_ppm += (c - self._sensed_ppm) * (1.0 - np.exp(-dt_s / tau))
        x = self._sensed_ppm
        span = RAW_MAX - cfg.baseline_raw
        raw = cfg.baseline_raw + span * x / (x + cfg.half_response_ppm)
        if cfg.noise_std_raw > 0.0:
            raw = raw + self._rng.normal(0.0, cfg.noise_std_raw, len(raw))
        return np.clip(np.rint(raw), 0, RAW_MAX).astype(int)
