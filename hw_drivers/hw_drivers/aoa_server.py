"""The TCP server the AoA locator host connects to.

The authors' locator binary is a TCP *client* that exits when it cannot connect, so this
side listens (on 127.0.0.1 by default) before the locator starts. One client at a time: a new
connection replaces the old one (a restarted locator must not be locked out by its own
half-dead predecessor). Every poll is bounded: one select with a short timeout and at most
``max_read_per_poll`` bytes, so a flooding client cannot starve the caller, and the JSON
decoder caps its buffer, so a slow or never-ending object cannot grow memory.
"""

from __future__ import annotations

import errno
import selectors
import socket
from collections.abc import Callable

from hw_drivers.aoa_protocol import AngleReport, JsonStreamDecoder, parse_angle_report
from hw_drivers.errors import DeviceUnavailableError, FatalDeviceError, ProtocolError

__all__ = ['LocatorServer']


class LocatorServer:
    """Listen for the locator, decode its JSON stream, hand valid reports to a callback.

    Args:
        host: address to bind (keep 127.0.0.1 unless the locator runs on another machine).
        port: TCP port (0 picks a free one; see :attr:`port`).
        on_report: receives each valid angle report (called from the polling thread).
        max_buffer_bytes: cap of the undecoded JSON text.
        max_read_per_poll: most bytes read in one poll.
        select_timeout_s: longest wait of one poll [s].

    Raises:
        DeviceUnavailableError: the port is in use (retry later).
        FatalDeviceError: the address cannot be bound for another reason (e.g. EACCES).
    """

    def __init__(
        self,
        host: str,
        port: int,
        on_report: Callable[[AngleReport], None],
        *,
        max_buffer_bytes: int = 16 * 1024,
        max_read_per_poll: int = 64 * 1024,
        select_timeout_s: float = 0.05,
    ) -> None:
        self._on_report = on_report
        self.max_read_per_poll = max_read_per_poll
        self.select_timeout_s = select_timeout_s
        self.decoder = JsonStreamDecoder(max_buffer_bytes=max_buffer_bytes)
        self._selector = selectors.DefaultSelector()
        self._listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self._listener.bind((host, port))
            self._listener.listen(2)
        except OSError as err:
            self._listener.close()
            self._selector.close()
            if err.errno in (errno.EADDRINUSE, errno.EADDRNOTAVAIL):
                raise DeviceUnavailableError(f'cannot listen on {host}:{port}: {err}') from err
            raise FatalDeviceError(f'cannot listen on {host}:{port}: {err}') from err
        self._listener.setblocking(False)
        self._selector.register(self._listener, selectors.EVENT_READ)
        # Read once: another thread may ask after the socket has been closed.
        self._port = int(self._listener.getsockname()[1])
        self._closed = False
        self._client: socket.socket | None = None
        self.client_address: tuple[str, int] | None = None
        self.connections = 0
        self.replaced_clients = 0
        self.disconnects = 0
        self.invalid_reports = 0
        self.ignored_objects = 0
        self.reports = 0
        self.last_error = ''

    @property
    def port(self) -> int:
        """The bound TCP port (still known after :meth:`close`)."""
        return self._port

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has run: the server no longer listens."""
        return self._closed

    @property
    def client_connected(self) -> bool:
        """True while a locator is connected."""
        return self._client is not None

    def poll(self) -> bool:
        """Accept or read once; return True when at least one report was delivered."""
        produced = False
        for key, _ in self._selector.select(self.select_timeout_s):
            if key.fileobj is self._listener:
                self._accept()
            elif key.fileobj is self._client:
                produced |= self._read()
        return produced

    def _accept(self) -> None:
        try:
            conn, address = self._listener.accept()
        except BlockingIOError:
            return
        if self._client is not None:
            self.replaced_clients += 1
            self._drop_client()
        conn.setblocking(False)
        self._client = conn
        self.client_address = address
        self.connections += 1
        self.decoder.reset()
        self._selector.register(conn, selectors.EVENT_READ)

    def _drop_client(self) -> None:
        client, self._client = self._client, None
        if client is not None:
            self._selector.unregister(client)
            client.close()
        self.client_address = None
        self.decoder.reset()

    def _read(self) -> bool:
        assert self._client is not None
        received = 0
        produced = False
        while received < self.max_read_per_poll:
            try:
                data = self._client.recv(min(4096, self.max_read_per_poll - received))
            except BlockingIOError:
                break
            except OSError as err:
                self.last_error = f'locator connection failed: {err}'
                data = b''
            if not data:
                self.disconnects += 1
                self._drop_client()
                break
            received += len(data)
            produced |= self._deliver(self.decoder.feed(data))
        return produced

    def _deliver(self, values: list[object]) -> bool:
        produced = False
        for value in values:
            try:
                report = parse_angle_report(value)
            except ProtocolError as err:
                self.invalid_reports += 1
                self.last_error = str(err)
                continue
            if report is None:
                self.ignored_objects += 1
                continue
            self.reports += 1
            self._on_report(report)
            produced = True
        return produced

    def close(self) -> None:
        """Close the client and the listening socket (again: nothing)."""
        if self._closed:
            return
        self._closed = True
        self._drop_client()
        self._selector.unregister(self._listener)
        self._listener.close()
        self._selector.close()
