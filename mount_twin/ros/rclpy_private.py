"""The two places where mount_twin reaches into rclpy below its public API (Jazzy, rclpy 7.x).

Both are tested (test/test_ros_node.py) so that an rclpy release that changes them fails CI
instead of silently dropping input or parameters:

- `take_waiting`: every message waiting in a subscription's queue, through the subscription
  handle the executor itself takes from. One executor wake-up then answers all the messages
  that arrived meanwhile instead of paying the executor once per message (measured
  2026-11-26, rclpy 7.1.6 on 2 shared cores: 0.86 ms of CPU a wake-up of a node holding one
  timer, 1.0 ms of this node's), which is what lets a Python node follow a 10 kHz sensor.
- `given_parameters`: the parameter overrides the node was started with (params files, `-p`,
  `parameter_overrides=`), before any is declared. rclpy keeps them in a private attribute; a
  node needs them to refuse unknown keys by name and to take an integer written for a double,
  which `declare_parameter` would otherwise reject or ignore without a word.
"""

from __future__ import annotations

from typing import Any

from rclpy.node import Node
from rclpy.subscription import Subscription


def take_waiting(sub: Subscription, limit: int) -> list[bytes]:
    """Up to `limit` raw messages waiting in `sub`'s queue (a raw=True subscription), oldest
    first, without the executor."""
    out: list[bytes] = []
    with sub.handle:
        while len(out) < limit:
            taken = sub.handle.take_message(sub.msg_type, True)
            if taken is None:
                break
            out.append(taken[0])
    return out


def given_parameters(node: Node) -> dict[str, Any]:
    """Name → value of every parameter override the node was given (Python values)."""
    return {name: param.value for name, param in node._parameter_overrides.items()}
