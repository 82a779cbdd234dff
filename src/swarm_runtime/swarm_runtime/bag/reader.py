"""Reading rosbag2 bags (ours or a robot's ``ros2 bag record -s mcap``) as message objects.

:func:`read_messages` yields :class:`BagMessage` tuples in log-time order. Messages are
decoded with the definitions stored in the bag (see :mod:`swarm_runtime.bag.decoding`), into
the generated classes of :mod:`swarm_runtime.messages`, whichever runtime the process uses:
the shared classes where the bag's type is identical to this workspace's (same RIHS01 hash),
classes generated from the bag's definition otherwise. Analysis code therefore sees the same
objects on the built-in runtime and on real rclpy.

Damage is reported, never glossed over: a missing or unreadable file raises a
:class:`~swarm_runtime.bag.errors.BagError` that names the file and the problem, a chunk whose
CRC or structure is wrong is never decoded, and a message whose bytes do not fit its type
raises. With ``allow_truncated=True`` the reader recovers what it can instead: a file without
a usable summary (cut, unfinished) is walked record by record, damaged chunks are skipped and
reading resumes at the next intact one, the complete messages of a chunk cut off by the end
of the file are kept, and each loss is reported in a :class:`TruncatedBagWarning`.
"""

from __future__ import annotations

import fnmatch
import heapq
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import yaml
from rosbags.interfaces import Qos
from rosbags.rosbag2.metadata import parse_qos

from ..messages.errors import MessageError
from .decoding import Decoder, TypeDecision
from .errors import BagNotFoundError, BagTypeError, CorruptBagError
from .mcap_scan import Damage, McapLayout, Segment, SegmentDamageError, open_layout, read_segment

__all__ = [
    'BagDamage',
    'BagInfo',
    'BagMessage',
    'TopicSummary',
    'TruncatedBagWarning',
    'read_bag_info',
    'read_messages',
]


class TruncatedBagWarning(UserWarning):
    """A damaged bag was read with recovery; the text says what was lost, and where."""


class BagMessage(NamedTuple):
    """One recorded message: topic, full type name, log time [ns] and the message.

    ``message`` is a message object, or the CDR bytes when read with ``raw=True``.
    """

    topic: str
    typename: str
    log_time_ns: int
    message: Any


@dataclass(frozen=True)
class BagDamage:
    """Where a storage file is damaged and why (one line from :meth:`describe`)."""

    file: Path
    offset: int
    resumed_at: int | None
    reason: str

    def describe(self) -> str:
        """'<file>: at byte N: <reason>; reading resumed at byte M' (or: nothing after it)."""
        return f'{self.file}: {Damage(self.offset, self.resumed_at, self.reason).describe()}'


@dataclass(frozen=True)
class TopicSummary:
    """What a bag holds for one topic.

    ``recorded_count`` is the count metadata.yaml gives, when it differs from
    ``message_count`` (the messages that could be read from a damaged bag).
    """

    topic: str
    typename: str
    message_count: int
    type_hash: str
    offered_qos_profiles: tuple[Qos, ...]
    recorded_count: int | None = None


@dataclass(frozen=True)
class BagInfo:
    """Summary of a bag: its files, time span [ns], topics and, when recovered, its damage."""

    path: Path
    storage_files: tuple[Path, ...]
    start_time_ns: int
    end_time_ns: int
    message_count: int
    topics: dict[str, TopicSummary] = field(default_factory=dict)
    damage: tuple[BagDamage, ...] = ()
    recorded_message_count: int | None = None
    problems: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        """True when nothing in the bag was damaged or missing."""
        return not self.damage and not self.problems


# --------------------------------------------------------------------------- metadata.yaml


@dataclass(frozen=True)
class _TopicMetadata:
    name: str
    typename: str
    type_hash: str
    offered_qos_profiles: tuple[Qos, ...]
    message_count: int


@dataclass(frozen=True)
class _Metadata:
    files: tuple[str, ...]
    topics: dict[str, _TopicMetadata]
    message_count: int
    start_time_ns: int
    duration_ns: int


def _read_metadata(path: Path) -> _Metadata:
    try:
        document = yaml.safe_load(path.read_text(encoding='utf-8'))
        info = document['rosbag2_bagfile_information']
        storage = info.get('storage_identifier', 'mcap')
        if storage != 'mcap':
            msg = f'{path}: storage {storage!r} is not supported (only mcap bags are read)'
            raise CorruptBagError(msg)
        if (info.get('compression_mode') or '').lower() not in ('', 'none'):
            msg = (
                f'{path}: the bag is compressed as whole files '
                f'({info.get("compression_mode")}); decompress it first '
                '(ros2 bag convert) or record with chunk compression'
            )
            raise CorruptBagError(msg)
        topics: dict[str, _TopicMetadata] = {}
        for entry in info.get('topics_with_message_count') or []:
            meta = entry['topic_metadata']
            previous = topics.get(meta['name'])
            qos = tuple(parse_qos(meta.get('offered_qos_profiles') or []))
            count = int(entry.get('message_count', 0))
            if previous is not None:
                qos = previous.offered_qos_profiles + qos
                count += previous.message_count
            topics[meta['name']] = _TopicMetadata(
                meta['name'],
                meta['type'],
                meta.get('type_description_hash', '') or '',
                qos,
                count,
            )
        return _Metadata(
            files=tuple(str(name) for name in info['relative_file_paths']),
            topics=topics,
            message_count=int(info.get('message_count', 0)),
            start_time_ns=int(info['starting_time']['nanoseconds_since_epoch']),
            duration_ns=int(info['duration']['nanoseconds']),
        )
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError) as err:
        msg = f'{path}: not a valid rosbag2 metadata file ({_metadata_problem(err)})'
        raise CorruptBagError(msg) from err


def _metadata_problem(error: Exception) -> str:
    """What is wrong with a metadata.yaml, in the file's terms rather than Python's."""
    if isinstance(error, KeyError):
        return f'the field {error.args[0]!r} is missing'
    if isinstance(error, TypeError | AttributeError):
        return 'a field is missing or is not the mapping, list or number rosbag2 writes'
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__


# --------------------------------------------------------------------------- locating files


@dataclass(frozen=True)
class _BagFiles:
    root: Path
    storage_files: tuple[Path, ...]
    metadata: _Metadata | None
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
        return _BagFiles(path, (path,), None, None)

    on_disk = tuple(sorted(path.glob('*.mcap')))
    metadata_path = path / 'metadata.yaml'
    if not metadata_path.is_file():
        if not on_disk:
            msg = f'{path}: not a bag (no metadata.yaml and no .mcap file)'
            raise BagNotFoundError(msg)
        problem = f'{metadata_path} is missing (the recording was not closed)'
        return _BagFiles(path, on_disk, None, problem)
    metadata = _read_metadata(metadata_path)
    listed = tuple(path / Path(name).name for name in metadata.files)
    missing = [str(p) for p in listed if not p.is_file()]
    if missing:
        problem = f'{metadata_path} lists storage files that do not exist: {", ".join(missing)}'
        return _BagFiles(path, tuple(p for p in listed if p.is_file()) or on_disk, None, problem)
    return _BagFiles(path, listed, metadata, None)


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


# --------------------------------------------------------------------------- the bag's files


@dataclass(frozen=True)
class _Channel:
    """One MCAP channel with what the bag says about its type."""

    topic: str
    typename: str
    encoding: str
    definition: str
    type_hash: str
    offered_qos_profiles: tuple[Qos, ...]


class _Source:
    """The storage files of a bag, mapped, with the damage found so far."""

    def __init__(self, files: _BagFiles, *, recover: bool) -> None:
        self.files = files
        self.recover = recover
        self.layouts: list[McapLayout] = []
        self.channels: dict[tuple[int, int], _Channel] = {}
        self.damage: list[BagDamage] = []
        #: Files read by walking their records because their summary could not be used.
        self.notes: list[str] = []
        for index, storage_file in enumerate(files.storage_files):
            try:
                layout = open_layout(storage_file, walk=recover)
            except OSError as err:
                msg = f'{storage_file}: cannot read the file: {err.strerror or err}'
                raise CorruptBagError(msg) from err
            if layout.summary_problem is not None and not recover:
                msg = f'{storage_file}: cannot read the bag: {layout.summary_problem}'
                raise CorruptBagError(msg, recoverable=True)
            if layout.damage and not recover:
                msg = f'{storage_file}: damaged {layout.damage[0].describe()}'
                raise CorruptBagError(msg, recoverable=True)
            if layout.summary_problem is not None and not layout.damage:
                problem = layout.summary_problem
                self.notes.append(
                    f'{storage_file}: {problem}; its records were read from the start'
                )
            for damage in layout.damage:
                self.damage.append(
                    BagDamage(storage_file, damage.offset, damage.resumed_at, damage.reason)
                )
            self.layouts.append(layout)
            for channel_id, channel in layout.channels.items():
                self.channels[index, channel_id] = self._describe(layout, channel)

    def _describe(self, layout: McapLayout, channel: Any) -> _Channel:
        schema = layout.schemas.get(channel.schema_id)
        typename = schema.name if schema is not None else ''
        meta = self.files.metadata.topics.get(channel.topic) if self.files.metadata else None
        if meta is not None and meta.typename == typename:
            type_hash = meta.type_hash
            qos = meta.offered_qos_profiles
        else:
            type_hash = channel.metadata.get('topic_type_hash', '')
            try:
                qos = tuple(parse_qos(channel.metadata.get('offered_qos_profiles', '') or []))
            except (KeyError, TypeError, ValueError, AttributeError):
                qos = ()
        return _Channel(
            topic=channel.topic,
            typename=typename,
            encoding=schema.encoding if schema is not None else '',
            definition=schema.data if schema is not None else '',
            type_hash=type_hash,
            offered_qos_profiles=qos,
        )

    def raw(
        self, wanted: set[tuple[int, int]], on_damage: Callable[[BagDamage], None]
    ) -> Iterator[tuple[tuple[int, int], int, bytes]]:
        """(channel key, log time, CDR bytes) of the wanted channels, in log-time order."""
        per_file: dict[int, frozenset[int]] = {}
        for file_index, channel_id in wanted:
            per_file[file_index] = per_file.get(file_index, frozenset()) | {channel_id}
        pending: list[tuple[int, int, int, Segment]] = []
        for file_index in per_file:
            for segment in self.layouts[file_index].segments:
                pending.append((segment.start_ns, file_index, segment.offset, segment))
        pending.sort(key=lambda item: item[:3])
        heap: list[tuple[int, int, int, list[Any], int]] = []
        loaded = 0
        while True:
            while loaded < len(pending) and (not heap or pending[loaded][0] <= heap[0][0]):
                _, file_index, _, segment = pending[loaded]
                order = loaded
                loaded += 1
                layout = self.layouts[file_index]
                try:
                    messages = read_segment(layout, segment, per_file[file_index])
                except SegmentDamageError as err:
                    damage = BagDamage(layout.path, segment.offset, segment.end, str(err))
                    if not self.recover:
                        msg = f'{layout.path}: damaged data: {err}'
                        raise CorruptBagError(msg, recoverable=True) from err
                    self.damage.append(damage)
                    on_damage(damage)
                    continue
                if messages:
                    heapq.heappush(heap, (messages[0].log_time_ns, order, 0, messages, file_index))
            if not heap:
                return
            _, order, position, messages, file_index = heapq.heappop(heap)
            message = messages[position]
            if position + 1 < len(messages):
                heapq.heappush(
                    heap,
                    (messages[position + 1].log_time_ns, order, position + 1, messages, file_index),
                )
            yield (file_index, message.channel_id), message.log_time_ns, message.data


def _warn(text: str) -> None:
    warnings.warn(text, TruncatedBagWarning, stacklevel=4)


def _open_source(files: _BagFiles, *, recover: bool) -> _Source:
    if files.problem is not None:
        if not recover:
            raise BagNotFoundError(files.problem, recoverable=bool(files.storage_files))
        _warn(f'{files.problem}; reading the .mcap files it holds')
    return _Source(files, recover=recover)


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
        allow_truncated: Recover a damaged bag: read every intact part of it, skip the
            damage, and report each loss with a :class:`TruncatedBagWarning`.
        raw: Yield the CDR bytes instead of decoding them.

    Raises:
        BagNotFoundError: the bag, its metadata.yaml or a listed file does not exist (raised
            by the call itself).
        CorruptBagError: the bag is damaged (raised on the first ``next()`` when the file's
            structure is, or while iterating at a damaged chunk or message, after every
            message before it).
        BagTypeError: a selected topic's type cannot be decoded (on the first ``next()``).
    """
    files = _locate(Path(path))
    if files.problem is not None and (not allow_truncated or not files.storage_files):
        raise BagNotFoundError(files.problem, recoverable=bool(files.storage_files))
    return _iterate(files, _topic_filter(topics), recover=allow_truncated, raw=raw)


def _iterate(
    files: _BagFiles, selected: Callable[[str], bool], *, recover: bool, raw: bool
) -> Iterator[BagMessage]:
    source = _open_source(files, recover=recover)
    for note in source.notes:
        _warn(note)
    for damage in source.damage:
        _warn(damage.describe())
    decoder = Decoder()
    decisions: dict[tuple[int, int], TypeDecision | None] = {}
    for key, channel in source.channels.items():
        if not selected(channel.topic):
            continue
        if raw:
            decisions[key] = None
            continue
        try:
            decisions[key] = decoder.decision(
                channel.topic,
                channel.typename,
                channel.encoding,
                channel.definition,
                channel.type_hash,
            )
        except BagTypeError as err:
            if not recover:
                raise
            _warn(f'{err}; skipped')
    for key, log_time, data in source.raw(
        set(decisions), lambda damage: _warn(f'{damage.describe()}; that chunk was skipped')
    ):
        channel = source.channels[key]
        decision = decisions[key]
        if decision is None:
            message: Any = data
        else:
            try:
                message = decision.decode(data)
            except MessageError as err:
                problem = (
                    f'{files.storage_files[key[0]]}: the message on {channel.topic} at '
                    f'{log_time} ns does not decode as {channel.typename} ({err})'
                )
                if not recover:
                    raise CorruptBagError(problem) from err
                _warn(f'{problem}; skipped')
                continue
        yield BagMessage(channel.topic, channel.typename, log_time, message)


# --------------------------------------------------------------------------- summary


def read_bag_info(path: str | Path, *, allow_truncated: bool = False) -> BagInfo:
    """Summarize a bag: files, time span, and per topic type, count, hash and offered QoS.

    With ``allow_truncated`` a damaged bag is summarized as far as it can be read: every
    chunk is read and checked, counts are what can be read, ``damage`` says where the rest
    was lost and each topic's ``recorded_count`` what metadata.yaml promised.

    Raises:
        BagNotFoundError, CorruptBagError: as :func:`read_messages` (without recovery).
    """
    files = _locate(Path(path))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', TruncatedBagWarning)
        source = _open_source(files, recover=allow_truncated)
        if not allow_truncated:
            return _info_from_summaries(files, source)
        counts: dict[str, int] = {}
        start: int | None = None
        end = 0
        for key, log_time, _ in source.raw(set(source.channels), lambda damage: None):
            topic = source.channels[key].topic
            counts[topic] = counts.get(topic, 0) + 1
            start = log_time if start is None else min(start, log_time)
            end = max(end, log_time)
    topics: dict[str, TopicSummary] = {}
    for channel in source.channels.values():
        topics.setdefault(
            channel.topic,
            TopicSummary(
                channel.topic,
                channel.typename,
                counts.get(channel.topic, 0),
                channel.type_hash,
                channel.offered_qos_profiles,
            ),
        )
    metadata = files.metadata
    if metadata is not None:
        for name, meta in metadata.topics.items():
            summary = topics.get(name)
            if summary is None:
                topics[name] = TopicSummary(
                    name, meta.typename, 0, meta.type_hash, meta.offered_qos_profiles, None
                )
                summary = topics[name]
            if meta.message_count != summary.message_count:
                topics[name] = TopicSummary(
                    summary.topic,
                    summary.typename,
                    summary.message_count,
                    summary.type_hash,
                    summary.offered_qos_profiles,
                    meta.message_count,
                )
    total = sum(counts.values())
    return BagInfo(
        path=files.root,
        storage_files=files.storage_files,
        start_time_ns=start if start is not None else 0,
        end_time_ns=end,
        message_count=total,
        topics=topics,
        damage=tuple(source.damage),
        recorded_message_count=metadata.message_count if metadata is not None else None,
        problems=((files.problem,) if files.problem else ()) + tuple(source.notes),
    )


def _info_from_summaries(files: _BagFiles, source: _Source) -> BagInfo:
    counts: dict[str, int] = {}
    topics: dict[str, TopicSummary] = {}
    start: int | None = None
    end = 0
    for (file_index, channel_id), channel in source.channels.items():
        layout = source.layouts[file_index]
        counts[channel.topic] = counts.get(channel.topic, 0) + layout.channel_counts.get(
            channel_id, 0
        )
        topics.setdefault(
            channel.topic,
            TopicSummary(
                channel.topic, channel.typename, 0, channel.type_hash, channel.offered_qos_profiles
            ),
        )
    for layout in source.layouts:
        for segment in layout.segments:
            start = segment.start_ns if start is None else min(start, segment.start_ns)
            end = max(end, segment.end_ns)
    metadata = files.metadata
    if metadata is not None:
        for name, meta in metadata.topics.items():
            counts[name] = meta.message_count
            topics[name] = TopicSummary(
                name, meta.typename, 0, meta.type_hash, meta.offered_qos_profiles
            )
        if metadata.message_count:
            start = metadata.start_time_ns
            end = metadata.start_time_ns + metadata.duration_ns
    topics = {
        name: TopicSummary(
            s.topic, s.typename, counts.get(name, 0), s.type_hash, s.offered_qos_profiles
        )
        for name, s in topics.items()
    }
    total = sum(counts.values())
    return BagInfo(
        path=files.root,
        storage_files=files.storage_files,
        start_time_ns=start if (start is not None and total) else 0,
        end_time_ns=end if total else 0,
        message_count=total,
        topics=topics,
    )
