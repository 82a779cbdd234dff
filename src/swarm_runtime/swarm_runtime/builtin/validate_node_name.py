"""``rclpy.validate_node_name``."""

from __future__ import annotations

from ._names import check_node_name
from .exceptions import InvalidNodeNameException

__all__ = ['validate_node_name']


def validate_node_name(node_name: str) -> bool:
    """Return True for a valid node name.

    Raises:
        InvalidNodeNameException: the name is invalid; the message points at the culprit.
    """
    problem = check_node_name(node_name)
    if problem is not None:
        raise InvalidNodeNameException(node_name, *problem)
    return True
