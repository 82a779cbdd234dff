"""Message <-> core translations: round trips and rejection of malformed input."""

import math

import numpy as np
import pytest
from msc_pf.particle_filter import TargetEstimate
from msc_pf.peers import PeerInfo, Phase, Role
from msc_pf.robot import RobotStatus
from swarm_common.angles import yaw_from_unit_quaternion, yaw_to_quaternion
from swarm_runtime.ros import message_module

from msc_pf import conversions

swarm = message_module('swarm_interfaces')
builtin = message_module('builtin_interfaces')
nav = message_module('nav_msgs')
geometry = message_module('geometry_msgs')

PEER = PeerInfo(
    robot_id=4,
    stamp_s=12.5,
    position_m=(1000.25, 990.5),
    movement=(0.6, -0.8),
    role=Role.LEADER,
    leader_id=4,
    members=(6, 9),
    phase=Phase.FAR_LOCALISATION,
    target_id=3,
    target_rssi_dbm=-84.5,
    evaluation=-84.5,
    readings=((3, -84.25), (7, -99.0)),
    captured_ids=(1, 2),
    visited_cell=5049,
)


def test_peer_round_trip_keeps_every_field():
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    assert msg.robot == 'r4'
    assert conversions.peer_from_ros(msg) == PEER


def test_peer_with_mismatched_readings_is_rejected():
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    msg.reading_rssi_dbm = [-80.0]
    with pytest.raises(ValueError, match='2 reading IDs but 1 values'):
        conversions.peer_from_ros(msg)


def test_peer_with_unknown_phase_or_bad_position_is_rejected():
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    msg.phase = 42
    with pytest.raises(ValueError, match='unknown role or phase'):
        conversions.peer_from_ros(msg)
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    msg.position_x = math.inf
    with pytest.raises(ValueError, match='non-finite position'):
        conversions.peer_from_ros(msg)


def test_peer_readings_of_emitters_outside_the_accepted_ids_are_left_out():
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    msg.reading_ids = [3, 1000, 7, 1001]
    msg.reading_rssi_dbm = [-84.25, -70.0, -99.0, -70.0]
    assert conversions.peer_from_ros(msg, accepted_ids=frozenset({3, 7})) == PEER
    assert conversions.peer_from_ros(msg).readings == (
        (3, -84.25),
        (1000, -70.0),
        (7, -99.0),
        (1001, -70.0),
    )


@pytest.mark.parametrize('field', ['reading_ids', 'members', 'captured_ids'])
def test_peer_with_an_array_longer_than_the_cap_is_rejected(field):
    n = conversions.MAX_PEER_ARRAY_LENGTH
    msg = conversions.peer_to_ros(PEER, 'r4', swarm, builtin)
    setattr(msg, field, list(range(1000, 1000 + n)))
    if field == 'reading_ids':
        msg.reading_rssi_dbm = [-70.0] * n
    conversions.peer_from_ros(msg)  # at the cap: accepted
    setattr(msg, field, list(range(1000, 1001 + n)))
    if field == 'reading_ids':
        msg.reading_rssi_dbm = [-70.0] * (n + 1)
    with pytest.raises(ValueError, match=f'{n + 1} {field}, more than {n}'):
        conversions.peer_from_ros(msg)


def test_readings_drop_non_finite_repeated_and_unknown_emitters():
    msg = swarm.RssiArray(
        readings=[
            swarm.EmitterRssi(emitter_id=1, rssi_dbm=-70.0),
            swarm.EmitterRssi(emitter_id=1, rssi_dbm=-71.0),
            swarm.EmitterRssi(emitter_id=2, rssi_dbm=math.nan),
            swarm.EmitterRssi(emitter_id=50, rssi_dbm=-60.0),
        ]
    )
    readings, ignored = conversions.readings_from_ros(msg, accepted_ids={1, 2})
    assert readings == {1: -70.0}
    assert ignored == 3
    readings, _ = conversions.readings_from_ros(msg)
    assert readings == {1: -70.0, 50: -60.0}


def test_status_is_translated_with_estimates():
    estimate = TargetEstimate(
        3, np.array([1100.0, 950.0]), 12.5, np.array([1101.0, 951.0]), True, 40
    )
    status = RobotStatus(
        robot_id=4,
        stamp_s=3.0,
        phase=Phase.DIRECT_APPROACH,
        role=Role.FOLLOWER,
        swarm_id=1,
        target_id=3,
        target_rssi_dbm=-90.0,
        goal_m=np.array([1100.0, 950.0]),
        estimates=(estimate,),
        captured_ids=(1,),
    )
    msg = conversions.status_to_ros(status, 'r4', 'proposed', swarm, builtin)
    assert msg.phase == swarm.MscPfState.PHASE_DIRECT_APPROACH
    assert (msg.role, msg.swarm_id, msg.target_id) == (1, 1, 3)
    assert (msg.goal_x, msg.goal_y) == (1100.0, 950.0)
    item = msg.estimates[0]
    assert (item.target_id, item.x, item.y, item.converged, item.updates) == (
        3,
        1100.0,
        950.0,
        True,
        40,
    )
    assert list(msg.captured_ids) == [1]


def test_stamp_round_trip_and_odometry_pose():
    stamp = conversions.stamp_to_ros(1234.567891234, builtin)
    assert conversions.stamp_from_ros(stamp) == pytest.approx(1234.567891234, abs=1e-9)
    odom = nav.Odometry()
    odom.pose.pose.position.x = 3.0
    odom.pose.pose.position.y = -2.0
    odom.pose.pose.orientation.z = math.sin(0.4)
    odom.pose.pose.orientation.w = math.cos(0.4)
    x, y, yaw = conversions.pose_from_odometry(odom)
    assert (x, y) == (3.0, -2.0)
    assert yaw == pytest.approx(0.8)


def odometry_with(x: float, y: float, z: float, w: float) -> object:
    odom = nav.Odometry()
    q = odom.pose.pose.orientation
    q.x, q.y, q.z, q.w = x, y, z, w
    return odom


@pytest.mark.parametrize(
    'quaternion',
    [
        (0.0, 0.0, 0.0, 0.0),
        (0.0, 0.0, 1e-300, 1e-300),
        (0.0, 0.0, math.nan, 1.0),
        (0.0, 0.0, math.inf, 1.0),
    ],
)
def test_odometry_with_a_zero_or_non_finite_quaternion_is_rejected(quaternion):
    with pytest.raises(ValueError, match='no orientation'):
        conversions.pose_from_odometry(odometry_with(*quaternion))


def test_odometry_with_a_slightly_non_unit_quaternion_is_normalised():
    for scale in (0.95, 1.05, 1.0 + 1e-7):
        q = (0.0, 0.0, scale * math.sin(0.4), scale * math.cos(0.4))
        assert conversions.pose_from_odometry(odometry_with(*q))[2] == pytest.approx(0.8)


@pytest.mark.parametrize(
    'quaternion', [(0.0, 0.0, 1.0, 1.0), (0.0, 0.0, 0.0, 5.0), (0.0, 0.0, 0.0, 0.8)]
)
def test_odometry_with_a_quaternion_far_from_unit_is_rejected(quaternion):
    with pytest.raises(ValueError, match=r'not within 0\.1 of 1'):
        conversions.pose_from_odometry(odometry_with(*quaternion))


def test_odometry_yaw_of_unit_quaternions_keeps_the_unit_formulas_bits():
    for yaw in np.linspace(-math.pi, math.pi, 2001):
        q = yaw_to_quaternion(float(yaw))
        assert conversions.pose_from_odometry(odometry_with(*q))[2] == yaw_from_unit_quaternion(*q)


def test_robot_ids_come_from_names_and_bad_names_are_rejected():
    assert conversions.robot_id_from_name('/r12') == 12
    with pytest.raises(ValueError, match='r<number>'):
        conversions.robot_id_from_name('robot')


def test_twist_carries_python_floats():
    msg = conversions.twist_to_ros(np.float32(0.5), 1, geometry)
    assert msg.linear.x == 0.5
    assert msg.angular.z == 1.0
