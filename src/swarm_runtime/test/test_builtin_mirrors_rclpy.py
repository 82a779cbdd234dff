"""The built-in runtime offers rclpy 7.1's API as rclpy spells it, and nothing of its own.

Node code written against the built-in runtime must run unchanged on real rclpy, so every
public name the built-in runtime shares with rclpy has rclpy's signature (parameter names,
kinds, which are required, defaults), every attribute is a property where rclpy's is, and
it adds no public name that rclpy lacks beyond the few listed in :data:`BUILTIN_ONLY`, each
with its reason. Needs the real rclpy (the rclpy leg of the suite).
"""

from __future__ import annotations

import enum
import importlib
import inspect
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import pytest
from swarm_runtime.ros import using_real_rclpy

from swarm_runtime import builtin

pytestmark = pytest.mark.skipif(
    not using_real_rclpy(), reason='needs the real rclpy (SWARM_RUNTIME=rclpy)'
)

#: Public names of the built-in runtime that rclpy does not have, and why they exist.
BUILTIN_ONLY = {
    'errors': "the built-in runtime's own exception for what it does not simulate",
    'clock.STEADY_EPOCH_NS': "the virtual steady clock's start; real clocks need none",
    'clock.SYSTEM_EPOCH_NS': "the virtual system clock's start; real clocks need none",
    'clock_type.ClockChange': 'defined beside ClockType; rclpy.clock exports it as rclpy does',
    'logging.PYTHON_ROOT_LOGGER': 'the Python logger the node loggers write through',
    'publisher.PublisherImpl': 'stands for the _rclpy handle that rclpy passes in',
    'subscription.SubscriptionImpl': 'stands for the _rclpy handle that rclpy passes in',
    'subscription.MessageInfo': 'the type of the dict rclpy hands a two-argument callback',
    'type_hash.TypeHashDictionary': 'the type of the dict TypeHash.to_dict returns',
    'utilities.RMW_IMPLEMENTATION_IDENTIFIER': 'what get_rmw_implementation_identifier says',
}

#: Signatures that differ from rclpy's on purpose: every call the built-in one accepts, rclpy
#: accepts too.
LOOSER_IN_RCLPY = {
    'topic_endpoint_info.TopicEndpointInfo': 'rclpy takes **kwargs of these names; here the '
    'same names, keyword-only and typed',
}


def _mirrored_modules() -> Iterator[tuple[str, ModuleType]]:
    for name in builtin.__all__:
        module = getattr(builtin, name)
        if isinstance(module, ModuleType):
            yield name, module


def _own(module: ModuleType) -> list[str]:
    """The module's public names that the built-in runtime itself defines."""
    names = getattr(module, '__all__', None) or [n for n in vars(module) if not n.startswith('_')]
    own = []
    for name in names:
        value = getattr(module, name)
        if isinstance(value, ModuleType):
            continue
        defined_in = getattr(value, '__module__', module.__name__) or module.__name__
        if defined_in.startswith('swarm_runtime.builtin'):
            own.append(name)
    return own


def _default(value: Any) -> str:
    if value is inspect.Parameter.empty:
        return 'required'
    if inspect.isclass(value):
        return f'class {value.__name__}'
    if isinstance(value, enum.Enum):
        return f'{type(value).__name__}.{value.name}'
    return repr(value)


def _shape(target: Any) -> list[tuple[str, str, str]] | None:
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):  # a builtin without a text signature
        return None
    return [(p.name, p.kind.name, _default(p.default)) for p in signature.parameters.values()]


def _class_members(cls: type) -> Iterator[tuple[str, Any]]:
    """Public attributes that a built-in runtime class defines itself (not those of int,
    Enum or object)."""
    for klass in cls.__mro__:
        if not klass.__module__.startswith('swarm_runtime.builtin'):
            continue
        for name, value in vars(klass).items():
            if not name.startswith('_'):
                yield name, value


def _differences() -> tuple[list[str], list[str]]:
    extra: list[str] = []
    mismatched: list[str] = []

    def compare(label: str, ours: Any, real: Any) -> None:
        if label in LOOSER_IN_RCLPY:
            return
        shape_ours, shape_real = _shape(ours), _shape(real)
        if shape_ours is not None and shape_real is not None and shape_ours != shape_real:
            mismatched.append(f'{label}: {shape_ours} != rclpy {shape_real}')

    for name in builtin.__all__:
        value = getattr(builtin, name)
        if not isinstance(value, ModuleType):
            compare(name, value, getattr(importlib.import_module('rclpy'), name))
    for module_name, module in _mirrored_modules():
        try:
            real_module = importlib.import_module(f'rclpy.{module_name}')
        except ImportError:
            extra.append(module_name)
            continue
        for name in _own(module):
            label = f'{module_name}.{name}'
            ours = getattr(module, name)
            if not hasattr(real_module, name):
                extra.append(label)
                continue
            real = getattr(real_module, name)
            compare(label, ours, real)
            if not inspect.isclass(ours):
                continue
            seen = set()
            for member, value in _class_members(ours):
                if member in seen:
                    continue
                seen.add(member)
                member_label = f'{label}.{member}'
                if not hasattr(real, member):
                    extra.append(member_label)
                    continue
                real_value = inspect.getattr_static(real, member)
                if isinstance(value, property) != isinstance(real_value, property):
                    mismatched.append(f'{member_label}: a property in only one of the two')
                elif callable(value) or isinstance(value, (staticmethod, classmethod)):
                    compare(member_label, getattr(ours, member), getattr(real, member))
    return extra, mismatched


def test_every_shared_name_has_rclpys_signature_and_no_name_is_invented() -> None:
    extra, mismatched = _differences()
    assert mismatched == []
    assert sorted(set(extra) - set(BUILTIN_ONLY)) == []


def test_the_lists_of_departures_name_only_what_exists() -> None:
    extra, _ = _differences()
    assert sorted(set(BUILTIN_ONLY) - set(extra)) == [], 'now in rclpy, or gone: drop it'
    for label in LOOSER_IN_RCLPY:
        module_name, name = label.split('.')
        assert hasattr(getattr(builtin, module_name), name)
