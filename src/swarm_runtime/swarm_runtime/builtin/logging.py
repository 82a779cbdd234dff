"""``rclpy.logging``: rcutils-style loggers backed by Python's :mod:`logging`.

A ROS logger named ``r0.algo`` (a node ``algo`` in namespace ``/r0``) writes to the Python
logger ``ros.r0.algo``, so the usual Python tools apply: ``caplog`` in tests, handlers and
levels set with :mod:`logging` (``logging.getLogger('ros.r0').setLevel(logging.DEBUG)``).
Severities have the same numbers as Python levels (FATAL is CRITICAL).

``rclpy.init()`` (``Context.init(initialize_logging=True)``) sets the default severity to INFO,
as rcutils does, and attaches a console handler to the ``ros`` logger that prints
``[INFO] [<time>] [r0.algo]: message`` to stderr, but only while the application has not
configured Python logging itself (the root logger has no handlers); otherwise records simply
propagate to the application's handlers.
"""

from __future__ import annotations

import logging as _py_logging
import sys
from enum import IntEnum
from types import CodeType
from typing import Any

__all__ = [
    'PYTHON_ROOT_LOGGER',
    'LoggingSeverity',
    'RcutilsLogger',
    'clear_config',
    'get_logger',
    'get_logger_effective_level',
    'initialize',
    'set_logger_level',
    'shutdown',
]

#: Name of the Python logger that every ROS logger lives under.
PYTHON_ROOT_LOGGER = 'ros'

_FILTER_OPTIONS = ('throttle_duration_sec', 'throttle_time_source_type', 'skip_first', 'once')


class LoggingSeverity(IntEnum):
    """Log severities (rcutils values, equal to Python's levels)."""

    UNSET = 0
    DEBUG = 10
    INFO = 20
    WARN = 30
    ERROR = 40
    FATAL = 50


_LEVEL_NAMES = {
    LoggingSeverity.DEBUG: 'DEBUG',
    LoggingSeverity.INFO: 'INFO',
    LoggingSeverity.WARN: 'WARN',
    LoggingSeverity.ERROR: 'ERROR',
    LoggingSeverity.FATAL: 'FATAL',
}


def _python_logger(name: str) -> _py_logging.Logger:
    return _py_logging.getLogger(f'{PYTHON_ROOT_LOGGER}.{name}' if name else PYTHON_ROOT_LOGGER)


def _severity_of(level: int) -> LoggingSeverity:
    """The severity at or below a Python level (a custom level 25 reads as INFO)."""
    for severity in sorted(LoggingSeverity, reverse=True):
        if level >= severity:
            return severity
    return LoggingSeverity.UNSET


class _CallSite:
    """Filter state of one logging call site (rclpy keeps one per caller)."""

    __slots__ = ('filters', 'first_skipped', 'last_logged_ns', 'logged_once', 'options', 'severity')

    def __init__(self, severity: LoggingSeverity, options: dict[str, Any]) -> None:
        self.severity = severity
        self.options = options
        self.filters = tuple(
            key for key in ('throttle', 'skip_first', 'once') if _wants(key, options)
        )
        self.last_logged_ns = 0
        self.first_skipped = False
        self.logged_once = False

    def should_log(self) -> bool:
        # Like rcutils, every filter updates its state even when an earlier one said no.
        decision = True
        if 'throttle' in self.filters:
            clock = self.options['throttle_time_source_type']
            now = clock.now().nanoseconds
            if now >= self.last_logged_ns + self.options['throttle_duration_sec'] * 1e9:
                self.last_logged_ns = now
            else:
                decision = False
        if 'skip_first' in self.filters and not self.first_skipped:
            self.first_skipped = True
            decision = False
        if 'once' in self.filters:
            if self.logged_once:
                decision = False
            self.logged_once = True
        return decision


def _wants(filter_name: str, options: dict[str, Any]) -> bool:
    if filter_name == 'throttle':
        return bool(options.get('throttle_duration_sec'))
    return bool(options.get(filter_name))


class RcutilsLogger:
    """A named ROS logger (what ``node.get_logger()`` returns)."""

    def __init__(self, name: str = '') -> None:
        self.name = name
        self._logger = _python_logger(name)
        self._call_sites: dict[tuple[CodeType, int], _CallSite] = {}

    def get_child(self, name: str) -> RcutilsLogger:
        """Return the logger ``<this name>.<name>``."""
        if not name:
            raise ValueError('Child logger name must not be empty.')
        return RcutilsLogger(f'{self.name}.{name}' if self.name else name)

    def set_level(self, level: LoggingSeverity | int) -> None:
        """Set this logger's severity threshold."""
        self._logger.setLevel(int(LoggingSeverity(level)))

    def get_effective_level(self) -> LoggingSeverity:
        """Return the severity threshold in effect (own or inherited)."""
        return _severity_of(self._logger.getEffectiveLevel())

    def is_enabled_for(self, severity: LoggingSeverity | int) -> bool:
        """Whether a message of this severity would be logged."""
        return self._logger.isEnabledFor(int(LoggingSeverity(severity)))

    def log(self, message: str, severity: LoggingSeverity | int, **kwargs: Any) -> bool:
        """Log ``message``; return False when the severity or a filter suppressed it.

        Keyword options (rclpy's): ``throttle_duration_sec`` (with optional
        ``throttle_time_source_type``, a Clock; default the system clock), ``skip_first``,
        ``once``, and ``name`` to log under another logger name.

        Raises:
            TypeError: an unknown option, or a message that is not a str.
            ValueError: a call site changed its severity or options between calls.
        """
        return self._log(message, severity, kwargs)

    def _log(self, message: str, severity: LoggingSeverity | int, options: dict[str, Any]) -> bool:
        # Frames: caller -> debug()/info()/... or log() -> _log().
        if not isinstance(message, str):
            msg = f'log message must be a str, got {type(message).__name__}'
            raise TypeError(msg)
        severity = LoggingSeverity(severity)
        logger = self._logger
        if options and 'name' in options:
            options = dict(options)
            logger = _python_logger(options.pop('name'))
        if not logger.isEnabledFor(severity):
            return False
        if options:
            caller = sys._getframe(2)
            if not self._passes_filters((caller.f_code, caller.f_lasti), severity, options):
                return False
        logger.log(severity, message, stacklevel=3)
        return True

    def _passes_filters(
        self, site_key: tuple[CodeType, int], severity: LoggingSeverity, options: dict[str, Any]
    ) -> bool:
        unknown = [key for key in options if key not in _FILTER_OPTIONS]
        if unknown:
            msg = (
                f'parameter "{unknown[0]}" is not one of the recognized logging options '
                f'"{list(_FILTER_OPTIONS)}"'
            )
            raise TypeError(msg)
        options = dict(options)
        if options.get('throttle_duration_sec') and not options.get('throttle_time_source_type'):
            from .clock import Clock

            options['throttle_time_source_type'] = Clock()
        site = self._call_sites.get(site_key)
        if site is None:
            site = _CallSite(severity, options)
            self._call_sites[site_key] = site
        elif site.severity != severity:
            raise ValueError('Logger severity cannot be changed between calls.')
        elif any(
            site.options.get(key) != options.get(key)
            for key in _FILTER_OPTIONS
            if key != 'throttle_time_source_type'
        ):
            raise ValueError('Logging filter parameters cannot be changed between calls.')
        return site.should_log()

    def debug(self, message: str, **kwargs: Any) -> bool:
        """Log with DEBUG severity."""
        return self._log(message, LoggingSeverity.DEBUG, kwargs)

    def info(self, message: str, **kwargs: Any) -> bool:
        """Log with INFO severity."""
        return self._log(message, LoggingSeverity.INFO, kwargs)

    def warning(self, message: str, **kwargs: Any) -> bool:
        """Log with WARN severity."""
        return self._log(message, LoggingSeverity.WARN, kwargs)

    def warn(self, message: str, **kwargs: Any) -> bool:
        """Log with WARN severity (deprecated spelling)."""
        return self._log(message, LoggingSeverity.WARN, kwargs)

    def error(self, message: str, **kwargs: Any) -> bool:
        """Log with ERROR severity."""
        return self._log(message, LoggingSeverity.ERROR, kwargs)

    def fatal(self, message: str, **kwargs: Any) -> bool:
        """Log with FATAL severity."""
        return self._log(message, LoggingSeverity.FATAL, kwargs)


def get_logger(name: str) -> RcutilsLogger:
    """Return the ROS logger ``name``.

    Raises:
        ValueError: an empty name.
    """
    if not name:
        raise ValueError('Logger name must not be empty.')
    return RcutilsLogger(name)


def set_logger_level(name: str, level: LoggingSeverity | int, detailed_error: bool = False) -> None:
    """Set the severity threshold of the ROS logger ``name``."""
    _python_logger(name).setLevel(int(LoggingSeverity(level)))


def get_logger_effective_level(name: str) -> LoggingSeverity:
    """Return the severity threshold in effect for the ROS logger ``name``."""
    return _severity_of(_python_logger(name).getEffectiveLevel())


class _ConsoleFallbackHandler(_py_logging.Handler):
    """Prints ROS log records like rcutils, unless the application configured logging."""

    def emit(self, record: _py_logging.LogRecord) -> None:
        if _py_logging.getLogger().handlers:
            return
        try:
            severity = _severity_of(record.levelno)
            name = record.name.removeprefix(PYTHON_ROOT_LOGGER).removeprefix('.')
            line = f'[{_LEVEL_NAMES.get(severity, severity.name)}] [{record.created:.9f}] '
            sys.stderr.write(f'{line}[{name}]: {record.getMessage()}\n')
        except Exception:  # a logging handler must never raise into the caller
            self.handleError(record)


def initialize() -> None:
    """Set the default severity (INFO) and the console fallback handler, once."""
    root = _py_logging.getLogger(PYTHON_ROOT_LOGGER)
    if root.level == _py_logging.NOTSET:
        root.setLevel(_py_logging.INFO)
    if not any(isinstance(handler, _ConsoleFallbackHandler) for handler in root.handlers):
        root.addHandler(_ConsoleFallbackHandler())


def shutdown() -> None:
    """Nothing to release: Python logging outlives contexts."""


def clear_config() -> None:
    """Remove the console handler and the levels set on the ``ros`` logger."""
    root = _py_logging.getLogger(PYTHON_ROOT_LOGGER)
    for handler in [h for h in root.handlers if isinstance(h, _ConsoleFallbackHandler)]:
        root.removeHandler(handler)
    root.setLevel(_py_logging.NOTSET)
