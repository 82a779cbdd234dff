"""The sim bridge node: the simulator's ROS face (world <-> topics, /clock, ground truth)."""
