"""Configuration defaults are Table I's and invalid values are rejected at start."""

import pytest
from msc_pf.errors import ConfigError
from msc_pf.schemes import Scheme
from msc_pf.settings import (
    MscPfConfig,
    ParticleFilterConfig,
    PhaseConfig,
    RadioConfig,
    SwarmConfig,
)


def test_defaults_are_the_papers_table_one():
    cfg = MscPfConfig()
    assert cfg.particle_filter.n_particles == 5041
    assert (cfg.particle_filter.r_conv_m, cfg.particle_filter.r_err_m) == (20.0, 10.0)
    assert (cfg.search.alpha_outside, cfg.search.alpha_inside) == (20.0, 5.0)
    assert (cfg.search.k_s, cfg.search.k_o) == (1.2, 0.5)
    assert cfg.swarm.max_size == 3
    assert cfg.swarm.comm_range_m == 150.0
    assert (cfg.phases.gamma1_dbm, cfg.phases.gamma2_dbm, cfg.phases.gamma3_dbm) == (
        -78.0,
        -58.0,
        -48.0,
    )
    assert cfg.phases.retarget_penalty == -100.0
    assert (cfg.msc.inertia, cfg.msc.cognitive, cfg.msc.social) == (0.5, 1.0, 1.0)
    assert (cfg.msc.avoidance_degree, cfg.msc.dispersion_degree) == (2.0, -100.0)


def test_radio_thresholds_fall_on_the_papers_distances():
    radio = RadioConfig()
    assert radio.rssi_at_1m_dbm == pytest.approx(-27.046)
    assert radio.distance_for_rssi_m(-48.0) == pytest.approx(5.0, abs=0.01)
    assert radio.distance_for_rssi_m(-78.0) == pytest.approx(50.0, abs=0.1)
    assert radio.detection_range_m == pytest.approx(292.0, abs=0.5)


def test_scheme_is_parsed_from_its_name_and_unknown_names_are_rejected():
    assert MscPfConfig(scheme='msc_pf').scheme is Scheme.MSC_PF
    with pytest.raises(ConfigError, match='not one of'):
        MscPfConfig(scheme='pso')


@pytest.mark.parametrize(
    ('factory', 'message'),
    [
        (lambda: PhaseConfig(gamma2_dbm=-90.0), 'gamma1 < gamma2 < gamma3'),
        (lambda: PhaseConfig(retarget_penalty=10.0), 'negative'),
        (lambda: PhaseConfig(goal_progress_window_s=-1.0), 'goal_progress_window_s'),
        (lambda: PhaseConfig(goal_progress_min_m=0.0), 'goal_progress_min_m'),
        (lambda: ParticleFilterConfig(n_particles=2), 'at least 4'),
        (lambda: ParticleFilterConfig(resampling='stratified'), 'resampling'),
        (lambda: ParticleFilterConfig(r_conv_m=float('nan')), 'finite'),
        (lambda: SwarmConfig(max_size=0), 'L_th'),
        (lambda: MscPfConfig(period_s=0.0), 'period_s'),
    ],
)
def test_invalid_parameters_are_rejected(factory, message):
    with pytest.raises(ConfigError, match=message):
        factory()


def test_scheme_features_follow_the_papers_table():
    assert not Scheme.MSC.uses_particle_filter
    assert Scheme.MSC_PF.uses_particle_filter
    assert Scheme.MSC_PF.uses_direct_approach
    assert not Scheme.MSC_PF.uses_far_formation
    assert not Scheme.MSC_PF.uses_stored_estimates
    assert Scheme.PROPOSED.uses_far_formation
    assert Scheme.PROPOSED.uses_stored_estimates
