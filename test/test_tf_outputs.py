"""Frames RViz and Foxglove can place: /tf (body pose), /tf_static (mount frames), the mount
prefix of the wrench frames, and the latched QoS of /tf_static in a replayed bag.

Truth is independent of the package: bags are read back with rosbags' AnyReader, rotations are
built with scipy (`Rotation.from_euler('xyz', rpy)`: extrinsic x, y, z = the fixed-axis roll,
pitch, yaw the scene's orientation_rpy documents), equilibrium is Newton's (Σ F = m·g up at rest).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from io_helpers import REST, SCENE_FILE, G, default_scene, read_bag, scene_with, stamp_ns
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability, QosReliability
from scipy.spatial.transform import Rotation

from mount_twin.engine.batch import OutputBatch
from mount_twin.errors import SceneError
from mount_twin.io.messages import IMU, NODE_NAME, TF, TF_STATIC_TOPIC, TF_TOPIC, TYPESTORE
from mount_twin.io.output_bag import write_bag
from mount_twin.io.output_encoding import encode_outputs, imu_messages, static_transforms
from mount_twin.io.output_topics import output_types
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file, scene_from_params
from mount_twin.scene.description import Scene

T = TYPESTORE.types
START_NS = 1_700_000_000_250_000_000
N_REST = 200  # 0.2 s at 1 kHz
RNG = np.random.default_rng(5)


def _rest_bag(path: Path) -> list[int]:
    """An Imu bag of a foundation at rest (+g up, no rotation) on /deck/imu; its stamps (ns)."""
    stamps = START_NS + np.arange(N_REST, dtype=np.int64) * 1_000_000
    accel = np.tile(REST, (N_REST, 1))
    msgs = imu_messages(stamps, accel, np.zeros((N_REST, 3)), "deck_imu")
    assert write_bag(path, "/deck/imu", IMU, iter(msgs)) == N_REST
    return stamps.tolist()


@pytest.fixture(scope="module")
def rest(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The default scene replayed over an at-rest bag, read back with rosbags."""
    d = tmp_path_factory.mktemp("tf")
    stamps = _rest_bag(d / "in")
    replay(default_scene(), d / "in", d / "out", progress=False)
    types, msgs = read_bag(d / "out")
    return {"stamps": stamps, "types": types, "msgs": msgs, "out": d / "out", "in": d / "in"}


def _xyzw(q: Any) -> np.ndarray:
    return np.array([q.x, q.y, q.z, q.w])


def _xyz(v: Any) -> np.ndarray:
    return np.array([v.x, v.y, v.z])


# --------------------------------------------------------------------------- encoding


def _rosbags_tf(stamp: int, parent: str, child: str, v: np.ndarray) -> bytes:
    """A one-transform TFMessage built and serialized by rosbags alone."""
    sec, nsec = divmod(stamp, 1_000_000_000)
    header = T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id=parent
    )
    tf = T["geometry_msgs/msg/TransformStamped"](
        header=header,
        child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](x=v[0], y=v[1], z=v[2]),
            rotation=T["geometry_msgs/msg/Quaternion"](x=v[3], y=v[4], z=v[5], w=v[6]),
        ),
    )
    return bytes(TYPESTORE.serialize_cdr(T[TF](transforms=[tf]), TF))


@pytest.mark.parametrize(
    ("foundation", "body"), [("deck", "pump"), ("odom", "base_link"), ("f", "a_longer_body")]
)
def test_tf_fast_path_is_byte_equal_to_rosbags(foundation: str, body: str) -> None:
    """Frame names of several lengths, so several paddings of the fixed layout."""
    scene = scene_with(frames={"foundation": foundation, "body": body})
    k = 40
    stamps = START_NS + np.cumsum(RNG.integers(1, 2_000_000, k))
    pose = RNG.normal(size=(k, 10))
    wrenches = RNG.normal(size=(k, len(scene.mounts), 6))
    msgs = encode_outputs(scene, OutputBatch(stamps * 1e-9, np.arange(k), pose, wrenches), stamps)
    tf = [(s, raw) for topic, s, raw in msgs if topic == TF_TOPIC]
    assert [s for s, _ in tf] == stamps.tolist()
    for row, (stamp, raw) in enumerate(tf):
        assert raw == _rosbags_tf(int(stamp), foundation, body, pose[row, :7]), row


def test_static_transforms_decode_to_one_transform_per_mount() -> None:
    scene = default_scene()
    topic, stamp, raw = static_transforms(scene, START_NS)
    assert (topic, stamp) == ("/tf_static", START_NS) and topic == TF_STATIC_TOPIC
    msg = TYPESTORE.deserialize_cdr(raw, TF)
    assert [t.child_frame_id for t in msg.transforms] == [m.name for m in scene.mounts]
    for t, m in zip(msg.transforms, scene.mounts, strict=True):
        assert t.header.frame_id == "deck" and stamp_ns(t) == START_NS
        assert _xyz(t.transform.translation).tolist() == list(m.position)
        np.testing.assert_allclose(np.linalg.norm(_xyzw(t.transform.rotation)), 1.0, atol=1e-15)


# --------------------------------------------------------------------------- replayed bag


def test_replayed_bag_has_tf_and_tf_static_with_their_type(rest: dict[str, Any]) -> None:
    assert rest["types"]["/tf"] == rest["types"]["/tf_static"] == "tf2_msgs/msg/TFMessage"
    assert len(rest["msgs"]["/tf"]) == len(rest["msgs"][f"/{NODE_NAME}/pose"]) == N_REST
    assert len(rest["msgs"]["/tf_static"]) == 1


def test_every_tf_transform_equals_the_pose_of_the_same_stamp(rest: dict[str, Any]) -> None:
    poses = {stamp_ns(m): m for _, m in rest["msgs"][f"/{NODE_NAME}/pose"]}
    assert sorted(poses) == rest["stamps"]
    for log_time, msg in rest["msgs"]["/tf"]:
        (tf,) = msg.transforms
        pose = poses[stamp_ns(tf)]
        assert log_time == stamp_ns(tf)
        assert (tf.header.frame_id, tf.child_frame_id) == ("deck", "pump")
        assert tf.header.frame_id == pose.header.frame_id
        assert _xyz(tf.transform.translation).tolist() == _xyz(pose.pose.position).tolist()
        assert _xyzw(tf.transform.rotation).tolist() == _xyzw(pose.pose.orientation).tolist()


def test_tf_static_is_written_once_first_at_the_first_input_stamp(rest: dict[str, Any]) -> None:
    ((log_time, msg),) = rest["msgs"]["/tf_static"]
    first = rest["stamps"][0]
    assert log_time == first and {stamp_ns(t) for t in msg.transforms} == {first}
    assert all(t >= log_time for msgs in rest["msgs"].values() for t, _ in msgs)
    scene = default_scene()
    assert [(t.header.frame_id, t.child_frame_id) for t in msg.transforms] == [
        ("deck", m.name) for m in scene.mounts
    ]
    for t, m in zip(msg.transforms, scene.mounts, strict=True):
        assert _xyz(t.transform.translation).tolist() == list(m.position)


def test_tf_static_rotation_is_the_fixed_axis_rpy_of_the_mount(rest: dict[str, Any]) -> None:
    """Rotation.from_quat(q) must map the mount's local axes e_x, e_y, e_z to the directions
    Rotation.from_euler('xyz', rpy) gives (fixed axes: R = Rz(yaw)·Ry(pitch)·Rx(roll))."""
    ((_, msg),) = rest["msgs"]["/tf_static"]
    scene = default_scene()
    inclined = 0
    for t, m in zip(msg.transforms, scene.mounts, strict=True):
        got = Rotation.from_quat(_xyzw(t.transform.rotation))  # scipy: (x, y, z, w)
        want = Rotation.from_euler("xyz", m.orientation_rpy)
        np.testing.assert_allclose(got.apply(np.eye(3)), want.apply(np.eye(3)), atol=1e-12)
        inclined += not np.allclose(want.as_matrix(), np.eye(3))
    assert inclined == 4, "the default scene has four inclined mounts: the check must see them"
    # by hand: Rx(roll) takes e_z to (0, −sin roll, cos roll); fl (roll −30°): (0, 0.5, 0.866)
    roll = scene.mounts[0].orientation_rpy[0]
    assert scene.mounts[0].name == "fl" and roll == pytest.approx(-0.5236)
    fl = Rotation.from_quat(_xyzw(msg.transforms[0].transform.rotation))
    np.testing.assert_allclose(
        fl.apply([0.0, 0.0, 1.0]), [0.0, -np.sin(roll), np.cos(roll)], atol=1e-12
    )


def test_mount_wrenches_placed_by_tf_static_balance_gravity_at_rest(rest: dict[str, Any]) -> None:
    """At rest the mounts carry the body. Each WrenchStamped, rotated into F by the /tf_static
    transform of its header.frame_id: Σ F_i = m·g along +z of F (the forces of the inclined
    mounts have lateral components that only cancel in F), and about the CG (/tf at the same
    stamp) Σ r_i × F_i + Σ C_i = 0, r_i the body point of the mount's static translation."""
    scene = default_scene()
    ((_, static),) = rest["msgs"]["/tf_static"]
    frames = {t.child_frame_id: t.transform for t in static.transforms}
    (last_tf,) = rest["msgs"]["/tf"][-1][1].transforms
    body = Rotation.from_quat(_xyzw(last_tf.transform.rotation))
    cg_ref = np.array(scene.body.cg)
    total, moment = np.zeros(3), np.zeros(3)
    lateral = 0.0
    for m in scene.mounts:
        stamp, wrench = rest["msgs"][f"/{NODE_NAME}/mounts/{m.name}/wrench"][-1]
        assert wrench.header.frame_id == m.name and stamp == stamp_ns(last_tf)
        frame = frames[wrench.header.frame_id]
        rot = Rotation.from_quat(_xyzw(frame.rotation))
        force = rot.apply(_xyz(wrench.wrench.force))
        couple = rot.apply(_xyz(wrench.wrench.torque))
        arm = body.apply(_xyz(frame.translation) - cg_ref)
        lateral = max(lateral, abs(force[1]))
        total += force
        moment += np.cross(arm, force) + couple
    weight = scene.body.mass * G
    np.testing.assert_allclose(total, [0.0, 0.0, weight], rtol=0, atol=1e-6 * weight)
    np.testing.assert_allclose(moment, 0.0, rtol=0, atol=1e-6 * weight)  # N·m, arms ~1 m
    assert lateral > 0.01 * weight / len(scene.mounts), "inclined mounts push sideways in F"


def test_the_wrong_rotation_would_not_balance(rest: dict[str, Any]) -> None:
    """Control: the wrench forces summed without their mount rotation (or with its inverse) miss
    m·g, so the balance above really tests the rotation."""
    scene = default_scene()
    ((_, static),) = rest["msgs"]["/tf_static"]
    weight = scene.body.mass * G
    for use in ("none", "inverse"):
        total = np.zeros(3)
        for t, m in zip(static.transforms, scene.mounts, strict=True):
            (_, wrench), *_ = reversed(rest["msgs"][f"/{NODE_NAME}/mounts/{m.name}/wrench"])
            f = _xyz(wrench.wrench.force)
            rot = Rotation.from_quat(_xyzw(t.transform.rotation))
            total += f if use == "none" else rot.inv().apply(f)
        assert abs(total[2] - weight) > 1e-3 * weight, use


def test_tf_static_is_offered_transient_local_in_the_bag(rest: dict[str, Any]) -> None:
    with AnyReader([rest["out"]], default_typestore=TYPESTORE) as reader:
        qos = {c.topic: c.ext.offered_qos_profiles for c in reader.connections}
    (static,) = qos["/tf_static"]
    assert static.durability == QosDurability.TRANSIENT_LOCAL
    assert static.reliability == QosReliability.RELIABLE
    assert static.depth == 1
    assert qos["/tf"] == [] and qos[f"/{NODE_NAME}/pose"] == [], "other topics unchanged"
    meta = yaml.safe_load((rest["out"] / "metadata.yaml").read_text(encoding="utf-8"))
    topics = {
        t["topic_metadata"]["name"]: t["topic_metadata"]
        for t in meta["rosbag2_bagfile_information"]["topics_with_message_count"]
    }
    offered = topics["/tf_static"]["offered_qos_profiles"]
    offered = yaml.safe_load(offered) if isinstance(offered, str) else offered
    assert [p["durability"] for p in offered] == ["transient_local"]


# --------------------------------------------------------------------------- scene keys


def test_mount_prefix_names_the_wrench_frames_and_the_static_children() -> None:
    scene = scene_with(frames={"mount_prefix": "pump/"})
    k = 2
    stamps = START_NS + np.arange(k, dtype=np.int64)
    out = OutputBatch(stamps * 1e-9, np.arange(k), RNG.normal(size=(k, 10)), np.zeros((k, 8, 6)))
    types = output_types(scene)
    frames = {
        TYPESTORE.deserialize_cdr(raw, types[topic]).header.frame_id
        for topic, _, raw in encode_outputs(scene, out, stamps)
        if types[topic] == "geometry_msgs/msg/WrenchStamped"
    }
    assert frames == {f"pump/{m.name}" for m in scene.mounts}
    _, _, raw = static_transforms(scene, START_NS)
    children = [t.child_frame_id for t in TYPESTORE.deserialize_cdr(raw, TF).transforms]
    assert children == [f"pump/{m.name}" for m in scene.mounts]


def test_mount_prefix_in_a_replayed_bag(tmp_path: Path) -> None:
    _rest_bag(tmp_path / "in")
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    data["frames"]["mount_prefix"] = "pump/"
    data["outputs"]["tf"] = False
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    scene = load_scene_file(path)
    assert scene.frames.mount_prefix == "pump/" and scene.outputs.tf is False
    replay(scene, tmp_path / "in", tmp_path / "out", progress=False)
    types, msgs = read_bag(tmp_path / "out")
    assert "/tf" not in types and types["/tf_static"] == TF, "outputs.tf only drops /tf"
    ((_, static),) = msgs["/tf_static"]
    assert [t.child_frame_id for t in static.transforms] == [
        f"pump/{m.name}" for m in scene.mounts
    ]
    for m in scene.mounts:
        got = {w.header.frame_id for _, w in msgs[f"/{NODE_NAME}/mounts/{m.name}/wrench"]}
        assert got == {f"pump/{m.name}"}


def test_outputs_tf_false_removes_tf() -> None:
    on, off = default_scene(), scene_with(outputs={"tf": False})
    assert on.outputs.tf is True and output_types(on)["/tf"] == TF
    assert "/tf" not in output_types(off)
    out = OutputBatch(
        np.array([0.25]), np.array([0]), RNG.normal(size=(1, 10)), np.zeros((1, 8, 6))
    )
    topics_on = [t for t, _, _ in encode_outputs(on, out, np.array([START_NS]))]
    topics_off = [t for t, _, _ in encode_outputs(off, out, np.array([START_NS]))]
    assert topics_on == [*topics_off, "/tf"]


def test_defaults_of_the_new_keys() -> None:
    scene = default_scene()
    assert scene.frames.mount_prefix == "" and scene.outputs.tf is True
    assert scene.frames.mount_frame("fl") == "fl"


def _scene_file_with(tmp_path: Path, section: str, key: str, value: Any) -> Path:
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    data.setdefault(section, {})[key] = value
    path = tmp_path / "bad.scene.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("section", "key", "value", "rest"),
    [
        ("frames", "mount_prefix", 5, r"expected a string, got 5"),
        ("frames", "mount_prefix", ["a"], r"expected a string"),
        ("frames", "mount_prefix", "/pump/", r"no leading '/'"),
        ("outputs", "tf", "yes", r"expected true or false, got 'yes'"),
        ("outputs", "tf", 1, r"expected true or false, got 1"),
    ],
)
def test_bad_new_keys_fail_naming_the_key_path(
    tmp_path: Path, section: str, key: str, value: Any, rest: str
) -> None:
    path = _scene_file_with(tmp_path, section, key, value)
    with pytest.raises(SceneError, match=re.escape(f"{path}: {section}.{key}: ") + ".*" + rest):
        load_scene_file(path)


def test_bad_new_parameters_fail_naming_the_parameter() -> None:
    from io_helpers import params_yaml

    from mount_twin.scene.params import PARAMETERS, flatten

    assert PARAMETERS["frames.mount_prefix"][0] == "string"
    assert PARAMETERS["outputs.tf"][0] == "bool"
    flat = dict(flatten(params_yaml()))
    for name, value in (("outputs.tf", "yes"), ("frames.mount_prefix", 3)):
        with pytest.raises(SceneError, match=re.escape(f"params: {name}: ")):
            scene_from_params({**flat, name: value}, "params")
    scene: Scene = scene_from_params({**flat, "frames.mount_prefix": "p_"}, "params")
    assert scene.frames.mount_frame("fl") == "p_fl"
