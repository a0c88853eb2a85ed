"""Command line: `mount-twin COMMAND ...`; the commands live in mount_twin.commands."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Protocol, cast

from mount_twin.commands import COMMANDS, stopping
from mount_twin.errors import DamagedBagError, MountTwinError, Terminated


class DefaultsShown(argparse.HelpFormatter):
    """Every option's help ends with its default, unless it has none or already says it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if (
            "default" in text
            or action.default in (None, False, argparse.SUPPRESS)
            or action.required
            or not action.option_strings
        ):
            return text
        return f"{text} (default: %(default)s)".lstrip()


class Command(Protocol):
    """What a module of mount_twin.commands provides (see its docstring)."""

    NAME: str
    HELP: str
    # optional: EXIT_STATUS (str), STOPS_AT_CHECKPOINTS (bool), STOPPED_OUTPUT (str), read with
    # getattr

    def add_arguments(self, parser: argparse.ArgumentParser) -> None: ...

    def run(self, args: argparse.Namespace) -> int: ...


def _version() -> str:
    """The installed distribution's version (importlib.metadata: no package import)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("mount_twin")
    except PackageNotFoundError:
        return "(not installed)"


def build_parser() -> tuple[argparse.ArgumentParser, dict[str, Command]]:
    """The parser of every command, and each command's module by its name as typed."""
    parser = argparse.ArgumentParser(
        prog="mount-twin",
        description="Digital twin of a machine on compliant mounts: replay bags, make inputs.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="cmd", required=True)
    modules: dict[str, Command] = {}
    for name in COMMANDS:
        module = cast("Command", importlib.import_module(f"mount_twin.commands.{name}"))
        module.add_arguments(
            sub.add_parser(
                module.NAME,
                help=module.HELP,
                description=module.HELP,
                epilog=exit_statuses(module),
                formatter_class=DefaultsShown,
            )
        )
        modules[module.NAME] = module
    return parser, modules


EXIT_DAMAGED, EXIT_SIGINT, EXIT_SIGPIPE, EXIT_SIGTERM = 5, 130, 141, 143
"""Exit statuses besides 0 and the commands' own: 2 bad input or configuration (named), 5 an
input damaged part-way (what came before it was processed), 128 + the signal's number when
stopped by SIGINT (Ctrl-C) or SIGTERM (output bags are finished and marked partial), or when
the reader of the output closed it (SIGPIPE: `| head`), silently, as a Unix tool is."""


EXIT_STATUS = "exit status: 0 done; 2 bad input (the message names the option, file or key)"
"""The exit statuses of a command that has none of its own (no EXIT_STATUS)."""


def exit_statuses(module: Command) -> str:
    """A command's exit statuses for its --help: its own (its EXIT_STATUS, each code leading a
    clause after "; "), then those `main` gives every command on a signal."""
    held = getattr(module, "STOPPED_OUTPUT", "")
    stopped = f"; on either, -o {held}" if held else ""
    return (
        f"{getattr(module, 'EXIT_STATUS', EXIT_STATUS)}; {EXIT_SIGINT} SIGINT (Ctrl-C); "
        f"{EXIT_SIGTERM} SIGTERM{stopped}; {EXIT_SIGPIPE} SIGPIPE: the reader of the output "
        "closed it (`| head`), quietly"
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status (see EXIT_*; 2: bad input or configuration)."""
    parser, modules = build_parser()
    args = parser.parse_args(argv)
    if threading.current_thread() is threading.main_thread():
        # A command that polls `checkpoint` (replay) stops between chunks, so that a signal
        # never lands inside the writing of a bag; others stop at once.
        polls = getattr(modules[args.cmd], "STOPS_AT_CHECKPOINTS", False)
        stopping.install(polls)
    held = getattr(modules[args.cmd], "STOPPED_OUTPUT", "")
    try:
        code = modules[args.cmd].run(args)
        sys.stdout.flush()  # here, not at exit: a reader gone (`| head`) is seen below
        return code
    except BrokenPipeError:  # the reader closed the pipe: it took what it wanted, as `head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing left to flush
        return EXIT_SIGPIPE
    except DamagedBagError as err:
        _say_damaged(err, args, held)
        return EXIT_DAMAGED
    except (MountTwinError, ValueError, OSError) as err:
        if damage := _damage_behind(err):  # it failed after the damage (a write of the
            _say_damaged(damage, args, held)  # summary up to it): neither is hidden
        print(f"mount-twin: error: {_error_text(err)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"mount-twin: interrupted (SIGINT){_partial(args, held)}", file=sys.stderr)
        return EXIT_SIGINT
    except Terminated:
        print(f"mount-twin: terminated (SIGTERM){_partial(args, held)}", file=sys.stderr)
        return EXIT_SIGTERM


def _damage_behind(err: BaseException) -> DamagedBagError | None:
    """The DamagedBagError being handled where `err` (or an error it replaced) was raised, if
    any."""
    seen = err.__context__
    while seen is not None and not isinstance(seen, DamagedBagError):
        seen = seen.__context__
    return seen


def _say_damaged(err: DamagedBagError, args: argparse.Namespace, held: str) -> None:
    """Say on stderr that the input was damaged part-way, and where the output so far is."""
    print(f"mount-twin: error: {err}{_partial(args, held)}", file=sys.stderr)


def _error_text(err: Exception) -> str:
    """An error's message; an OSError's as "FILE: what" when it names its file (it had read
    "[Errno 28] No space left on device", naming none, for an output on a full disk)."""
    if isinstance(err, OSError) and err.filename is not None and err.strerror:
        files = " -> ".join(str(f) for f in (err.filename, err.filename2) if f is not None)
        return f"{files}: {err.strerror}"
    return str(err)


def _partial(args: argparse.Namespace, held: str) -> str:
    """Where a stopped command's output so far is and what it `held` there: its module's
    STOPPED_OUTPUT (replay's bag is finished and marked partial, a sweep's table holds the
    finished cases); '' for a command without one, whose files are written whole or not at all
    (a report.html already there is the previous run's, not this one's)."""
    out = getattr(args, "output", None)
    if held and out and Path(out).exists():
        return f"; {out} {held}"
    return ""


if __name__ == "__main__":
    sys.exit(main())
