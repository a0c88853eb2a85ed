"""The node's process once `ros/start.py` has taken its signals: the command line checked,
rclpy started, the node (`node.MountTwinNode`) spun until the first stop and finished, and the
exit status that says how it ended."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions

from mount_twin.errors import MountTwinError
from mount_twin.ros.node import MountTwinNode
from mount_twin.ros.parameters import check_command_line, rcl_message

if TYPE_CHECKING:
    from mount_twin.ros.start import StopRequests


def run(stops: StopRequests, args: list[str] | None = None) -> int:
    """The node's process (`mount_twin.ros.start`, whose handler of SIGINT and SIGTERM takes
    `stops`): spin until the first stop, then publish the last diagnostics period and exit 0;
    a second stop that cut the shutdown short exits 128 + its signal (130 SIGINT, 143 SIGTERM,
    as the shell reports a process a signal ended). A configuration error exits 2 with one
    line. A stop before the node is made exits 0 at once."""
    if stops.first.is_set():
        return 0
    argv = sys.argv if args is None else args
    try:
        check_command_line(argv)
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    except MountTwinError as err:
        print(f"mount_twin_node: {err}", file=sys.stderr)
        return 2
    except RuntimeError as err:  # rcl's others (RCLError), e.g. a bad ROS_DOMAIN_ID
        print(f"mount_twin_node: {rcl_message(err)}", file=sys.stderr)
        return 2
    node = None
    cut_short = False
    try:
        node = MountTwinNode(argv)
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stops.first.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=0.1)
    except MountTwinError as err:
        print(f"mount_twin_node: {err}", file=sys.stderr)
        return 2
    except ExternalShutdownException:
        pass
    finally:
        if node is not None:
            if rclpy.ok():
                cut_short = node.finish(stops)
            node.destroy_node()
        rclpy.try_shutdown()
    return 128 + stops.again if cut_short and stops.again is not None else 0
