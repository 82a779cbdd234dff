"""``rclpy.validate_namespace``."""

from __future__ import annotations

from ._names import check_namespace
from .exceptions import InvalidNamespaceException

__all__ = ['validate_namespace']


def validate_namespace(namespace: str) -> bool:
    """Return True for a valid (absolute) namespace.

    Raises:
        InvalidNamespaceException: the namespace is invalid.
    """
    problem = check_namespace(namespace)
    if problem is not None:
        raise InvalidNamespaceException(namespace, *problem)
    return True
