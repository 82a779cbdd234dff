"""Shared fixtures: the paper's Case 1 field, defined here so the core tests need no simulator."""

import numpy as np
import pytest
from bayes_swarm.batch_sim import MissionSpec
from bayes_swarm.settings import BayesSwarmConfig

CASE1_SOURCE = np.array([1.0, 2.0])


def case1_field(points):
    """Appendix C, Eq. 19."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return np.exp(-((p - CASE1_SOURCE) ** 2).sum(1) / 3.0) + 0.5 * np.exp(
        -2.0 * ((p - [2.0, 0.5]) ** 2).sum(1)
    )


@pytest.fixture
def case1_spec():
    return MissionSpec(
        field=case1_field,
        source_m=CASE1_SOURCE,
        depots_m=np.array([[0.0, 0.0]]),
        planner=BayesSwarmConfig(),
    )
