"""Text files read whole, up to a size limit: /dev/zero, a sparse file or a wrong path given
as a scene or a CSV fails at the limit, naming it, instead of exhausting memory."""

from __future__ import annotations

from pathlib import Path

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
