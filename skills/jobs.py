"""Long work off the tick: a skill submits a job and polls it on later ticks.

In simulation, :class:`DeferredJobs` runs a job when it is first polled, one
tick after it was submitted, so a run stays deterministic in simulated time.
On real robots, :class:`ThreadJobs` runs jobs on worker threads (OMPL and
pybullet hold the GIL while they compute; use a process pool for parallel
planning).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Protocol, runtime_checkable


class Job(Protocol):
    """A unit of work whose result a skill polls."""

    def done(self) -> bool:
        """Whether the result is ready (polling may run the work)."""
        ...

    def result(self) -> Any:
        """The result; re-raises the work's exception."""
        ...


@runtime_checkable
class Jobs(Protocol):
    """Runs jobs for skills."""

    def submit(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Job:
        """Start ``fn(*args, **kwargs)``."""
        ...


class _Deferred:
    __slots__ = ("_call", "_done", "_error", "_polls", "_value")

    def __init__(self, call: Callable[[], Any]) -> None:
        self._call: Callable[[], Any] | None = call
        self._done = False
        self._value: Any = None
        self._error: BaseException | None = None
        self._polls = 0

    def done(self) -> bool:
        if not self._done:
            self._polls += 1
            if self._polls < 2:  # the tick that submitted it does not see the result
                return False
            call, self._call = self._call, None
            assert call is not None
            try:
                self._value = call()
            except Exception as exc:
                self._error = exc
            self._done = True
        return True

    def result(self) -> Any:
        if not self.done():
            raise RuntimeError("the job is not done yet: poll done() first")
        if self._error is not None:
            raise self._error
        return self._value


class DeferredJobs:
    """Runs each job when it is polled for the second time: deterministic, in simulated time."""

    def submit(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Job:
        """Defer ``fn(*args, **kwargs)`` to a later poll."""
        return _Deferred(lambda: fn(*args, **kwargs))


class _Threaded:
    __slots__ = ("_future",)

    def __init__(self, future: Future[Any]) -> None:
        self._future = future

    def done(self) -> bool:
        return self._future.done()

    def result(self) -> Any:
        return self._future.result()


class ThreadJobs:
    """Runs jobs on a pool of worker threads (for wall-clock runs).

    Args:
        workers: number of threads.
    """

    def __init__(self, workers: int = 1) -> None:
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="skill-job")

    def submit(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Job:
        """Run ``fn(*args, **kwargs)`` on a worker."""
        return _Threaded(self._pool.submit(fn, *args, **kwargs))

    def close(self) -> None:
        """Stop the workers after the running jobs."""
        self._pool.shutdown(wait=True)
