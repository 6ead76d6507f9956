"""One writer per folder: an OS file lock held by the process that writes a run, a collection or
a checkpoint, for as long as it runs.

The lock is `fcntl.flock` on the folder's `.lock` file, which also names its holder (process id
and command). The `.lock` leaves with its run: it is removed when the holder gives the folder up
or exits. The kernel drops the lock when its process ends, however it ends, so the `.lock` of a
run that was killed is simply taken over by the next run. A second process that finds the lock
held is refused in one line that names the holder, before it has written anything.
"""

from __future__ import annotations

import atexit
import errno
import fcntl
import os
import sys
import time
from pathlib import Path

from hsgplan.domain.errors import InvalidInputError

LOCK = ".lock"

# resolved folder -> the open lock file's descriptor and the process that opened it (a forked
# child inherits the table, never the lock's ownership)
_held: dict[str, tuple[int, int]] = {}


def hold_folder(folder: Path) -> None:
    """Make this process the one writer of `folder` (made if missing) until it ends or
    `release` is called; holding it already is fine. Refused in one line while another
    process holds it."""
    folder = Path(folder)
    if str(folder.resolve()) in _held:
        return
    made = [p for p in (folder, *folder.parents) if not p.exists()]
    folder.mkdir(parents=True, exist_ok=True)
    fd, created = _locked(folder)
    command = " ".join(["hsgplan", *sys.argv[1:]])[:200].replace("\n", " ")
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    try:
        os.ftruncate(fd, 0)  # the lock's own file: rewritten in place, it must stay this inode
        os.pwrite(fd, f"pid {os.getpid()} since {started}: {command}\n".encode(), 0)
    except OSError as e:  # a full disk: leave nothing behind that this call made
        if created:
            (folder / LOCK).unlink(missing_ok=True)
        os.close(fd)
        for path in made:  # deepest first
            path.rmdir()
        raise OSError(e.errno, e.strerror, str(folder / LOCK)) from None
    _held[str(folder.resolve())] = (fd, os.getpid())


def _locked(folder: Path) -> tuple[int, bool]:
    """The folder's `.lock` opened (made if missing) and flocked; whether this call made it.
    A lock its holder removed as this process took it is left for the one that stands."""
    flags = os.O_RDWR | os.O_NOFOLLOW  # a link planted as the lock is never written through
    while True:
        try:
            fd = os.open(folder / LOCK, flags | os.O_CREAT | os.O_EXCL, 0o644)
            created = True
        except FileExistsError:
            try:
                fd, created = os.open(folder / LOCK, flags), False
            except FileNotFoundError:  # removed by its leaving holder in between: again
                continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):  # no locks on this file system
                os.close(fd)
                raise OSError(
                    e.errno, f"cannot lock the folder ({e.strerror})", str(folder)
                ) from None
            holder = os.pread(fd, 1000, 0).decode("utf-8", errors="replace").strip()
            os.close(fd)
            raise InvalidInputError(
                f"'{folder}' is being written by another run ({holder or 'a process'}); "
                "wait for it to end or use another --out"
            ) from None
        if _same_file(fd, folder / LOCK):
            return fd, created
        os.close(fd)  # the file it locked was removed by its leaving holder: take the new one


def _same_file(fd: int, path: Path) -> bool:
    try:
        return os.fstat(fd).st_ino == os.lstat(path).st_ino
    except FileNotFoundError:
        return False


def holds(folder: Path) -> bool:
    """Whether this process holds `folder`'s lock."""
    return str(Path(folder).resolve()) in _held


def release(folder: Path) -> None:
    """Give `folder` up, its `.lock` removed."""
    key = str(Path(folder).resolve())
    held = _held.pop(key, None)
    if held is not None:
        _leave(key, *held)


def release_all() -> None:
    """Give every held folder up (also as the process exits)."""
    for key in list(_held):
        _leave(key, *_held.pop(key))


def _leave(folder: str, fd: int, owner: int) -> None:
    if owner != os.getpid():  # a forked child's copy: the lock is its parent's to remove
        return
    lock = Path(folder) / LOCK
    if _same_file(fd, lock):  # removed while still held: no other process holds that file
        lock.unlink(missing_ok=True)
    os.close(fd)  # closing the only descriptor drops the flock


atexit.register(release_all)
