"""Experiment harness: the spawners, the mission loop, batch runners and benchmark helpers."""
