"""Writing rosbag2 directories (metadata.yaml + one .mcap) with rosbags' Writer.

The bag is what ``ros2 bag record -s mcap`` produces: rosbag2 metadata version 9, storage
``mcap``, serialization ``cdr``, and for each topic its offered QoS profiles and the type's
RIHS01 hash, so ``ros2 bag info``, ``ros2 bag play`` and Foxglove open it.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.interfaces import Connection, Qos
from rosbags.rosbag2 import StoragePlugin, Writer, WriterError
from rosbags.typesys.store import Typestore

from .errors import BagWriteError

__all__ = ['BAG_VERSION', 'BagWriter']

#: rosbag2 metadata version written (Jazzy's).
BAG_VERSION = 9


class BagWriter:
    """Create a rosbag2 bag at ``path`` (a new directory) and write CDR messages into it.

    Use as a context manager or call :meth:`open` and :meth:`close`. Closing writes the MCAP
    summary and metadata.yaml; it also happens when the ``with`` block exits with an error, so
    whatever was recorded before the error is kept.

    Args:
        path: Directory to create; it must not exist.
        typestore: Types whose definitions and RIHS01 hashes are written (default: the
            ROS 2 Jazzy types plus swarm_interfaces, :func:`swarm_runtime.messages.get_typestore`).
    """

    def __init__(self, path: str | Path, *, typestore: Typestore | None = None) -> None:
        self._path = Path(path)
        if self._path.exists():
            msg = f'{self._path} exists already; a bag is never overwritten'
            raise BagWriteError(msg)
        if typestore is None:
            from swarm_runtime.messages import get_typestore

            typestore = get_typestore()
        self._typestore = typestore
        self._writer = Writer(self._path, version=BAG_VERSION, storage_plugin=StoragePlugin.MCAP)
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
        self, topic: str, typename: str, *, offered_qos_profiles: Sequence[Qos] = ()
    ) -> None:
        """Declare ``topic`` of type ``typename`` ('sensor_msgs/msg/LaserScan').

        Raises:
            BagWriteError: the type is unknown to the typestore, or the topic was already
                added with another type.
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
        if typename not in self._typestore.fielddefs:
            msg = f'{self._path}: cannot record {topic!r}: message type {typename!r} is unknown'
            raise BagWriteError(msg)
        try:
            self._connections[topic] = self._writer.add_connection(
                topic,
                typename,
                typestore=self._typestore,
                serialization_format='cdr',
                offered_qos_profiles=list(offered_qos_profiles),
            )
        except (WriterError, OSError) as err:
            msg = f'{self._path}: cannot add topic {topic!r}: {err}'
            raise BagWriteError(msg) from err

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
        """Serialize a generated message and append it; adds the topic on first use."""
        from swarm_runtime.messages import message_typename, serialize_cdr

        if topic not in self._connections:
            self.add_topic(topic, message_typename(message))
        self.write(topic, log_time_ns, serialize_cdr(message))

    def flush(self) -> None:
        """Push buffered messages to the MCAP file, so a crash cannot lose them.

        Closes the current MCAP chunk early and flushes the file. A bag whose writer never
        got to :meth:`close` is then readable up to this point with
        ``read_messages(..., allow_truncated=True)``.
        """
        self._require_open()
        storage = self._writer.storage
        chunk = getattr(storage, 'chunk', None)
        try:
            if chunk is not None and chunk.bio.tell():
                storage.close_chunk()  # type: ignore[union-attr]
            bio = getattr(storage, 'bio', None)
            if bio is not None:
                bio.flush()
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
