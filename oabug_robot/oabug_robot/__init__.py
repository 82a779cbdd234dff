"""OA-Bug swarm exploration (scent trail + AoA bearings, no map) and its four ablations, as a per-
robot ROS 2 node.
"""
