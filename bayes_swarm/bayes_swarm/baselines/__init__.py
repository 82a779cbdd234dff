"""Comparison methods of the Bayes-Swarm-P study."""

from bayes_swarm.baselines.exhaustive import sweep_paths
from bayes_swarm.baselines.glowworm import GlowwormSwarm, glowworm_step
from bayes_swarm.baselines.levy import LevyWalk

__all__ = ['GlowwormSwarm', 'LevyWalk', 'glowworm_step', 'sweep_paths']
