"""Node parameters declared once, on the fields of a frozen configuration dataclass (ROS-free).

A field becomes a node parameter when it carries :func:`parameter` metadata: its default is
the dataclass default (never written anywhere else), and the metadata adds the description,
the unit, the allowed range or choices and whether a running node accepts a new value. A
nested configuration is a :func:`section`; its parameters are named ``<section>.<field>``
(``phases.goal_progress_window_s``) or, with an explicit ``prefix``, ``<prefix><field>``
(``prefix=''`` puts them at the top level). Fields without metadata are not parameters (the
code that builds the configuration sets them, or they keep their default)::

    @dataclass(frozen=True)
    class DriveConfig:
        speed_mps: float = parameter(0.3, 'cruise speed', unit='m/s', gt=0.0)
        heading_bias_rad: float = parameter(0.0, 'bias of the fan', degrees=True)
        mode: Mode = parameter(Mode.FAST, 'how to drive', read_only=False)

    SPEC = ParameterSpec(DriveConfig)
    SPEC.defaults()                 # {'speed_mps': 0.3, 'heading_bias_deg': 0.0, 'mode': 'fast'}
    SPEC.build({'speed_mps': 0.5})  # DriveConfig(speed_mps=0.5, ...), validated

:class:`ParameterSpec` walks the dataclass once and provides what every node and tool needs:
the flat parameter list with types, the conversion between configurations and parameter
values (flattening and unflattening), type, range and choice checks with precise errors, the
parsing of ``NAME=VALUE`` text, and the rendering of a ROS 2 parameter file and of a markdown
table. ``swarm_runtime.parameters`` declares a spec on a node.

Parameter types follow the field's annotation: ``bool``, ``int``, ``float``, ``str``, an
``Enum`` whose values are strings (a string parameter with those choices), a ``Literal`` of
strings (the same), ``tuple[float, ...]``/``tuple[int, ...]``/``tuple[str, ...]`` (arrays;
``tuple[float, float]`` fixes the length) and ``frozenset[str]``. An optional field
(``float | None``) needs a parameter value that stands for None (``none=``; NaN for floats
unless given), because ROS parameters have no null.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
import types
import typing
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import MISSING, dataclass
from enum import Enum
from typing import Any

import yaml

from swarm_common.errors import SwarmError

__all__ = [
    'ParameterDef',
    'ParameterError',
    'ParameterInfo',
    'ParameterSpec',
    'SpecError',
    'kind_of_value',
    'parameter',
    'render_value',
    'section',
]

_PARAMETER_KEY = 'swarm_common.params.parameter'
_SECTION_KEY = 'swarm_common.params.section'
_NO_NONE = object()

#: Parameter value types: scalars and arrays of scalars, as in rcl_interfaces/ParameterType.
KINDS = ('bool', 'int', 'float', 'str', 'bool[]', 'int[]', 'float[]', 'str[]')
_KIND_WORDS = {
    'bool': 'true or false',
    'int': 'an integer',
    'float': 'a floating-point number',
    'str': 'a string',
    'bool[]': 'a list of true/false',
    'int[]': 'a list of integers',
    'float[]': 'a list of floating-point numbers',
    'str[]': 'a list of strings',
}
_SCALAR_TYPES: dict[str, type] = {'bool': bool, 'int': int, 'float': float, 'str': str}


class SpecError(TypeError):
    """A configuration dataclass cannot be read as a parameter spec (a programming error)."""


class ParameterError(SwarmError, ValueError):
    """A parameter name is unknown, or a value is of the wrong type, out of range or not a choice.

    Attributes:
        name: the parameter's name ('' when the problem concerns no single parameter).
        problem: what is wrong, without the name.
        unknown: True when the name is not a parameter at all.
        suggestions: for an unknown name, declared names close to it (best first).
    """

    def __init__(
        self, name: str, problem: str, *, unknown: bool = False, suggestions: Sequence[str] = ()
    ) -> None:
        if unknown:
            hint = f' (did you mean {", ".join(suggestions)}?)' if suggestions else ''
            message = f'unknown parameter {name!r}{hint}'
        else:
            message = f'parameter {name}: {problem}' if name else problem
        super().__init__(message)
        self.name = name
        self.problem = problem
        self.unknown = unknown
        self.suggestions = tuple(suggestions)


@dataclass(frozen=True)
class ParameterInfo:
    """What :func:`parameter` records on a field besides its default.

    Attributes:
        description: one or two sentences for ``ros2 param describe``, the YAML file and
            the docs (without the unit).
        unit: the unit of the parameter value ('' for none); shown as ``[unit]``.
        ge, gt, le, lt: bounds of the parameter value (>=, >, <=, <); None for none.
        choices: the allowed strings of a string parameter (filled in from an Enum or a
            Literal annotation when not given).
        read_only: True when a running node rejects a new value (the value is only read at
            start); False when the node applies a change.
        degrees: the field holds radians (its name ends in ``_rad``) and the parameter is in
            degrees, named with ``_deg``.
        none: the parameter value that stands for a None field value (optional fields).
        finite: float values must be finite (besides the ``none`` value).
        name: the parameter's full name, instead of the section prefix and the field name
            (kept for names that users' parameter files already use).
    """

    description: str
    unit: str = ''
    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None
    choices: tuple[str, ...] = ()
    read_only: bool = True
    degrees: bool = False
    none: Any = _NO_NONE
    finite: bool = True
    name: str = ''


def parameter(
    default: Any = MISSING,
    description: str = '',
    *,
    default_factory: Any = MISSING,
    unit: str = '',
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    choices: Sequence[str] = (),
    read_only: bool = True,
    degrees: bool = False,
    none: Any = _NO_NONE,
    finite: bool = True,
    name: str = '',
) -> Any:
    """A dataclass field that is a node parameter (see :class:`ParameterInfo`).

    ``default`` (or ``default_factory``) is the field's default, as for
    :func:`dataclasses.field`; the parameter's default is derived from it.
    """
    if not description.strip():
        raise SpecError('a parameter needs a description')
    info = ParameterInfo(
        description=' '.join(description.split()),
        unit=unit,
        ge=ge,
        gt=gt,
        le=le,
        lt=lt,
        choices=tuple(choices),
        read_only=read_only,
        degrees=degrees,
        none=none,
        finite=finite,
        name=name,
    )
    metadata = {_PARAMETER_KEY: info}
    if default_factory is not MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def section(default_factory: Any, *, prefix: str | None = None) -> Any:
    """A nested configuration whose parameters are ``<field>.<name>`` (or ``<prefix><name>``)."""
    return dataclasses.field(default_factory=default_factory, metadata={_SECTION_KEY: prefix})


# ------------------------------------------------------------------------------ values


def render_value(value: Any) -> str:
    """A parameter value as YAML text that rcl and PyYAML both read back as the same value."""
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return '.nan'
        if math.isinf(value):
            return '.inf' if value > 0 else '-.inf'
        text = repr(value)
        if 'e' in text and '.' not in text.split('e')[0]:
            mantissa, exponent = text.split('e')
            text = f'{mantissa}.0e{exponent}'
        return text
    if isinstance(value, str):
        return _render_string(value)
    if isinstance(value, list | tuple):
        return '[' + ', '.join(render_value(item) for item in value) + ']'
    raise SpecError(f'no YAML rendering for {value!r}')


_PLAIN_STRING = re.compile(r'[A-Za-z_/][A-Za-z0-9_./-]*')
_RCL_WORDS = frozenset(
    {'y', 'n', 'yes', 'no', 'true', 'false', 'on', 'off', 'null', 'nan', 'inf', 'infinity'}
)


def _render_string(text: str) -> str:
    plain = (
        _PLAIN_STRING.fullmatch(text)
        and text.lower() not in _RCL_WORDS
        and yaml.safe_load(text) == text
    )
    if plain:
        return text
    return "'" + text.replace("'", "''") + "'"


def kind_of_value(value: Any) -> str:
    """The parameter kind of a Python value ('bool', 'int', 'float', 'str', 'int[]', ...), or
    its type's name for anything else."""
    if isinstance(value, bool):
        return 'bool'
    if isinstance(value, int):
        return 'int'
    if isinstance(value, float):
        return 'float'
    if isinstance(value, str):
        return 'str'
    if isinstance(value, list | tuple):
        kinds = {kind_of_value(item) for item in value}
        if len(kinds) == 1:
            return kinds.pop() + '[]'
        return 'list'
    return type(value).__name__


def _describe_value(value: Any) -> str:
    kind = kind_of_value(value)
    words = {
        'bool': 'a boolean',
        'int': 'an integer',
        'float': 'a floating-point number',
        'str': 'a string',
    }
    return f'{words.get(kind, kind)} {value!r}' if kind in words else f'{value!r}'


# ------------------------------------------------------------------------------ one parameter


@dataclass(frozen=True)
class ParameterDef:
    """One parameter of a spec.

    Attributes:
        name: the parameter's name (dotted or prefixed for nested fields).
        path: field names from the root configuration to the field.
        kind: the parameter type, one of :data:`KINDS`.
        info: the field's :class:`ParameterInfo`.
        default: the default as a parameter value (from the root configuration's default).
        enum: the field's Enum type, if any.
        optional: the field may be None (carried as ``info.none``).
        length: the fixed length of a tuple field (None: any length).
        frozen: the field is a frozenset (an array parameter, sorted).
    """

    name: str
    path: tuple[str, ...]
    kind: str
    info: ParameterInfo
    default: Any
    enum: type[Enum] | None = None
    optional: bool = False
    length: int | None = None
    frozen: bool = False

    @property
    def read_only(self) -> bool:
        """True when a running node does not accept a new value."""
        return self.info.read_only

    @property
    def choices(self) -> tuple[str, ...]:
        """Allowed values of a string parameter (empty: any string)."""
        return self.info.choices

    @property
    def bounds_text(self) -> str:
        """The range as text, e.g. ``> 0``, ``0 .. 1`` or ``[0, 1)`` ('' without bounds)."""
        info = self.info
        low = info.ge if info.ge is not None else info.gt
        high = info.le if info.le is not None else info.lt
        if low is None and high is None:
            return ''
        if high is None:
            return f'{">=" if info.ge is not None else ">"} {_num(low)}'
        if low is None:
            return f'{"<=" if info.le is not None else "<"} {_num(high)}'
        opening = '[' if info.ge is not None else '('
        closing = ']' if info.le is not None else ')'
        return f'{opening}{_num(low)}, {_num(high)}{closing}'

    @property
    def constraints_text(self) -> str:
        """Range and choices in words (the descriptor's ``additional_constraints``)."""
        parts = []
        if self.choices:
            parts.append('one of ' + ', '.join(self.choices))
        if self.bounds_text:
            parts.append(f'range {self.bounds_text}')
        if self.optional:
            parts.append(f'{render_value(self.info.none)}: unset')
        return '; '.join(parts)

    @property
    def description_text(self) -> str:
        """The description with its unit, as declared on the node."""
        unit = f' [{self.info.unit}]' if self.info.unit else ''
        return f'{self.info.description}{unit}'

    # Conversions ------------------------------------------------------------------

    def to_parameter(self, value: Any) -> Any:
        """The parameter value of a field value."""
        if value is None:
            if not self.optional:
                raise SpecError(f'{self.name}: None in a field that is not optional')
            return self.info.none
        if self.enum is not None:
            return value.value
        if self.kind.endswith('[]'):
            items = sorted(value) if isinstance(value, frozenset | set) else list(value)
            return [self._scalar_to_parameter(item) for item in items]
        return self._scalar_to_parameter(value)

    def _scalar_to_parameter(self, value: Any) -> Any:
        if self.info.degrees:
            return math.degrees(value)
        if isinstance(value, float) and self.kind in ('int', 'int[]'):
            return int(value)
        if isinstance(value, int) and not isinstance(value, bool) and self.kind.startswith('float'):
            return float(value)
        return value

    def check(self, value: Any, *, strict: bool = False, error: type[ParameterError]) -> Any:
        """Validate a parameter value; return the field value it stands for.

        ``strict`` refuses an integer for a float parameter, as ROS does; otherwise it is
        taken as the float.

        Raises:
            ``error`` (a :class:`ParameterError`): wrong type, out of range, not a choice.
        """
        if self.optional and _same(value, self.info.none):
            return None
        if self.kind.endswith('[]'):
            if not isinstance(value, list | tuple):
                raise error(self.name, f'expected {_KIND_WORDS[self.kind]}, got {value!r}')
            if self.length is not None and len(value) != self.length:
                msg = f'expected {self.length} values, got {len(value)}: {list(value)!r}'
                raise error(self.name, msg)
            items = [self._check_scalar(item, strict, error, value) for item in value]
            return frozenset(items) if self.frozen else tuple(items)
        value = self._check_scalar(value, strict, error, None)
        if self.enum is not None:
            return self.enum(value)
        return value

    def _check_scalar(
        self, value: Any, strict: bool, error: type[ParameterError], whole: Any
    ) -> Any:
        kind = self.kind.removesuffix('[]')
        shown = value if whole is None else whole
        wanted = _KIND_WORDS[self.kind]
        if kind == 'float' and isinstance(value, int) and not isinstance(value, bool):
            if strict:
                msg = f'expected {wanted}, got the integer {value} (write {value}.0)'
                raise error(self.name, msg)
            value = float(value)
        if kind == 'bool' and not isinstance(value, bool):
            raise error(self.name, f'expected {wanted}, got {_describe_value(shown)}')
        if kind == 'int' and (not isinstance(value, int) or isinstance(value, bool)):
            raise error(self.name, f'expected {wanted}, got {_describe_value(shown)}')
        if kind == 'float' and not isinstance(value, float):
            raise error(self.name, f'expected {wanted}, got {_describe_value(shown)}')
        if kind == 'str' and not isinstance(value, str):
            raise error(self.name, f'expected {wanted}, got {_describe_value(shown)}')
        if kind == 'str' and self.choices:
            text = value.strip().lower() if self.enum is not None else value
            if text not in self.choices:
                close = difflib.get_close_matches(text, self.choices, n=1)
                hint = f' (did you mean {close[0]}?)' if close else ''
                msg = f'{value!r} is not one of {", ".join(self.choices)}{hint}'
                raise error(self.name, msg)
            value = text
        if kind in ('int', 'float'):
            self._check_number(value, error)
            if self.info.degrees:
                value = math.radians(value)
        return value

    def _check_number(self, value: float, error: type[ParameterError]) -> None:
        info = self.info
        if isinstance(value, float) and not math.isfinite(value) and info.finite:
            raise error(self.name, f'must be a finite number, got {value!r}')
        unit = f' {info.unit}' if info.unit else ''
        bounds: tuple[tuple[str, Any, Callable[[Any, Any], bool]], ...] = (
            ('>=', info.ge, lambda v, b: v >= b),
            ('>', info.gt, lambda v, b: v > b),
            ('<=', info.le, lambda v, b: v <= b),
            ('<', info.lt, lambda v, b: v < b),
        )
        for word, bound, ok in bounds:
            if bound is not None and not ok(value, bound):
                msg = f'must be {word} {_num(bound)}{unit}, got {_num(value)}{unit}'
                raise error(self.name, msg)

    def parse_text(self, text: str, *, error: type[ParameterError]) -> Any:
        """Read ``NAME=VALUE`` text (a YAML scalar, or a YAML list for arrays) as a value.

        Returns the parameter value (checked; integers become floats for float parameters).

        Raises:
            ``error``: text that is not a value of the parameter's type, or out of range.
        """
        text = text.strip()
        if self.kind == 'str':
            value: Any = text
        elif not text:
            raise error(self.name, f'no value given; expected {_KIND_WORDS[self.kind]}')
        else:
            try:
                value = yaml.safe_load(text)
            except yaml.YAMLError:
                value = text
            if self.kind == 'float' and isinstance(value, str):
                special = _special_float(value)
                value = value if special is None else special
        field_value = self.check(value, strict=False, error=error)
        return self.to_parameter(field_value)


def _special_float(text: str) -> Any:
    lowered = text.strip().lower()
    if lowered in ('nan', '.nan'):
        return math.nan
    if lowered in ('inf', '.inf', '+inf', '+.inf', 'infinity'):
        return math.inf
    if lowered in ('-inf', '-.inf', '-infinity'):
        return -math.inf
    return None


def _same(value: Any, none_value: Any) -> bool:
    if isinstance(none_value, float) and math.isnan(none_value):
        return isinstance(value, float) and math.isnan(value)
    return type(value) is type(none_value) and value == none_value


def _num(value: float | None) -> str:
    if value is None:
        return ''
    if isinstance(value, int):
        return str(value)  # exactly, as typed: 1000000000, not 1e+09
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value)) if abs(value) >= 1 or value == 0 else f'{value:g}'
    return f'{value:g}'


# ------------------------------------------------------------------------------ the spec


def _strip_optional(hint: Any) -> tuple[Any, bool]:
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        args = [arg for arg in typing.get_args(hint) if arg is not type(None)]
        if len(args) == 1 and len(typing.get_args(hint)) == 2:
            return args[0], True
    return hint, False


def _kind_of_hint(
    name: str, hint: Any
) -> tuple[str, type[Enum] | None, tuple[str, ...], int | None, bool]:
    """(kind, enum, implied choices, fixed length, frozenset) of a field annotation."""
    if isinstance(hint, type) and issubclass(hint, Enum):
        values = tuple(member.value for member in hint)
        if not all(isinstance(v, str) for v in values):
            raise SpecError(f'{name}: only Enums of strings can be parameters')
        return 'str', hint, values, None, False
    if hint in (bool, int, float, str):
        return hint.__name__, None, (), None, False
    origin = typing.get_origin(hint)
    args = typing.get_args(hint)
    if origin is typing.Literal:
        if not all(isinstance(a, str) for a in args):
            raise SpecError(f'{name}: only Literals of strings can be parameters')
        return 'str', None, tuple(args), None, False
    if origin is tuple and args:
        if len(args) == 2 and args[1] is Ellipsis:
            item, length = args[0], None
        elif len(set(args)) == 1:
            item, length = args[0], len(args)
        else:
            raise SpecError(f'{name}: tuples of mixed types cannot be parameters')
        if item in (bool, int, float, str):
            return item.__name__ + '[]', None, (), length, False
    if origin is frozenset and args and args[0] is str:
        return 'str[]', None, (), None, True
    raise SpecError(f'{name}: no parameter type for the annotation {hint!r}')


class ParameterSpec:
    """The parameters of a configuration dataclass: names, types, defaults, checks, renderings.

    Args:
        root: the frozen configuration dataclass; ``root()`` must build the defaults.
        error: the :class:`ParameterError` subclass raised for a bad value (a package gives
            its own, so that it is also that package's configuration error).

    Raises:
        SpecError: a field's annotation has no parameter type, two parameters share a name,
            or a default is not a valid value.
    """

    def __init__(self, root: type, *, error: type[ParameterError] = ParameterError) -> None:
        if not dataclasses.is_dataclass(root):
            raise SpecError(f'{root!r} is not a dataclass')
        self.root = root
        self.error = error
        defaults = root()
        found: list[ParameterDef] = []
        self._walk(root, defaults, (), '', found)
        self.parameters: tuple[ParameterDef, ...] = tuple(found)
        self._by_name = {p.name: p for p in found}
        if len(self._by_name) != len(found):
            names = [p.name for p in found]
            twice = sorted({n for n in names if names.count(n) > 1})
            raise SpecError(f'{root.__name__}: parameter names used twice: {", ".join(twice)}')

    def _walk(
        self, cls: type, instance: Any, path: tuple[str, ...], prefix: str, out: list[ParameterDef]
    ) -> None:
        hints = typing.get_type_hints(cls)
        for f in dataclasses.fields(cls):
            value = getattr(instance, f.name)
            if _SECTION_KEY in f.metadata:
                own = f.metadata[_SECTION_KEY]
                sub_prefix = prefix + (f'{f.name}.' if own is None else own)
                self._walk(type(value), value, (*path, f.name), sub_prefix, out)
                continue
            info = f.metadata.get(_PARAMETER_KEY)
            if info is None:
                continue
            hint, optional = _strip_optional(hints[f.name])
            kind, enum, implied, length, frozen = _kind_of_hint(f'{cls.__name__}.{f.name}', hint)
            if implied and not info.choices:
                info = dataclasses.replace(info, choices=implied)
            if optional and info.none is _NO_NONE:
                if kind != 'float':
                    raise SpecError(f'{cls.__name__}.{f.name}: an optional field needs none=')
                info = dataclasses.replace(info, none=math.nan)
            name = f.name
            if info.degrees:
                if not name.endswith('_rad') or kind not in ('float', 'float[]'):
                    raise SpecError(f'{cls.__name__}.{f.name}: degrees=True needs a float *_rad')
                name = name.removesuffix('_rad') + '_deg'
            definition = ParameterDef(
                name=info.name or prefix + name,
                path=(*path, f.name),
                kind=kind,
                info=info,
                default=None,
                enum=enum,
                optional=optional,
                length=length,
                frozen=frozen,
            )
            default = definition.to_parameter(value)
            definition = dataclasses.replace(definition, default=default)
            try:
                definition.check(default, strict=True, error=ParameterError)
            except ParameterError as err:
                raise SpecError(f'{cls.__name__}: default of {err}') from err
            out.append(definition)

    # Lookup -----------------------------------------------------------------------

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter name, in declaration order."""
        return tuple(p.name for p in self.parameters)

    def __contains__(self, name: object) -> bool:
        return name in self._by_name

    def __getitem__(self, name: str) -> ParameterDef:
        """The parameter called ``name``.

        Raises:
            ParameterError: no such parameter (``unknown``, with close names as suggestions).
        """
        try:
            return self._by_name[name]
        except KeyError:
            raise self.unknown(name) from None

    def unknown(self, name: str) -> ParameterError:
        """The error for an unknown name, with did-you-mean suggestions."""
        close = difflib.get_close_matches(name, self.names, n=3)
        if not close:
            tail = name.rsplit('.', 1)[-1]
            close = [n for n in self.names if n.rsplit('.', 1)[-1] == tail][:3]
        return self.error(name, 'unknown parameter', unknown=True, suggestions=close)

    # Values and configurations ------------------------------------------------------

    def defaults(self, base: Any = None) -> dict[str, Any]:
        """Parameter name -> default value (of ``base``, default: the dataclass defaults)."""
        if base is None:
            return {p.name: p.default for p in self.parameters}
        return self.values_of(base)

    def values_of(self, config: Any) -> dict[str, Any]:
        """Parameter name -> value of a configuration (flattening)."""
        values = {}
        for p in self.parameters:
            value = config
            for part in p.path:
                value = getattr(value, part)
            values[p.name] = p.to_parameter(value)
        return values

    def check(self, name: str, value: Any, *, strict: bool = False) -> Any:
        """Validate one value; return the field value (see :meth:`ParameterDef.check`).

        Raises:
            ParameterError (the spec's ``error`` class): unknown name or bad value.
        """
        return self[name].check(value, strict=strict, error=self.error)

    def parse_text(self, name: str, text: str) -> Any:
        """The parameter value that ``NAME=text`` gives (see :meth:`ParameterDef.parse_text`)."""
        return self[name].parse_text(text, error=self.error)

    def build(self, values: Mapping[str, Any], base: Any = None, *, strict: bool = False) -> Any:
        """The configuration with ``values`` applied to ``base`` (unflattening).

        Names missing from ``values`` keep ``base``'s values (default: the dataclass
        defaults). The configuration's own ``__post_init__`` checks (cross-field rules)
        run and raise their own errors.

        Raises:
            ParameterError: an unknown name or a bad value.
        """
        changes: dict[tuple[str, ...], Any] = {}
        for name, value in values.items():
            definition = self[name]
            changes[definition.path] = definition.check(value, strict=strict, error=self.error)
        config = self.root() if base is None else base
        return _apply(config, changes)

    # Renderings -------------------------------------------------------------------

    def render_yaml(
        self,
        node_key: str,
        *,
        base: Any = None,
        header: Iterable[str] = (),
    ) -> str:
        """A ROS 2 parameter file with every parameter, its default and its description.

        Dotted names become nested maps, as rcl reads them. ``header`` lines become comments.
        """
        lines = [f'# {line}'.rstrip() for line in header]
        lines += [f'{node_key}:', '  ros__parameters:']
        values = self.defaults(base)
        opened: list[str] = []
        for p in self.parameters:
            parts = p.name.split('.')
            groups, leaf = parts[:-1], parts[-1]
            common = 0
            while common < min(len(opened), len(groups)) and opened[common] == groups[common]:
                common += 1
            opened = opened[:common]
            for group in groups[common:]:
                lines.append('    ' + '  ' * len(opened) + f'{group}:')
                opened.append(group)
            indent = '    ' + '  ' * len(opened)
            for comment in _wrap(_comment_of(p), 96 - len(indent)):
                lines.append(f'{indent}# {comment}')
            lines.append(f'{indent}{leaf}: {render_value(values[p.name])}')
        return '\n'.join(lines) + '\n'

    def render_markdown(self, *, base: Any = None) -> str:
        """A markdown table: name, default, unit, range or choices, runtime change, description."""
        values = self.defaults(base)
        rows = [
            '| parameter | default | unit | range / choices | set at runtime | description |',
            '|---|---|---|---|---|---|',
        ]
        for p in self.parameters:
            constraints = p.constraints_text.replace('range ', '').replace('|', '\\|')
            description = p.info.description.replace('|', '\\|')
            rows.append(
                f'| `{p.name}` | `{render_value(values[p.name])}` | {p.info.unit} | '
                f'{constraints} | {"no" if p.read_only else "yes"} | {description} |'
            )
        return '\n'.join(rows) + '\n'


def _comment_of(p: ParameterDef) -> str:
    text = p.description_text
    extra = p.constraints_text
    if extra:
        text += f' ({extra})'
    if not p.read_only:
        text += ' Can be changed while the node runs.'
    return text


def _wrap(text: str, width: int) -> list[str]:
    lines: list[str] = []
    current = ''
    for word in text.split():
        if current and len(current) + 1 + len(word) > width:
            lines.append(current)
            current = word
        else:
            current = f'{current} {word}' if current else word
    if current:
        lines.append(current)
    return lines


def _apply(config: Any, changes: Mapping[tuple[str, ...], Any]) -> Any:
    if not changes:
        return config
    own: dict[str, Any] = {}
    nested: dict[str, dict[tuple[str, ...], Any]] = {}
    for path, value in changes.items():
        if len(path) == 1:
            own[path[0]] = value
        else:
            nested.setdefault(path[0], {})[path[1:]] = value
    for name, sub in nested.items():
        own[name] = _apply(getattr(config, name), sub)
    return dataclasses.replace(config, **own)
