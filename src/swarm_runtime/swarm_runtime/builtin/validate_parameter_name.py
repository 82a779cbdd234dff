"""``rclpy.validate_parameter_name``."""

from __future__ import annotations

__all__ = ['validate_parameter_name']


def validate_parameter_name(name: str) -> bool:
    """Return True: like rclpy 7.1, parameter names are not checked beyond being strings."""
    return True
