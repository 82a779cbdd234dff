"""The ROS-free simulator: world, geometry, ray casting, sensor models, sites and signal fields."""
