"""Peer relay decisions, bridge parameter mapping and the departure fan."""

import math

import numpy as np
import pytest
from sim_bridge.bridge_parameters import BRIDGE_PARAMETERS, BridgeNodeConfig, config_from_values
from swarm_sim.departure import departure_poses, preferred_directions
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError
from swarm_sim.faults import FaultConfig, FaultPlan
from swarm_sim.peer_relay import RelayConfig, RelayModel, parse_message_type


def test_relay_delivers_only_within_range_and_never_to_the_sender():
    relay = RelayModel(RelayConfig('pkg/msg/Peer', comm_range_m=5.0), np.random.default_rng(0))
    positions = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.1], [-1.0, 0.0]])
    assert relay.receivers(0, positions).tolist() == [1, 3]


def test_relay_drops_about_the_configured_fraction():
    config = RelayConfig('pkg/msg/Peer', loss_probability=0.25)
    relay = RelayModel(config, np.random.default_rng(1))
    positions = np.zeros((11, 2))
    for _ in range(400):
        relay.receivers(0, positions)
    assert relay.dropped / (relay.dropped + relay.delivered) == pytest.approx(0.25, abs=0.03)


def test_a_missions_relay_takes_the_link_faults_and_its_own_random_stream():
    config = RelayConfig('pkg/msg/Peer', comm_range_m=150.0, loss_probability=0.1)
    faults = FaultConfig(comm_range_m=120.0, comm_loss_probability=0.3)
    relay = RelayModel.for_mission(config, seed=4, plan=FaultPlan(faults, 5, 4))
    assert relay.config.comm_range_m == 120.0
    assert relay.config.loss_probability == pytest.approx(1.0 - 0.9 * 0.7)
    assert RelayModel.for_mission(config, seed=4).config == config  # no plan: as given
    # The same seed drops the same deliveries (the bridge and the batch runners agree).
    positions = np.zeros((8, 2))
    first, again = RelayModel.for_mission(config, 4), RelayModel.for_mission(config, 4)
    other = RelayModel.for_mission(config, 5)
    runs = [[r.receivers(0, positions).tolist() for _ in range(50)] for r in (first, again, other)]
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]


def test_message_types_are_parsed_or_rejected():
    assert parse_message_type('swarm_interfaces/msg/BayesSwarmPeer') == (
        'swarm_interfaces',
        'BayesSwarmPeer',
    )
    assert parse_message_type('std_msgs/String') == ('std_msgs', 'String')
    with pytest.raises(ConfigurationError, match='package/msg/Name'):
        RelayConfig('BayesSwarmPeer')
    assert not RelayConfig().enabled


def test_every_parameter_round_trips_through_the_engine_config():
    changed = EngineConfig(seed=3, physics_rate_hz=20.0)
    values = BRIDGE_PARAMETERS.values_of(BridgeNodeConfig(engine=changed))
    assert values['seed'] == 3
    assert values['physics_rate_hz'] == 20.0
    assert config_from_values(values) == changed


def test_parameter_values_reach_the_nested_config():
    config = config_from_values({'scan_rate_hz': 10, 'seed': 4, 'scent_walls_block': False})
    assert config.lidar.rate_hz == 10.0
    assert isinstance(config.lidar.rate_hz, float)
    assert config.seed == 4
    assert config.scent.walls_block is False


def test_bad_parameter_values_are_rejected_with_the_parameter_name():
    with pytest.raises(ConfigurationError, match="unknown parameter 'bogus'"):
        config_from_values({'bogus': 1.0})
    with pytest.raises(
        ConfigurationError,
        match='scan_rate_hz: expected a floating-point number',
    ):
        config_from_values({'scan_rate_hz': 'fast'})
    with pytest.raises(ConfigurationError, match='scan_rate_hz: must be > 0 Hz'):
        config_from_values({'scan_rate_hz': -1.0})


def test_centre_fan_spreads_robots_evenly_facing_outwards():
    poses = departure_poses((5.0, 3.0), 'center', 4, 0.0, start_radius_m=1.0)
    expected = np.array([[6.0, 3.0], [5.0, 4.0], [4.0, 3.0], [5.0, 2.0]])
    assert np.allclose(poses[:, :2], expected)
    headings = np.arctan2(poses[:, 1] - 3.0, poses[:, 0] - 5.0)
    assert np.allclose(np.cos(headings - poses[:, 2]), 1.0)


def test_edge_fan_is_a_half_circle_centred_on_the_way_in():
    into_site = math.pi / 2
    phi = preferred_directions('edge', 10, into_site - math.pi / 2)
    assert phi.min() > 0.0
    assert phi.max() < math.pi
    assert np.mean(phi) == pytest.approx(into_site)


def test_unknown_departure_is_rejected():
    with pytest.raises(ConfigurationError, match='center'):
        preferred_directions('roof', 3, 0.0)
