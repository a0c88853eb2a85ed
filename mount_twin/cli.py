"""Command line: `mount-twin COMMAND ...`; the commands live in mount_twin.commands."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import Protocol, cast

from mount_twin.commands import COMMANDS
from mount_twin.errors import MountTwinError


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
                formatter_class=DefaultsShown,
            )
        )
        modules[module.NAME] = module
    return parser, modules


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit status (2: bad input or configuration, named)."""
    parser, modules = build_parser()
    args = parser.parse_args(argv)
    try:
        return modules[args.cmd].run(args)
    except (MountTwinError, ValueError, OSError) as err:
        print(f"mount-twin: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
