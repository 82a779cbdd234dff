"""Comparison methods of the Bayes-Swarm-P study (docs/bayes_swarm.md)."""

from bayes_swarm.baselines.exhaustive import sweep_paths
from bayes_swarm.baselines.glowworm import GlowwormAgent, select_leader
from bayes_swarm.baselines.levy import LevyWalk

__all__ = ['GlowwormAgent', 'LevyWalk', 'select_leader', 'sweep_paths']
