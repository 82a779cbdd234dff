"""Bayes-Swarm-P decentralized batch Bayesian source seeking and its baselines (Bayes-Swarm-O,
Glowworm, Levy walk, exhaustive search).
"""
