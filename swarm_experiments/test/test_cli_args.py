"""The spawners' shared options: point lists ('x,y;x,y'), --physics and --render."""

import argparse
from pathlib import Path

import numpy as np
import pytest
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
