"""pybullet simulation bridge publishing the robots' sensor topics, site generator and layout
importer, signal fields, and the launch-free spawner.
"""
