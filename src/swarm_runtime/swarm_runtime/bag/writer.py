"""Writing rosbag2 directories (metadata.yaml + one .mcap).

The bag is what ``ros2 bag record -s mcap`` produces: rosbag2 metadata version 9, storage
``mcap``, serialization ``cdr``, and for each topic its offered QoS profiles and the type's
RIHS01 hash (in metadata.yaml and, as rosbag2 does, in the MCAP channel's ``topic_type_hash``),
so ``ros2 bag info``, ``ros2 bag play`` and Foxglove open it.

rosbags' ``Writer`` writes metadata.yaml; the MCAP file itself is written by the ``mcap``
library (plugged into rosbags' writer as its MCAP storage), because rosbags' own MCAP writer
leaves the chunk CRCs at 0: with a CRC every chunk is checked when it is read, so damage inside
a chunk is detected instead of decoded.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial
from pathlib import Path
from types import TracebackType
from typing import Any

from mcap.writer import CompressionType
from mcap.writer import Writer as McapLibraryWriter
from rosbags.interfaces import Connection, MessageDefinitionFormat, Qos
from rosbags.rosbag2 import StoragePlugin, Writer, WriterError
from rosbags.typesys.store import Typestore

from .errors import BagWriteError

__all__ = ['BAG_VERSION', 'CHUNK_COMPRESSIONS', 'DEFAULT_CHUNK_SIZE_BYTES', 'BagWriter']

#: rosbag2 metadata version written (Jazzy's).
BAG_VERSION = 9
#: Uncompressed size at which an MCAP chunk is closed (rosbag2's MCAP plugin uses 768 KiB).
DEFAULT_CHUNK_SIZE_BYTES = 768 * 1024
#: Chunk compressions :class:`BagWriter` can write.
CHUNK_COMPRESSIONS = {
    'none': CompressionType.NONE,
    'zstd': CompressionType.ZSTD,
    'lz4': CompressionType.LZ4,
}
_LIBRARY = 'swarm_runtime.bag'


class _McapStorage:
    """rosbags' storage-writer interface, implemented with the ``mcap`` library (with CRCs)."""

    def __init__(
        self, path: Path, compression: Any, *, chunk_compression: str, chunk_size_bytes: int
    ) -> None:
        del compression  # rosbag2 file/message compression: never enabled by BagWriter
        self.path = path / f'{path.name}.mcap'
        self._stream = self.path.open('xb')
        self._mcap = McapLibraryWriter(
            self._stream,
            chunk_size=chunk_size_bytes,
            compression=CHUNK_COMPRESSIONS[chunk_compression],
            enable_crcs=True,
        )
        self._mcap.start(profile='ros2', library=_LIBRARY)
        self._schemas: dict[str, int] = {}
        self._channels: dict[int, int] = {}

    def add_msgtype(self, connection: Connection) -> None:
        idl = connection.msgdef.format == MessageDefinitionFormat.IDL
        encoding = 'ros2idl' if idl else 'ros2msg'
        self._schemas[connection.msgtype] = self._mcap.register_schema(
            connection.msgtype, encoding, connection.msgdef.data.encode('utf-8')
        )

    def add_connection(self, connection: Connection, offered_qos_profiles: str) -> None:
        metadata = {'offered_qos_profiles': offered_qos_profiles}
        if connection.digest:
            metadata['topic_type_hash'] = connection.digest
        self._channels[connection.id] = self._mcap.register_channel(
            connection.topic, 'cdr', self._schemas[connection.msgtype], metadata
        )

    def write(self, connection: Connection, timestamp: int, data: bytes | memoryview) -> None:
        self._mcap.add_message(
            self._channels[connection.id], timestamp, bytes(data), publish_time=timestamp
        )

    def flush(self) -> None:
        self._mcap.flush()

    def close(self, version: int, metadata: str) -> None:
        del version
        self._mcap.flush()  # the last chunk before the metadata record, as in rosbag2's files
        self._mcap.add_metadata('rosbag2', {'serialized_metadata': metadata})
        self._mcap.finish()
        self._stream.close()

    def abort(self) -> None:
        self._stream.close()


def _serialize(message: Any) -> tuple[str, bytes]:
    """Type name and CDR bytes of a generated message or of a real rclpy one."""
    from swarm_runtime.messages import is_message, message_typename, serialize_cdr

    typename = message_typename(message)
    if is_message(message):
        return typename, serialize_cdr(message)
    from rclpy.serialization import serialize_message  # a real rosidl message

    return typename, serialize_message(message)


class BagWriter:
    """Create a rosbag2 bag at ``path`` (a new directory) and write CDR messages into it.

    Use as a context manager or call :meth:`open` and :meth:`close`. Closing writes the MCAP
    summary and metadata.yaml; it also happens when the ``with`` block exits with an error, so
    whatever was recorded before the error is kept.

    Args:
        path: Directory to create; it must not exist.
        typestore: Types whose definitions and RIHS01 hashes are written (default: the
            ROS 2 Jazzy types plus swarm_interfaces, :func:`swarm_runtime.messages.get_typestore`).
        chunk_compression: 'none' (default: a cut bag then keeps the whole messages of its
            last, partial chunk), 'zstd' or 'lz4'.
        chunk_size_bytes: Uncompressed chunk size at which a chunk is closed.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        typestore: Typestore | None = None,
        chunk_compression: str = 'none',
        chunk_size_bytes: int = DEFAULT_CHUNK_SIZE_BYTES,
    ) -> None:
        self._path = Path(path)
        if self._path.exists():
            msg = f'{self._path} exists already; a bag is never overwritten'
            raise BagWriteError(msg)
        if chunk_compression not in CHUNK_COMPRESSIONS:
            msg = f'chunk_compression must be one of {", ".join(CHUNK_COMPRESSIONS)}'
            raise ValueError(msg)
        if chunk_size_bytes <= 0:
            msg = 'chunk_size_bytes must be positive'
            raise ValueError(msg)
        if typestore is None:
            from swarm_runtime.messages import get_typestore

            typestore = get_typestore()
        self._typestore = typestore
        self._writer = Writer(self._path, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
        # An instance attribute shadows rosbags' class-level plugin table for this writer only.
        self._writer.STORAGE_PLUGINS = {  # type: ignore[misc]
            StoragePlugin.MCAP: partial(
                _McapStorage,
                chunk_compression=chunk_compression,
                chunk_size_bytes=int(chunk_size_bytes),
            )
        }
        self._connections: dict[str, Connection] = {}
        self._state = 'new'

    @property
    def path(self) -> Path:
        """The bag directory."""
        return self._path

    @property
    def mcap_path(self) -> Path:
        """The MCAP storage file inside the bag directory."""
        return self._path / f'{self._path.name}.mcap'

    @property
    def is_open(self) -> bool:
        """True between :meth:`open` and :meth:`close`."""
        return self._state == 'open'

    @property
    def topics(self) -> dict[str, str]:
        """Topic name -> type name of every topic added so far."""
        return {topic: connection.msgtype for topic, connection in self._connections.items()}

    def type_hash(self, topic: str) -> str:
        """RIHS01 hash recorded for an added topic."""
        return self._connections[topic].digest

    def open(self) -> None:
        """Create the directory and the MCAP file."""
        if self._state != 'new':
            msg = f'{self._path}: the writer was already opened'
            raise BagWriteError(msg)
        try:
            self._writer.open()
        except (WriterError, OSError) as err:
            msg = f'cannot create bag {self._path}: {err}'
            raise BagWriteError(msg) from err
        self._state = 'open'

    def __enter__(self) -> BagWriter:
        self.open()
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    def _require_open(self) -> None:
        if self._state != 'open':
            msg = f'{self._path}: the bag is not open for writing ({self._state})'
            raise BagWriteError(msg)

    def add_topic(
        self,
        topic: str,
        typename: str,
        *,
        offered_qos_profiles: Sequence[Qos] = (),
        definition: str | None = None,
        type_hash: str | None = None,
    ) -> None:
        """Declare ``topic`` of type ``typename`` ('sensor_msgs/msg/LaserScan').

        The definition and RIHS01 hash written come from the typestore, or from
        ``definition`` (rosbag2's ros2msg text: the type, then each dependency after a
        ``====`` line and ``MSG: pkg/Type``) and ``type_hash`` for a type it does not hold.

        Raises:
            BagWriteError: the type is unknown to the typestore and no definition was given,
                or the topic was already added with another type.
        """
        self._require_open()
        known = self._connections.get(topic)
        if known is not None:
            if known.msgtype != typename:
                msg = (
                    f'{self._path}: topic {topic!r} is recorded as {known.msgtype}, '
                    f'cannot add it again as {typename}'
                )
                raise BagWriteError(msg)
            return
        if definition is None and typename not in self._typestore.fielddefs:
            msg = f'{self._path}: cannot record {topic!r}: message type {typename!r} is unknown'
            raise BagWriteError(msg)
        if definition is not None and not type_hash:
            from .decoding import definition_hash

            type_hash = definition_hash(typename, definition)
        try:
            if definition is None:
                connection = self._writer.add_connection(
                    topic,
                    typename,
                    typestore=self._typestore,
                    serialization_format='cdr',
                    offered_qos_profiles=list(offered_qos_profiles),
                )
            else:
                connection = self._writer.add_connection(
                    topic,
                    typename,
                    msgdef=definition,
                    rihs01=type_hash,
                    serialization_format='cdr',
                    offered_qos_profiles=list(offered_qos_profiles),
                )
        except (WriterError, OSError) as err:
            msg = f'{self._path}: cannot add topic {topic!r}: {err}'
            raise BagWriteError(msg) from err
        self._connections[topic] = connection

    def add_offered_qos(
        self, topic: str, profiles: Sequence[Qos], *, replace: bool = False
    ) -> None:
        """Add (or, with ``replace``, substitute) offered QoS profiles of an added topic.

        For publishers that appeared after the topic was added. They are written into
        metadata.yaml when the bag is closed (the MCAP channel keeps the profiles known when
        the topic was added).
        """
        self._require_open()
        connection = self._connections.get(topic)
        if connection is None:
            msg = f'{self._path}: topic {topic!r} was not added'
            raise BagWriteError(msg)
        recorded = connection.ext.offered_qos_profiles  # type: ignore[union-attr]
        if replace:
            recorded.clear()
        recorded.extend(profiles)

    def write(self, topic: str, log_time_ns: int, data: bytes | memoryview) -> None:
        """Append one CDR-serialized message of an added topic, stamped ``log_time_ns``."""
        self._require_open()
        connection = self._connections.get(topic)
        if connection is None:
            msg = f'{self._path}: topic {topic!r} was not added before writing'
            raise BagWriteError(msg)
        try:
            self._writer.write(connection, int(log_time_ns), data)
        except (WriterError, OSError) as err:
            msg = f'{self._path}: cannot write a message of {topic!r}: {err}'
            raise BagWriteError(msg) from err

    def write_message(self, topic: str, log_time_ns: int, message: Any) -> None:
        """Serialize a message and append it; adds the topic on first use.

        ``message`` is a generated message (:mod:`swarm_runtime.messages`, what
        :func:`read_messages` returns) or, in a process with real rclpy, a real one.
        """
        typename, data = _serialize(message)
        if topic not in self._connections:
            self.add_topic(topic, typename)
        self.write(topic, log_time_ns, data)

    def flush(self) -> None:
        """Push buffered messages to the MCAP file, so a crash cannot lose them.

        Closes the current MCAP chunk early and flushes the file. A bag whose writer never
        got to :meth:`close` is then readable up to this point with recovery
        (``read_messages(..., allow_truncated=True)``).
        """
        self._require_open()
        storage = self._writer.storage
        try:
            if isinstance(storage, _McapStorage):
                storage.flush()
        except OSError as err:
            msg = f'{self._path}: cannot flush the bag: {err}'
            raise BagWriteError(msg) from err

    def close(self) -> None:
        """Write the MCAP summary and metadata.yaml; safe to call more than once."""
        if self._state != 'open':
            self._state = 'closed'
            return
        self._state = 'closed'
        try:
            self._writer.close()
        except (WriterError, OSError) as err:
            msg = f'{self._path}: cannot finish the bag: {err}'
            raise BagWriteError(msg) from err
