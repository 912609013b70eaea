"""Run a suite's calls in parallel spawned processes, and stop all of them when the suite stops.

``concurrent.futures.ProcessPoolExecutor`` used as a context manager waits for every submitted call on the way out,
also when the way out is an error: a run that failed (or a Ctrl-C) would stop the comparison suite only after every
other run had trained. And a ``SIGTERM`` (``kill``, ``pkill -f sb3_gqn.experiments.runner``) ends the parent at once and leaves
its workers training the runs already queued to them. :func:`run_in_processes` cancels what has not started and
terminates what runs, on an error of a call, on ``KeyboardInterrupt`` and on ``SIGTERM`` (turned into
``KeyboardInterrupt`` while it runs, in the main thread), then re-raises.
"""

from __future__ import annotations

import multiprocessing
import signal
import threading
import time
from collections.abc import Callable, Hashable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from types import FrameType
from typing import Any, TypeVar

__all__ = ["run_in_processes"]


def _interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def _terminate_children(deadline_seconds: float = 30.0) -> None:
    """Terminate every live child process, sweeping until none is left: the pool can still be starting a worker
    when the first sweep runs."""
    deadline = time.monotonic() + deadline_seconds
    while (children := multiprocessing.active_children()) and time.monotonic() < deadline:
        for child in children:
            child.terminate()
        for child in children:
            child.join(timeout=1.0)


#: a call's key: what names it to the callbacks
Key = TypeVar("Key", bound=Hashable)


def run_in_processes(
    calls: Sequence[tuple[Key, Callable[..., Any], tuple[Any, ...]]],
    jobs: int,
    on_finished: Callable[[Key], None] | None = None,
    on_wait: Callable[[list[Key]], None] | None = None,
    report_every: float = 15.0,
) -> None:
    """Run each ``(key, function, args)`` of ``calls`` in one of ``jobs`` spawned processes.

    :param calls: the calls, each with a key that names it to the callbacks (``function`` and ``args`` must pickle)
    :param jobs: number of worker processes
    :param on_finished: called with a call's key when it returned
    :param on_wait: called every ``report_every`` seconds with the keys of the calls not finished yet
    :raises: the first error of a call (the others are cancelled or terminated first); ``KeyboardInterrupt`` on
        Ctrl-C or ``SIGTERM``
    """
    in_main_thread = threading.current_thread() is threading.main_thread()
    previous_handler = signal.signal(signal.SIGTERM, _interrupt) if in_main_thread else None
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"))
    try:
        futures: dict[Future, Key] = {pool.submit(function, *args): key for key, function, args in calls}
        last_report = time.monotonic()
        while futures:
            # blocks until a call finishes or the next report is due (a signal's KeyboardInterrupt still ends it)
            timeout = None if on_wait is None else max(0.0, last_report + report_every - time.monotonic())
            done, _ = wait(futures, timeout=timeout, return_when=FIRST_COMPLETED)
            for future in [future for future in futures if future in done]:  # in the order of the calls
                key = futures.pop(future)
                future.result()  # a failed call stops the suite with its error
                if on_finished is not None:
                    on_finished(key)
            if on_wait is not None and futures and time.monotonic() - last_report >= report_every:
                on_wait(list(futures.values()))
                last_report = time.monotonic()
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        _terminate_children()
        raise
    finally:
        pool.shutdown(wait=True)
        if in_main_thread:
            signal.signal(signal.SIGTERM, previous_handler)
