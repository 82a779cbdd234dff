"""Payloads in the AoA locator's formats and a TCP client that plays the locator."""

from __future__ import annotations

import json
import socket

__all__ = ['FakeLocatorClient', 'authors_payload', 'ndjson_payload']


def authors_payload(
    sequence: int,
    tag_id: str,
    azimuth_deg: float,
    *,
    distance_m: float = 1.5,
    elevation_deg: float = 10.0,
    quality: int = 0,
) -> bytes:
    """One report as the authors' locator sends it: tab-indented lines, ends with CR LF."""
    text = (
        '{\n'
        f'\t"timeStamp":\t{sequence},\n'
        '\t"type":\t"auditory",\n'
        f'\t"tagId":\t"{tag_id}",\n'
        f'\t"azimuth":\t{azimuth_deg:.6f},\n'
        f'\t"distance":\t{distance_m:.6f},\n'
        f'\t"elevation":\t{elevation_deg:.6f},\n'
        f'\t"quality":\t{quality}\n'
        '}\r\n'
    )
    return text.encode()


def ndjson_payload(sequence: int, tag_id: str, azimuth_deg: float, **extra: object) -> bytes:
    """One report as compact single-line JSON ending in a newline."""
    obj = {'sequence': sequence, 'tagId': tag_id, 'azimuth': azimuth_deg, **extra}
    return json.dumps(obj, separators=(',', ':')).encode() + b'\n'


class FakeLocatorClient:
    """A TCP client on the loopback interface that sends locator payloads."""

    def __init__(self, port: int, host: str = '127.0.0.1', timeout_s: float = 2.0) -> None:
        self.sock = socket.create_connection((host, port), timeout=timeout_s)

    def send(self, data: bytes) -> None:
        """Send bytes as they are."""
        self.sock.sendall(data)

    def close(self) -> None:
        """Close the connection."""
        self.sock.close()
