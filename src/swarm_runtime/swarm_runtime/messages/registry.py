"""The registry that generates, caches and hands out message classes and their converters."""

from __future__ import annotations

import os
import threading
import types
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from rosbags.typesys.store import Typestore

from .cdr_codegen import CdrFunctions, build_cdr_functions
from .codegen import GeneratedMessage, build_converters, build_message_class
from .errors import (
    InterfaceDefinitionError,
    InterfacesNotFoundError,
    UnknownMessageTypeError,
    UnknownPackageError,
)
from .fields import MessageSpec, message_spec, split_typename
from .interface_paths import INTERFACES_PACKAGE, find_interface_msg_dir
from .typestore import jazzy_typestore, load_msg_directory

if TYPE_CHECKING:
    from .cdr import TypeCodec

__all__ = [
    'CHECK_FIELDS_ENV_VAR',
    'MessageModule',
    'MessageRegistry',
    'check_fields_from_environment',
    'default_registry',
    'restore_message',
]

CHECK_FIELDS_ENV_VAR = 'ROS_PYTHON_CHECK_FIELDS'

Converter = Callable[[Any], Any]


def check_fields_from_environment() -> bool:
    """True when ROS_PYTHON_CHECK_FIELDS is '1' (rosidl's test, read at module import)."""
    return os.environ.get(CHECK_FIELDS_ENV_VAR, '') == '1'


class MessageModule(types.ModuleType):
    """Module-like object holding one package's message classes, e.g. ``sensor_msgs.msg``.

    Classes are generated on first attribute access and then cached in the module's namespace.
    """

    def __init__(self, registry: MessageRegistry, package: str, *, check_fields: bool) -> None:
        super().__init__(f'{package}.msg', f'Message classes of {package} (generated).')
        self._registry = registry
        self._package = package
        self._check_fields = check_fields

    @property
    def check_fields(self) -> bool:
        """Default of ``_check_fields`` of new messages of this package."""
        return self._check_fields

    def __getattr__(self, name: str) -> type:
        if name.startswith('_'):
            raise AttributeError(name)
        typename = f'{self._package}/msg/{name}'
        if typename not in self._registry.typestore.fielddefs:
            msg = f"module '{self.__name__}' has no message type '{name}'"
            raise AttributeError(msg)
        cls = self._registry.get_class(typename)
        setattr(self, name, cls)
        return cls

    def __dir__(self) -> list[str]:
        return sorted({*super().__dir__(), *self._registry.type_names(self._package)})


class MessageRegistry:
    """Generates rosidl-like classes from a rosbags typestore and caches them.

    Args:
        typestore: Types to serve. Default: the ROS 2 Jazzy types plus swarm_interfaces,
            located with :func:`find_interface_msg_dir`.
        check_fields: Default of ``_check_fields`` for new messages. Default: read
            ROS_PYTHON_CHECK_FIELDS when a package's module is first created, as rosidl does
            when a generated module is imported.
    """

    def __init__(
        self, typestore: Typestore | None = None, *, check_fields: bool | None = None
    ) -> None:
        # Why swarm_interfaces is unavailable, if it is: raised when it is asked for, so the
        # standard types keep working without it.
        self._interfaces_error: InterfacesNotFoundError | InterfaceDefinitionError | None = None
        if typestore is None:
            typestore = jazzy_typestore()
            try:
                load_msg_directory(typestore, find_interface_msg_dir())
            except (InterfacesNotFoundError, InterfaceDefinitionError) as err:
                self._interfaces_error = err
        self._typestore = typestore
        self._check_fields = check_fields
        self._lock = threading.RLock()
        self._modules: dict[str, MessageModule] = {}
        self._classes: dict[str, type[GeneratedMessage]] = {}
        self._specs: dict[str, MessageSpec] = {}
        self._converters: dict[str, tuple[Converter, Converter]] = {}
        self._cdr: dict[str, CdrFunctions] = {}
        self._codecs: dict[str, TypeCodec] = {}

    @property
    def typestore(self) -> Typestore:
        """The rosbags typestore the classes are generated from."""
        return self._typestore

    def require_interfaces(self) -> None:
        """Raise the reason swarm_interfaces could not be loaded, if it could not."""
        if self._interfaces_error is not None:
            raise self._interfaces_error

    def type_names(self, package: str) -> list[str]:
        """Names of the message types of ``package`` (e.g. ['Bool', 'Header', ...])."""
        prefix = f'{package}/msg/'
        return sorted(t[len(prefix) :] for t in self._typestore.fielddefs if t.startswith(prefix))

    def get_module(self, package: str) -> MessageModule:
        """Return the module-like object of ``package`` (e.g. 'sensor_msgs')."""
        module = self._modules.get(package)
        if module is not None:
            return module
        with self._lock:
            if package not in self._modules:
                if not self.type_names(package):
                    if package == INTERFACES_PACKAGE:
                        self.require_interfaces()
                    msg = f'no message types of package {package!r} are known'
                    raise UnknownPackageError(msg, name=package)
                check = (
                    check_fields_from_environment()
                    if self._check_fields is None
                    else self._check_fields
                )
                self._modules[package] = MessageModule(self, package, check_fields=check)
            return self._modules[package]

    def spec(self, typename: str) -> MessageSpec:
        """Return the :class:`MessageSpec` of a full type name."""
        spec = self._specs.get(typename)
        if spec is None:
            spec = message_spec(self._typestore, typename)
            self._specs[typename] = spec
        return spec

    def get_class(self, typename: str) -> type[GeneratedMessage]:
        """Return the class of 'sensor_msgs/msg/LaserScan' (or 'sensor_msgs/LaserScan')."""
        cls = self._classes.get(typename)
        if cls is not None:
            return cls
        full = normalize_typename(typename)
        with self._lock:
            cls = self._classes.get(full)
            if cls is None:
                cls = self._generate(full)
            self._classes[typename] = cls
            return cls

    def _generate(self, typename: str) -> type[GeneratedMessage]:
        package, _, _ = split_typename(typename)
        if typename not in self._typestore.fielddefs:
            if package == INTERFACES_PACKAGE:
                self.require_interfaces()
            msg = f'unknown message type {typename!r}'
            raise UnknownMessageTypeError(msg)
        module = self.get_module(package)
        spec = self.spec(typename)
        nested = {name: self.get_class(name) for name in spec.nested_types()}
        cls = build_message_class(spec, nested, check_fields=module.check_fields)
        self._classes[typename] = cls
        return cls

    def converters(self, typename: str) -> tuple[Converter, Converter]:
        """Return ``(to_rosbags, from_rosbags)`` for a full type name."""
        pair = self._converters.get(typename)
        if pair is not None:
            return pair
        with self._lock:
            pair = self._converters.get(typename)
            if pair is None:
                spec = self.spec(typename)
                cls = self.get_class(typename)
                nested = {name: self.converters(name) for name in spec.nested_types()}
                pair = build_converters(
                    spec,
                    cls,
                    self._typestore.types[typename],
                    nested,
                    check_fields=self.get_module(spec.package).check_fields,
                )
                self._converters[typename] = pair
            return pair

    def cdr_functions(self, typename: str) -> CdrFunctions:
        """Return the generated CDR encoder and decoder of a full type name."""
        functions = self._cdr.get(typename)
        if functions is not None:
            return functions
        with self._lock:
            functions = self._cdr.get(typename)
            if functions is None:
                functions = build_cdr_functions(
                    self.spec(typename),
                    self.spec,
                    self.get_class,
                    self.cdr_functions,
                    self._package_check_fields,
                )
                self._cdr[typename] = functions
            return functions

    def codec(self, typename: str) -> TypeCodec:
        """Return the :class:`~.cdr.TypeCodec` of a type (one per type and registry)."""
        codec = self._codecs.get(typename)
        if codec is not None:
            return codec
        from .cdr import TypeCodec

        with self._lock:
            codec = self._codecs.get(typename)
            if codec is None:
                codec = TypeCodec(typename, self)
                self._codecs[typename] = codec
            return codec

    def _package_check_fields(self, typename: str) -> bool:
        return self.get_module(split_typename(typename)[0]).check_fields


def normalize_typename(typename: str) -> str:
    """'sensor_msgs/LaserScan' or 'sensor_msgs.msg.LaserScan' -> 'sensor_msgs/msg/LaserScan'."""
    parts = typename.replace('.', '/').split('/')
    if len(parts) == 2 and all(parts):
        return f'{parts[0]}/msg/{parts[1]}'
    if len(parts) == 3 and all(parts):
        return '/'.join(parts)
    msg = f'{typename!r} is not a message type name like "sensor_msgs/msg/LaserScan"'
    raise UnknownMessageTypeError(msg)


_DEFAULT: list[MessageRegistry] = []
_DEFAULT_LOCK = threading.Lock()


def default_registry() -> MessageRegistry:
    """The process-wide registry behind :func:`swarm_runtime.messages.get_message_module`."""
    if not _DEFAULT:
        with _DEFAULT_LOCK:
            if not _DEFAULT:
                _DEFAULT.append(MessageRegistry())
    return _DEFAULT[0]


def restore_message(typename: str, state: dict[str, Any]) -> GeneratedMessage:
    """Rebuild a pickled message (see ``GeneratedMessage.__reduce__``)."""
    cls = default_registry().get_class(typename)
    message = object.__new__(cls)
    for slot, value in state.items():
        setattr(message, slot, value)
    return message
