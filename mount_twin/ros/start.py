"""`mount_twin_node`: the node's process entry. SIGINT and SIGTERM are taken from its first
moment, before the imports of rclpy, numpy and the compiled core (about a second), during which
Python's default handlers ended the process with a KeyboardInterrupt traceback (exit 130) or
without a word (exit 143): a stop asked for then ends it with exit 0, as one asked for later
does, after the last diagnostics (`mount_twin.ros.node.run`)."""

from __future__ import annotations

import signal
import sys
import threading


def main(args: list[str] | None = None) -> int:
    """Console entry point `mount_twin_node` (`args`: rclpy's, default the process's)."""
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    from mount_twin.ros.node import run

    return run(stop, args)


if __name__ == "__main__":
    sys.exit(main())
