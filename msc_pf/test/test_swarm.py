"""Leader election, membership, join and split on scripted neighbour sets."""

import numpy as np
from msc_pf.peers import NO_TARGET, PeerInfo, Phase, Role
from msc_pf.settings import SwarmConfig
from msc_pf.swarm import SwarmMembership, form_initial_swarms


def peer(robot_id, leader_id=None, members=(), target=NO_TARGET, phase=Phase.SEARCH, x=0.0):
    leader_id = robot_id if leader_id is None else leader_id
    return PeerInfo(
        robot_id=robot_id,
        stamp_s=1.0,
        position_m=(x, 0.0),
        movement=(1.0, 0.0),
        role=Role.LEADER if leader_id == robot_id else Role.FOLLOWER,
        leader_id=leader_id,
        members=tuple(members),
        phase=phase,
        target_id=target,
        target_rssi_dbm=float('nan'),
        evaluation=float('nan'),
        readings=(),
        captured_ids=(),
        visited_cell=-1,
    )


def peers(*infos):
    return {p.robot_id: p for p in infos}


def test_initial_formation_groups_the_nearest_robots_under_the_lowest_ids():
    ids = [0, 1, 2, 3, 4, 5, 6]
    positions = np.array([[0, 0], [50, 0], [1, 0], [2, 0], [51, 0], [52, 0], [100, 0]], float)
    leader_of = form_initial_swarms(ids, positions, max_size=3, comm_range_m=150.0)
    assert leader_of == {0: 0, 2: 0, 3: 0, 1: 1, 4: 1, 5: 1, 6: 6}


def test_initial_formation_recruits_only_robots_in_range():
    positions = np.array([[0, 0], [200, 0], [10, 0]], float)
    leader_of = form_initial_swarms([0, 1, 2], positions, max_size=3, comm_range_m=150.0)
    assert leader_of == {0: 0, 2: 0, 1: 1}


def test_every_robot_computes_the_same_formation_from_the_same_peers():
    positions = {0: (0.0, 0.0), 1: (5.0, 0.0), 2: (10.0, 0.0), 3: (15.0, 0.0)}
    views = {}
    for me in positions:
        membership = SwarmMembership(me, SwarmConfig())
        others = {r: peer(r, x=positions[r][0]) for r in positions if r != me}
        membership.form(np.array(positions[me]), others)
        views[me] = membership.leader_id
    assert views == {0: 0, 1: 0, 2: 0, 3: 3}


def follower_of(leader, me=5):
    membership = SwarmMembership(me, SwarmConfig())
    membership.formed = True
    membership.leader_id = leader
    return membership


def test_follower_that_loses_its_leader_leads_itself():
    membership = follower_of(leader=1)
    note = membership.update(peers(peer(2)), NO_TARGET, Phase.SEARCH)
    assert membership.role is Role.LEADER
    assert 'lost leader 1' in note


def test_follower_follows_its_leaders_new_leader_after_a_join():
    membership = follower_of(leader=3)
    membership.update(peers(peer(3, leader_id=1), peer(1, members=(3,))), NO_TARGET, Phase.SEARCH)
    assert membership.leader_id == 1


def test_follower_not_listed_by_its_leader_leaves_after_the_grace_steps():
    membership = follower_of(leader=1)
    unlisted = peers(peer(1, members=(2, 3)))
    for _ in range(SwarmConfig().membership_grace_steps):
        membership.update(unlisted, NO_TARGET, Phase.SEARCH)
        assert membership.leader_id == 1
    membership.update(unlisted, NO_TARGET, Phase.SEARCH)
    assert membership.role is Role.LEADER


def test_follower_with_another_target_splits_into_a_swarm_heading_there():
    membership = follower_of(leader=1)
    heard = peers(
        peer(1, members=(5,), target=7, phase=Phase.MSC_APPROACH),
        peer(2, members=(3, 4), target=9, phase=Phase.MSC_APPROACH),  # full
        peer(6, members=(), target=9, phase=Phase.MSC_APPROACH),
    )
    note = membership.update(heard, 9, Phase.MSC_APPROACH)
    assert membership.leader_id == 6
    assert 'split toward target 9' in note


def test_follower_with_another_target_and_no_swarm_to_join_leads_a_new_one():
    membership = follower_of(leader=1)
    membership.update(peers(peer(1, members=(5,), target=7)), 9, Phase.MSC_APPROACH)
    assert membership.role is Role.LEADER
    assert membership.members == ()


def test_follower_that_hears_nothing_yet_does_not_split():
    membership = follower_of(leader=1)
    membership.update(peers(peer(1, members=(5,), target=7)), NO_TARGET, Phase.SEARCH)
    assert membership.leader_id == 1


def test_leaders_heading_to_the_same_target_merge_under_the_lower_id():
    membership = SwarmMembership(4, SwarmConfig())
    membership.formed = True
    heard = peers(peer(2, target=7, phase=Phase.MSC_APPROACH))
    note = membership.update(heard, 7, Phase.MSC_APPROACH)
    assert membership.leader_id == 2
    assert note == 'joins swarm of 2'


def test_leaders_do_not_merge_beyond_l_th_or_toward_different_targets():
    membership = SwarmMembership(4, SwarmConfig())
    membership.formed = True
    heard = peers(
        peer(1, members=(8,), target=7, phase=Phase.MSC_APPROACH),  # 2 + 2 > 3
        peer(2, target=9, phase=Phase.MSC_APPROACH),  # other target
        peer(5, leader_id=4, target=7, phase=Phase.MSC_APPROACH),  # my follower
    )
    assert membership.update(heard, 7, Phase.MSC_APPROACH) is None
    assert membership.role is Role.LEADER
    assert membership.members == (5,)


def test_leader_accepts_at_most_l_th_minus_one_followers():
    membership = SwarmMembership(0, SwarmConfig())
    membership.formed = True
    heard = peers(*(peer(r, leader_id=0) for r in (3, 1, 2)))
    membership.update(heard, NO_TARGET, Phase.SEARCH)
    assert membership.members == (1, 2)


def test_working_robot_is_never_a_follower():
    membership = follower_of(leader=1)
    membership.update(peers(peer(1, members=(5,))), 7, Phase.WORK)
    assert membership.role is Role.LEADER


def test_searching_alone_robots_start_apart_and_merge_only_on_a_heard_target():
    config = SwarmConfig(search_alone=True)
    me = SwarmMembership(4, config)
    near = peers(peer(1, x=1.0), peer(2, x=2.0))
    me.form(np.zeros(2), near)
    assert me.leader_id == 4
    # Searching without a target, a lower-ID searching leader does not absorb it...
    assert me.update(near, NO_TARGET, Phase.SEARCH) is None
    assert me.role is Role.LEADER
    # ...but one heading to the target this robot heard does.
    heading = peers(peer(1, target=7, phase=Phase.MSC_APPROACH, x=1.0))
    assert me.update(heading, 7, Phase.MSC_APPROACH) == 'joins swarm of 1'
    assert me.leader_id == 1


def test_searching_alone_a_swarm_dissolves_when_its_leader_searches_again():
    config = SwarmConfig(search_alone=True)
    me = SwarmMembership(5, config)
    me.formed = True
    me.leader_id = 1
    leader = peers(peer(1, members=(5,), target=NO_TARGET, phase=Phase.SEARCH))
    assert 'searches alone' in me.update(leader, NO_TARGET, Phase.SEARCH)
    assert me.role is Role.LEADER
    # The paper's swarms keep searching together.
    paper = SwarmMembership(5, SwarmConfig())
    paper.formed = True
    paper.leader_id = 1
    assert paper.update(leader, NO_TARGET, Phase.SEARCH) is None
    assert paper.leader_id == 1
