"""The parameter API of :class:`~.node.Node`, as in rclpy 7.1 (Jazzy).

Declaration, reading, setting, descriptors (type, read-only, ranges and steps) and the
pre/on/post-set callbacks, with rclpy's exceptions and exact ``SetParametersResult`` reasons.
Kept apart from the node's communication code so that each reads on its own.

:class:`NodeParameters` is a mixin: the node owns the state it works on (``_parameters``,
``_descriptors``, ``_parameter_overrides``, the callback lists, ``_allow_undeclared_parameters``)
and provides ``_check_alive()``, ``_clock``, ``_fully_qualified_name`` and
``_parameter_event_publisher``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from ._messages import interface_module
from .exceptions import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterImmutableException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from .parameter import PARAMETER_SEPARATOR_STRING, Parameter
from .validate_parameter_name import validate_parameter_name

if TYPE_CHECKING:
    from .clock import ROSClock
    from .publisher import Publisher

__all__ = ['NodeParameters']


def _rcl_interfaces() -> Any:
    return interface_module('rcl_interfaces')


class NodeParameters:
    """Parameter methods of a node (mixed into :class:`~.node.Node`)."""

    #: Relative tolerance when comparing floating-point parameter values with ranges.
    PARAM_REL_TOL = 1e-6

    _parameters: dict[str, Parameter]
    _descriptors: dict[str, Any]
    _parameter_overrides: dict[str, Parameter]
    _pre_set_parameters_callbacks: list[Callable[[list[Parameter]], list[Parameter]]]
    _on_set_parameters_callbacks: list[Callable[[list[Parameter]], Any]]
    _post_set_parameters_callbacks: list[Callable[[list[Parameter]], None]]
    _allow_undeclared_parameters: bool
    _parameter_event_publisher: Publisher | None
    _clock: ROSClock
    _fully_qualified_name: str
    _check_alive: Callable[[], None]

    # Parameters: declaration

    def declare_parameter(
        self,
        name: str,
        value: Any = None,
        descriptor: Any = None,
        ignore_override: bool = False,
    ) -> Parameter:
        """Declare a parameter; an override (``-p``, params file, parameter_overrides) wins.

        The type is inferred from ``value`` unless ``descriptor.dynamic_typing``.

        Raises:
            ParameterAlreadyDeclaredException: declared before.
            InvalidParameterTypeException: the override has another type than the default.
            InvalidParameterValueException: a callback or the descriptor (range) rejected it.
        """
        if value is None and descriptor is None:
            spec: tuple[Any, ...] = (name,)
        else:
            descriptor = (
                _rcl_interfaces().ParameterDescriptor() if descriptor is None else descriptor
            )
            spec = (name, value, descriptor)
        return self.declare_parameters('', [spec], ignore_override)[0]

    def declare_parameters(
        self,
        namespace: str,
        parameters: Sequence[tuple[Any, ...]],
        ignore_override: bool = False,
    ) -> list[Parameter]:
        """Declare ``namespace.name`` for each ``(name[, value_or_type[, descriptor]])``.

        Raises:
            TypeError: a malformed tuple.
            ValueError: a statically typed parameter without a usable type.
            ParameterAlreadyDeclaredException, InvalidParameterTypeException,
            InvalidParameterValueException: as :meth:`declare_parameter`.
        """
        self._check_alive()
        descriptor_class = _rcl_interfaces().ParameterDescriptor
        to_declare: list[Parameter] = []
        descriptors: dict[str, Any] = {}
        for index, spec in enumerate(parameters):
            if not 1 <= len(spec) <= 3:
                msg = (
                    f'Invalid parameter tuple length at index {index} in parameters list: '
                    f'{spec}; expecting length between 1 and 3'
                )
                raise TypeError(msg)
            name = spec[0]
            if not isinstance(name, str):
                msg = f'First element {name} at index {index} in parameters list is not a str.'
                raise TypeError(msg)
            if namespace:
                name = f'{namespace}{PARAMETER_SEPARATOR_STRING}{name}'
            validate_parameter_name(name)
            second = spec[1] if len(spec) > 1 else None
            descriptor = spec[2] if len(spec) > 2 else descriptor_class()
            if not isinstance(descriptor, descriptor_class):
                msg = (
                    f'Third element {descriptor} at index {index} in parameters list '
                    'is not a ParameterDescriptor.'
                )
                raise TypeError(msg)
            if len(spec) == 1:
                warnings.warn(
                    f"when declaring parameter named '{name}', declaring a parameter only "
                    'providing its name is deprecated. You have to either:\n'
                    '\t- Pass a name and a default value different to "PARAMETER NOT SET" '
                    '(and optionally a descriptor).\n'
                    '\t- Pass a name and a parameter type.\n'
                    '\t- Pass a name and a descriptor with `dynamic_typing=True',
                    stacklevel=3,
                )
                descriptor.dynamic_typing = True
            value = None
            if isinstance(second, Parameter.Type):
                if second is Parameter.Type.NOT_SET:
                    msg = f'Cannot declare parameter {{{name}}} as statically typed of type NOT_SET'
                    raise ValueError(msg)
                if descriptor.dynamic_typing:
                    msg = (
                        f'When declaring parameter {{{name}}} passing a descriptor with'
                        '`dynamic_typing=True` is not allowed when the parameter type is provided'
                    )
                    raise ValueError(msg)
                descriptor.type = second.value
            else:
                value = second
                if not descriptor.dynamic_typing:
                    descriptor.type = Parameter.Type.from_parameter_value(value).value
                    if descriptor.type == Parameter.Type.NOT_SET.value:
                        raise ValueError(
                            'Cannot declare a statically typed parameter with default value '
                            'of type PARAMETER_NOT_SET'
                        )
            if not ignore_override and name in self._parameter_overrides:
                value = self._parameter_overrides[name].value
            to_declare.append(Parameter(name, value=value))
            descriptors[name] = descriptor
        already = [p.name for p in to_declare if p.name in self._parameters]
        if already:
            raise ParameterAlreadyDeclaredException(already)
        for parameter in to_declare:
            result = self._set_parameters_atomically_common(
                [parameter], descriptors, allow_not_set_type=True
            )
            if not result.successful:
                if result.reason.startswith('Wrong parameter type'):
                    expected = Parameter.Type(descriptors[parameter.name].type).name
                    raise InvalidParameterTypeException(parameter, expected)
                raise InvalidParameterValueException(parameter.name, parameter.value, result.reason)
        return [self._parameters[p.name] for p in to_declare]

    def undeclare_parameter(self, name: str) -> None:
        """Undeclare a parameter.

        Raises:
            ParameterNotDeclaredException: not declared.
            ParameterImmutableException: it is read-only.
        """
        if not self.has_parameter(name):
            raise ParameterNotDeclaredException(name)
        if self._descriptors[name].read_only:
            raise ParameterImmutableException(name)
        del self._parameters[name]
        del self._descriptors[name]

    def has_parameter(self, name: str) -> bool:
        """True if the parameter is declared."""
        return name in self._parameters

    # Parameters: reading

    def get_parameter(self, name: str) -> Parameter:
        """Return a declared parameter.

        Raises:
            ParameterNotDeclaredException: not declared (and undeclared ones not allowed).
            ParameterUninitializedException: statically typed and never given a value.
        """
        if name in self._parameters:
            parameter = self._parameters[name]
            if (
                parameter.type_ is not Parameter.Type.NOT_SET
                or self._descriptors[name].dynamic_typing
            ):
                return parameter
            raise ParameterUninitializedException(name)
        if self._allow_undeclared_parameters:
            return Parameter(name, Parameter.Type.NOT_SET, None)
        raise ParameterNotDeclaredException(name)

    def get_parameters(self, names: list[str]) -> list[Parameter]:
        """Return several parameters (see :meth:`get_parameter`)."""
        if not all(isinstance(name, str) for name in names):
            raise TypeError('All names must be instances of type str')
        return [self.get_parameter(name) for name in names]

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        """Return the parameter, or ``alternative_value`` if undeclared or unset."""
        if alternative_value is None:
            alternative_value = Parameter(name, Parameter.Type.NOT_SET)
        parameter = self._parameters.get(name)
        if parameter is None or parameter.type_ is Parameter.Type.NOT_SET:
            return alternative_value
        return parameter

    def get_parameter_type(self, name: str) -> Any:
        """Return the type of a parameter (its number, like rclpy; NOT_SET if undeclared)."""
        if name in self._parameters:
            return self._parameters[name].type_.value
        if self._allow_undeclared_parameters:
            return Parameter.Type.NOT_SET
        raise ParameterNotDeclaredException(name)

    def get_parameter_types(self, names: list[str]) -> list[Any]:
        """Return the types of several parameters."""
        if not all(isinstance(name, str) for name in names):
            raise TypeError('All names must be instances of type str')
        return [self.get_parameter_type(name) for name in names]

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        """Return ``{name without 'prefix.': parameter}`` for parameters under ``prefix``."""
        if prefix:
            prefix += PARAMETER_SEPARATOR_STRING
        return {
            name[len(prefix) :]: parameter
            for name, parameter in self._parameters.items()
            if name.startswith(prefix)
        }

    def describe_parameter(self, name: str) -> Any:
        """Return the ParameterDescriptor of a parameter.

        Raises:
            ParameterNotDeclaredException: not declared (and undeclared ones not allowed).
        """
        if name in self._descriptors:
            return self._descriptors[name]
        if self._allow_undeclared_parameters:
            return _rcl_interfaces().ParameterDescriptor()
        raise ParameterNotDeclaredException(name)

    def describe_parameters(self, names: list[str]) -> list[Any]:
        """Return the descriptors of several parameters."""
        return [self.describe_parameter(name) for name in names]

    def list_parameters(self, prefixes: list[str], depth: int) -> Any:
        """Return a ListParametersResult of the names (and prefixes) under ``prefixes``.

        ``depth`` 0 means unlimited; otherwise names with at most ``depth`` dots below a
        prefix.
        """
        if not isinstance(prefixes, list):
            raise TypeError('The prefixes argument must be a list')
        if not all(isinstance(prefix, str) for prefix in prefixes):
            raise TypeError('All prefixes must be instances of type str')
        if not isinstance(depth, int):
            raise TypeError('The depth must be instance of type int')
        if depth < 0:
            raise ValueError('The depth must be greater than or equal to zero')
        result = _rcl_interfaces().ListParametersResult()
        separator = PARAMETER_SEPARATOR_STRING

        def shallow(name: str) -> bool:
            return depth == 0 or name.count(separator) < depth

        names: list[str] = []
        result_prefixes: list[str] = []
        for name in self._parameters:
            if prefixes:
                selected = any(
                    name == prefix
                    or (name.startswith(prefix + separator) and shallow(name[len(prefix) + 1 :]))
                    for prefix in prefixes
                )
            else:
                selected = shallow(name)
            if not selected:
                continue
            names.append(name)
            if separator in name:
                prefix = name.rsplit(separator, 1)[0]
                if prefix not in result_prefixes:
                    result_prefixes.append(prefix)
        result.names = names
        result.prefixes = result_prefixes
        return result

    # Parameters: setting

    def set_parameters(self, parameter_list: list[Parameter]) -> list[Any]:
        """Set parameters one at a time; return one SetParametersResult each.

        A wrong type or a rejected value gives ``successful=False`` with a reason, not an
        exception.

        Raises:
            ParameterNotDeclaredException: a parameter is undeclared (and that is not allowed).
        """
        return [self._set_parameters_atomically([parameter]) for parameter in parameter_list]

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        """Set all parameters or none; return one aggregate SetParametersResult."""
        return self._set_parameters_atomically(parameter_list)

    def _set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        if self._pre_set_parameters_callbacks:
            modified: list[Parameter] = []
            for callback in self._pre_set_parameters_callbacks:
                modified.extend(callback(parameter_list))
            parameter_list = modified
            if not parameter_list:
                return _rcl_interfaces().SetParametersResult(
                    successful=False,
                    reason='parameter list cannot be empty, this might be due to '
                    'pre_set_parameters_callback modifying the original parameters list.',
                )
        if not all(isinstance(parameter, Parameter) for parameter in parameter_list):
            msg = f"parameter must be instance of type '{Parameter!r}'"
            raise TypeError(msg)
        undeclared = [p.name for p in parameter_list if p.name not in self._parameters]
        if undeclared and not self._allow_undeclared_parameters:
            raise ParameterNotDeclaredException(undeclared)
        return self._set_parameters_atomically_common(parameter_list)

    def _set_parameters_atomically_common(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, Any] | None = None,
        allow_not_set_type: bool = False,
    ) -> Any:
        set_result_class = _rcl_interfaces().SetParametersResult
        if descriptors is not None:
            result = self._apply_descriptors(parameter_list, descriptors, check_read_only=False)
        else:
            result = self._apply_descriptors(parameter_list, self._descriptors)
        if not result.successful:
            return result
        for callback in self._on_set_parameters_callbacks:
            result = callback(parameter_list)
            if not isinstance(result, set_result_class):
                warnings.warn(
                    'Callback returned an invalid type, it should return SetParameterResult.',
                    stacklevel=2,
                )
                return set_result_class(
                    successful=False, reason='Callback returned an invalid type'
                )
            if not result.successful:
                return result
        new: list[Parameter] = []
        changed: list[Parameter] = []
        deleted: list[Parameter] = []
        for parameter in parameter_list:
            name = parameter.name
            if not allow_not_set_type and parameter.type_ is Parameter.Type.NOT_SET:
                deleted.append(parameter)
                self._parameters.pop(name, None)
                self._descriptors.pop(name, None)
                continue
            if descriptors is not None:
                self._descriptors[name] = descriptors[name]
            elif name not in self._descriptors:
                self._descriptors[name] = _rcl_interfaces().ParameterDescriptor(dynamic_typing=True)
            if self.get_parameter_or(name).type_ is Parameter.Type.NOT_SET:
                new.append(parameter)
            else:
                changed.append(parameter)
            self._parameters[name] = parameter
        self._publish_parameter_event(new, changed, deleted)
        for callback in self._post_set_parameters_callbacks:
            callback(parameter_list)
        return set_result_class(successful=True)

    def _publish_parameter_event(
        self, new: list[Parameter], changed: list[Parameter], deleted: list[Parameter]
    ) -> None:
        """Publish on /parameter_events, if anyone listens (building it costs)."""
        publisher = self._parameter_event_publisher
        if publisher is None or not publisher._connected:
            return
        event = _rcl_interfaces().ParameterEvent(
            stamp=self._clock.now().to_msg(),
            node=self._fully_qualified_name,
            new_parameters=[p.to_parameter_msg() for p in new],
            changed_parameters=[p.to_parameter_msg() for p in changed],
            deleted_parameters=[p.to_parameter_msg() for p in deleted],
        )
        publisher.publish(event)

    def _apply_descriptors(
        self,
        parameter_list: list[Parameter],
        descriptors: dict[str, Any],
        check_read_only: bool = True,
    ) -> Any:
        for parameter in parameter_list:
            if parameter.name in descriptors:
                result = self._apply_descriptor(
                    parameter, descriptors[parameter.name], check_read_only
                )
                if not result.successful:
                    return result
        return _rcl_interfaces().SetParametersResult(successful=True)

    def _apply_descriptor(
        self, parameter: Parameter, descriptor: Any = None, check_read_only: bool = True
    ) -> Any:
        """Check a parameter against a descriptor: read-only, type, range and step."""
        result_class = _rcl_interfaces().SetParametersResult
        if descriptor is None:
            descriptor = self.describe_parameter(parameter.name)
        else:
            descriptor.name = parameter.name
        if check_read_only and descriptor.read_only:
            return result_class(
                successful=False,
                reason=f'Trying to set a read-only parameter: {parameter.name}.',
            )
        if descriptor.dynamic_typing:
            descriptor.type = parameter.type_.value
        elif self.has_parameter(parameter.name) and parameter.type_ is Parameter.Type.NOT_SET:
            return result_class(successful=False, reason='Static parameter cannot be undeclared')
        elif (
            parameter.type_ is not Parameter.Type.NOT_SET
            and parameter.type_.value != descriptor.type
        ):
            return result_class(
                successful=False,
                reason=(
                    f"Wrong parameter type, expected '{Parameter.Type(descriptor.type)}'"
                    f" got '{parameter.type_}'"
                ),
            )
        if parameter.type_ is Parameter.Type.INTEGER and descriptor.integer_range:
            return self._apply_integer_range(parameter, descriptor.integer_range[0])
        if parameter.type_ is Parameter.Type.DOUBLE and descriptor.floating_point_range:
            return self._apply_floating_point_range(parameter, descriptor.floating_point_range[0])
        return result_class(successful=True)

    def _apply_integer_range(self, parameter: Parameter, integer_range: Any) -> Any:
        result_class = _rcl_interfaces().SetParametersResult
        low = min(integer_range.from_value, integer_range.to_value)
        high = max(integer_range.from_value, integer_range.to_value)
        value = parameter.value
        if value in (low, high):
            return result_class(successful=True)
        if not low < value < high:
            return result_class(
                successful=False,
                reason=f'Parameter {parameter.name} out of range. '
                f'Min: {low}, Max: {high}, value: {value}',
            )
        step = integer_range.step
        if step != 0 and (value - low) % step != 0:
            return result_class(
                successful=False,
                reason=f'The parameter value for {parameter.name} is not a valid step. '
                f'Min: {low}, max: {high}, value: {value}, step: {step}',
            )
        return result_class(successful=True)

    def _apply_floating_point_range(self, parameter: Parameter, floating_range: Any) -> Any:
        result_class = _rcl_interfaces().SetParametersResult
        low = min(floating_range.from_value, floating_range.to_value)
        high = max(floating_range.from_value, floating_range.to_value)
        value = parameter.value
        tolerance = self.PARAM_REL_TOL
        if math.isclose(value, low, rel_tol=tolerance) or math.isclose(
            value, high, rel_tol=tolerance
        ):
            return result_class(successful=True)
        if not low < value < high:
            return result_class(
                successful=False,
                reason=f'Parameter {parameter.name} out of range '
                f'Min: {low}, Max: {high}, value: {value}',
            )
        step = floating_range.step
        if step != 0.0:
            steps = round((value - low) / step)
            if not math.isclose(low + steps * step, value, rel_tol=tolerance):
                return result_class(
                    successful=False,
                    reason=f'The parameter value for {parameter.name} is not close enough to a '
                    f'valid step. Min: {low}, max: {high}, value: {value}, step: {step}',
                )
        return result_class(successful=True)

    def set_descriptor(self, name: str, descriptor: Any, alternative_value: Any = None) -> Any:
        """Replace a parameter's descriptor; return its (possibly replaced) ParameterValue.

        Raises:
            ParameterNotDeclaredException: not declared.
            ParameterImmutableException: read-only.
            InvalidParameterValueException: neither value complies with the new descriptor.
        """
        if not self.has_parameter(name):
            if not self._allow_undeclared_parameters:
                raise ParameterNotDeclaredException(name)
            return self.get_parameter(name).get_parameter_value()
        if self.describe_parameter(name).read_only:
            raise ParameterImmutableException(name)
        current = self.get_parameter(name)
        if alternative_value is None:
            alternative = current
        else:
            message = _rcl_interfaces().Parameter(name=name, value=alternative_value)
            alternative = Parameter.from_parameter_msg(message)
        if not self._apply_descriptor(current, descriptor, False).successful:
            result = self._apply_descriptor(alternative, descriptor, False)
            if not result.successful:
                raise InvalidParameterValueException(name, alternative.value, result.reason)
            self._parameters[name] = alternative
        self._descriptors[name] = descriptor
        return self.get_parameter(name).get_parameter_value()

    # Parameters: callbacks

    def add_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Call ``callback(parameters) -> parameters`` before validation when setting."""
        self._pre_set_parameters_callbacks.insert(0, callback)

    def add_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        """Call ``callback(parameters) -> SetParametersResult`` to accept or reject values.

        Raises:
            TypeError: ``callback`` is not callable.
        """
        if not callable(callback):
            msg = f'Callback must be callable, got {type(callback)}'
            raise TypeError(msg)
        self._on_set_parameters_callbacks.insert(0, callback)

    def add_post_set_parameters_callback(self, callback: Callable[[list[Parameter]], None]) -> None:
        """Call ``callback(parameters)`` after parameters were set or declared."""
        self._post_set_parameters_callbacks.insert(0, callback)

    def remove_pre_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], list[Parameter]]
    ) -> None:
        """Remove a pre-set callback (ValueError if absent)."""
        self._pre_set_parameters_callbacks.remove(callback)

    def remove_on_set_parameters_callback(self, callback: Callable[[list[Parameter]], Any]) -> None:
        """Remove an on-set callback (ValueError if absent)."""
        self._on_set_parameters_callbacks.remove(callback)

    def remove_post_set_parameters_callback(
        self, callback: Callable[[list[Parameter]], None]
    ) -> None:
        """Remove a post-set callback (ValueError if absent)."""
        self._post_set_parameters_callbacks.remove(callback)
