"""The rclpy shell on a ROS 2 Jazzy machine (skipped where rclpy is not installed)."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy")

from rclpy.parameter import Parameter

from mount_twin.io.messages import imu_messages
from mount_twin.scene.params import flatten

CONFIG = Path(__file__).resolve().parents[1] / "config"


@pytest.fixture
def ros_context():
    os.environ["ROS_PYTHON_CHECK_FIELDS"] = "1"
    rclpy.init()
    yield
    rclpy.try_shutdown()


@pytest.mark.parametrize("batch_period_s", [0.0, 0.005], ids=["per_message", "batched"])
def test_node_publishes_wrenches_for_raw_imu_bytes(ros_context, batch_period_s: float) -> None:
    import yaml
    from geometry_msgs.msg import WrenchStamped
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Imu

    from mount_twin.ros.node import MountTwinNode

    params = yaml.safe_load((CONFIG / "params.yaml").read_text())["mount_twin"]["ros__parameters"]
    overrides = [Parameter(k, value=v) for k, v in flatten(params) if k != "scene_file"]
    overrides.append(Parameter("batch_period_s", value=batch_period_s))
    node = MountTwinNode(parameter_overrides=overrides)
    helper = rclpy.create_node("mount_twin_test_helper")
    got: list[WrenchStamped] = []
    helper.create_subscription(WrenchStamped, "/mount_twin/mounts/fl/wrench", got.append, 10)
    pub = helper.create_publisher(Imu, "/deck/imu", qos_profile_sensor_data)
    n = 50
    accel = np.tile([0.0, 0.0, 9.80665], (n, 1))
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    executor.add_node(helper)
    for _, raw in imu_messages(stamps, accel, np.zeros((n, 3)), "deck_imu"):
        pub.publish(raw)
        executor.spin_once(timeout_sec=0.01)
    deadline = time.monotonic() + 5.0
    while len(got) < 10 and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    assert got, "no wrench received from the node"
    assert got[-1].header.frame_id == "fl"
    # At rest the mounts carry the weight: eight mounts, m = 1200 kg, fl inclined by 30°.
    assert 0.5 * 1200.0 * 9.80665 / 8 < got[-1].wrench.force.z < 1.5 * 1200.0 * 9.80665 / 8
    node.destroy_node()
    helper.destroy_node()
