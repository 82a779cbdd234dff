"""Unit conversion constants, as in ``rclpy.constants``."""

__all__ = ['S_TO_NS']

#: Nanoseconds per second.
S_TO_NS = 1_000_000_000
