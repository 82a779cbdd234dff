"""Bag replay, mission metrics (coverage, relative completion time, capture completion time), plots
and experiment reports.
"""
