"""Exceptions raised while recording, reading or replaying rosbag2 bags."""

from __future__ import annotations

__all__ = ['BagError', 'BagNotFoundError', 'BagWriteError', 'CorruptBagError']


class BagError(Exception):
    """Base class of every bag error; the message names the file and what is wrong."""


class BagNotFoundError(BagError, FileNotFoundError):
    """The bag directory, its metadata.yaml or a storage file it lists does not exist."""


class CorruptBagError(BagError):
    """A bag file is truncated or damaged, or holds data that cannot be decoded."""


class BagWriteError(BagError):
    """A bag cannot be created or written."""
