"""``rclpy.validate_topic_name``."""

from __future__ import annotations

from ._names import check_topic_name
from .exceptions import InvalidServiceNameException, InvalidTopicNameException

__all__ = ['validate_topic_name']


def validate_topic_name(name: str, *, is_service: bool = False) -> bool:
    """Return True for a valid topic name before expansion (relative, ``~/x`` or absolute).

    Raises:
        InvalidTopicNameException: (InvalidServiceNameException with ``is_service``) invalid.
    """
    problem = check_topic_name(name, is_service=is_service)
    if problem is not None:
        error = InvalidServiceNameException if is_service else InvalidTopicNameException
        raise error(name, *problem)
    return True
