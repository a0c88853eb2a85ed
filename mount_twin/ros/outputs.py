"""The node's outputs: a reliable byte publisher per output topic, the latched ones (/tf_static,
~/scene) published once, the twin's messages published, and at shutdown the wait until every
reliable subscriber has acknowledged them. `OutputNode` is the rclpy node that holds them, of
which `node.MountTwinNode` is made; it moves raw CDR bytes only (`io.output_encoding` builds
them)."""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, TypeVar

from rclpy.duration import Duration
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.exceptions import InvalidTopicNameException
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from mount_twin.errors import MountTwinError
from mount_twin.io.messages import TF, TF_STATIC_TOPIC
from mount_twin.io.output_encoding import static_transforms
from mount_twin.io.output_topics import output_types
from mount_twin.io.scene_record import STRING, scene_message

if TYPE_CHECKING:
    from mount_twin.ros.parameters import NodeOptions
    from mount_twin.ros.start import StopRequests
    from mount_twin.scene.description import Scene


T = TypeVar("T")
SHUTDOWN_ACK_S = 10.0
"""At shutdown, how long (s, steady clock) the node waits for every reliable subscriber to
acknowledge what it published last (the final, partial diagnostics period among it) before it
destroys its publishers; what is still unacknowledged then is named in a warning."""
ACK_POLL_S = 0.05
"""Slice (s) of that wait per publisher, between which a second stop is seen."""
NO_EVENTS = PublisherEventCallbacks(use_default_callbacks=False)
"""The outputs' publishers take no middleware events. rclpy's default ones (a log line on an
incompatible QoS or type, which the subscriber's side logs too) are two waitables a publisher,
and the executor builds its wait set anew at every wake-up: with the pump's 14 publishers, 31
waitables took 1.6 ms of CPU a wake-up."""


def message_class(msgtype: str) -> type:
    """The rclpy message class of a ROS type name ('pkg/msg/Name'), without rosidl_runtime_py."""
    package, _, name = msgtype.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


class OutputNode(Node):
    """An rclpy node with the twin's output publishers (`_pubs`: unresolved topic → publisher,
    made by `_create_outputs`), for the scene and options its subclass sets at construction."""

    options: NodeOptions
    scene: Scene
    _pubs: dict[str, Publisher]

    def _create_outputs(self) -> dict[str, Publisher]:
        """A reliable publisher per output (unresolved topic → publisher); the mount frames on
        latched /tf_static (`_latched`). Without tf2_msgs (not on the package registry) no TF,
        said once."""
        reliable = QoSProfile(
            depth=self.options.output_queue_depth,
            reliability=ReliabilityPolicy.RELIABLE,
            history=HistoryPolicy.KEEP_LAST,
        )
        pubs: dict[str, Publisher] = {}
        try:
            tf_class: type | None = message_class(TF)
        except ImportError:  # tf2_msgs comes with a ROS install, not from the package registry
            tf_class = None
            self.get_logger().warning(
                f"tf2_msgs is not importable: /tf and {TF_STATIC_TOPIC} are not published; "
                "`mount-twin replay` writes them to bags"
            )
        for topic, msgtype in output_types(self.scene).items():
            if msgtype == TF and tf_class is None:
                continue
            cls = message_class(msgtype)  # the others are dependencies: missing ones raise
            pubs[topic] = self._named(
                "outputs",
                partial(self.create_publisher, cls, topic, reliable, event_callbacks=NO_EVENTS),
            )
        if tf_class is not None:
            now = self.get_clock().now().nanoseconds
            self._static = self._latched(tf_class, static_transforms(self.scene, now))
        return pubs

    def _publish_scene(self) -> Publisher:
        """The scene the node runs, once, latched on ~/scene (`io.scene_record`: its digest,
        file, overrides and value), as robot_state_publisher gives /robot_description; the
        scene is read-only (a change restarts the node), so once is all."""
        message = scene_message(self.scene, self.get_clock().now().nanoseconds)
        return self._latched(message_class(STRING), message)

    def _latched(self, cls: type, message: tuple[str, int, bytes]) -> Publisher:
        """A latched publisher (reliable, transient local, depth 1: tf2_ros' static
        broadcaster) of `message`'s topic, which it publishes once."""
        latched = QoSProfile(
            depth=1,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        topic, _, data = message
        pub = self.create_publisher(cls, topic, latched, event_callbacks=NO_EVENTS)
        pub.publish(bytes(data))
        return pub

    def _named(self, parameter: str, create: Callable[[], T]) -> T:
        """Create a publisher or subscription; a name rclpy refuses names the parameter."""
        try:
            return create()
        except InvalidTopicNameException as err:
            msg = f"{self.get_fully_qualified_name()}: {parameter}: {err}".replace("\n", " ")
            raise MountTwinError(msg) from err

    def _publish(self, messages: list[tuple[str, int, bytes]]) -> None:
        for topic, _stamp, data in messages:
            pub = self._pubs.get(topic)
            if pub is not None:
                pub.publish(bytes(data))

    def _wait_for_acks(self, stops: StopRequests) -> bool:
        """Wait up to SHUTDOWN_ACK_S until every reliable subscriber has acknowledged every
        output, or until a second stop; a warning names the topics still unacknowledged. True
        where the second stop cut the wait short."""
        deadline = time.monotonic() + SHUTDOWN_ACK_S
        waiting = list(self._pubs.values())
        slice_s = Duration(seconds=ACK_POLL_S)  # a signal's handler runs only between them
        while True:  # once at least, even after a second stop: what is acknowledged is not lost
            waiting = [p for p in waiting if not p.wait_for_all_acked(slice_s)]
            if not waiting or stops.hurried or time.monotonic() >= deadline:
                break
        if not waiting:
            return False
        topics = ", ".join(
            f"{p.topic_name} (subscribers matched: {p.get_subscription_count()})" for p in waiting
        )
        if stops.hurried:
            self.get_logger().warning(
                f"shutdown: stopped again: the last outputs not acknowledged by every "
                f"subscriber were dropped on {topics}"
            )
            return True
        self.get_logger().warning(
            f"shutdown: not acknowledged by every subscriber within {SHUTDOWN_ACK_S} s, "
            f"the last messages may be lost on {topics}"
        )
        return False
