"""The ROS indirection for swarm nodes: real rclpy when present, otherwise a deterministic built-in
sim-time runtime with rclpy-like message classes, plus rosbag2 MCAP recording and replay.
"""
