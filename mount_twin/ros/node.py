"""The rclpy shell: the only module that imports rclpy.

Moves raw CDR bytes only (raw subscription, byte publishers) so that every (de)serialization is
the rosbags code the bag replay and the tests run. Parameters: a params YAML in the Nav2 style or
a `scene_file`, both through `scene_from_params`.
"""

from __future__ import annotations

import rclpy
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from rosidl_runtime_py.utilities import get_message

from mount_twin.io.messages import output_types
from mount_twin.scene.params import (
    COMMON_MOUNT_PARAMETERS,
    PARAMETERS,
    mount_parameters,
    scene_from_params,
)
from mount_twin.stream import TwinStream

_TYPES = {
    "string": Parameter.Type.STRING,
    "double": Parameter.Type.DOUBLE,
    "double_array": Parameter.Type.DOUBLE_ARRAY,
    "string_array": Parameter.Type.STRING_ARRAY,
    "bool": Parameter.Type.BOOL,
    "integer": Parameter.Type.INTEGER,
}


class MountTwinNode(Node):
    """Foundation acceleration in; pose, α/γ/δ, mount wrenches and diagnostics out."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__("mount_twin", **kwargs)
        flat = self._declare_and_read()
        self.scene = scene_from_params(flat, f"parameters of {self.get_fully_qualified_name()}")
        self.stream = TwinStream(self.scene)
        reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self._pubs = {
            topic: self.create_publisher(get_message(msgtype), topic, reliable)
            for topic, msgtype in output_types(self.scene).items()
        }
        spec = self.scene.input
        batch_period = self.declare_parameter(
            "batch_period_s",
            0.0,
            ParameterDescriptor(
                description="0.0: process each input message on arrival; > 0: queue them and "
                "process the queue every batch_period_s (s) in one engine call, for input "
                "rates where the per-message overhead would not keep up (e.g. 10 kHz)",
                read_only=True,
            ),
        ).value
        self._pending: list[bytes] = []
        if batch_period > 0.0:
            self._timer = self.create_timer(batch_period, self._drain)
        self._sub = self.create_subscription(
            get_message(spec.msg_type),
            spec.topic,
            self._pending.append if batch_period > 0.0 else self._on_input,
            qos_profile_sensor_data,
            raw=True,
        )
        self.get_logger().info(
            f"scene {self.scene.name!r} from {self.scene.source}: "
            f"{len(self.scene.mounts)} mounts, DOFs {list(self.scene.dofs)}; input "
            f"{self._sub.topic_name} ({spec.msg_type}); outputs "
            + ", ".join(p.topic_name for p in self._pubs.values())
        )

    def _declare_and_read(self) -> dict[str, object]:
        """Declare every scene parameter with a descriptor; return the ones set (flat names)."""
        names = dict(PARAMETERS)
        self.declare_parameter(
            "mount_names",
            Parameter.Type.STRING_ARRAY,
            ParameterDescriptor(description=PARAMETERS["mount_names"][1], read_only=True),
        )
        mount_names = self.get_parameter("mount_names")
        if mount_names.type_ != Parameter.Type.NOT_SET:
            for mount in mount_names.value:
                kind = self.declare_parameter(
                    f"mounts.{mount}.kind",
                    "linear",
                    ParameterDescriptor(
                        description=COMMON_MOUNT_PARAMETERS["kind"][1], read_only=True
                    ),
                ).value
                names.update(
                    {f"mounts.{mount}.{key}": spec for key, spec in mount_parameters(kind).items()}
                )
        flat: dict[str, object] = {}
        for name, (ptype, description) in names.items():
            if name != "mount_names" and not self.has_parameter(name):
                self.declare_parameter(
                    name,
                    _TYPES[ptype],
                    ParameterDescriptor(description=description, read_only=True),
                )
            param = self.get_parameter(name)
            if param.type_ != Parameter.Type.NOT_SET:
                value = param.value
                flat[name] = list(value) if ptype.endswith("_array") else value
        return flat

    def publish_final_diagnostics(self) -> None:
        """Process what is still queued, then publish the last, partial diagnostics period."""
        self._drain()
        self._publish(self.stream.finish())

    def _on_input(self, raw: bytes) -> None:
        self._publish(self.stream.process([raw]))

    def _drain(self) -> None:
        if self._pending:
            raws = self._pending[:]
            del self._pending[:]  # the subscription appends to this very list
            self._publish(self.stream.process(raws))

    def _publish(self, messages: list[tuple[str, int, bytes]]) -> None:
        for topic, _stamp, data in messages:
            self._pubs[topic].publish(data)


def main(args: list[str] | None = None) -> None:
    """Console entry point `mount_twin_node`."""
    rclpy.init(args=args)
    node = None
    try:
        node = MountTwinNode()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            if rclpy.ok():
                node.publish_final_diagnostics()
            node.destroy_node()
        rclpy.try_shutdown()
