"""The numpy fast path for CDR (mount_twin.io.fixed_layout) against rosbags message by message."""

from __future__ import annotations

import numpy as np
import pytest
from io_helpers import default_scene

from mount_twin.engine.batch import OutputBatch
from mount_twin.io.fixed_layout import FixedLayout
from mount_twin.io.input_decoding import decode_inputs
from mount_twin.io.messages import IMU, TYPESTORE
from mount_twin.io.output_encoding import encode_outputs

T = TYPESTORE.types
RNG = np.random.default_rng(11)


def rosbags_imu(stamp: int, frame: str, v: np.ndarray) -> bytes:
    """An Imu with every numeric field set, built and serialized by rosbags alone."""
    sec, nsec = divmod(stamp, 1_000_000_000)
    vec = T["geometry_msgs/msg/Vector3"]
    msg = T[IMU](
        header=T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec), frame_id=frame
        ),
        orientation=T["geometry_msgs/msg/Quaternion"](x=v[0], y=v[1], z=v[2], w=v[3]),
        orientation_covariance=v[4:13].copy(),
        angular_velocity=vec(x=v[13], y=v[14], z=v[15]),
        angular_velocity_covariance=v[16:25].copy(),
        linear_acceleration=vec(x=v[25], y=v[26], z=v[27]),
        linear_acceleration_covariance=v[28:37].copy(),
    )
    return bytes(TYPESTORE.serialize_cdr(msg, IMU))


def _inputs(n: int, frames: list[str]) -> tuple[list[bytes], np.ndarray, np.ndarray, list[str]]:
    stamps = 1_700_000_000_000_000_000 + np.cumsum(RNG.integers(1, 2_000_000, n))
    values = RNG.normal(0.0, 10.0, (n, 37))
    frame_of = [frames[i % len(frames)] for i in range(n)]
    raws = [rosbags_imu(int(s), f, v) for s, f, v in zip(stamps, frame_of, values, strict=True)]
    return raws, stamps, values, frame_of


@pytest.mark.parametrize("frames", [["deck_imu"], ["a", "imu_link_2", "abc"]])
def test_decoded_imu_equals_rosbags_field_by_field(frames: list[str]) -> None:
    """Frame ids of several lengths (so several layouts) interleaved, and bad messages between."""
    raws, stamps, values, frame_of = _inputs(300, frames)
    raws[7] = b"\x00\x01garbage"
    raws[50] = raws[50][:-8]  # truncated: rosbags rejects it
    keep = [i for i in range(300) if i not in (7, 50)]
    dec = decode_inputs(raws, IMU)
    assert dec.undecodable == 2
    np.testing.assert_array_equal(dec.stamps_ns, stamps[keep])
    np.testing.assert_array_equal(dec.accel, values[keep][:, 25:28])
    np.testing.assert_array_equal(dec.gyro, values[keep][:, 13:16])
    assert dec.frame_ids == [frame_of[i] for i in keep]


@pytest.mark.parametrize("frames", [["deck_imu"], ["a", "imu_link_2", "abc"]])
def test_imu_decoded_one_message_at_a_time_equals_rosbags(frames: list[str]) -> None:
    """The live node's single-message path (the last frame's layout, struct) against rosbags,
    with frames switching, garbage of the right length and dirty padding between."""
    raws, _, _, _ = _inputs(60, frames)
    raws[5] = bytes(len(raws[4]))  # zeros, as long as a real message: not its layout
    raws[9] = raws[9][:22] + b"\xff" * 6 + raws[9][28:] if len(frames[0]) == 8 else raws[9]
    for raw in raws:
        dec = decode_inputs([raw], IMU)
        try:
            msg = TYPESTORE.deserialize_cdr(raw, IMU)
        except Exception:
            assert dec.undecodable == 1 and dec.stamps_ns.shape == (0,)
            continue
        a, w = msg.linear_acceleration, msg.angular_velocity
        assert dec.undecodable == 0
        assert dec.stamps_ns.tolist() == [msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec]
        assert dec.accel.tolist() == [[a.x, a.y, a.z]]
        assert dec.gyro.tolist() == [[w.x, w.y, w.z]]
        assert dec.frame_ids == [msg.header.frame_id]


def test_a_writer_with_nonzero_padding_is_decoded_through_rosbags() -> None:
    """CDR padding is unspecified: bytes there must not be taken for data, nor break decoding."""
    raws, stamps, values, _ = _inputs(20, ["imu_x"])
    # CDR: 4-byte encapsulation, sec, nanosec, string length, 'imu_x' + NUL ends at byte 22;
    # the orientation's doubles align to 8 from byte 4, so bytes 22..27 are padding
    dirty = [r[:22] + b"\xff\xee\xdd\xcc\xbb\xaa" + r[28:] for r in raws]
    assert TYPESTORE.deserialize_cdr(dirty[0], IMU).header.frame_id == "imu_x"
    dec = decode_inputs(dirty, IMU)
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    np.testing.assert_array_equal(dec.accel, values[:, 25:28])


@pytest.mark.parametrize("k", [25, 1], ids=["batch", "one_row"])  # one row: the struct path
def test_encoded_outputs_are_byte_equal_to_rosbags(k: int) -> None:
    scene = default_scene()
    nm = len(scene.mounts)
    stamps = 1_700_000_000_000_000_000 + np.cumsum(RNG.integers(1, 2_000_000, k))
    pose = RNG.normal(size=(k, 10))
    wrenches = RNG.normal(0.0, 1e4, (k, nm, 6))
    out = OutputBatch(stamps * 1e-9, np.arange(k), pose, wrenches)
    msgs = encode_outputs(scene, out, stamps)
    per_row = 3 + nm  # pose, angles, the wrenches, /tf
    assert len(msgs) == k * per_row
    vec = T["geometry_msgs/msg/Vector3"]
    for j, (topic, stamp, raw) in enumerate(msgs):
        row, slot = divmod(j, per_row)
        assert stamp == stamps[row]
        sec, nsec = divmod(int(stamp), 1_000_000_000)
        time = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)
        p = pose[row]
        if slot == 0:
            header = T["std_msgs/msg/Header"](stamp=time, frame_id=scene.frames.foundation)
            want = T["geometry_msgs/msg/PoseStamped"](
                header=header,
                pose=T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=p[2]),
                    orientation=T["geometry_msgs/msg/Quaternion"](x=p[3], y=p[4], z=p[5], w=p[6]),
                ),
            )
            typename = "geometry_msgs/msg/PoseStamped"
        elif slot == 1:
            header = T["std_msgs/msg/Header"](stamp=time, frame_id=scene.frames.foundation)
            want = T["geometry_msgs/msg/Vector3Stamped"](
                header=header, vector=vec(x=p[7], y=p[8], z=p[9])
            )
            typename = "geometry_msgs/msg/Vector3Stamped"
        elif slot == per_row - 1:
            header = T["std_msgs/msg/Header"](stamp=time, frame_id=scene.frames.foundation)
            want = T["tf2_msgs/msg/TFMessage"](
                transforms=[
                    T["geometry_msgs/msg/TransformStamped"](
                        header=header,
                        child_frame_id=scene.frames.body,
                        transform=T["geometry_msgs/msg/Transform"](
                            translation=vec(x=p[0], y=p[1], z=p[2]),
                            rotation=T["geometry_msgs/msg/Quaternion"](
                                x=p[3], y=p[4], z=p[5], w=p[6]
                            ),
                        ),
                    )
                ]
            )
            typename = "tf2_msgs/msg/TFMessage"
        else:
            i = slot - 2
            w = wrenches[row, i]
            header = T["std_msgs/msg/Header"](stamp=time, frame_id=scene.mounts[i].name)
            want = T["geometry_msgs/msg/WrenchStamped"](
                header=header,
                wrench=T["geometry_msgs/msg/Wrench"](
                    force=vec(x=w[0], y=w[1], z=w[2]), torque=vec(x=w[3], y=w[4], z=w[5])
                ),
            )
            typename = "geometry_msgs/msg/WrenchStamped"
        assert raw == bytes(TYPESTORE.serialize_cdr(want, typename)), (topic, row)


def test_a_layout_whose_length_depends_on_the_numbers_is_refused() -> None:
    def build(v):
        return T["std_msgs/msg/String"](data="x" * int(v[0] % 7))

    with pytest.raises(ValueError, match="not a fixed layout"):
        FixedLayout.probe(
            build, ["<i4"], lambda m: TYPESTORE.serialize_cdr(m, "std_msgs/msg/String")
        )


def test_a_frame_id_that_defeats_the_probe_is_decoded_through_rosbags() -> None:
    """The probe locates fields by sentinel bytes; a frame_id holding one (here the nanosec
    sentinel A5 01 5A 3C: '¥' is C2 A5 in UTF-8) must not break decoding (bad input is never
    raised out of the twin), only lose the fast path."""
    frame = "imu\u00a5\x01Z<"
    raws, stamps, values, _ = _inputs(10, [frame])
    dec = decode_inputs(raws, IMU)
    assert dec.undecodable == 0
    np.testing.assert_array_equal(dec.stamps_ns, stamps)
    np.testing.assert_array_equal(dec.accel, values[:, 25:28])
    assert dec.frame_ids == [frame] * 10
