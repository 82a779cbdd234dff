"""The spawners' shared options: point lists ('x,y;x,y'), --physics and --render."""

import argparse
from pathlib import Path

import numpy as np
import pytest
from swarm_common.errors import UsageError
from swarm_experiments.cli_args import (
    add_physics_option,
    add_render_option,
    points_argument,
    render_config,
)
from swarm_sim.errors import ConfigurationError


def test_point_lists_become_an_n_by_2_array() -> None:
    parse = points_argument('--depots')
    np.testing.assert_array_equal(parse('1,2; -3.5,4;'), [[1.0, 2.0], [-3.5, 4.0]])


@pytest.mark.parametrize('text', ['1,2,3', 'a,b', '1;2', ''])
def test_malformed_point_lists_are_rejected_naming_the_option(text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match='--target-positions must look like'):
        points_argument('--target-positions')(text)


def test_physics_and_render_options_build_the_engine_settings() -> None:
    parser = argparse.ArgumentParser()
    add_physics_option(parser)
    add_render_option(parser)
    args = parser.parse_args(['--physics', 'pybullet', '--render', 'frames', 'out/frames'])
    assert args.physics == 'pybullet'
    render = render_config(args.render)
    assert (render.mode, render.frames_dir) == ('frames', Path('out/frames'))
    assert render_config(['gui']).mode == 'gui'
    assert render_config(None).mode == 'none'
    assert parser.parse_args([]).physics == 'numpy'


@pytest.mark.parametrize('values', [['frames'], ['gui', 'x'], ['movie', 'x'], ['frames', 'a', 'b']])
def test_malformed_render_options_are_rejected(values: list[str]) -> None:
    with pytest.raises(ConfigurationError, match="--render takes 'gui' or 'frames DIR'"):
        render_config(values)


@pytest.mark.parametrize(
    ('module', 'settings'),
    [
        ('swarm_experiments.spawn', {'site': 'small', 'robots': 2}),
        ('swarm_experiments.spawn_bayes_swarm', {}),
        ('swarm_experiments.spawn_msc_pf', {}),
    ],
)
def test_every_spawner_takes_record_topics_and_defaults_to_sensors(module, settings) -> None:
    import importlib

    spawner = importlib.import_module(module)
    parser = spawner._parser() if hasattr(spawner, '_parser') else spawner.build_parser()
    assert parser.parse_args([]).record_topics == 'sensors'
    assert parser.parse_args(['--record-topics', 'mission']).record_topics == 'mission'
    with pytest.raises(UsageError, match="--record-topics: invalid choice: 'scans'"):
        parser.parse_args(['--record-topics', 'scans'])
    assert spawner.SpawnSettings(**settings).record_topics == 'sensors'


def test_record_sets_add_the_sensor_topics_or_leave_them_out() -> None:
    from swarm_experiments.mission import RECORD_TOPIC_SETS, recorded_topics

    mission, sensors = ('/clock', '/r*/state'), ('/r*/odom', '/clock')
    assert recorded_topics('mission', mission=mission, sensors=sensors) == mission
    assert recorded_topics('sensors', mission=mission, sensors=sensors) == (
        '/clock',
        '/r*/state',
        '/r*/odom',
    )
    assert recorded_topics('all', mission=mission, sensors=sensors) is None
    assert set(RECORD_TOPIC_SETS) == {'sensors', 'mission', 'all'}
    with pytest.raises(ConfigurationError, match='unknown record topic set'):
        recorded_topics('scans', mission=mission, sensors=sensors)
