"""Many small jobs over the cores in one stage: one worker process per core, started once (fork, so nothing
is imported twice), fed in chunks. N episodes cost `workers` process starts, not N.

The stage alone takes interrupts: on Ctrl-C or SIGTERM it stops its workers (SIGTERM, which ends a worker at
once: a Python handler could wait forever in a worker blocked on the job queue) and exits 130/143; what they
were writing is a temporary file the caller removes. A worker whose stage is killed outright ends too.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from pipeline.core import interrupts

T = TypeVar("T")
MAX_WORKERS = 64


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def workers_for(requested: int, jobs: int) -> int:
    """`requested` workers (0: one per core), never more than there are jobs."""
    return max(1, min(requested or cores(), jobs, MAX_WORKERS))


_job: list[Callable] = []


def _init(fn: Callable) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    interrupts.die_with_parent()
    _job[:] = [fn]


def _call(item: Any) -> Any:
    return _job[0](item)


def imap(fn: Callable[[Any], T], items: Iterable[Any], workers: int = 0, chunksize: int = 0) -> Iterator[T]:
    """fn(item) for every item, in order, on `workers` processes (0: one per core); in this process when one
    worker is enough. `fn` may be a closure: workers are forked with it."""
    items = list(items)
    n = workers_for(workers, len(items))
    if n == 1 or "fork" not in multiprocessing.get_all_start_methods():
        yield from map(fn, items)
        return
    chunksize = chunksize or max(1, min(16, len(items) // (4 * n)))
    pool = multiprocessing.get_context("fork").Pool(n, initializer=_init, initargs=(fn,))
    finished = False
    try:
        yield from pool.imap(_call, items, chunksize=chunksize)
        finished = True
    finally:
        if finished:
            pool.close()
        else:
            pool.terminate()   # an interrupt or an error: stop every worker now; it propagates
        pool.join()
