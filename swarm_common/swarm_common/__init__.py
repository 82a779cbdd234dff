"""Small ROS-free helpers shared by every layer of the suite (stdlib and numpy only)."""
