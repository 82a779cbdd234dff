"""Exceptions raised while recording, reading or replaying rosbag2 bags."""

from __future__ import annotations

__all__ = ['BagError', 'BagNotFoundError', 'BagTypeError', 'BagWriteError', 'CorruptBagError']


class BagError(Exception):
    """Base class of every bag error; the message (one line) names the file and what is wrong.

    ``recoverable`` is True when reading with recovery would get messages out of the bag
    (a cut or damaged file, a recording that was never closed).
    """

    def __init__(self, message: str, *, recoverable: bool = False) -> None:
        super().__init__(message)
        self.recoverable = recoverable


class BagNotFoundError(BagError, FileNotFoundError):
    """The bag directory, its metadata.yaml or a storage file it lists does not exist."""


class CorruptBagError(BagError):
    """A bag file is truncated or damaged, or holds data that cannot be decoded."""


class BagTypeError(BagError):
    """A topic's messages cannot be decoded: no definition fits its recorded type hash."""


class BagWriteError(BagError):
    """A bag cannot be created or written."""
