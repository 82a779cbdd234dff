"""Multi-target RSSI search and capture: MSC with a particle filter (proposed swarm control) and
the MSC and MSC+PF reference schemes.
"""
