"""Re-targeting after a capture with the R * N_r rule, on the paper's Fig. 3 example."""

import numpy as np
import pytest
from msc_pf.settings import PhaseConfig, RadioConfig
from msc_pf.targeting import Candidate, candidate_value, count_closer_to, select_retarget

RADIO = RadioConfig()
PHASES = PhaseConfig()

# Fig. 3: robot 1 has converged estimates of targets A and B after a capture. A is nearer,
# but 4 neighbours are closer to A than robot 1 is, and 3 are closer to B.
ROBOT_1 = np.array([1000.0, 1000.0])
TARGET_A = np.array([1080.0, 1000.0])
TARGET_B = np.array([1000.0, 880.0])
NEIGHBOURS = np.array(
    [
        [1060.0, 1005.0],
        [1065.0, 995.0],
        [1070.0, 1010.0],
        [1050.0, 990.0],  # these four are closer to A than robot 1 (80 m)
        [1000.0, 920.0],
        [990.0, 930.0],
        [1010.0, 940.0],  # these three are closer to B than robot 1 (120 m)
    ]
)
A_ID, B_ID = 1, 2


def test_fig3_neighbour_counts_are_four_for_a_and_three_for_b():
    assert count_closer_to(ROBOT_1, TARGET_A, NEIGHBOURS) == 4
    assert count_closer_to(ROBOT_1, TARGET_B, NEIGHBOURS) == 3


def test_fig3_robot_picks_b_when_neither_target_is_heard():
    candidates = [Candidate(A_ID, TARGET_A), Candidate(B_ID, TARGET_B)]
    assert select_retarget(candidates, ROBOT_1, NEIGHBOURS, RADIO, PHASES) == B_ID


def test_fig3_robot_picks_b_when_both_targets_are_heard():
    # Heard: the penalty needs N_r > N_thr = 3, so only A (N_r = 4) is degraded.
    candidates = [
        Candidate(A_ID, TARGET_A, rssi_dbm=-84.0),
        Candidate(B_ID, TARGET_B, rssi_dbm=-89.0),
    ]
    assert select_retarget(candidates, ROBOT_1, NEIGHBOURS, RADIO, PHASES) == B_ID
    value_b = candidate_value(candidates[1], ROBOT_1, 3, RADIO, PHASES)
    assert value_b == -89.0


def test_without_neighbours_the_nearer_target_wins():
    candidates = [Candidate(A_ID, TARGET_A), Candidate(B_ID, TARGET_B)]
    assert select_retarget(candidates, ROBOT_1, np.empty((0, 2)), RADIO, PHASES) == A_ID


def test_unheard_candidate_is_degraded_from_the_first_closer_neighbour():
    candidate = Candidate(A_ID, TARGET_A)
    plain = candidate_value(candidate, ROBOT_1, 0, RADIO, PHASES)
    assert plain == pytest.approx(RADIO.mean_rssi_dbm(80.0))
    assert candidate_value(candidate, ROBOT_1, 1, RADIO, PHASES) == pytest.approx(plain - 100.0)


def test_ties_go_to_the_lower_target_id():
    same = np.array([1100.0, 1000.0])
    mirrored = np.array([900.0, 1000.0])
    candidates = [Candidate(7, same), Candidate(5, mirrored)]
    assert select_retarget(candidates, ROBOT_1, np.empty((0, 2)), RADIO, PHASES) == 5


def test_no_candidate_gives_no_target():
    assert select_retarget([], ROBOT_1, NEIGHBOURS, RADIO, PHASES) is None
