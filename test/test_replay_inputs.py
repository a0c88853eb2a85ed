"""Replay inputs beyond the scene's own: ROS 1 bags, and --topic / --frame-id overrides."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import CONFIG, ROOT, read_bag, read_raw
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.typesys import Stores, get_typestore

from mount_twin.cli import main
from mount_twin.io.messages import IMU, TYPESTORE

SHIP = ROOT / "bags" / "ship_motion_1khz"
PUMP = CONFIG / "pump_8_mounts.scene.yaml"
N = 300


def _ros1_copy(path: Path, frame_id: str | None = None) -> None:
    """The first N messages of the ship bag, as a ROS 1 bag (header.seq numbered), their
    header.frame_id replaced by `frame_id` if given."""
    ros1 = get_typestore(Stores.ROS1_NOETIC)
    t = ros1.types
    with Ros1Writer(path) as writer:
        conn = writer.add_connection("/deck/imu", IMU, typestore=ros1)
        for seq, (stamp, raw) in enumerate(read_raw(SHIP, ["/deck/imu"])["/deck/imu"][:N]):
            m = TYPESTORE.deserialize_cdr(raw, IMU)
            msg = t[IMU](
                header=t["std_msgs/msg/Header"](
                    seq=seq,
                    stamp=t["builtin_interfaces/msg/Time"](
                        sec=m.header.stamp.sec, nanosec=m.header.stamp.nanosec
                    ),
                    frame_id=m.header.frame_id if frame_id is None else frame_id,
                ),
                orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=m.orientation_covariance,
                angular_velocity=t["geometry_msgs/msg/Vector3"](
                    x=m.angular_velocity.x, y=m.angular_velocity.y, z=m.angular_velocity.z
                ),
                angular_velocity_covariance=m.angular_velocity_covariance,
                linear_acceleration=t["geometry_msgs/msg/Vector3"](
                    x=m.linear_acceleration.x,
                    y=m.linear_acceleration.y,
                    z=m.linear_acceleration.z,
                ),
                linear_acceleration_covariance=m.linear_acceleration_covariance,
            )
            writer.write(conn, stamp, ros1.serialize_ros1(msg, IMU))


def _replay(bag: Path, out: Path, *extra: str, scene: Path = PUMP) -> int:
    args = ["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]
    return main([*args, *extra])


def test_a_ros1_bag_replays_like_the_same_messages_in_a_ros2_bag(tmp_path: Path) -> None:
    ros1 = tmp_path / "ship.bag"
    _ros1_copy(ros1)
    ros2_part = tmp_path / "ros2_part"
    assert (
        main(
            [
                "generate",
                "ship-motion",
                "-o",
                str(ros2_part),
                "--rate",
                "1000",
                "--duration",
                str(N / 1000),
            ]
        )
        == 0
    )  # the same first N samples of ship motion
    assert _replay(ros1, tmp_path / "o1") == 0
    assert _replay(ros2_part, tmp_path / "o2") == 0
    _, a = read_bag(tmp_path / "o1")
    _, b = read_bag(tmp_path / "o2")
    pose = [[m.pose.position.z, m.pose.orientation.x] for _, m in a["/mount_twin/pose"]]
    want = [[m.pose.position.z, m.pose.orientation.x] for _, m in b["/mount_twin/pose"]]
    assert len(pose) == N
    np.testing.assert_array_equal(pose, want)


def test_a_ros1_frame_id_with_a_leading_slash_can_be_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """ROS 1 frame ids start with '/': --frame-id /imu was refused as no tf2 frame id."""
    ros1 = tmp_path / "slash.bag"
    _ros1_copy(ros1, "/imu")
    assert _replay(ros1, tmp_path / "out", "--frame-id", "/imu") == 0
    assert f"{N} received, {N} accepted" in capsys.readouterr().out


def test_topic_and_frame_overrides(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    data["input"].update(topic="/imu/data", frame_id="imu_link")
    scene = tmp_path / "other.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert _replay(SHIP, tmp_path / "none", scene=scene) == 2
    err = capsys.readouterr().err
    assert "no topic '/imu/data' (input.topic; `replay --topic` overrides it)" in err
    assert "the bag has: /deck/imu (sensor_msgs/msg/Imu, 5000 messages)" in err
    assert _replay(SHIP, tmp_path / "wrong_frame", "--topic", "/deck/imu", scene=scene) == 3
    capsys.readouterr()
    args = ("--topic", "/deck/imu", "--frame-id", "deck_imu")
    assert _replay(SHIP, tmp_path / "ok", *args, scene=scene) == 0
    assert "5000 received, 5000 accepted" in capsys.readouterr().out
    assert _replay(SHIP, tmp_path / "bad", "--topic", "not a topic", scene=scene) == 2
