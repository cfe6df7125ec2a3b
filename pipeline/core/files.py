"""Every output is published whole or not at all, and two processes never write the same file at once.

A file is written under a unique hidden temporary name in its own directory and renamed onto its final
name when complete (`os.replace` is atomic on one filesystem): a reader sees the old file or the new one,
never half of one, and a killed writer leaves only a hidden `.partial` that no reader lists. Runs also take
an advisory lock per run id (`flock`, released by the kernel when the process dies), so a second process
asked to write the same run refuses instead of racing.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

PARTIAL_SUFFIX = ".partial"
LOCKS_DIR = ".locks"
_UMASK = os.umask(0)
os.umask(_UMASK)


def temporary_name(path: Path) -> Path:
    """A new, unique, hidden file beside `path` (created empty, so no other process can take the name)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=PARTIAL_SUFFIX)
    os.fchmod(fd, 0o666 & ~_UMASK)  # mkstemp makes it private; outputs are as readable as any other file
    os.close(fd)
    return Path(name)


def publish(temporary: Path, path: Path) -> Path:
    """Make a finished temporary file durable and give it its final name."""
    with open(temporary, "rb+") as f:
        os.fsync(f.fileno())
    os.replace(temporary, path)
    return path


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """`with atomic_path(out) as tmp: write(tmp)`: `out` appears complete when the block ends, or not at all."""
    path = Path(path)
    tmp = temporary_name(path)
    try:
        yield tmp
        publish(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def write_text(path: str | Path, text: str) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def stale_partials(path: Path) -> list[Path]:
    """Temporary files of `path` left by writers that died (call only while holding `path`'s lock)."""
    return sorted(path.parent.glob(f".{path.name}.*{PARTIAL_SUFFIX}"))


class Busy(RuntimeError):
    """Another live process holds the lock."""


class Locks:
    """Exclusive advisory locks on names under `<root>/.locks/`, all taken at once or none.

    Lock files stay (removing them would race with a process about to lock them); they are empty."""

    def __init__(self, root: Path, names: list[str]):
        self._locks = [(name, Path(root) / LOCKS_DIR / f"{name}.lock") for name in names]
        self._files: list = []

    def acquire(self) -> Locks:
        """Take every lock, or raise Busy naming the first one another process holds (and take none)."""
        try:
            for name, path in self._locks:
                path.parent.mkdir(parents=True, exist_ok=True)
                f = open(path, "a+")  # held until __exit__
                self._files.append(f)
                try:
                    fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    raise Busy(name) from None
        except BaseException:
            self.release()
            raise
        return self

    def release(self) -> None:
        for f in self._files:
            f.close()  # closing releases the flock
        self._files.clear()

    def __enter__(self) -> Locks:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()


@contextlib.contextmanager
def atomic_dir(path: str | Path) -> Iterator[Path]:
    """`with atomic_dir(out) as tmp: fill(tmp)`: the directory `out` is replaced whole when the block ends (the
    old one stays until then), or left as it was."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=PARTIAL_SUFFIX))
    os.chmod(tmp, 0o777 & ~_UMASK)
    try:
        yield tmp
        old = path.parent / f".{path.name}.old{PARTIAL_SUFFIX}"
        if old.exists():
            shutil.rmtree(old)
        if path.exists():
            os.replace(path, old)    # two renames: a reader sees the old tree or the new one
        os.replace(tmp, path)
        shutil.rmtree(old, ignore_errors=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
