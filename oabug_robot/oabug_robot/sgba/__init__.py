"""SGBA, the Swarm Gradient Bug Algorithm (McGuire et al., Science Robotics 2019), on the
OA-Bug robot's sensors: the comparison the OA-Bug paper leaves open.

:mod:`~oabug_robot.sgba.controller` is the ROS-free controller (its outbound exploration),
:mod:`~oabug_robot.sgba.loop` the sample-and-hold loop the node and the batch runner both
drive, :mod:`~oabug_robot.sgba.settings` its parameters and :mod:`~oabug_robot.sgba.node`
the ROS node (``ros2 run oabug_robot sgba``).
"""
