"""`mount-twin build-tf2-msgs`: give a pip-installed node /tf and /tf_static.

tf2_msgs is not on the package registry; this builds it from the registry's rosidl wheels (pip
installs the missing ones) with the system's cmake and C++ compiler, into a prefix inside the
environment, and activates it there (mount_twin.ros.tf2_msgs_build). About a minute the first
time; a second run finds the build and only checks it. Not needed with a ROS install.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from mount_twin.commands.common import positive_int

NAME = "build-tf2-msgs"
HELP = "build tf2_msgs from registry wheels so the pip-installed node publishes /tf (ROS has it)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--prefix",
        type=Path,
        help="where to build and install (default: share/mount_twin/tf2_msgs in this Python "
        "environment: the build is tied to its Python and geometry_msgs)",
    )
    parser.add_argument(
        "--jobs", "-j", type=positive_int, help="parallel compile jobs (default: cores)"
    )
    parser.add_argument("--force", action="store_true", help="rebuild even if up to date")


def run(args: argparse.Namespace) -> int:
    from mount_twin.ros.tf2_msgs_build import build

    start = time.perf_counter()
    done = build(args.prefix, jobs=args.jobs, force=args.force)
    state = "built" if done.built else "up to date"
    print(f"tf2_msgs {state} in {done.prefix} ({time.perf_counter() - start:.1f} s)")
    print(f"a new interpreter imports it with its type support from {done.module}")
    if done.exports:
        print("the node finds it once a shell has run:")
        for line in done.exports:
            print(f"    {line}")
    else:
        print("this environment finds it: the node publishes /tf and /tf_static")
    return 0
