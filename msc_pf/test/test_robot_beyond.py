"""The robot's settings beyond the paper: the sector sweep and the PF-driven approach."""

import math

import numpy as np
import pytest
from msc_pf.peers import NO_TARGET, PeerInfo, Phase, Role
from msc_pf.robot import RobotController
from msc_pf.settings import MscPfConfig, PhaseConfig, RadioConfig, SearchConfig, SwarmConfig

RADIO = RadioConfig()
HOME = np.array([1000.0, 1000.0])
SECTOR = SearchConfig(mode='sector')
ALONE = SwarmConfig(search_alone=True)


def peer(robot_id, stamp, position, *, readings=(), target=NO_TARGET, rssi=math.nan, cell=-1):
    return PeerInfo(
        robot_id=robot_id,
        stamp_s=stamp,
        position_m=(float(position[0]), float(position[1])),
        movement=(0.0, 0.0),
        role=Role.LEADER,
        leader_id=robot_id,
        members=(),
        phase=Phase.SEARCH if target == NO_TARGET else Phase.FAR_LOCALISATION,
        target_id=target,
        target_rssi_dbm=rssi,
        evaluation=rssi,
        readings=tuple(readings),
        captured_ids=(),
        visited_cell=cell,
    )


@pytest.mark.parametrize('robot_id', [0, 1, 2, 3])
def test_each_robot_sweeps_its_own_quarter_when_four_search_alone(robot_id):
    config = MscPfConfig(scheme='msc', search=SECTOR, swarm=ALONE)
    robot = RobotController(robot_id, config, seed=1)
    # Its three peers stand where it stands: the start centroid is HOME.
    others = [r for r in range(4) if r != robot_id]
    out = None
    for t in range(1, 8):
        peers = [peer(r, float(t), HOME) for r in others]
        out = robot.step(float(t), HOME, {}, peers)
    assert out is not None
    assert out.status.phase is Phase.SEARCH
    bearing = math.degrees(math.atan2(out.displacement_m[1], out.displacement_m[0])) % 360.0
    assert 90.0 * robot_id <= bearing < 90.0 * (robot_id + 1)
    assert np.hypot(*out.displacement_m) == pytest.approx(1.0)


def test_the_sweep_waits_for_the_formation_time_then_moves():
    config = MscPfConfig(scheme='msc', search=SECTOR, swarm=ALONE)
    robot = RobotController(0, config, seed=1)
    steps = []
    for t in range(1, 9):
        out = robot.step(float(t), HOME, {}, [peer(1, float(t), HOME), peer(2, float(t), HOME)])
        steps.append(float(np.hypot(*out.displacement_m)))
    # Peers are noted for formation_timeout_s (5 s) from the first step, then it sweeps.
    assert steps[:5] == [0.0] * 5
    assert steps[5:] == pytest.approx([1.0] * 3)


def test_a_robot_leaves_a_target_to_closer_pursuers_with_max_pursuers():
    def hears_with_a_louder_pursuer(phases):
        robot = RobotController(0, MscPfConfig(scheme='msc', phases=phases), seed=1)
        robot.step(1.0, HOME, {}, [peer(1, 1.0, HOME + 50.0)])
        out = None
        for t in range(2, 6):
            loud = peer(1, float(t), HOME + 50.0, target=7, rssi=-70.0)
            out = robot.step(float(t), HOME, {7: -80.0}, [loud])
        return out

    assert hears_with_a_louder_pursuer(PhaseConfig()).status.target_id == 7
    out = hears_with_a_louder_pursuer(PhaseConfig(max_pursuers=1))
    assert out.status.target_id == NO_TARGET
    assert out.status.phase is Phase.SEARCH
    # Two pursuers allowed: one louder robot is not enough to keep this one out.
    assert hears_with_a_louder_pursuer(PhaseConfig(max_pursuers=2)).status.target_id == 7


TARGET = np.array([1300.0, 1000.0])  # 300 m east of HOME


def hear_once_then_silence(phases, steps=40, search=None):
    """A lone proposed-scheme robot at HOME hears TARGET for 5 s, then nothing."""
    rng = np.random.default_rng(2)
    config = MscPfConfig(
        scheme='proposed', phases=phases, swarm=ALONE, search=search or SearchConfig()
    )
    robot = RobotController(0, config, seed=4)
    robot.step(1.0, HOME, {}, [peer(1, 1.0, HOME + np.array([0.0, 100.0]))])
    outs = []
    for t in range(2, 2 + steps):
        heard = {3: RADIO.mean_rssi_dbm(300.0) + 3.0 + rng.normal()} if t < 7 else {}
        outs.append(robot.step(float(t), HOME, heard))
    return robot, outs


def test_pursue_memory_keeps_a_target_through_a_signal_gap():
    _, outs = hear_once_then_silence(PhaseConfig())
    assert outs[4].status.target_id == 3
    assert outs[12].status.target_id == NO_TARGET  # 3 s of silence: search again
    _, outs = hear_once_then_silence(PhaseConfig(pursue_memory_s=20.0))
    assert [o.status.target_id for o in outs[4:24]] == [3] * 20
    assert outs[30].status.target_id == NO_TARGET


def test_non_detections_push_the_belief_away_from_the_robot():
    robot, _ = hear_once_then_silence(PhaseConfig(pursue_memory_s=20.0), steps=12)
    plain = np.hypot(*(robot.filters.particles(3) - HOME).T)
    robot, _ = hear_once_then_silence(
        PhaseConfig(pursue_memory_s=20.0, non_detection_window_s=60.0), steps=12
    )
    folded = np.hypot(*(robot.filters.particles(3) - HOME).T)
    # Six silent steps at HOME: particles within earshot of HOME lose their weight.
    assert np.mean(folded < 250.0) < 0.5 * np.mean(plain < 250.0)


def test_the_far_leader_heads_for_the_estimate_with_far_aim_estimate():
    robot, outs = hear_once_then_silence(
        PhaseConfig(pursue_memory_s=20.0, far_aim='estimate'), steps=6
    )
    out = outs[-1]
    assert out.status.phase is Phase.FAR_LOCALISATION
    aim = robot.filters.estimate(3).position_m
    heading = out.displacement_m / np.hypot(*out.displacement_m)
    assert heading @ ((aim - HOME) / np.hypot(*(aim - HOME))) > 0.99


def new_filter_after_a_sweep(weight):
    """A lone robot drove from x = 500 m to HOME; then it hears target 3 300 m away."""
    search = SearchConfig(mode='sector', coverage_prior_weight=weight)
    rng = np.random.default_rng(3)
    robot = RobotController(0, MscPfConfig(scheme='proposed', search=search, swarm=ALONE), 1)
    t = 1.0
    for x in np.arange(500.0, 1001.0, 10.0):
        robot.step(t, (x, 1000.0), {}, [peer(1, t, (x, 1100.0))])
        t += 1.0
    robot.step(t, HOME, {3: RADIO.mean_rssi_dbm(300.0) + rng.normal()})
    particles = robot.filters.particles(3)
    return robot._sweep.covered_at(particles).mean(), particles


def test_the_coverage_prior_puts_a_new_filter_on_the_unsearched_side():
    searched, _ = new_filter_after_a_sweep(1.0)
    assert searched > 0.3  # the ring of distances crosses the ground searched on the way
    searched, particles = new_filter_after_a_sweep(0.05)
    assert searched < 0.1
    assert np.mean(particles[:, 0] > 1000.0) > 0.6
