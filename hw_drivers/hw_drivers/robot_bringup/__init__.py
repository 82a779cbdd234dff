"""One robot's bringup without launch files (see :mod:`hw_drivers.robot_bringup.cli`)."""
