"""What the runtime needs from :mod:`swarm_runtime.messages`, looked up lazily.

The built-in runtime does not define message classes; the messages package does. Importing
it is deferred to first use, so importing the runtime stays cheap and the two packages can be
tested apart. This is also the one place that reads the CDR round-trip switch.
"""

from __future__ import annotations

import os
from functools import cache
from types import ModuleType
from typing import Any

__all__ = [
    'CDR_ROUNDTRIP_ENV_VAR',
    'cdr_codec',
    'cdr_roundtrip_enabled',
    'interface_class',
    'interface_module',
    'message_typename',
    'type_hash_text',
]

#: Environment variable: when truthy, every published message reaches each subscriber as a
#: CDR round trip of itself (own copy, float32 rounding), as between processes on a robot.
CDR_ROUNDTRIP_ENV_VAR = 'SWARM_RUNTIME_CDR_ROUNDTRIP'
_TRUTHY = frozenset({'1', 'true', 'yes', 'on'})


def cdr_roundtrip_enabled() -> bool:
    """Return True when ``SWARM_RUNTIME_CDR_ROUNDTRIP`` asks for the CDR round trip."""
    return os.environ.get(CDR_ROUNDTRIP_ENV_VAR, '').strip().lower() in _TRUTHY


@cache
def interface_module(package: str) -> ModuleType:
    """Return the message module of an interface package, e.g. ``'rcl_interfaces'``."""
    from swarm_runtime.messages import get_message_module

    return get_message_module(package)


def interface_class(package: str, name: str) -> Any:
    """Return one message class, e.g. ``interface_class('builtin_interfaces', 'Time')``."""
    return getattr(interface_module(package), name)


def message_typename(msg_type: Any) -> str:
    """Return ``'pkg/msg/Name'`` of a message class.

    Raises:
        RuntimeError: ``msg_type`` is not a message class (rclpy raises RuntimeError too).
    """
    from swarm_runtime.messages import message_typename as typename_of

    if not isinstance(msg_type, type):
        msg = f'The message type provided is not valid ({msg_type!r}): expected a message class'
        raise RuntimeError(msg)
    try:
        return typename_of(msg_type)
    except (LookupError, TypeError, ValueError) as err:
        msg = f'The message type provided is not valid ({msg_type!r}): {err}'
        raise RuntimeError(msg) from err


def cdr_codec(typename: str) -> Any:
    """Return the CDR codec of a type (``.serialize(msg)``, ``.deserialize(data)``)."""
    from swarm_runtime.messages import get_cdr_codec

    return get_cdr_codec(typename)


@cache
def type_hash_text(typename: str) -> str:
    """The RIHS01 hash of a message type as text ('RIHS01_<hex>'); '' when it is unknown."""
    from swarm_runtime.messages import default_registry

    try:
        return default_registry().typestore.hash_rihs01(typename)
    except KeyError:
        return ''
