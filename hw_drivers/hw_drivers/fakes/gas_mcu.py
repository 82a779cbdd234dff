"""The authors' gas microcontroller (Seeed XIAO M0) as a byte-level fake."""

from __future__ import annotations

from collections.abc import Callable

__all__ = ['FakeGasMcu', 'FakeGasMcuPort', 'xiao_reply']


def xiao_reply(counter: int, value: int) -> bytes:
    """One reply as the firmware prints it: a multi-line, tab-indented JSON object + CR LF."""
    text = f'{{\n\t"timeStamp": {counter},\n\t"type": "olfactory",\n\t"value": {value}\n}}\r\n'
    return text.encode()


class FakeGasMcu:
    """Answers every received byte with one reading of ``value()``; the counter increments.

    ``mangle`` may rewrite each reply (garbage, truncation, silence) for fault tests.
    """

    def __init__(self, value: Callable[[], int] = lambda: 84) -> None:
        self.value = value
        self.counter = 0
        self.mangle: Callable[[bytes], bytes] | None = None

    def handle(self, data: bytes) -> bytes:
        """Replies to the received bytes."""
        out = bytearray()
        for _ in data:
            reply = xiao_reply(self.counter, self.value())
            self.counter = (self.counter + 1) % 2**32
            out += self.mangle(reply) if self.mangle else reply
        return bytes(out)


class FakeGasMcuPort:
    """An in-memory SerialPort wired to a :class:`FakeGasMcu`."""

    def __init__(self, mcu: FakeGasMcu) -> None:
        self.mcu = mcu
        self._buffer = bytearray()
        self.closed = False
        self.unplugged = False

    def _check(self) -> None:
        if self.unplugged:
            raise OSError(5, 'Input/output error')

    @property
    def in_waiting(self) -> int:
        self._check()
        return len(self._buffer)

    def read(self, size: int = 1) -> bytes:
        self._check()
        data = bytes(self._buffer[:size])
        del self._buffer[:size]
        return data

    def write(self, data: bytes) -> int:
        self._check()
        self._buffer += self.mcu.handle(data)
        return len(data)

    def reset_input_buffer(self) -> None:
        self._buffer.clear()

    def close(self) -> None:
        self.closed = True
