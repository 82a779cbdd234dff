"""Fixtures shared by the swarm_experiments tests."""

from __future__ import annotations

import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from bayes_swarm.settings import BayesSwarmConfig
from swarm_experiments.bayes_batch import MissionSpec

BENCHMARKS = Path(__file__).resolve().parents[2] / 'benchmarks'
CASE1_SOURCE = np.array([1.0, 2.0])


def case1_field(points):
    """Bayes-Swarm Case 1 (Appendix C, Eq. 19)."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return np.exp(-((p - CASE1_SOURCE) ** 2).sum(1) / 3.0) + 0.5 * np.exp(
        -2.0 * ((p - [2.0, 0.5]) ** 2).sum(1)
    )


@pytest.fixture
def case1_spec():
    """A Bayes-Swarm batch mission on Case 1 from one depot at the origin."""
    return MissionSpec(
        field=case1_field,
        source_m=CASE1_SOURCE,
        depots_m=np.array([[0.0, 0.0]]),
        planner=BayesSwarmConfig(),
    )


@pytest.fixture(scope='session')
def benchmark_script() -> Callable[[str], ModuleType]:
    """Load a script of ``benchmarks/`` (not a package) as a module, by its name."""
    loaded: dict[str, ModuleType] = {}

    def load(name: str) -> ModuleType:
        if name not in loaded:
            spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f'{name}.py')
            assert spec is not None
            assert spec.loader is not None
            module = importlib.util.module_from_spec(spec)
            sys.modules[spec.name] = module  # dataclasses look their module up there
            spec.loader.exec_module(module)
            loaded[name] = module
        return loaded[name]

    return load
