"""One robot's bringup without launch files (see :mod:`hw_drivers.bringup.cli`)."""
