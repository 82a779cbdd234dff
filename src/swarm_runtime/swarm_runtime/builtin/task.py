"""``rclpy.task``: a minimal Future, for ``spin_until_future_complete``.

Coroutines and ``Executor.create_task`` are not provided by the built-in runtime.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ['Future']


class Future:
    """The outcome of some work: a result, an exception, or cancellation."""

    def __init__(self, *, executor: Any = None) -> None:
        self._done = False
        self._cancelled = False
        self._result: Any = None
        self._exception: BaseException | None = None
        self._callbacks: list[Callable[[Future], Any]] = []

    def cancelled(self) -> bool:
        """True if the future was cancelled."""
        return self._cancelled

    def done(self) -> bool:
        """True once a result or exception was set, or the future was cancelled."""
        return self._done

    def result(self) -> Any:
        """The result (None while pending); raises the exception if one was set."""
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        """The exception set on the future, or None."""
        return self._exception

    def set_result(self, result: Any) -> None:
        """Complete the future with ``result`` and run the done callbacks."""
        self._result = result
        self._finish()

    def set_exception(self, exception: BaseException) -> None:
        """Complete the future with an exception and run the done callbacks."""
        self._exception = exception
        self._finish()

    def cancel(self) -> None:
        """Cancel the future unless it is done already."""
        if not self._done:
            self._cancelled = True
            self._finish()

    def _finish(self) -> None:
        self._done = True
        callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            callback(self)

    def add_done_callback(self, callback: Callable[[Future], Any]) -> None:
        """Call ``callback(future)`` when done (at once if done already)."""
        if self._done:
            callback(self)
        else:
            self._callbacks.append(callback)
