"""One process per run directory: a second one would interleave metrics records and race the first
in its checkpoint writes. The lock is ``flock`` on RUN_DIR/.lock, which the kernel releases when
the holder dies, so a crashed run's lock is taken over without any cleanup."""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
from collections.abc import Iterator

from splid_jax.common.errors import InvalidConfig
from splid_jax.common.paths import missing_parents

LOCK = ".lock"


def _holder(fd: int) -> str:
    with contextlib.suppress(OSError, ValueError):
        return f"process {int(os.pread(fd, 32, 0).decode().strip())}"
    return "another process"


def acquire(run_dir: str, field: str = "run_dir") -> tuple[int, list[str]]:
    """The locked file's descriptor and the directories made for it; raises ``InvalidConfig`` when
    another live process holds the lock (nothing made then) or the directory cannot be written."""
    made = missing_parents(run_dir)
    path = os.path.join(run_dir, LOCK)
    try:
        os.makedirs(run_dir, exist_ok=True)
        while True:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                who = _holder(fd)
                os.close(fd)
                raise InvalidConfig(field, run_dir, f"a directory no other run is using ({who} holds it)") from None
            # a holder that was releasing may have removed the file we opened: lock the one at the path
            with contextlib.suppress(FileNotFoundError):
                if os.fstat(fd).st_ino == os.stat(path).st_ino:
                    break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        return fd, made
    except OSError as e:
        _remove_made(made)
        why = "no space left on the device" if e.errno == errno.ENOSPC else e.strerror
        raise InvalidConfig(field, run_dir, f"a writable directory ({why})") from None


def release(run_dir: str, fd: int, made: list[str]) -> None:
    """Removes the lock file (while still holding it, so no one locks the removed file) and the
    directories ``acquire`` made, if the run left them empty."""
    with contextlib.suppress(OSError):
        os.remove(os.path.join(run_dir, LOCK))
    os.close(fd)
    _remove_made(made)


def _remove_made(made: list[str]) -> None:
    for d in made:
        with contextlib.suppress(OSError):
            os.rmdir(d)


@contextlib.contextmanager
def hold(run_dir: str, enabled: bool = True, field: str = "run_dir") -> Iterator[None]:
    """``run_dir`` locked for this process while the block runs (nothing done when not ``enabled``:
    the processes of a run over several hosts that leave the directory to process 0)."""
    if not enabled:
        yield
        return
    fd, made = acquire(run_dir, field)
    try:
        yield
    finally:
        release(run_dir, fd, made)
