"""Text files read whole, up to a size limit: /dev/zero, a sparse file or a wrong path given
as a scene or a CSV fails at the limit, naming it, instead of exhausting memory. Output files
written whole or not at all: a full disk fails naming the file and leaves no part of it."""

from __future__ import annotations

import os
import secrets
import stat
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager, suppress
from pathlib import Path
from typing import TextIO

MIB = 1 << 20


class FileTooLargeError(ValueError):
    """A file is larger than the limit for what it is read as."""


def read_limited(path: Path, limit: int, limit_name: str, encoding: str = "utf-8") -> str:
    """The text of `path`, or FileTooLargeError (its message names `limit_name`) if it has
    more than `limit` bytes; OSError and UnicodeDecodeError as Path.read_text raises them."""
    with path.open("rb") as fh:
        data = fh.read(limit + 1)
    if len(data) > limit:
        msg = f"larger than {limit // MIB} MiB, the most {limit_name} allows"
        raise FileTooLargeError(msg)
    return data.decode(encoding)


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """A path to write the new content of `path` at, put in its place when the block ends:
    a new file in the same directory, renamed over `path` (through a symlink, its target)
    when written and synced, removed if anything fails. A failure to write is an OSError
    naming `path` (its filename; its strerror says "cannot write: ..."): a bare errno had not
    said which file, and a full disk had left a truncated file. An existing file keeps its
    permissions; a new one gets the umask's. The directories missing above a new one are
    made, and removed again if it is not written (`directories_above`). A target that is no
    regular file (a FIFO, /dev/full) or is named under /dev or /proc (/dev/stdout, even
    redirected to a file: the rename would put a new file in place of the shell's) is written
    directly."""
    with replacing_all() as replace:
        yield replace(path)


@contextmanager
def replacing_all() -> Iterator[Callable[[str | Path], Path]]:
    """`replace(path)`, which gives the path to write the new content of `path` at (each as
    `replacing` gives it), for files put in place together when the block ends: every one
    written and synced before the first is renamed into place, so that a failure while any is
    written (a full disk, a signal) leaves none of them, not the first few looking finished,
    and the files that were there as they were. A rename failing after others (a race, a
    signal) removes the files those made new; those they replaced stay replaced, each whole.
    A failure is an OSError naming the file: the one last given out while the block ran, the
    one synced or renamed after it."""
    stack = ExitStack()
    pending: list[tuple[Path, Path, Path, bool]] = []  # given, tmp, target, target was there
    current: list[Path] = []  # the file a failure is named after

    def replace(path: str | Path) -> Path:
        given = Path(path)
        current[:] = [given]
        try:
            mode = os.stat(given).st_mode
        except FileNotFoundError:
            mode = None
        device = Path(os.path.abspath(given)).parts[1:2] in (("dev",), ("proc",))
        if device or (mode is not None and not stat.S_ISREG(mode)):
            return given
        stack.enter_context(directories_above(given))  # not through a symlink's target
        target = Path(os.path.realpath(given))
        tmp = target.with_name(f".{target.stem}.partial-{secrets.token_hex(4)}{target.suffix}")
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        stack.callback(_remove, tmp)  # gone once renamed into place
        if mode is not None:
            os.chmod(tmp, stat.S_IMODE(mode))
        pending.append((given, tmp, target, mode is not None))
        return tmp

    try:
        with stack:
            yield replace
            for given, tmp, _, _ in pending:
                current[:] = [given]
                fd = os.open(tmp, os.O_RDONLY)
                try:
                    os.fsync(fd)  # a delayed allocation's ENOSPC comes here, before the rename
                finally:
                    os.close(fd)
            renamed: list[tuple[Path, bool]] = []
            try:
                for given, tmp, target, there in pending:
                    current[:] = [given]
                    os.replace(tmp, target)
                    renamed.append((target, there))
            except BaseException:  # an error, or a signal between two renames
                for target, there in renamed:
                    if not there:
                        _remove(target)
                raise
    except OSError as err:
        if not current:  # not one of the files: the block's own
            raise
        raise _cannot_write(current[0], err) from err


def _remove(path: Path) -> None:
    """Remove the file `path` if it is there."""
    with suppress(OSError):
        path.unlink()


@contextmanager
def text_output(path: str | Path, newline: str | None = None) -> Iterator[TextIO]:
    """The UTF-8 text file `path`, open for writing, put in place whole when the block ends
    (see `replacing`); `newline` as open takes it ('' for the csv module)."""
    with replacing(path) as tmp, tmp.open("w", encoding="utf-8", newline=newline) as fh:
        yield fh


def write_text(path: str | Path, text: str) -> None:
    """Write `text` as the UTF-8 file `path`, whole or not at all (see `replacing`)."""
    with text_output(path) as fh:
        fh.write(text)


def on_disk(path: Path) -> Path | None:
    """`path` or the nearest directory above it that is there, a dangling symlink included:
    Path.exists follows a link and reads a dangling one as absent, where mkdir then fails
    with "File exists" (None if none is: a relative path's "." always is)."""
    return next((p for p in (path, *path.parents) if os.path.lexists(p)), None)


def no_directory(path: Path) -> str:
    """Why `path`, which is there (`on_disk`), is no directory to make one in or to write
    into: '' if it is one (or a symlink to one), else "PATH is a symlink to TARGET, which does
    not exist" or "PATH is not a directory"."""
    if path.is_dir():
        return ""
    if path.is_symlink() and not path.exists():
        return f"{path} is a symlink to {os.readlink(path)}, which does not exist"
    return f"{path} is not a directory"


def new_directory_refusal(path: str | Path) -> str:
    """Why no new directory can be made at `path` (with the missing ones above it): '' if one
    can; "exists" if a directory or file is there; else what is in the way at or above it
    (`no_directory`: a dangling symlink, or a file where a directory goes). Checked before
    long work: the write at its end had failed with "File exists" or rosbags' traceback."""
    return "exists" if Path(path).exists() else directory_refusal(path)


def directory_refusal(path: str | Path) -> str:
    """Why `path` can be no directory to write into, the one there or one made with the
    missing ones above it (as `directories_above` makes them): '' if it can be; else what is
    in the way at or above it (`no_directory`): checked before the work, for a directory of
    outputs and for an output file's directory alike."""
    there = on_disk(Path(path))
    return "" if there is None else no_directory(there)


@contextmanager
def directories_above(path: str | Path) -> Iterator[Path]:
    """`path`, with the directories missing above it made (`mkdir -p` of its parent, as `ros2
    bag record -o` and rosbags' Writer make them) for the block to make `path` in. If the block
    raises, those made here are removed again, nearest first, each if empty: an output the
    block left at `path` keeps them, one it removed (or never began) leaves none behind, where
    they had been left empty, made by a run that wrote nothing."""
    target = Path(path)
    made = [p for p in target.parents if not os.path.lexists(p)]  # nearest first
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        yield target
    except BaseException:
        for directory in made:
            with suppress(OSError):  # not empty (an output kept), or never made
                directory.rmdir()
        raise


def _cannot_write(path: Path, err: OSError) -> OSError:
    """`err` as an OSError of the same errno naming `path` as the file that was not written."""
    return OSError(err.errno, f"cannot write: {err.strerror or err}", str(path))
