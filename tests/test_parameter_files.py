"""Every node's parameters: generated files up to date, defaults kept, bad files one line.

* The parameter files (``<package>/config/<node>.yaml``) and the docs tables are generated
  from the specs by scripts/regenerate_parameters.py; they must not differ from the specs.
* ``data/node_parameter_defaults_before_specs.json`` holds every parameter default the nodes
  declared before the specs replaced their hand-written tables; the specs keep them all.
* A malformed ``--params-file`` stops each node's ``main()`` with exit status 2 and one line
  naming the file and the parameter, before ROS is initialised (so on either runtime).
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

import pytest
import yaml
from swarm_runtime.parameters import check_parameter_arguments

REPO = Path(__file__).resolve().parents[1]
BEFORE = Path(__file__).with_name('data') / 'node_parameter_defaults_before_specs.json'
# Parameters added since the recording (name -> default).
_SIM_BRIDGE_ADDED = {
    'aoa_nlos_bias_std_rad_per_wall': 0.0,
    'aoa_nlos_bias_correlation_s': 5.0,
    'aoa_outlier_probability_los': 0.0,
    'aoa_outlier_probability_per_wall': 0.0,
    'aoa_outlier_probability_max': 0.5,
    'aoa_wall_distance_factor': 1.0,
    'fault_dropout_robots': 0,
    'fault_dropout_time_s': 0.0,
    'fault_sensor_time_s': 0.0,
    'fault_stale_lidar_robots': 0,
    'fault_stuck_gas_robots': 0,
    'fault_drifting_gas_robots': 0,
    'fault_gas_drift_per_s': 2.0,
    'fault_imu_drift_robots': 0,
    'fault_imu_drift_radps': math.radians(0.5),
    'fault_bearing_dropout_probability': 0.0,
    'fault_comm_range_m': 'inf',
    'fault_comm_loss_probability': 0.0,
    # The multi-process mission (--processes): mission file, end condition, outcome.
    'mission_file': '',
    'max_sim_time_s': 'inf',
    'stop_when_all_rooms_covered': False,
    'outcome_file': '',
    'trajectory_period_s': 0.5,
    'start_after_clock_subscribers': 0,
}
ADDED = {
    'oabug': {
        'min_turn_rate_radps': 0.3,
        'robot_contact_distance_m': 0.16,
        'robot_contact_in_path': True,
        'inner_corner_arc_radius_m': 0.15,
    },
    'sim_bridge': {'physics': 'numpy', **_SIM_BRIDGE_ADDED},
    'msc_pf': {
        'swarm.search_alone': False,
        'msc.turn_margin_db': 2.0,
        # The sector sweep and the PF-driven approach (beyond the paper, off by default).
        'search.mode': 'history',
        'search.coverage_prior_weight': 1.0,
        'search.sweep_radius_m': 250.0,
        'search.sector_reach': -1,
        'phases.converged_give_up_m': 0.0,
        'phases.converged_max_age_s': 0.0,
        'phases.far_aim': 'best_particle',
        'phases.max_pursuers': 0,
        'phases.near_estimate_spread_m': 0.0,
        'phases.non_detection_window_s': 0.0,
        'phases.pursue_memory_s': 0.0,
    },
    'bayes_swarm': {
        'inner_optimizer': 'lbfgsb',
        'cobyla_max_iterations': 1000,
        'penalty_estimate': False,
        'penalty_log_space': False,
        'cobyla_library': 'nlopt',
        'signal_scale': 1.0,
        'weaker_source_within_eps': False,
    },
}
# Defaults changed on purpose since the recording (name -> new default): the Bayes-Swarm
# planner defaults to the paper's solvers; the project's grid solver is the 'grid' profile.
CHANGED = {'bayes_swarm': {'outer_optimizer': 'cobyla'}}


def _regenerate():
    spec = importlib.util.spec_from_file_location(
        'regenerate_parameters', REPO / 'scripts' / 'regenerate_parameters.py'
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault('regenerate_parameters', module)
    spec.loader.exec_module(module)
    return module


REGENERATE = _regenerate()
ENTRIES = {entry.node: entry for entry in REGENERATE.NODES}


def test_generated_parameter_files_and_tables_match_the_specs() -> None:
    stale = [str(path.relative_to(REPO)) for path in REGENERATE.stale_files()]
    assert not stale, f'out of date (run python scripts/regenerate_parameters.py): {stale}'


def test_a_changed_default_makes_the_check_fail(tmp_path) -> None:
    for entry in REGENERATE.NODES:
        for relative in (entry.yaml, entry.doc):
            target = tmp_path / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text((REPO / relative).read_text())
    assert REGENERATE.stale_files(tmp_path) == []
    yaml_file = tmp_path / ENTRIES['oabug'].yaml
    yaml_file.write_text(yaml_file.read_text().replace('gas_threshold: 200', 'gas_threshold: 201'))
    doc = tmp_path / 'docs' / 'msc_pf.md'
    doc.write_text(doc.read_text().replace('| `period_s` | `1.0` |', '| `period_s` | `2.0` |'))
    assert REGENERATE.stale_files(tmp_path) == [yaml_file, doc]


def _plain(value: object) -> object:
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)
    return value


@pytest.mark.parametrize('node', sorted(ENTRIES))
def test_the_specs_keep_every_default_declared_before_them(node: str) -> None:
    before = json.loads(BEFORE.read_text())[node]
    defaults = {k: _plain(v) for k, v in REGENERATE.load_spec(ENTRIES[node]).defaults().items()}
    assert defaults == {**before, **ADDED.get(node, {}), **CHANGED.get(node, {})}
    for name, value in before.items():
        assert type(defaults[name]) is type(value), name


@pytest.mark.parametrize('node', sorted(ENTRIES))
def test_the_generated_file_is_accepted_by_its_node(node: str) -> None:
    entry = ENTRIES[node]
    path = REPO / entry.yaml
    document = yaml.safe_load(path.read_text())
    assert list(document) == [f'/**/{node}']
    spec = REGENERATE.load_spec(entry)
    check_parameter_arguments(spec, node, ['prog', '--ros-args', '--params-file', str(path)])


@pytest.mark.parametrize('case', ['case1', 'case2', 'case3', 'avalanche'])
def test_the_bayes_swarm_case_files_are_valid_parameter_files(case: str) -> None:
    spec = REGENERATE.load_spec(ENTRIES['bayes_swarm'])
    path = REPO / 'bayes_swarm' / 'config' / f'{case}.yaml'
    args = ['prog', '--ros-args', '-r', '__ns:=/r0', '--params-file', str(path)]
    check_parameter_arguments(spec, 'bayes_swarm', args)


def _mains():
    from oabug_robot.sgba import node as sgba_node

    from bayes_swarm import node as bayes_node
    from hw_drivers import (
        aoa_receiver_node,
        gas_node,
        mpu6050_node,
        pump_node,
        rplidar_node,
        static_frames_node,
    )
    from msc_pf import node as msc_node
    from oabug_robot import node as oabug_node
    from sim_bridge import bridge_node

    return {
        'oabug': oabug_node.main,
        'sgba': sgba_node.main,
        'bayes_swarm': bayes_node.main,
        'msc_pf': msc_node.main,
        'sim_bridge': bridge_node.main,
        'rplidar_node': rplidar_node.main,
        'gas_adc_node': gas_node.main,
        'mpu6050_node': mpu6050_node.main,
        'aoa_receiver_node': aoa_receiver_node.main,
        'pump_node': pump_node.main,
        'static_frames_node': static_frames_node.main,
    }


BAD_FILES = {
    'not YAML': ('{"/**": [', ''),
    'wrong type': ('stale_timeout_s: fast', 'parameter stale_timeout_s: expected a floating'),
    'unknown': ('stale_timeout: 1.0', "unknown parameter 'stale_timeout'"),
    'out of range': ('stale_timeout_s: -1.0', 'parameter stale_timeout_s: must be > 0'),
}
# A parameter of each node to get wrong (every driver has stale_timeout_s or control_rate_hz).
WRONG = {
    'bayes_swarm': 'odom_timeout_s',
    'msc_pf': 'odom_timeout_s',
    'sim_bridge': 'coverage_rate_hz',
    'pump_node': 'command_timeout_s',
    'static_frames_node': 'laser_xyz_m',
}
# Nodes whose wrong parameter is an array: how each problem looks there.
ARRAY_FILES = {
    'wrong type': ('laser_xyz_m: fast', 'parameter laser_xyz_m: expected a list'),
    'out of range': ('laser_xyz_m: [0.1, 0.2]', 'parameter laser_xyz_m: expected 3 values'),
}


@pytest.mark.parametrize('problem', sorted(BAD_FILES))
@pytest.mark.parametrize('node', sorted(ENTRIES))
def test_a_malformed_params_file_stops_the_node_with_one_line(
    node, problem, tmp_path, capsys, monkeypatch
) -> None:
    monkeypatch.setenv('SWARM_RUNTIME', 'builtin')  # drivers refuse to start alone otherwise
    body, expected = BAD_FILES[problem]
    name = WRONG.get(node, 'stale_timeout_s')
    if name.endswith('_xyz_m'):
        body, expected = ARRAY_FILES.get(problem, (body, expected))
    body = body.replace('stale_timeout_s', name).replace('stale_timeout', name[:-2])
    expected = expected.replace('stale_timeout_s', name).replace(
        "'stale_timeout'", f"'{name[:-2]}'"
    )
    path = tmp_path / 'bad.yaml'
    text = body if problem == 'not YAML' else f'/**:\n  ros__parameters:\n    {body}\n'
    path.write_text(text)
    args = ['prog', '--ros-args', '-r', '__ns:=/r0', '--params-file', str(path)]
    try:
        code = _mains()[node](args)
    except SystemExit as stop:
        code = stop.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f'{node}: {path}')
    assert expected in err[0]


MALFORMED_ROS_ARGS = {
    'a -p without name:=value': (['-p', 'bogus'], "cannot start ROS: Couldn't parse"),
    'a remap without from:=to': (['-r', 'foo'], "cannot start ROS: Couldn't parse"),
    'a trailing --params-file': (['--params-file'], "cannot start ROS: Couldn't parse"),
    'an unknown log level': (['--log-level', 'loud'], "cannot start ROS: Couldn't parse"),
    'an unknown flag': (['--bogus', '--x'], 'unknown ROS arguments after --ros-args: --bogus --x'),
}


@pytest.mark.parametrize('problem', sorted(MALFORMED_ROS_ARGS))
@pytest.mark.parametrize('node', ['oabug', 'msc_pf', 'sim_bridge'])
def test_malformed_ros_arguments_stop_the_node_with_one_line(node, problem, capsys) -> None:
    # On the runtime under test: real rclpy raises RCLError / UnknownROSArgsError from init,
    # the built-in runtime their mirrors; either way one line and status 2, no traceback.
    extra, expected = MALFORMED_ROS_ARGS[problem]
    try:
        code = _mains()[node](['prog', '--ros-args', *extra])
    except SystemExit as stop:
        code = stop.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f'{node}: {expected}')
    assert '.c:' not in err[0]  # rcl's source locations are left out
