"""How a command stops on SIGINT (Ctrl-C) and SIGTERM.

By default a signal stops a command at once: SIGINT raises KeyboardInterrupt, SIGTERM raises
`Terminated`, wherever the program is. A command that writes bags (replay, demo) instead has the
signal noted and calls `checkpoint` where stopping is safe (between chunks), so that a signal
never lands inside the writing of a bag and the bag can be finished and marked partial. The
state lives in this module, not in `mount_twin.cli`, which may run as `__main__`.
"""

from __future__ import annotations

import signal

from mount_twin.errors import Terminated

_noted: list[int] = []
"""Signals noted and not yet acted on."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def _note(signum: int, frame: object) -> None:
    _noted.append(signum)


def install(at_checkpoints: bool) -> None:
    """Handle SIGINT and SIGTERM at once, or (`at_checkpoints`) at the next `checkpoint`."""
    _noted.clear()
    signal.signal(signal.SIGTERM, _note if at_checkpoints else _terminate)
    signal.signal(signal.SIGINT, _note if at_checkpoints else signal.default_int_handler)


def checkpoint() -> None:
    """Act on a noted SIGINT (KeyboardInterrupt) or SIGTERM (Terminated) now."""
    if _noted:
        raise KeyboardInterrupt if _noted[0] == signal.SIGINT else Terminated
