"""Files written whole or not at all.

Every file the project writes goes through `atomic` (or `write_atomically`): the content goes
to a hidden temporary file beside the target, is flushed to the disk (fsync), and only then
renamed over the target, and the folder's entry is flushed too. A full disk, a kill or a power
cut therefore leaves the old file or no file, never a truncated one; a write that fails removes
its temporary file and raises the `OSError`, which the CLI reports in one line.

Append-only logs (`episodes.jsonl`, the demonstrations' JSON lines) are the one exception:
they are appended to line by line, and their readers skip a line cut short.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path


def temporary_name(path: Path) -> Path:
    """The hidden temporary file beside `path`, this process's own (two processes writing one
    file never write into each other's), keeping its suffix (writers that choose a format by
    the suffix, numpy's `.npz` or an image's, still see it); a name starting with a dot never
    looks like a chunk, a dataset or a run's file."""
    return path.with_name(f".{path.stem}.tmp{os.getpid()}{path.suffix}")


def _fsync_folder(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # a folder that cannot be opened for reading: the rename stands anyway
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic(path: Path | str) -> Iterator[Path]:
    """A temporary path to write `path`'s new content to; when the block ends without an
    error, the content is flushed to the disk and renamed over `path`. On an error (a full
    disk, an interruption) the temporary file is removed and `path` is left as it was."""
    path = Path(path)
    tmp = temporary_name(path)
    try:
        yield tmp
        with open(tmp, "rb+") as written:
            os.fsync(written.fileno())
        os.replace(tmp, path)
    except OSError as e:  # a full disk: said of the file we were writing
        tmp.unlink(missing_ok=True)
        if e.errno is not None and (e.filename is None or Path(e.filename) == tmp):
            raise OSError(e.errno, e.strerror, str(path)) from None
        raise
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_folder(path.parent)


def write_atomically(path: Path | str, content: str | bytes) -> None:
    """Write `content` (text as UTF-8) as the whole of `path`, atomically."""
    data = content.encode("utf-8") if isinstance(content, str) else content
    with atomic(path) as tmp, open(tmp, "wb") as f:
        f.write(data)
