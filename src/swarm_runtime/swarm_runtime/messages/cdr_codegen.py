"""Specialised CDR encoders and decoders generated per message type.

rosbags' serializer needs its own message objects, so going through it costs a conversion in
each direction on top of the encoding. The functions generated here read and write the
generated classes' slots directly, in little-endian CDR (XCDR1, the encoding rmw uses):

- nested messages that are not in a sequence are flattened into their parent's code;
- consecutive fixed-size fields whose alignment is known when the code is generated are
  packed or unpacked by one precompiled ``struct.Struct`` call (an Imu's 37 doubles are one
  call), alignment padding included;
- after a string or sequence the offset is only known modulo a smaller number, so the next
  wider field is aligned at run time;
- numeric arrays and sequences are copied as one block of bytes.

The encoders produce exactly the bytes rosbags' ``serialize_cdr`` produces (the tests check
this for every Jazzy type and for random messages of a probe type with every kind of field).
Big-endian data and big-endian hosts are left to the rosbags path.
"""

from __future__ import annotations

import struct
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from itertools import count
from typing import Any

import numpy as np

from .fields import FieldSpec, MessageSpec

__all__ = ['CdrDecodeError', 'CdrFunctions', 'build_cdr_functions', 'cdr_source']

# rosbags base type -> (struct code, size in bytes).
_PRIMITIVES = {
    'bool': ('?', 1),
    'byte': ('B', 1),
    'char': ('B', 1),
    'int8': ('b', 1),
    'uint8': ('B', 1),
    'int16': ('h', 2),
    'uint16': ('H', 2),
    'int32': ('i', 4),
    'uint32': ('I', 4),
    'int64': ('q', 8),
    'uint64': ('Q', 8),
    'float32': ('f', 4),
    'float64': ('d', 8),
}
_ZEROS = tuple(bytes(n) for n in range(8))
_U32 = struct.Struct('<I')


class CdrDecodeError(ValueError):
    """The bytes do not hold a valid CDR encoding of the type."""


@dataclass(frozen=True)
class CdrFunctions:
    """The generated functions of one message type.

    ``serialize(msg) -> bytes`` returns the full CDR (with the encapsulation header);
    ``deserialize(data) -> msg`` takes bytes that start with the header.
    ``write(msg, buf)`` appends a message at an arbitrary offset of ``buf``;
    ``read(data, pos) -> (msg, pos)`` reads one at an arbitrary offset.
    """

    serialize: Callable[[Any], bytes]
    deserialize: Callable[[bytes], Any]
    write: Callable[[Any, bytearray], None]
    read: Callable[[bytes, int], tuple[Any, int]]


# --------------------------------------------------------------------------- runtime helpers


def _sequence_bytes(value: Any, typecode: str, dtype: str) -> bytes:
    """Bytes of a numeric sequence (array.array fast path)."""
    if type(value) is array and value.typecode == typecode:
        return value.tobytes()
    values = np.asarray(value, dtype=dtype)
    if values.ndim != 1:
        msg = f'expected a flat sequence, got shape {values.shape}'
        raise ValueError(msg)
    return values.tobytes()


def _octets(value: Any) -> bytes:
    """rosidl's list of one-byte ``bytes`` (or a bytes-like object) as raw bytes."""
    if isinstance(value, (bytes, bytearray, memoryview)):
        return bytes(value)
    joined = b''.join(value)
    if len(joined) != len(value):
        msg = 'every element of a byte sequence must be one byte'
        raise ValueError(msg)
    return joined


def _write_string(buf: bytearray, value: str) -> None:
    """Append a 4-aligned CDR string (length with the terminator, UTF-8, NUL)."""
    buf += _ZEROS[(4 - len(buf)) & 3]
    encoded = value.encode()
    buf += _U32.pack(len(encoded) + 1)
    buf += encoded
    buf.append(0)


def _read_string(data: bytes, pos: int) -> tuple[str, int]:
    """Read a 4-aligned CDR string at ``pos``; return it and the position after it."""
    pos += (4 - pos) & 3
    (size,) = _U32.unpack_from(data, pos)
    pos += 4
    end = pos + size
    if size < 1 or end > len(data) or data[end - 1] != 0:
        msg = f'invalid string of {size} bytes at offset {pos - 4}'
        raise CdrDecodeError(msg)
    return data[pos : end - 1].decode(), end


def _read_count(data: bytes, pos: int, element_size: int) -> tuple[int, int]:
    """Read a 4-aligned sequence length; reject one that cannot fit in the data."""
    pos += (4 - pos) & 3
    (size,) = _U32.unpack_from(data, pos)
    pos += 4
    if size * element_size > len(data) - pos:
        msg = f'sequence of {size} elements at offset {pos - 4} exceeds the data'
        raise CdrDecodeError(msg)
    return size, pos


def _read_array(data: bytes, pos: int, typecode: str, size: int, length: int) -> array:
    end = pos + size * length
    if end > len(data):
        msg = f'array of {length} elements at offset {pos} exceeds the data'
        raise CdrDecodeError(msg)
    return array(typecode, data[pos:end])


# --------------------------------------------------------------------------- code generation


@dataclass
class _Alignment:
    """What is known at generation time about the offset (from the end of the header)."""

    modulus: int = 8
    offset: int = 0

    def static_padding(self, alignment: int) -> int | None:
        """Padding bytes needed, or None when the alignment must be computed at run time."""
        if alignment <= self.modulus:
            return (-self.offset) % alignment
        return None

    def advance(self, size: int) -> None:
        self.offset = (self.offset + size) % self.modulus

    def reset(self, modulus: int) -> None:
        self.modulus, self.offset = modulus, 0


@dataclass
class _Writer:
    """Builds the body of an encoder: lines plus one pending ``struct`` run."""

    structs: dict[str, str]
    names: Callable[[str], str]
    lines: list[str] = field(default_factory=list)
    align: _Alignment = field(default_factory=_Alignment)
    run_codes: list[str] = field(default_factory=list)
    run_values: list[str] = field(default_factory=list)
    # Lines computing values of the pending run (encoded strings), emitted before it.
    pre_lines: list[str] = field(default_factory=list)

    def flush(self) -> None:
        if not self.run_codes:
            return
        codes = ''.join(self.run_codes)
        name = self.structs.setdefault(codes, f'_S{len(self.structs)}')
        self.lines.extend(self.pre_lines)
        self.pre_lines = []
        if self.run_values:
            self.lines.append(f'buf += {name}.pack({", ".join(self.run_values)})')
        else:
            self.lines.append(f'buf += {name}.pack()')
        self.run_codes, self.run_values = [], []

    def pad(self, alignment: int) -> None:
        padding = self.align.static_padding(alignment)
        if padding is None:
            self.flush()
            self.lines.append(f'buf += _ZEROS[(4 - len(buf)) & {alignment - 1}]')
            self.align.reset(alignment)
        elif padding:
            self.run_codes.append(f'{padding}x')
            self.align.advance(padding)

    def primitive(self, base: str, expr: str) -> None:
        code, size = _PRIMITIVES[base]
        self.pad(size)
        self.run_codes.append(code)
        self.run_values.append(f'{expr}[0]' if base == 'byte' else expr)
        self.align.advance(size)

    def fixed_array(self, base: str, expr: str, length: int) -> None:
        code, size = _PRIMITIVES[base]
        self.pad(size)
        self.run_codes.append(f'{length}{code}')
        local = self.names('a')
        self.pre_lines.append(f'{local} = {expr}')
        # Elements as Python numbers for struct (numpy arrays via tolist(), others as they are).
        self.run_values.append(f'*({local}.tolist() if type({local}) is _ndarray else {local})')
        self.align.advance(size * length)

    def string(self, expr: str) -> None:
        """A string: its length joins the pending run, the bytes and NUL follow."""
        encoded = self.names('t')
        self.pad(4)
        self.pre_lines.append(f'{encoded} = {expr}.encode()')
        self.run_codes.append('I')
        self.run_values.append(f'len({encoded}) + 1')
        self.align.advance(4)
        self.flush()
        self.lines.append(f'buf += {encoded}')
        self.lines.append('buf.append(0)')
        self.align.reset(1)

    def statement(self, line: str, modulus_after: int) -> None:
        self.flush()
        self.lines.append(line)
        self.align.reset(modulus_after)


@dataclass
class _Reader:
    """Builds the body of a decoder: lines plus one pending ``struct`` run."""

    structs: dict[str, str]
    names: Callable[[str], str]
    lines: list[str] = field(default_factory=list)
    align: _Alignment = field(default_factory=_Alignment)
    run_codes: list[str] = field(default_factory=list)
    run_targets: list[tuple[str, str]] = field(default_factory=list)  # (target, base)
    # Fixed numeric arrays of the run: (target, dtype, item size, length, offset in the run).
    run_arrays: list[tuple[str, str, int, int, int]] = field(default_factory=list)
    run_size: int = 0

    def _array_lines(self) -> list[str]:
        """Read the run's fixed arrays, each into its own new array.

        Arrays of one dtype share a view of the data (one ``frombuffer``) that each copies its
        slice from, which is cheaper than a ``frombuffer`` per array.
        """
        lines = []
        by_dtype: dict[str, list[tuple[str, str, int, int, int]]] = {}
        for spec in self.run_arrays:
            by_dtype.setdefault(spec[1], []).append(spec)
        for dtype, specs in by_dtype.items():
            first = specs[0][4]
            size = specs[0][2]
            shared = len(specs) > 1 and all((spec[4] - first) % size == 0 for spec in specs)
            if not shared:
                lines.extend(
                    f'{target} = _np.frombuffer(data, _np.{dtype}, {length}, pos + {offset}).copy()'
                    for target, _, _, length, offset in specs
                )
                continue
            last = specs[-1]
            count = (last[4] - first) // size + last[3]
            view = self.names('b')
            lines.append(f'{view} = _np.frombuffer(data, _np.{dtype}, {count}, pos + {first})')
            for target, _, _, length, offset in specs:
                start = (offset - first) // size
                lines.append(f'{target} = {view}[{start}:{start + length}].copy()')
        return lines

    def flush(self) -> None:
        if not self.run_codes:
            return
        codes = ''.join(self.run_codes)
        name = self.structs.setdefault(codes, f'_S{len(self.structs)}')
        if self.run_targets:
            # Unpack straight into the slots; octets go through a temporary to become bytes.
            names = []
            conversions = []
            for target, base in self.run_targets:
                if base == 'byte':
                    temp = self.names('v')
                    names.append(temp)
                    conversions.append(f'{target} = bytes(({temp},))')
                else:
                    names.append(target)
            self.lines.append(f'{", ".join(names)}, = {name}.unpack_from(data, pos)')
            self.lines.extend(conversions)
        elif self.run_arrays:
            # Nothing to unpack, but the struct call checks that the bytes are there.
            self.lines.append(f'{name}.unpack_from(data, pos)')
        self.lines.extend(self._array_lines())
        self.lines.append(f'pos += {self.run_size}')
        self.run_codes, self.run_targets, self.run_arrays, self.run_size = [], [], [], 0

    def pad(self, alignment: int) -> None:
        padding = self.align.static_padding(alignment)
        if padding is None:
            self.flush()
            self.lines.append(f'pos += (4 - pos) & {alignment - 1}')
            self.align.reset(alignment)
        elif padding:
            self.run_codes.append(f'{padding}x')
            self.run_size += padding
            self.align.advance(padding)

    def primitive(self, base: str, target: str) -> None:
        code, size = _PRIMITIVES[base]
        self.pad(size)
        self.run_codes.append(code)
        self.run_targets.append((target, base))
        self.run_size += size
        self.align.advance(size)

    def string(self, target: str) -> None:
        """A string: its length joins the pending run, then the checked bytes are decoded."""
        size = self.names('n')
        end = self.names('e')
        self.pad(4)
        self.run_codes.append('I')
        self.run_targets.append((size, 'uint32'))
        self.run_size += 4
        self.align.advance(4)
        self.flush()
        self.lines.append(f'{end} = pos + {size}')
        self.lines.append(
            f'if {size} < 1 or {end} > len(data) or data[{end} - 1] != 0: '
            f"raise _CdrDecodeError(f'invalid string of {{{size}}} bytes at offset {{pos - 4}}')"
        )
        self.lines.append(f'{target} = data[pos:{end} - 1].decode()')
        self.lines.append(f'pos = {end}')
        self.align.reset(1)

    def fixed_array(self, base: str, dtype: str, target: str, length: int) -> None:
        _, size = _PRIMITIVES[base]
        self.pad(size)
        self.run_codes.append(f'{size * length}x')
        self.run_arrays.append((target, dtype, size, length, self.run_size))
        self.run_size += size * length
        self.align.advance(size * length)

    def statement(self, line: str, modulus_after: int) -> None:
        self.flush()
        self.lines.append(line)
        self.align.reset(modulus_after)


class _Generator:
    """Generates the encoder and decoder source of one message type."""

    def __init__(self, specs: Callable[[str], MessageSpec], top: MessageSpec) -> None:
        self._specs = specs
        self.top = top
        self.structs: dict[str, str] = {}
        self.classes: dict[str, str] = {}  # type name -> namespace name of its class
        self.externals: dict[str, str] = {}  # type name -> prefix of its write/read functions
        self._counter = count()

    def name(self, prefix: str) -> str:
        return f'_{prefix}{next(self._counter)}'

    def class_name(self, typename: str) -> str:
        return self.classes.setdefault(typename, f'_C{len(self.classes)}')

    def external(self, typename: str) -> str:
        return self.externals.setdefault(typename, f'_X{len(self.externals)}')

    # ----------------------------------------------------------------- encoder

    def write_message(self, out: _Writer, spec: MessageSpec, expr: str) -> None:
        if spec.padded_empty:
            out.primitive('uint8', '0')
            return
        for item in spec.fields:
            self.write_field(out, item, f'{expr}._{item.name}')

    def write_field(self, out: _Writer, item: FieldSpec, expr: str) -> None:
        element = item.element
        if not item.is_nested:
            if element.is_message:
                local = out.names('m')
                out.lines.append(f'{local} = {expr}')
                self.write_message(out, self._specs(element.nested), local)
            elif element.is_string:
                out.string(expr)
            else:
                out.primitive(element.base, expr)
            return
        if item.is_sequence:
            local = out.names('s')
            out.lines.append(f'{local} = {expr}')
            out.pad(4)
            out.run_codes.append('I')
            out.run_values.append(f'len({local})')
            out.align.advance(4)
            if item.length:
                out.lines.append(
                    f'if len({local}) > {item.length}: '
                    f"raise ValueError('sequence longer than its bound of {item.length}')"
                )
            self.write_elements(out, item, local, counted=True)
        else:
            self.write_elements(out, item, expr, counted=False)

    def write_elements(self, out: _Writer, item: FieldSpec, expr: str, *, counted: bool) -> None:
        element = item.element
        length = item.length
        if element.is_numeric:
            _, size = _PRIMITIVES[element.base]
            if counted:
                if size > 4:
                    out.flush()
                    out.lines.append(f'if len({expr}): buf += _ZEROS[(4 - len(buf)) & 7]')
                    out.align.reset(4)
                out.statement(
                    f'buf += _sequence_bytes({expr}, {element.typecode!r}, {element.dtype!r})',
                    min(size, 4),
                )
            else:
                out.fixed_array(element.base, expr, length)
            return
        check = '' if counted else f'_check_length({expr}, {length}); '
        if element.base == 'bool':
            out.statement(f'{check}buf += bytes(map(bool, {expr}))', 1)
        elif element.base == 'byte':
            out.statement(f'{check}buf += _octets({expr})', 1)
        elif element.is_string:
            out.statement(f'{check}[_write_string(buf, item) for item in {expr}]', 1)
        else:
            # The element's encoder inlined in a loop: no function call per element.
            item = out.names('i')
            body = _Writer(self.structs, self.name, align=_Alignment(1, 0))
            self.write_message(body, self._specs(element.nested), item)
            body.flush()
            if check:
                out.statement(check.rstrip('; '), 1)
            out.statement(f'for {item} in {expr}:', 1)
            out.lines.extend(_indent(body.lines or ['pass']))

    # ----------------------------------------------------------------- decoder

    def read_message(self, out: _Reader, spec: MessageSpec, target: str) -> None:
        cls = self.class_name(spec.typename)
        out.lines.append(f'{target} = _new({cls})')
        out.lines.append(f'{target}._check_fields = {cls}_check')
        if spec.padded_empty:
            out.pad(1)
            out.run_codes.append('x')
            out.run_size += 1
            out.align.advance(1)
            return
        for item in spec.fields:
            self.read_field(out, item, target)

    def read_field(self, out: _Reader, item: FieldSpec, owner: str) -> None:
        element = item.element
        target = f'{owner}._{item.name}'
        if not item.is_nested:
            if element.is_message:
                local = out.names('m')
                self.read_message(out, self._specs(element.nested), local)
                out.lines.append(f'{target} = {local}')
            elif element.is_string:
                out.string(target)
            else:
                out.primitive(element.base, target)
            return
        if item.is_sequence:
            size = _PRIMITIVES[element.base][1] if element.base in _PRIMITIVES else 1
            length = out.names('n')
            out.statement(f'{length}, pos = _read_count(data, pos, {size})', 4)
            if item.length:
                out.lines.append(
                    f'if {length} > {item.length}: '
                    f"raise _CdrDecodeError('sequence longer than its bound of {item.length}')"
                )
        else:
            length = str(item.length)
        self.read_elements(out, item, target, length, counted=item.is_sequence)

    def read_elements(
        self, out: _Reader, item: FieldSpec, target: str, length: str, *, counted: bool
    ) -> None:
        element = item.element
        if element.is_numeric:
            _, size = _PRIMITIVES[element.base]
            if counted:
                if size > 4:
                    out.flush()
                    out.lines.append(f'if {length}: pos += (4 - pos) & 7')
                    out.align.reset(4)
                out.statement(
                    f'{target} = _read_array(data, pos, {element.typecode!r}, {size}, {length}); '
                    f'pos += {size} * {length}',
                    min(size, 4),
                )
            else:
                out.fixed_array(element.base, element.dtype, target, int(length))
            return
        if element.base == 'bool':
            out.statement(
                f'{target} = [b != 0 for b in data[pos:pos + {length}]]; pos += {length}', 1
            )
        elif element.base == 'byte':
            out.statement(
                f'{target} = [data[i:i + 1] for i in range(pos, pos + {length})]; pos += {length}',
                1,
            )
        elif element.is_string:
            items = out.names('l')
            out.statement(f'{items} = []', 1)
            out.lines.append(f'for _ in range({length}):')
            out.lines.append('    text, pos = _read_string(data, pos)')
            out.lines.append(f'    {items}.append(text)')
            out.lines.append(f'{target} = {items}')
        else:
            # The element's decoder inlined in a loop: no function call per element.
            items = out.names('l')
            item = out.names('i')
            body = _Reader(self.structs, self.name, align=_Alignment(1, 0))
            self.read_message(body, self._specs(element.nested), item)
            body.flush()
            out.statement(f'{items} = []', 1)
            out.lines.append(f'for _ in range({length}):')
            out.lines.extend(_indent([*body.lines, f'{items}.append({item})']))
            out.lines.append(f'{target} = {items}')
        if not counted:
            out.lines.append(f'_check_decoded_length({target}, {length})')


def _indent(lines: list[str]) -> list[str]:
    return [f'    {line}' for line in lines]


def cdr_source(spec: MessageSpec, specs: Callable[[str], MessageSpec]) -> tuple[str, _Generator]:
    """Source of ``_serialize``, ``_deserialize``, ``_write`` and ``_read`` for ``spec``."""
    generator = _Generator(specs, spec)
    generator.class_name(spec.typename)

    top_writer = _Writer(generator.structs, generator.name)
    generator.write_message(top_writer, spec, 'msg')
    top_writer.flush()
    nested_writer = _Writer(generator.structs, generator.name, align=_Alignment(1, 0))
    generator.write_message(nested_writer, spec, 'msg')
    nested_writer.flush()

    top_reader = _Reader(generator.structs, generator.name)
    generator.read_message(top_reader, spec, 'msg')
    top_reader.flush()
    nested_reader = _Reader(generator.structs, generator.name, align=_Alignment(1, 0))
    generator.read_message(nested_reader, spec, 'msg')
    nested_reader.flush()

    out = [
        'def _serialize(msg):',
        "    buf = bytearray(b'\\x00\\x01\\x00\\x00')",
        *_indent(top_writer.lines),
        '    return bytes(buf)',
        '',
        'def _write(msg, buf):',
        *_indent(nested_writer.lines or ['pass']),
        '',
        'def _deserialize(data):',
        '    pos = 4',
        *_indent(top_reader.lines),
        '    if len(data) - pos > 3:',
        "        raise _CdrDecodeError(f'{len(data) - pos} bytes left after the message')",
        '    return msg',
        '',
        'def _read(data, pos):',
        *_indent(nested_reader.lines),
        '    return msg, pos',
        '',
    ]
    return '\n'.join(out), generator


def _check_length(value: Any, length: int) -> None:
    if len(value) != length:
        msg = f'expected {length} elements, got {len(value)}'
        raise ValueError(msg)


def _check_decoded_length(value: Any, length: int) -> None:
    if len(value) != length:
        msg = f'decoded {len(value)} elements, expected {length}'
        raise CdrDecodeError(msg)


def build_cdr_functions(
    spec: MessageSpec,
    specs: Callable[[str], MessageSpec],
    classes: Callable[[str], type],
    nested_functions: Callable[[str], CdrFunctions],
    check_fields: Callable[[str], bool],
) -> CdrFunctions:
    """Compile the CDR functions of ``spec``.

    Args:
        spec: The message type.
        specs: Type name -> MessageSpec, for nested types.
        classes: Type name -> generated class.
        nested_functions: Type name -> CdrFunctions, for types inside sequences and arrays.
        check_fields: Type name -> default ``_check_fields`` of decoded messages (rclpy builds
            received messages with the class constructor, so they get the package default).
    """
    source, generator = cdr_source(spec, specs)
    namespace: dict[str, Any] = {
        '_np': np,
        '_ndarray': np.ndarray,
        '_new': object.__new__,
        '_ZEROS': _ZEROS,
        '_CdrDecodeError': CdrDecodeError,
        '_write_string': _write_string,
        '_read_string': _read_string,
        '_read_count': _read_count,
        '_read_array': _read_array,
        '_sequence_bytes': _sequence_bytes,
        '_octets': _octets,
        '_check_length': _check_length,
        '_check_decoded_length': _check_decoded_length,
    }
    for codes, name in generator.structs.items():
        namespace[name] = struct.Struct('<' + codes)
    for typename, name in generator.classes.items():
        namespace[name] = classes(typename)
        namespace[name + '_check'] = check_fields(typename)
    for typename, prefix in generator.externals.items():
        functions = nested_functions(typename)
        namespace[f'{prefix}w'] = functions.write
        namespace[f'{prefix}r'] = functions.read
    exec(compile(source, f'<cdr {spec.typename}>', 'exec'), namespace)
    return CdrFunctions(
        serialize=namespace['_serialize'],
        deserialize=namespace['_deserialize'],
        write=namespace['_write'],
        read=namespace['_read'],
    )
