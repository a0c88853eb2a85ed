"""The twin's outputs as CDR messages: per-row outputs message by message or in blocks of rows,
the diagnostics reports, the body IMU comparison, the mount frames' static transforms, and
sensor_msgs/Imu messages of given readings."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import chain
from typing import Any

import numpy as np

from mount_twin.engine.batch import HealthReport, OutputBatch
from mount_twin.engine.body_check import BodyComparison
from mount_twin.io.fixed_layout import split_rows
from mount_twin.io.messages import (
    DIAGNOSTICS,
    DIAGNOSTICS_TOPIC,
    IMU,
    TF,
    TF_STATIC_TOPIC,
    TYPESTORE,
    pack_messages,
    stamped_header,
    transform_stamped,
)
from mount_twin.io.output_topics import (
    BODY_PREDICTED_TOPIC,
    BODY_RESIDUAL_TOPIC,
    Stream,
    output_streams,
)
from mount_twin.physics.rotations import quaternion_from_matrix, rpy_matrix
from mount_twin.scene.description import Scene

_T = TYPESTORE.types


@dataclass(frozen=True)
class RowBlock:
    """Per-row output messages in columns: row k holds, for each topic j in order, the message
    stamped stamps_ns[k] whose CDR bytes are rows[j][k] (`messages` lists them row by row, the
    order they are published in). A bag writer takes the block whole (`io.mcap_writer`).

    Attributes:
        topics: (m,) topic of each column (unresolved from `encode_output_blocks`; `renamed`).
        stamps_ns: (k,) int64 stamps, ns.
        rows: m arrays (k, L_j) uint8, each message of topic j one row of L_j bytes.
    """

    topics: tuple[str, ...]
    stamps_ns: np.ndarray
    rows: tuple[np.ndarray, ...]

    def messages(self) -> list[tuple[str, int, bytes]]:
        """(topic, stamp ns, CDR bytes) row by row."""
        k = len(self.stamps_ns)
        stamps = self.stamps_ns.tolist()
        columns = []
        for topic, rows in zip(self.topics, self.rows, strict=True):
            columns.append(zip([topic] * k, stamps, split_rows(rows), strict=True))
        return list(chain.from_iterable(zip(*columns, strict=True)))

    def renamed(self, names: dict[str, str]) -> RowBlock:
        """The block with each topic t as names[t]."""
        return RowBlock(tuple(names[t] for t in self.topics), self.stamps_ns, self.rows)


Encoded = tuple[str, int, bytes] | RowBlock
"""An encoded output: one message (topic, stamp ns, CDR bytes), or a block of per-row ones."""


def messages_of(encoded: Sequence[Encoded]) -> list[tuple[str, int, bytes]]:
    """The messages of encoded outputs one by one, in order."""
    out: list[tuple[str, int, bytes]] = []
    for item in encoded:
        if isinstance(item, RowBlock):
            out += item.messages()
        else:
            out.append(item)
    return out


def encode_outputs(
    scene: Scene,
    out: OutputBatch,
    stamps_ns: np.ndarray,
    streams: Sequence[Stream] | None = None,
) -> list[tuple[str, int, bytes]]:
    """`encode_output_blocks` message by message."""
    return messages_of(encode_output_blocks(scene, out, stamps_ns, streams))


PACK_ONE_MAX = 4
"""Most rows `encode_output_blocks` packs message by message (`FixedLayout.pack_one`, a
struct call each) rather than in blocks (`pack_rows`, numpy's per-call overhead a topic):
a live wake-up's one sample or few."""


def encode_output_blocks(
    scene: Scene,
    out: OutputBatch,
    stamps_ns: np.ndarray,
    streams: Sequence[Stream] | None = None,
) -> list[Encoded]:
    """CDR messages for an output batch, in the order the samples were processed: blocks of
    per-row messages (`RowBlock`), each diagnostics report (topic, stamp ns, bytes) after the
    rows published before it was due (`HealthReport.rows`).

    Args:
        stamps_ns: (n,) header stamps of the pushed samples, integer ns; rows reuse them, so
            output stamps equal input stamps exactly however long the twin runs.
        streams: `output_streams(scene)`, where the caller keeps them (a live stream encodes
            each sample on its own: building them took a tenth of its encoding).

    Per published row, in this order: pose, angles, one wrench per mount (header.frame_id =
    the mount's frame, `Frames.mount_frame`), /tf (frames.foundation → frames.body, the pose's
    numbers). Only the outputs the scene enables are built: unused outputs cost nothing.
    """
    stamps = stamps_ns[out.sample]
    if streams is None:
        streams = output_streams(scene)
    topics = tuple(st.topic for st in streams)
    if len(stamps) <= PACK_ONE_MAX:  # a live wake-up's few samples: struct, not numpy
        values = [st.values(out).tolist() for st in streams]  # (k, m) each
        per_row: list[list[Encoded]] = []
        for r, stamp in enumerate(stamps.tolist()):
            head = divmod(stamp, 1_000_000_000)
            per_row.append(
                [
                    (st.topic, stamp, st.layout.pack_one([*head, *v[r]]))
                    for st, v in zip(streams, values, strict=True)
                ]
            )
    else:
        sec, nsec = np.divmod(stamps, 1_000_000_000)
        rows = tuple(st.layout.pack_rows([sec, nsec, st.values(out)]) for st in streams)

    def block(a: int, b: int) -> list[Encoded]:
        if b <= a or not topics:
            return []
        if len(stamps) <= PACK_ONE_MAX:
            return [m for row in per_row[a:b] for m in row]
        return [RowBlock(topics, stamps[a:b], tuple(r[a:b] for r in rows))]

    encoded: list[Encoded] = []
    done = 0  # rows encoded
    for report in out.health:  # each before the first row at or after its `rows`
        upto = max(done, min(report.rows, len(stamps)))
        encoded += block(done, upto)
        encoded.append(encode_report(scene, report, int(stamps_ns[report.sample])))
        done = upto
    return encoded + block(done, len(stamps))


def encode_report(scene: Scene, report: HealthReport, stamp_ns: int) -> tuple[str, int, bytes]:
    """A health report as (unresolved topic, stamp ns, DiagnosticArray CDR bytes)."""
    msg = diagnostics_message(report, stamp_ns)
    return DIAGNOSTICS_TOPIC, stamp_ns, bytes(TYPESTORE.serialize_cdr(msg, DIAGNOSTICS))


def diagnostics_message(report: HealthReport, stamp_ns: int) -> Any:
    """diagnostic_msgs/DiagnosticArray of a health report (level is a byte: int in rosbags)."""
    status_t, kv_t = _T["diagnostic_msgs/msg/DiagnosticStatus"], _T["diagnostic_msgs/msg/KeyValue"]
    statuses = [
        status_t(
            level=s.level,
            name=s.name,
            message=s.message,
            hardware_id="mount_twin",
            values=[kv_t(key=k, value=v) for k, v in s.values.items()],
        )
        for s in report.statuses
    ]
    return _T[DIAGNOSTICS](header=stamped_header(stamp_ns, ""), status=statuses)


def body_frame_id(scene: Scene) -> str:
    """The frame id of the body IMU's prediction and residual: its own, else <frames.body>_imu."""
    sensor = scene.body_sensor
    return (sensor.frame_id if sensor else "") or f"{scene.frames.body}_imu"


def encode_body(scene: Scene, rows: BodyComparison) -> list[tuple[str, int, bytes]]:
    """The body comparison as (unresolved topic, stamp ns, CDR bytes): per compared sample its
    prediction and residual (stamped as the sample; linear_acceleration the specific force,
    m/s², angular_velocity the rate, rad/s, in the sensor's axes; no orientation; a reading
    the sample does not provide marked so in the residual, REP-145, its value NaN), then each
    window's report on /diagnostics."""
    frame = body_frame_id(scene)
    msgs: list[tuple[str, int, bytes]] = []
    if rows.stamps_ns.shape[0]:
        off = rows.residual
        pairs = zip(
            imu_messages(rows.stamps_ns, rows.predicted[:, :3], rows.predicted[:, 3:], frame),
            imu_messages(rows.stamps_ns, off[:, :3], off[:, 3:], frame, ~rows.present),
            strict=True,
        )
        for (stamp, predicted), (_, residual) in pairs:
            msgs += [
                (BODY_PREDICTED_TOPIC, stamp, predicted),
                (BODY_RESIDUAL_TOPIC, stamp, residual),
            ]
    for stamp, status in rows.reports:
        msgs.append(encode_report(scene, HealthReport(stamp * 1e-9, -1, [status]), stamp))
    return msgs


def mount_quaternion(orientation_rpy: Sequence[float]) -> np.ndarray:
    """Unit quaternion (x, y, z, w), w ≥ 0, of a mount's axes relative to F.

    Args:
        orientation_rpy: the mount's fixed-axis roll, pitch, yaw, rad.

    The rotation is the model's (`rpy_matrix`, columns = mount axes in F): it takes a vector
    expressed in the mount's axes (a WrenchStamped of that mount) to the same vector in F.
    """
    quat = np.empty(4)
    quaternion_from_matrix(rpy_matrix(*orientation_rpy), quat)
    return quat


def static_transforms(scene: Scene, stamp_ns: int) -> tuple[str, int, bytes]:
    """The /tf_static message of the mount frames, as (topic, stamp ns, TFMessage CDR bytes).

    One TransformStamped per mount, in scene order: parent frames.foundation, child the mount's
    frame (`Frames.mount_frame`), translation the mount's position (m, in F at the reference
    pose), rotation its axes relative to F (`mount_quaternion`). These frames are fixed in F:
    the mount axes of the wrench outputs are those of the reference pose.

    Args:
        stamp_ns: header stamp of every transform, ns (the replay uses the first input stamp;
            tf2 ignores the stamps of static transforms).

    Publish once, latched: TF_STATIC_TOPIC with reliable, transient_local, keep-last depth 1
    (tf2_ros' static broadcaster QoS), so late RViz/Foxglove subscribers still get it.
    """
    sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
    frames = scene.frames
    transforms = [
        transform_stamped(
            frames.foundation,
            frames.mount_frame(m.name),
            [sec, nanosec, *m.position, *mount_quaternion(m.orientation_rpy)],
        )
        for m in scene.mounts
    ]
    raw = bytes(TYPESTORE.serialize_cdr(_T[TF](transforms=transforms), TF))
    return TF_STATIC_TOPIC, int(stamp_ns), raw


def imu_messages(
    stamps_ns: np.ndarray,
    accel: np.ndarray,
    gyro: np.ndarray,
    frame_id: str,
    unprovided: np.ndarray | None = None,
) -> list[tuple[int, bytes]]:
    """sensor_msgs/Imu messages (no orientation estimate: orientation_covariance[0] = −1; the
    acceleration, the angular velocity marked not provided alike where `unprovided`, (k, 2),
    says so: REP-145)."""
    k = stamps_ns.shape[0]
    extra = np.zeros((k, 31))  # orientation (x, y, z, w), then three covariances
    extra[:, 3] = 1.0
    extra[:, 4] = -1.0  # orientation_covariance[0]
    if unprovided is not None:
        extra[unprovided[:, 1], 13] = -1.0  # angular_velocity_covariance[0]
        extra[unprovided[:, 0], 22] = -1.0  # linear_acceleration_covariance[0]
    sec, nsec = np.divmod(stamps_ns, 1_000_000_000)
    values = np.concatenate([accel, gyro, extra], axis=1)
    return list(
        zip(stamps_ns.tolist(), pack_messages(IMU, frame_id, sec, nsec, values), strict=True)
    )
