# ruff: noqa: N818 - the exception names are rclpy's, node code catches them by name.
"""The exception types of ``rclpy.exceptions``, with the messages rclpy formats.

Node code catches these by name (``except ParameterNotDeclaredException``), so the names,
base classes and constructor arguments follow rclpy 7.1 (Jazzy).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .parameter import Parameter

__all__ = [
    'InvalidHandle',
    'InvalidNamespaceException',
    'InvalidNodeNameException',
    'InvalidParameterException',
    'InvalidParameterTypeException',
    'InvalidParameterValueException',
    'InvalidServiceNameException',
    'InvalidTopicNameException',
    'NameValidationException',
    'NoTypeSupportImportedException',
    'NotInitializedException',
    'ParameterAlreadyDeclaredException',
    'ParameterException',
    'ParameterImmutableException',
    'ParameterNotDeclaredException',
    'ParameterUninitializedException',
    'ROSInterruptException',
]


class NotInitializedException(Exception):
    """rclpy.init() was not called (or the context was shut down) before using rclpy."""

    def __init__(self, message: str | None = None) -> None:
        text = 'rclpy.init() has not been called.'
        if message:
            text = f'rclpy.init() has not been called. msg:{message}'
        super().__init__(text)


class NoTypeSupportImportedException(Exception):
    """A message type without type support was used."""

    def __init__(self) -> None:
        super().__init__('no type_support imported')


class InvalidHandle(RuntimeError):
    """An entity (node, publisher, timer...) was used after it was destroyed."""


class NameValidationException(Exception):
    """A topic name, node name or namespace is invalid; the message points at the culprit."""

    def __init__(self, name_type: str, name: str, error_msg: str, invalid_index: int) -> None:
        pointer = ' ' * invalid_index
        super().__init__(f"Invalid {name_type}: {error_msg}:\n  '{name}'\n   {pointer}^")


class InvalidNamespaceException(NameValidationException):
    """A namespace is invalid."""

    def __init__(self, name: str, error_msg: str, invalid_index: int) -> None:
        super().__init__('namespace', name, error_msg, invalid_index)


class InvalidNodeNameException(NameValidationException):
    """A node name is invalid."""

    def __init__(self, name: str, error_msg: str, invalid_index: int) -> None:
        super().__init__('node name', name, error_msg, invalid_index)


class InvalidTopicNameException(NameValidationException):
    """A topic name is invalid."""

    def __init__(self, name: str, error_msg: str, invalid_index: int) -> None:
        super().__init__('topic name', name, error_msg, invalid_index)


class InvalidServiceNameException(NameValidationException):
    """A service name is invalid."""

    def __init__(self, name: str, error_msg: str, invalid_index: int) -> None:
        super().__init__('service name', name, error_msg, invalid_index)


class ParameterException(Exception):
    """Base class of the parameter errors: ``'<what>: <parameter names>'``."""

    def __init__(self, error_msg: str, parameters: str | list[str]) -> None:
        super().__init__(f'{error_msg}: {parameters}')


class ParameterNotDeclaredException(ParameterException):
    """An undeclared parameter was accessed while undeclared parameters are not allowed."""

    def __init__(self, parameters: str | list[str]) -> None:
        super().__init__('Invalid access to undeclared parameter(s)', parameters)


class ParameterAlreadyDeclaredException(ParameterException):
    """A parameter was declared a second time."""

    def __init__(self, parameters: str | list[str]) -> None:
        super().__init__('Parameter(s) already declared', parameters)


class InvalidParameterException(ParameterException):
    """A parameter name is invalid."""

    def __init__(self, parameter_name: str) -> None:
        super().__init__('Invalid parameter name', parameter_name)


class InvalidParameterTypeException(ParameterException):
    """A parameter value (usually an override) does not have the declared type."""

    def __init__(self, desired_parameter: Parameter, expected_type: Any) -> None:
        from .parameter import Parameter

        value = desired_parameter.value
        value_type = Parameter.Type.from_parameter_value(value).name
        super().__init__(
            f"Trying to set parameter '{desired_parameter.name}' to '{value}' of type "
            f"'{value_type}', expecting type '{expected_type}'",
            desired_parameter.name,
        )


class InvalidParameterValueException(ParameterException):
    """A parameter value was rejected by a callback or by its descriptor (e.g. a range)."""

    def __init__(self, parameter: str, value: Any, reason: str) -> None:
        super().__init__(
            f'Invalid parameter value ({value}) for parameter. Reason: {reason}', parameter
        )


class ParameterImmutableException(ParameterException):
    """A read-only parameter was modified."""

    def __init__(self, parameter_name: str) -> None:
        super().__init__('Attempted to modify read-only parameter', parameter_name)


class ParameterUninitializedException(ParameterException):
    """A statically typed parameter without a value was read."""

    def __init__(self, parameter_name: str) -> None:
        super().__init__(f"The parameter '{parameter_name}' is not initialized", parameter_name)


class ROSInterruptException(Exception):
    """An operation was cancelled because rclpy shut down."""

    def __init__(self) -> None:
        super().__init__('rclpy.shutdown() has been called')
