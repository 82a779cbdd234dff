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


def _arrived_controller() -> RobotController:
    # A robot at its first waypoint with a sample: the next Glowworm iteration runs.
    controller = _controller()
    controller.on_pose((1.0, 1.0, 0.0), 0.0)
    controller.on_signal(2.0)
    controller.control(0.0)  # the first decision: the dispersal waypoint
    waypoint = controller.waypoint_m
    controller.on_pose((float(waypoint[0]), float(waypoint[1]), 0.0), 5.0)
    return controller


def test_an_iteration_is_a_broadcast_then_a_move_toward_a_brighter_peer() -> None:
    controller = _arrived_controller()
    assert controller.glowworm_move() is None  # nothing broadcast yet: no move
    position = np.array(controller.pose_m)
    assert controller.on_glowworm_peer('r1', 1, position + np.array([0.5, 0.0]), 100.0)
    sent = controller.glowworm_broadcast()
    assert sent is not None
    np.testing.assert_array_equal(sent.position_m, position)
    assert sent.luciferin == pytest.approx(0.6 * 5.0 + 0.6 * 2.0)
    waypoint = controller.glowworm_move()
    assert waypoint is not None
    assert waypoint[0] > position[0]
    assert waypoint[1] == pytest.approx(position[1])
    assert controller.glowworm_move() is None  # one move per broadcast
