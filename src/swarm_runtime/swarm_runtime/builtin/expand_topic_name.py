"""``rclpy.expand_topic_name``."""

from __future__ import annotations

from ._names import expand_name
from .exceptions import InvalidTopicNameException

__all__ = ['expand_topic_name']


def expand_topic_name(topic_name: str, node_name: str, node_namespace: str) -> str:
    """Expand ``~``, ``{node}``, ``{ns}`` and relative names to an absolute topic name.

    Raises:
        InvalidTopicNameException: an unknown ``{substitution}``.
    """
    try:
        return expand_name(topic_name, node_name, node_namespace)
    except ValueError as err:
        raise InvalidTopicNameException(topic_name, str(err), topic_name.find('{')) from err
