"""The twin's outputs declared once: per output its topic, message type, frames, table and
columns, the fields its values fill (the writer's streams, the bag reader's tables); the body
IMU comparison's topics read back."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from dataclasses import fields as dataclass_fields
from functools import cached_property
from operator import attrgetter
from typing import Any

import numpy as np

from mount_twin.engine.batch import OutputBatch
from mount_twin.io.fixed_layout import FixedLayout
from mount_twin.io.messages import (
    BUILDERS,
    DIAGNOSTICS,
    DIAGNOSTICS_TOPIC,
    IMU,
    POSE,
    TF,
    TF_TOPIC,
    TYPESTORE,
    VECTOR3,
    WRENCH,
    layout_of,
)
from mount_twin.physics import pose_row
from mount_twin.scene.description import Outputs, Scene


@dataclass(frozen=True)
class Stream:
    """One topic of a per-row output.

    Attributes:
        topic: name before resolution ('~' is the node's namespace/name; remappable in ROS,
            resolved by `resolve` for bags).
        msgtype: its message type, one of the fixed-layout types of `BUILDERS`.
        frames: the frame id(s) its messages carry (a transform's parent and child).
        values: the float fields of its messages from an OutputBatch, one row per message.
        table: the table a bag reader files its messages under (`io.output_tables`), or None
            (not read back: /tf).
    """

    topic: str
    msgtype: str
    frames: tuple[str, ...]
    values: Callable[[OutputBatch], np.ndarray]
    table: str | None

    @cached_property
    def layout(self) -> FixedLayout:
        """Its messages' layout (`layout_of`), looked up once: a live sample encodes each
        topic's one message on its own."""
        return layout_of(self.msgtype, *self.frames)


@dataclass(frozen=True)
class Readback:
    """A topic the bag reader files into a table (`output_table`, then `export`, `report`,
    the plots).

    Attributes:
        topic: its topic before resolution ('~' is the node's namespace/name); `{mount}`
            stands for each mount's name (one stream per mount).
        msgtype: its message type.
        table: the table its messages are read into (`{mount}` as in topic), or None: not read
            back.
        columns: the table's numeric columns, unit in the name.
        fields: the message field (dotted path) each column is read from, in column order.
    """

    topic: str
    msgtype: str
    table: str | None
    columns: tuple[str, ...]
    fields: tuple[str, ...]

    def __post_init__(self) -> None:
        """Refuse a readback (or output) registered half-way, at import, naming what is
        missing."""
        missing = _output_gaps(self)
        if missing:
            name = f"{self.flag!r} ({self.topic})" if isinstance(self, Output) else self.topic
            msg = f"io.output_topics: output {name}: {'; '.join(missing)}"
            raise ValueError(msg)

    @cached_property
    def _getter(self) -> Callable[[Any], Any]:
        return attrgetter(*self.fields)

    def read(self, msg: Any) -> tuple[float, ...]:
        """A message's values in column order (deserialized: rosbags' message classes)."""
        got = self._getter(msg)
        return tuple(got) if len(self.fields) > 1 else (got,)

    @property
    def per_mount(self) -> bool:
        """One stream per mount."""
        return "{mount}" in self.topic

    def table_of(self, topic: str, msgtype: str) -> str | None:
        """The table a resolved topic of msgtype is read into, if it is this output's: its
        topic after the node's namespace and name ('~'), a mount's name where `{mount}` is."""
        if self.table is None or msgtype != self.msgtype:
            return None
        head, _, tail = self.topic.lstrip("~").partition("{mount}")
        pattern = re.escape(head) + (
            "(?P<mount>[^/]+)" + re.escape(tail) if self.per_mount else ""
        )
        found = re.search(pattern + "$", topic)
        return None if found is None else self.table.format(**found.groupdict())


@dataclass(frozen=True)
class Output(Readback):
    """What one per-row output is, declared once: the writer (`output_streams`), the bag reader
    (`output_table`, then `export`, `report`, dashboards) and `info` read it.

    Attributes (besides `Readback`'s):
        flag: its switch in `scene.outputs`.
        frames: the frame id(s) its messages carry, from the scene (and the mount's name).
        values: its rows' float fields from an OutputBatch (and the mount's index).
    """

    flag: str
    frames: Callable[[Scene, str], tuple[str, ...]]
    values: Callable[[OutputBatch, int], np.ndarray]

    def streams(self, scene: Scene) -> list[Stream]:
        """Its streams for `scene`."""
        names = [m.name for m in scene.mounts] if self.per_mount else [""]
        return [
            Stream(
                self.topic.format(mount=name),
                self.msgtype,
                self.frames(scene, name),
                self._values_of(i),
                None if self.table is None else self.table.format(mount=name),
            )
            for i, name in enumerate(names)
        ]

    def _values_of(self, i: int) -> Callable[[OutputBatch], np.ndarray]:
        """Its rows' values for the i-th mount (or the one stream)."""
        return lambda out: self.values(out, i)


def _has_field(msgtype: str, path: str) -> bool:
    """Whether the dotted field path exists in `msgtype` (the typestore's definitions)."""
    node: Any = msgtype  # a type's name, then each field's (node type, subtype) subtype
    for name in path.split("."):
        fields = dict(TYPESTORE.fielddefs[node][1]) if node in TYPESTORE.fielddefs else {}
        if name not in fields:
            return False
        node = fields[name][1]
    return True


def _output_gaps(out: Readback) -> list[str]:
    """What a readback's or an output's declaration lacks or contradicts (empty: complete)."""
    gaps = []
    if isinstance(out, Output) and out.flag not in {f.name for f in dataclass_fields(Outputs)}:
        gaps.append(f"no switch {out.flag!r} in scene.outputs (mount_twin.scene.description)")
    if out.msgtype not in BUILDERS:
        gaps.append(f"no builder for {out.msgtype} in io.messages.BUILDERS")
    if len(out.columns) != len(out.fields):
        gaps.append(f"{len(out.columns)} columns but {len(out.fields)} fields to read them from")
    if (out.table is None) != (not out.columns):
        gaps.append("a table needs columns, and columns a table")
    if out.table is not None and ("{mount}" in out.table) != out.per_mount:
        gaps.append("the table and the topic must both name {mount}, or neither")
    gaps.extend(
        f"{out.msgtype} has no field {f}" for f in out.fields if not _has_field(out.msgtype, f)
    )
    return gaps


def _pose_fields(out: OutputBatch, i: int) -> np.ndarray:
    return out.pose[:, pose_row.POSE_COLS]


POSE_COLUMNS = ("x_m", "y_m", "z_m", "qx", "qy", "qz", "qw")
"""The pose table's numeric columns: CG position (m, F), quaternion x, y, z, w (body → F)."""
POSE_FIELDS = tuple(f"pose.position.{a}" for a in "xyz") + tuple(
    f"pose.orientation.{a}" for a in "xyzw"
)


POSE_OUTPUT = Output(
    flag="pose",
    topic="~/pose",
    msgtype=POSE,
    table="pose",
    columns=POSE_COLUMNS,
    fields=POSE_FIELDS,
    frames=lambda sc, _: (sc.frames.foundation,),
    values=_pose_fields,
)


ANGLES_OUTPUT = Output(
    flag="angles",
    topic="~/angles",
    msgtype=VECTOR3,
    table="angles",
    columns=("alpha_rad", "gamma_rad", "delta_rad"),
    fields=tuple(f"vector.{a}" for a in "xyz"),
    frames=lambda sc, _: (sc.frames.foundation,),
    values=lambda out, i: out.angles,
)


WRENCHES_OUTPUT = Output(
    flag="wrenches",
    topic="~/mounts/{mount}/wrench",
    msgtype=WRENCH,
    table="mount_{mount}",
    columns=("fx_N", "fy_N", "fz_N", "tx_Nm", "ty_Nm", "tz_Nm"),
    fields=tuple(f"wrench.{p}.{a}" for p in ("force", "torque") for a in "xyz"),
    frames=lambda sc, name: (sc.frames.mount_frame(name),),
    values=lambda out, i: out.wrenches[:, i],
)


TF_OUTPUT = Output(
    flag="tf",
    topic=TF_TOPIC,
    msgtype=TF,
    table=None,
    columns=(),
    fields=(),
    frames=lambda sc, _: (sc.frames.foundation, sc.frames.body),
    values=_pose_fields,
)


OUTPUTS: tuple[Output, ...] = (POSE_OUTPUT, ANGLES_OUTPUT, WRENCHES_OUTPUT, TF_OUTPUT)
"""The per-row outputs, in the order their messages follow each other (each flag is one of
`scene.outputs`: tested to be the same set). A new output is a builder in `BUILDERS` for a new
message type, an entry here and its flag in the scene's `Outputs`: its table is then read back
under its own name."""


def output_streams(scene: Scene) -> list[Stream]:
    """Every per-row output topic the scene enables, in publishing order."""
    return [st for out in OUTPUTS if getattr(scene.outputs, out.flag) for st in out.streams(scene)]


def output_table(topic: str, msgtype: str) -> tuple[str, Readback] | None:
    """The table a resolved output topic of msgtype is read into, and its output (columns and
    fields), or None: not an output of the twin read back (another node's topic, /tf,
    diagnostics). The per-row outputs, then the body IMU comparison's (`BODY_READBACKS`)."""
    for out in (*OUTPUTS, *BODY_READBACKS):
        table = out.table_of(topic, msgtype)
        if table is not None:
            return table, out
    return None


def output_types(scene: Scene) -> dict[str, str]:
    """Unresolved topic → message type for every output the scene enables (diagnostics first;
    the body IMU's prediction and residual last, with a body_sensor)."""
    body = {BODY_PREDICTED_TOPIC: IMU, BODY_RESIDUAL_TOPIC: IMU} if scene.body_sensor else {}
    return {
        DIAGNOSTICS_TOPIC: DIAGNOSTICS,
        **{st.topic: st.msgtype for st in output_streams(scene)},
        **body,
    }


BODY_PREDICTED_TOPIC = "~/body_imu/predicted"
"""The twin's prediction of each body IMU sample (sensor_msgs/Imu, its stamp and axes)."""
BODY_RESIDUAL_TOPIC = "~/body_imu/residual"
"""The body IMU's sample minus the prediction (sensor_msgs/Imu, its stamp and axes)."""
_BODY_COLUMNS = ("fx_m_s2", "fy_m_s2", "fz_m_s2", "wx_rad_s", "wy_rad_s", "wz_rad_s")


_BODY_FIELDS = tuple(
    f"{v}.{a}" for v in ("linear_acceleration", "angular_velocity") for a in "xyz"
)


BODY_READBACKS = (
    Readback(BODY_PREDICTED_TOPIC, IMU, "body_imu_predicted", _BODY_COLUMNS, _BODY_FIELDS),
    Readback(BODY_RESIDUAL_TOPIC, IMU, "body_imu_residual", _BODY_COLUMNS, _BODY_FIELDS),
)
"""The body IMU comparison's topics, read back as tables (specific force, rate; its axes)."""
