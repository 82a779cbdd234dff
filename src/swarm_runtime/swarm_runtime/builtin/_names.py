"""ROS name rules: validation of node names, namespaces and topic names, and expansion.

The rules are those of rmw (``rmw_validate_full_topic_name``, ``rmw_validate_namespace``,
``rmw_validate_node_name``) and rcl (``rcl_validate_topic_name``, ``rcl_expand_topic_name``).
Each check returns ``None`` for a valid name or ``(message, index)`` pointing at the first
offending character; the public ``validate_*`` modules turn that into rclpy's exceptions.
"""

from __future__ import annotations

import re

__all__ = [
    'FULL_TOPIC_NAME_MAX_LENGTH',
    'NAMESPACE_MAX_LENGTH',
    'NODE_NAME_MAX_LENGTH',
    'check_full_topic_name',
    'check_namespace',
    'check_node_name',
    'check_topic_name',
    'expand_name',
    'logger_name_of',
]

NODE_NAME_MAX_LENGTH = 255
FULL_TOPIC_NAME_MAX_LENGTH = 247
NAMESPACE_MAX_LENGTH = FULL_TOPIC_NAME_MAX_LENGTH - 2

_SUBSTITUTION = re.compile(r'\{([^{}]*)\}')

Problem = tuple[str, int] | None


def _is_word_char(char: str) -> bool:
    return char == '_' or (char.isascii() and char.isalnum())


def check_node_name(name: str) -> Problem:
    """Check a node name: non-empty, alphanumerics and '_', not starting with a digit."""
    if not name:
        return 'node name must not be empty', 0
    for index, char in enumerate(name):
        if not _is_word_char(char):
            return "node name must not contain characters other than alphanumerics or '_'", index
    if name[0].isdigit():
        return 'node name must not start with a number', 0
    if len(name) > NODE_NAME_MAX_LENGTH:
        return f"node name should not exceed '{NODE_NAME_MAX_LENGTH}'", NODE_NAME_MAX_LENGTH - 1
    return None


def _check_absolute(name: str, kind: str, max_length: int) -> Problem:
    if not name:
        return f'{kind} must not be empty', 0
    if name[0] != '/':
        return f"{kind} must be absolute, it must lead with a '/'", 0
    if name.endswith('/'):
        return f"{kind} must not end with a '/'", len(name) - 1
    for index, char in enumerate(name):
        if char != '/' and not _is_word_char(char):
            return f"{kind} must not contain characters other than alphanumerics, '_', or '/'", (
                index
            )
    for index in range(1, len(name)):
        if name[index] == '/' and name[index - 1] == '/':
            return f"{kind} must not contain repeated '/'", index
        if name[index - 1] == '/' and name[index].isdigit():
            return f'{kind} must not have a token that starts with a number', index
    if len(name) > max_length:
        return f"{kind} should not exceed '{max_length}'", max_length - 1
    return None


def check_full_topic_name(name: str, *, is_service: bool = False) -> Problem:
    """Check an expanded (absolute) topic or service name."""
    kind = 'service name' if is_service else 'topic name'
    return _check_absolute(name, kind, FULL_TOPIC_NAME_MAX_LENGTH)


def check_namespace(namespace: str) -> Problem:
    """Check a node namespace: ``'/'`` or an absolute name without a trailing '/'."""
    if namespace == '/':
        return None
    return _check_absolute(namespace, 'namespace', NAMESPACE_MAX_LENGTH)


def check_topic_name(name: str, *, is_service: bool = False) -> Problem:
    """Check a topic name before expansion: relative, private (``~``) or absolute."""
    kind = 'service name' if is_service else 'topic name'
    if not name:
        return f'{kind} must not be empty', 0
    if name.endswith('/'):
        return f'{kind} must not end with a forward slash', len(name) - 1
    in_braces = False
    for index, char in enumerate(name):
        if char == '{':
            if in_braces:
                return f'{kind} must not contain nested curly braces', index
            in_braces = True
        elif char == '}':
            if not in_braces:
                return f'{kind} must not contain an unmatched closing curly brace', index
            in_braces = False
        elif char == '~':
            if index != 0:
                return f'{kind} must not contain a tilde (~) except as the first character', index
            if len(name) > 1 and name[1] != '/':
                return f'{kind} must have a forward slash after a leading tilde (~)', 1
        elif char == '/':
            if in_braces:
                return f'{kind} must not contain a forward slash inside curly braces', index
            if index > 0 and name[index - 1] == '/':
                return f'{kind} must not contain repeated forward slashes', index
        elif not _is_word_char(char):
            return (
                f"{kind} must not contain characters other than alphanumerics, '_', '~', "
                "'{', or '}'",
                index,
            )
        elif char.isdigit() and (index == 0 or name[index - 1] == '/'):
            return f'{kind} must not have a token that starts with a number', index
    if in_braces:
        return f'{kind} must not contain an unmatched opening curly brace', name.rindex('{')
    return None


def expand_name(name: str, node_name: str, node_namespace: str) -> str:
    """Expand a topic name to an absolute one (rcl_expand_topic_name).

    ``~`` becomes the node's fully qualified name, ``{node}`` the node name, ``{ns}`` and
    ``{namespace}`` the namespace; relative names go under the namespace.

    Raises:
        ValueError: an unknown ``{substitution}``.
    """
    prefix = '/' if node_namespace == '/' else node_namespace + '/'
    if name.startswith('~'):
        name = prefix + node_name + name[1:]

    def substitute(match: re.Match[str]) -> str:
        key = match.group(1)
        if key == 'node':
            return node_name
        if key in ('ns', 'namespace'):
            return node_namespace
        msg = f"unknown substitution '{{{key}}}' in topic name '{name}'"
        raise ValueError(msg)

    if '{' in name:
        name = _SUBSTITUTION.sub(substitute, name)
        name = name.replace('//', '/')
    if not name.startswith('/'):
        name = prefix + name
    return name


def logger_name_of(node_name: str, node_namespace: str) -> str:
    """Return rcl's logger name of a node: ``/r0`` + ``algo`` gives ``'r0.algo'``."""
    namespace = node_namespace.strip('/')
    if not namespace:
        return node_name
    return namespace.replace('/', '.') + '.' + node_name
