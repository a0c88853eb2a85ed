"""`mount_twin_node`: the node's process entry. SIGINT and SIGTERM are taken from its first
moment, before the imports of rclpy, numpy and the compiled core (about a second), during which
Python's default handlers ended the process with a KeyboardInterrupt traceback (exit 130) or
without a word (exit 143): a stop asked for then ends it with exit 0, as one asked for later
does, after the last diagnostics (`mount_twin.ros.process.run`). A second stop while the node
shuts down (Ctrl-C pressed again) cuts the shutdown's waits short (`StopRequests`)."""

from __future__ import annotations

import signal
import sys
import threading


class StopRequests:
    """SIGINT and SIGTERM as the node takes them: the first (`first`) ends the spin and starts
    the shutdown; a later one (`again`: its signal number) skips what the shutdown still waits
    for, as `ros2 launch` and most command-line tools take a second Ctrl-C."""

    def __init__(self) -> None:
        self.first = threading.Event()
        self.again: int | None = None

    def take(self, signum: int, _frame: object = None) -> None:
        """The signal handler."""
        if self.first.is_set():
            self.again = signum
        self.first.set()

    @property
    def hurried(self) -> bool:
        """True once a second stop has come."""
        return self.again is not None


def main(args: list[str] | None = None) -> int:
    """Console entry point `mount_twin_node` (`args`: rclpy's, default the process's)."""
    stops = StopRequests()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, stops.take)
    from mount_twin.ros.process import run

    return run(stops, args)


if __name__ == "__main__":
    sys.exit(main())
