"""Reading rosbag2 bags (ours or a robot's ``ros2 bag record -s mcap``) as message objects.

:func:`read_messages` yields :class:`BagMessage` tuples in log-time order. Messages are
decoded into the generated classes of :mod:`swarm_runtime.messages`, or into the real rclpy
classes when the process runs on real rclpy (``swarm_runtime.ros`` selected it). Types the
bag defines differently from this workspace (an older swarm_interfaces, a robot's custom
package) are decoded with the definitions stored in the bag itself.

Damage is reported, never glossed over: a missing or unreadable file raises a
:class:`~swarm_runtime.bag.errors.BagError` that names the file and the problem. With
``allow_truncated=True`` the reader instead recovers what it can: it falls back to a
streaming scan of the MCAP records (a bag whose recorder died has no MCAP summary and no
metadata.yaml), returns every message before the damage and stops there with a
:class:`TruncatedBagWarning`.
"""

from __future__ import annotations

import fnmatch
import struct
import sys
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import yaml
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import Connection, ConnectionExtRosbag2, Qos
from rosbags.rosbag2 import ReaderError
from rosbags.serde import SerdeError
from rosbags.typesys import (
    Stores,
    TypesysError,
    get_types_from_idl,
    get_types_from_msg,
    get_typestore,
)
from rosbags.typesys.store import Typestore

from ..messages.errors import MessageError
from ..messages.fields import referenced_types
from .errors import BagError, BagNotFoundError, CorruptBagError
from .mcap_scan import McapScan, ScannedMessage

__all__ = [
    'BagInfo',
    'BagMessage',
    'TopicSummary',
    'TruncatedBagWarning',
    'read_bag_info',
    'read_messages',
]

# What a damaged file makes rosbags raise: its own errors, and plain ones from reading bogus
# lengths and offsets (a garbage length can even ask for more memory than exists).
_READ_ERRORS = (
    AnyReaderError,
    ReaderError,
    SerdeError,
    TypesysError,
    MessageError,
    OSError,
    ValueError,
    EOFError,
    LookupError,
    ArithmeticError,
    struct.error,
    MemoryError,
    AssertionError,
)


def _error_text(err: BaseException) -> str:
    text = str(err).strip().rstrip('.')
    return f'{type(err).__name__}: {text}' if text else type(err).__name__


class TruncatedBagWarning(UserWarning):
    """A damaged bag was read only up to the damage (``allow_truncated=True``)."""


class BagMessage(NamedTuple):
    """One recorded message: topic, full type name, log time [ns] and the message.

    ``message`` is a message object, or the CDR bytes when read with ``raw=True``.
    """

    topic: str
    typename: str
    log_time_ns: int
    message: Any


@dataclass(frozen=True)
class TopicSummary:
    """What a bag holds for one topic."""

    topic: str
    typename: str
    message_count: int
    type_hash: str
    offered_qos_profiles: tuple[Qos, ...]


@dataclass(frozen=True)
class BagInfo:
    """Summary of a bag: its files, time span [ns] and topics."""

    path: Path
    storage_files: tuple[Path, ...]
    start_time_ns: int
    end_time_ns: int
    message_count: int
    topics: dict[str, TopicSummary] = field(default_factory=dict)


# --------------------------------------------------------------------------- locating files


@dataclass(frozen=True)
class _BagFiles:
    root: Path
    storage_files: tuple[Path, ...]
    problem: str | None  # why the files cannot be read through metadata.yaml, if they cannot


def _locate(path: Path) -> _BagFiles:
    """Find the storage files of a bag directory (or a lone .mcap file)."""
    if not path.exists():
        msg = f'{path}: no such bag directory or file'
        raise BagNotFoundError(msg)
    if path.is_file():
        if path.suffix != '.mcap':
            msg = f'{path}: not a bag directory or an .mcap file'
            raise BagNotFoundError(msg)
        return _BagFiles(path, (path,), None)

    on_disk = tuple(sorted(path.glob('*.mcap')))
    metadata_path = path / 'metadata.yaml'
    if not metadata_path.is_file():
        problem = (
            f'{metadata_path} is missing (was the recording closed?); '
            'read with allow_truncated=True to recover what the .mcap files hold'
        )
        return _BagFiles(path, on_disk, problem)
    try:
        metadata = yaml.safe_load(metadata_path.read_text(encoding='utf-8'))
        info = metadata['rosbag2_bagfile_information']
        listed = tuple(path / name for name in info['relative_file_paths'])
    except (OSError, yaml.YAMLError, KeyError, TypeError) as err:
        msg = f'{metadata_path}: not a valid rosbag2 metadata file: {err}'
        raise CorruptBagError(msg) from err
    missing = [str(p) for p in listed if not p.is_file()]
    if missing:
        problem = f'{metadata_path} lists storage files that do not exist: {", ".join(missing)}'
        return _BagFiles(path, tuple(p for p in listed if p.is_file()) or on_disk, problem)
    return _BagFiles(path, listed, None)


def _topic_filter(topics: Iterable[str] | None) -> Callable[[str], bool]:
    if topics is None:
        return lambda _topic: True
    if isinstance(topics, str):
        topics = [topics]
    names = set()
    patterns = []
    for topic in topics:
        if any(ch in topic for ch in '*?['):
            patterns.append(topic)
        else:
            names.add(topic)
    return lambda topic: topic in names or any(fnmatch.fnmatchcase(topic, p) for p in patterns)


# --------------------------------------------------------------------------- decoding


def _real_rclpy_selected() -> bool:
    """True when node code in this process runs on real rclpy (swarm_runtime.ros chose it)."""
    ros = sys.modules.get('swarm_runtime.ros')
    return bool(ros is not None and ros.using_real_rclpy())


class _Decoder:
    """Turns CDR bytes of a connection into message objects.

    Types this workspace knows with the same RIHS01 hash decode into the shared generated
    classes; any other type decodes with the bag's own definitions.
    """

    def __init__(self, bag_typestore: Callable[[], Typestore]) -> None:
        self._bag_typestore = bag_typestore
        self._bag_registry: Any = None
        self._real = _real_rclpy_selected()
        self._decoders: dict[tuple[str, str], Callable[[bytes], Any]] = {}

    def decode(self, typename: str, digest: str, data: bytes) -> Any:
        key = (typename, digest)
        decoder = self._decoders.get(key)
        if decoder is None:
            decoder = self._make(typename, digest)
            self._decoders[key] = decoder
        return decoder(data)

    def _make(self, typename: str, digest: str) -> Callable[[bytes], Any]:
        if self._real:
            from rclpy.serialization import deserialize_message
            from rosidl_runtime_py.utilities import get_message

            cls = get_message(typename)
            return lambda data: deserialize_message(data, cls)

        from swarm_runtime.messages import MessageRegistry, cdr, default_registry

        registry = default_registry()
        typestore = registry.typestore
        ours = typestore.hash_rihs01(typename) if typename in typestore.fielddefs else None
        theirs = digest or self._bag_hash(typename)
        if ours is None or (theirs is not None and theirs != ours):
            if self._bag_registry is None:
                self._bag_registry = MessageRegistry(self._bag_typestore())
            registry = self._bag_registry
        return lambda data: cdr.deserialize_cdr(data, typename, registry)

    def _bag_hash(self, typename: str) -> str | None:
        """RIHS01 hash of the bag's own definition of ``typename``, if the bag has one."""
        try:
            typestore = self._bag_typestore()
            if typename not in typestore.fielddefs:
                return None
            return typestore.hash_rihs01(typename)
        except (TypesysError, KeyError, ValueError):
            return None


def _typestore_from_schemas(schemas: Iterable[tuple[str, str, str]]) -> Typestore:
    """A typestore of the definitions stored in a bag, completed from the Jazzy types."""
    from swarm_runtime.messages.typestore import jazzy_typestore

    types: dict[str, Any] = {}
    for name, encoding, text in schemas:
        if not text:
            continue
        if encoding == 'ros2msg':
            types.update(get_types_from_msg(text, name))
        elif encoding == 'ros2idl':
            separator = '=' * 80 + '\n'
            for part in text.split(separator):
                body = part.split('\n', 1)[1] if part.startswith('IDL: ') else part
                if body.strip():
                    types.update(get_types_from_idl(body))
    jazzy = jazzy_typestore().fielddefs
    missing = {n for defs in types.values() for n in referenced_types(defs[1])} - types.keys()
    while missing:
        name = missing.pop()
        if name in jazzy and name not in types:
            types[name] = jazzy[name]
            missing |= referenced_types(jazzy[name][1]) - types.keys()
    typestore = get_typestore(Stores.EMPTY)
    typestore.register(types)
    return typestore


# --------------------------------------------------------------------------- reading


def read_messages(
    path: str | Path,
    topics: Iterable[str] | None = None,
    *,
    allow_truncated: bool = False,
    raw: bool = False,
) -> Iterator[BagMessage]:
    """Yield the messages of a bag in log-time order.

    Args:
        path: A rosbag2 directory (metadata.yaml + .mcap files) or a single .mcap file.
        topics: Topic names or glob patterns ('/r*/scan') to read; None reads all.
        allow_truncated: Recover a damaged bag: read up to the damage, then stop with a
            :class:`TruncatedBagWarning` instead of raising.
        raw: Yield the CDR bytes instead of decoding them.

    Raises:
        BagNotFoundError: the bag, its metadata.yaml or a listed file does not exist (raised
            by the call itself).
        CorruptBagError: the bag is damaged (raised while iterating, at the damage; the
            messages before it have been yielded).
    """
    files = _locate(Path(path))
    if files.problem is not None and (not allow_truncated or not files.storage_files):
        raise BagNotFoundError(files.problem)
    return _iterate(files, _topic_filter(topics), allow_truncated=allow_truncated, raw=raw)


def _iterate(
    files: _BagFiles, selected: Callable[[str], bool], *, allow_truncated: bool, raw: bool
) -> Iterator[BagMessage]:
    if files.problem is not None:
        _warn(files.problem)
        yield from _scan_files(files.storage_files, selected, raw=raw)
        return

    from swarm_runtime.messages import get_typestore

    reader = AnyReader([files.root], default_typestore=get_typestore())
    try:
        reader.open()
    except _READ_ERRORS as err:
        problem = f'{_describe_files(files)}: cannot open the bag: {_error_text(err)}'
        if not allow_truncated:
            raise CorruptBagError(f'{problem}; allow_truncated=True recovers its messages') from err
        _warn(problem)
        yield from _scan_files(files.storage_files, selected, raw=raw)
        return

    try:
        connections = [c for c in reader.connections if selected(c.topic)]
        if not connections:
            return
        decoder = _Decoder(lambda: reader.typestore)
        stream = reader.messages(connections)
        while True:
            try:
                connection, log_time, data = next(stream)
                message = (
                    data if raw else decoder.decode(connection.msgtype, connection.digest, data)
                )
            except StopIteration:
                return
            except (*_READ_ERRORS, BagError) as err:
                problem = f'{_describe_files(files)}: damaged data: {_error_text(err)}'
                if not allow_truncated:
                    raise CorruptBagError(problem) from err
                _warn(f'{problem}; stopped reading there')
                return
            yield BagMessage(connection.topic, connection.msgtype, log_time, message)
    finally:
        reader.close()


def _describe_files(files: _BagFiles) -> str:
    return ', '.join(str(p) for p in files.storage_files) or str(files.root)


def _warn(text: str) -> None:
    warnings.warn(text, TruncatedBagWarning, stacklevel=3)


def _scan_files(
    storage_files: Iterable[Path], selected: Callable[[str], bool], *, raw: bool
) -> Iterator[BagMessage]:
    """Recovery path: stream every file's records, stop at the first damage."""
    for storage_file in storage_files:
        scan = McapScan(storage_file)
        decoder = _Decoder(
            lambda scan=scan: _typestore_from_schemas(
                (s.name, s.encoding, s.data) for s in scan.schemas.values()
            )
        )
        for record in scan:
            if not selected(record.channel.topic):
                continue
            typename = _typename(scan, record)
            if raw:
                message = record.data
            else:
                try:
                    message = decoder.decode(typename, '', record.data)
                except (*_READ_ERRORS, BagError) as err:
                    _warn(
                        f'{storage_file}: message on {record.channel.topic} at '
                        f'{record.log_time_ns} ns cannot be decoded ({_error_text(err)}); '
                        'stopped reading there'
                    )
                    return
            yield BagMessage(record.channel.topic, typename, record.log_time_ns, message)
        if scan.damage is not None:
            _warn(f'{storage_file}: {scan.damage}; read {scan.message_count} messages before it')
            return


def _typename(scan: McapScan, record: ScannedMessage) -> str:
    schema = scan.schemas.get(record.channel.schema_id)
    return schema.name if schema is not None else ''


# --------------------------------------------------------------------------- summary


def read_bag_info(path: str | Path) -> BagInfo:
    """Summarize an intact bag: files, time span, and per topic type, count, hash and QoS.

    Raises:
        BagNotFoundError, CorruptBagError: as :func:`read_messages`.
    """
    files = _locate(Path(path))
    if files.problem is not None:
        raise BagNotFoundError(files.problem)
    from swarm_runtime.messages import get_typestore

    try:
        with AnyReader([files.root], default_typestore=get_typestore()) as reader:
            topics: dict[str, TopicSummary] = {}
            for connection in reader.connections:
                topics[connection.topic] = _summary(connection, topics.get(connection.topic))
            count = reader.message_count
            return BagInfo(
                path=files.root,
                storage_files=files.storage_files,
                start_time_ns=reader.start_time if count else 0,
                end_time_ns=reader.end_time - 1 if count else 0,
                message_count=count,
                topics=topics,
            )
    except _READ_ERRORS as err:
        msg = f'{_describe_files(files)}: cannot open the bag: {_error_text(err)}'
        raise CorruptBagError(msg) from err


def _summary(connection: Connection, previous: TopicSummary | None) -> TopicSummary:
    ext = connection.ext
    qos = tuple(ext.offered_qos_profiles) if isinstance(ext, ConnectionExtRosbag2) else ()
    if previous is not None:
        return TopicSummary(
            previous.topic,
            previous.typename,
            previous.message_count + connection.msgcount,
            previous.type_hash,
            previous.offered_qos_profiles + qos,
        )
    return TopicSummary(
        connection.topic, connection.msgtype, connection.msgcount, connection.digest, qos
    )
