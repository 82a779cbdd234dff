"""The spawners' point-list option reads 'x,y;x,y' and names itself on bad input."""

import argparse

import numpy as np
import pytest
from swarm_experiments.cli_args import points_argument


def test_point_lists_become_an_n_by_2_array() -> None:
    parse = points_argument('--depots')
    np.testing.assert_array_equal(parse('1,2; -3.5,4;'), [[1.0, 2.0], [-3.5, 4.0]])


@pytest.mark.parametrize('text', ['1,2,3', 'a,b', '1;2', ''])
def test_malformed_point_lists_are_rejected_naming_the_option(text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match='--target-positions must look like'):
        points_argument('--target-positions')(text)
