"""The `mount-twin` subcommands, one module each.

A command module is imported to build the argument parser, so at module level it may import only
the standard library and `mount_twin.errors`: numpy, scipy and rosbags take a second to import, and
`--help` or a mistyped argument must answer at once (tested). Each module defines

- ``NAME``: the subcommand, as typed;
- ``HELP``: one line for `mount-twin --help`;
- ``add_arguments(parser)``: its options;
- ``run(args) -> int``: carry it out, importing what it needs; returns the exit status;
- optionally ``EXIT_STATUS``: the statuses `run` returns, "exit status: 0 ...; 2 ...", each code
  leading a clause (default: 0 and 2); `--help` lists them with the signals' (mount_twin.cli).

A new command is a new module here and one entry in `COMMANDS`.
"""

from __future__ import annotations

COMMANDS = (
    "replay",
    "demo",
    "info",
    "generate",
    "import_csv",
    "export",
    "report",
    "srs",
    "synthesize",
    "qualify",
    "calibrate",
    "track",
    "modes",
    "accuracy",
    "sweep",
    "show",
    "dashboard",
    "build_tf2_msgs",
)
"""Module names under mount_twin.commands, in the order `--help` lists them."""
