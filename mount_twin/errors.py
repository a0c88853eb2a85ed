"""Errors raised by mount_twin; each message names the file, key path or message at fault."""

from typing import Any


class MountTwinError(Exception):
    """Base class of every error mount_twin raises on purpose."""


class SceneError(MountTwinError):
    """A scene or parameter set is invalid; the message names the source and key path, or the
    source alone where the error is the file's as a whole (`path` "": unreadable, not YAML)."""

    def __init__(self, source: str, path: str, msg: str) -> None:
        self.source = source
        self.path = path
        self.message = msg
        super().__init__(f"{source}: {path}: {msg}" if path else f"{source}: {msg}")


class ModelError(MountTwinError):
    """The assembled model cannot be used (e.g. no static equilibrium exists)."""


class BagError(MountTwinError):
    """A bag cannot be read or written, or lacks the configured input topic."""


class DamagedBagError(BagError):
    """An input bag is damaged part-way: what came before the damage was processed.

    Attributes:
        summary: where a replay raised it, its `replay_summary.ReplaySummary` up to the damage (its
            `damaged` says this error); else None.
    """

    summary: Any = None


class Terminated(BaseException):
    """SIGTERM, raised in the main thread (like KeyboardInterrupt for SIGINT) so that the
    command stops cleanly: output bags are finished and marked partial."""


def require(value: object, expected: type, where: str) -> None:
    """Raise TypeError naming `where` (the function and argument) unless `value` is an
    `expected`: the public API's entry points refuse a wrong object with a message that says
    what they take, not with an AttributeError from deep inside."""
    if not isinstance(value, expected):
        msg = f"{where}: got a {type(value).__name__}, expected a {expected.__name__}"
        raise TypeError(msg)
