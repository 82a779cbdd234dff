"""Exceptions raised by the message class generator and the CDR helpers."""

from __future__ import annotations

__all__ = [
    'DeserializationError',
    'InterfaceDefinitionError',
    'InterfacesNotFoundError',
    'MessageError',
    'SerializationError',
    'UnknownMessageTypeError',
    'UnknownPackageError',
]


class MessageError(Exception):
    """Base class of every error raised by :mod:`swarm_runtime.messages`."""


class InterfacesNotFoundError(MessageError, FileNotFoundError):
    """The swarm_interfaces message definitions could not be located."""


class InterfaceDefinitionError(MessageError, ValueError):
    """A .msg definition could not be parsed or registered."""


class UnknownPackageError(MessageError, ImportError):
    """No message type of the requested interface package is known."""


class UnknownMessageTypeError(MessageError, LookupError):
    """The requested message type is not known, or an object is not a message."""


class SerializationError(MessageError, TypeError):
    """A message holds a value that cannot be serialized to CDR."""


class DeserializationError(MessageError, ValueError):
    """Bytes could not be decoded as CDR of the requested message type."""
