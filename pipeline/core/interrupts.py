"""An interrupt stops the stage: it is never recorded as a run's status.

Simulators written in C++ (Exudyn, IPOPT, …) may catch the KeyboardInterrupt that Python raises inside a
callback and report it as their own failure. The handler below remembers the signal as well as raising, so
the runner can tell "the solver failed" from "the user pressed Ctrl-C" whatever the library did with it.
Sweep workers also die with their parent: a killed sweep leaves no orphan finishing it.
"""

from __future__ import annotations

import os
import signal
import threading
import time

EXIT_CODES = {signal.SIGINT: 130, signal.SIGTERM: 143}
_received: list[int] = []


class Interrupted(KeyboardInterrupt):
    """The stage was interrupted by a signal (SIGINT or SIGTERM)."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.exit_code = EXIT_CODES.get(signum, 128 + signum)


def _handler(signum, _frame) -> None:
    _received.append(signum)
    raise Interrupted(signum)


def install() -> None:
    """Take SIGINT and SIGTERM in the main thread of this process (a no-op elsewhere)."""
    if threading.current_thread() is threading.main_thread():
        for sig in EXIT_CODES:
            signal.signal(sig, _handler)


def raise_if_received() -> None:
    """Raise Interrupted if a signal arrived, even if a library swallowed the exception it raised."""
    if _received:
        raise Interrupted(_received[-1])


def exit_code(err: KeyboardInterrupt) -> int:
    return getattr(err, "exit_code", EXIT_CODES[signal.SIGINT])


_watching: list[int] = []


def die_with_parent(poll_s: float = 0.5) -> None:
    """In a worker process: exit as soon as the process that started it is gone (re-parented)."""
    if _watching:
        return
    parent = os.getppid()
    _watching.append(parent)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(poll_s)
        os.kill(os.getpid(), signal.SIGTERM)  # the stage's handler aborts the open run cleanly
        time.sleep(5.0)
        os._exit(EXIT_CODES[signal.SIGTERM])  # the worker's own loop did not end with it

    threading.Thread(target=watch, name="die-with-parent", daemon=True).start()
