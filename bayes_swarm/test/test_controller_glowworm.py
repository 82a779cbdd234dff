"""The Glowworm controller's peer input: what a broadcast it cannot use does to it."""

import math

import numpy as np
import pytest
from bayes_swarm.controller import RobotController
from bayes_swarm.node_settings import settings_from_values


def _controller() -> RobotController:
    return RobotController(
        settings_from_values({'algorithm': 'glowworm', 'robot_index': 0, 'n_robots': 3}), 'r0'
    )


@pytest.mark.parametrize(
    ('position', 'luciferin'),
    [
        ((1.0, 1.0), math.inf),
        ((1.0, 1.0), math.nan),
        ((math.nan, 1.0), 5.0),
        ((math.inf, 0.0), 5.0),
    ],
)
def test_a_broadcast_that_is_not_finite_is_ignored(position, luciferin) -> None:
    # An infinite luciferin, kept, would make the leader draw's probabilities NaN
    # (numpy's choice raises) at the robot's next Glowworm step.
    controller = _controller()
    assert not controller.on_glowworm_peer('r1', 1, np.array(position), luciferin)
    assert controller.on_glowworm_peer('r1', 1, np.array([1.0, 1.0]), 5.0)


def test_own_and_older_broadcasts_are_ignored_and_newer_ones_kept() -> None:
    controller = _controller()
    assert not controller.on_glowworm_peer('r0', 1, np.array([1.0, 1.0]), 5.0)
    assert controller.on_glowworm_peer('r1', 2, np.array([1.0, 1.0]), 5.0)
    assert not controller.on_glowworm_peer('r1', 2, np.array([2.0, 1.0]), 6.0)
    assert controller.on_glowworm_peer('r1', 3, np.array([2.0, 1.0]), 6.0)
