"""Shared helpers for the mount_twin tests (plain functions, no fixtures: there is no conftest)."""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from collections import defaultdict
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from hypothesis import HealthCheck, settings
from rosbags.highlevel import AnyReader

from mount_twin.engine.batch import HealthReport, OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.messages import DIAGNOSTICS, TYPESTORE
from mount_twin.model.assemble import Model, assemble
from mount_twin.scene import Scene, load_scene_file

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config"
SCENE_FILE = CONFIG / "pump_8_mounts.scene.yaml"
PARAMS_FILE = CONFIG / "params.yaml"
DATA_DIR = ROOT / "test" / "data"
"""Excerpts of real records, each with its provenance and license (`*.md` beside it)."""
G = 9.80665
REST = np.array([0.0, 0.0, G])
"""Specific force of a foundation at rest, m/s², in F (gravity included: +g up)."""


def run_python(
    *args: str, cwd: Path = ROOT, env: dict[str, str] | None = None, timeout: float = 120.0
) -> subprocess.CompletedProcess[str]:
    """`python ARGS` in a new interpreter (this one's executable), output captured as text."""
    return subprocess.run(
        [sys.executable, *args],
        cwd=cwd,
        env=env,
        check=False,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


@cache
def default_scene() -> Scene:
    """config/pump_8_mounts.scene.yaml, loaded once."""
    return load_scene_file(SCENE_FILE)


@cache
def default_model() -> Model:
    """The default scene assembled once (a Model is immutable)."""
    return assemble(default_scene())


def params_yaml() -> dict[str, Any]:
    """config/params.yaml as rcl reads it for the node named mount_twin."""
    return yaml.safe_load(PARAMS_FILE.read_text(encoding="utf-8"))["/**"]["ros__parameters"]


def scene_with(scene: Scene | None = None, **sections: dict[str, Any]) -> Scene:
    """A copy of `scene` (default scene if None) with fields of its sections replaced, e.g.
    scene_with(input={"gap_policy": "bridge"}, outputs={"decimation": 4})."""
    scene = scene or default_scene()
    changes = {}
    for section, fields in sections.items():
        changes[section] = dataclasses.replace(getattr(scene, section), **fields)
    return dataclasses.replace(scene, **changes)


def engine_for(scene: Scene | None = None) -> TwinEngine:
    """A fresh engine; reuses the assembled default model when the scene is the default one."""
    if scene is None or scene == default_scene():
        return TwinEngine(default_model())
    return TwinEngine(assemble(scene))


def batch(
    stamps: Sequence[float] | np.ndarray,
    accel: np.ndarray | None = None,
    gyro: np.ndarray | None = None,
    frame_ids: Sequence[str] | str = "deck_imu",
) -> SampleBatch:
    """Samples at `stamps` (s); a foundation at rest unless accel/gyro are given."""
    stamps = np.asarray(stamps, dtype=float)
    n = stamps.shape[0]
    accel = (
        np.tile(REST, (n, 1)) if accel is None else np.asarray(accel, dtype=float).reshape(n, 3)
    )
    gyro = np.zeros((n, 3)) if gyro is None else np.asarray(gyro, dtype=float).reshape(n, 3)
    fids = [frame_ids] * n if isinstance(frame_ids, str) else list(frame_ids)
    return SampleBatch(stamps, accel, gyro, fids)


def split(b: SampleBatch, sizes: Iterable[int]) -> list[SampleBatch]:
    """Cut a batch into consecutive pieces of the given sizes (the rest is one last piece)."""
    out, i = [], 0
    for size in sizes:
        if i >= len(b):
            break
        out.append(b.part(slice(i, i + size)))
        i += size
    if i < len(b):
        out.append(b.part(slice(i, None)))
    return out


def read_bag(path: Path) -> tuple[dict[str, str], dict[str, list[tuple[int, Any]]]]:
    """(topic → msgtype, topic → [(log time ns, deserialized message)]) of a bag."""
    types: dict[str, str] = {}
    msgs: dict[str, list[tuple[int, Any]]] = defaultdict(list)
    with AnyReader([Path(path)], default_typestore=TYPESTORE) as reader:
        for conn in reader.connections:
            types[conn.topic] = conn.msgtype
        for conn, t, raw in reader.messages():
            msgs[conn.topic].append((t, reader.deserialize(raw, conn.msgtype)))
    return types, dict(msgs)


def read_raw(
    path: Path, topics: Sequence[str] | None = None
) -> dict[str, list[tuple[int, bytes]]]:
    """topic → [(log time ns, raw CDR bytes)] of a bag (optionally only some topics)."""
    out: dict[str, list[tuple[int, bytes]]] = defaultdict(list)
    with AnyReader([Path(path)], default_typestore=TYPESTORE) as reader:
        conns = [c for c in reader.connections if topics is None or c.topic in topics]
        for conn, t, raw in reader.messages(connections=conns):
            out[conn.topic].append((t, bytes(raw)))
    return dict(out)


def stamp_ns(msg: Any) -> int:
    """header.stamp of a deserialized message, ns."""
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def mount_forces_in_f(scene: Scene, wrenches: np.ndarray) -> np.ndarray:
    """(k, n_mounts, 3) mount forces rotated from mount axes into F (at the reference pose)."""
    from mount_twin.physics.rotations import rpy_matrix

    axes = np.array([rpy_matrix(*m.orientation_rpy) for m in scene.mounts])  # columns: axes in F
    return np.einsum("nij,knj->kni", axes, wrenches[..., :3])


def push_all(
    engine: TwinEngine, parts: list[SampleBatch]
) -> tuple[OutputBatch, list[list[HealthReport]]]:
    """Push each part, then flush (the end of the stream: the rows the gyro delay holds); return
    the concatenated outputs and the reports of each push and of the flush (the joined `sample`
    column is per push, so meaningless here: tests read stamps, poses and wrenches)."""
    outs = [*(engine.push(p) for p in parts), engine.flush()]
    joined = OutputBatch(
        np.concatenate([o.stamps for o in outs]),
        np.concatenate([o.sample for o in outs]),
        np.concatenate([o.pose for o in outs]),
        np.concatenate([o.wrenches for o in outs]),
    )
    return joined, [o.health for o in outs]


def fuzz_settings(max_examples: int, **kwargs: Any) -> settings:
    """Hypothesis settings of a fuzz suite: in the suite a fixed (derandomized) campaign of
    `max_examples`; with MOUNT_TWIN_FUZZ_EXAMPLES=N a fresh campaign of N examples, seeded by
    pytest's --hypothesis-seed (how docs/benchmarks.md's hostile-input figures are re-measured:
    `MOUNT_TWIN_FUZZ_EXAMPLES=1000 python3 -m pytest test/test_fuzz_stream.py
    --hypothesis-seed=7`)."""
    campaign = os.environ.get("MOUNT_TWIN_FUZZ_EXAMPLES")
    return settings(
        max_examples=int(campaign) if campaign else max_examples,
        derandomize=not campaign,
        database=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
        **kwargs,
    )


def comparable_messages(path: Path) -> dict[str, list[tuple[int, object]]]:
    """Topic → (stamp, message) of an output bag, to compare two runs: raw bytes, and for
    /diagnostics the decoded statuses less the wall-time figures (the real-time factor differs
    between any two runs)."""
    out: dict[str, list[tuple[int, object]]] = {}
    for topic, messages in read_raw(path).items():
        if topic != "/diagnostics":
            out[topic] = [(stamp, bytes(raw)) for stamp, raw in messages]
            continue
        out[topic] = [(stamp, comparable_diagnostics(raw)) for stamp, raw in messages]
    return out


def comparable_diagnostics(raw: bytes) -> list[tuple[str, int, str, list[tuple[str, str]]]]:
    """A /diagnostics message's statuses less the wall-time figures (the real-time factor
    differs between any two runs)."""
    return [
        (
            s.name,
            s.level,
            s.message,
            [(v.key, v.value) for v in s.values if v.key != "real_time_factor"],
        )
        for s in TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS).status
    ]


def ageing_bag(
    path: Path, scene: Scene, total_s: float, change_s: float, body_topic: str
) -> list[tuple[str, int, bytes]]:
    """A bag at `path` of `ageing_messages`. Returns its (topic, stamp ns, raw) messages in
    stamp order."""
    from mount_twin.io.messages import IMU
    from mount_twin.io.output_bag import OutputBag

    msgs = ageing_messages(scene, total_s, change_s, body_topic)
    with OutputBag(path, {"/deck/imu": IMU, body_topic: IMU}) as bag:
        bag.write(msgs)
    return msgs


def ageing_messages(
    scene: Scene,
    total_s: float,
    change_s: float,
    body_topic: str,
    jump: tuple[float, float] | None = None,
) -> list[tuple[str, int, bytes]]:
    """The deck IMU (/deck/imu, 200 Hz of ship motion with 1-40 Hz machinery vibration at
    0.3 m/s² RMS) and the body IMU (`body_topic`) of the scene's machine whose mounts all lose
    30 % of their stiffness at `change_s`; 0.01 m/s² of noise on both: (topic, stamp ns, raw)
    messages in the order of the record's time. `jump` (at s, by s): the stamps of both from
    `at` on are `by` earlier (a recorder's clock set back)."""
    from scipy.signal import butter, sosfiltfilt

    from mount_twin.analysis.calibration import predict
    from mount_twin.analysis.calibration_parameters import calibrated_scene
    from mount_twin.io.output_encoding import imu_messages
    from mount_twin.io.signals import Signal, ship_motion

    rate, stamp0 = 200.0, 1_700_000_000_000_000_000
    sea = ship_motion(rate_hz=rate, total=total_s)
    sos = butter(4, [1.0, 40.0], btype="band", fs=rate, output="sos")
    vib = sosfiltfilt(sos, np.random.default_rng(5).normal(0, 1, sea.accel.shape), axis=0)
    deck = Signal(sea.t, sea.accel + 0.3 * vib / vib.std(axis=0), sea.gyro)
    t, intact = predict(scene, deck)
    _, aged = predict(calibrated_scene(scene, {"stiffness": 0.7}), deck)
    rng = np.random.default_rng(1)
    body = np.where((t >= change_s)[:, None], aged, intact) + rng.normal(0, 0.01, intact.shape)
    noisy = deck.accel + rng.normal(0, 0.01, deck.accel.shape)
    at, by = jump or (math.inf, 0.0)
    ns = stamp0 + np.round(np.where(deck.t >= at, deck.t - by, deck.t) * 1e9).astype(np.int64)
    body_ns = stamp0 + np.round(np.where(t >= at, t - by, t) * 1e9).astype(np.int64)
    deck_msgs = imu_messages(ns, noisy, deck.gyro, "deck_imu")
    body_msgs = imu_messages(body_ns, body, np.zeros_like(body), "")
    timed = sorted(
        [(float(u), "/deck/imu", m) for u, m in zip(deck.t, deck_msgs, strict=True)]
        + [(float(u), body_topic, m) for u, m in zip(t, body_msgs, strict=True)],
        key=lambda m: (m[0], m[1]),
    )
    return [(topic, s, r) for _, topic, (s, r) in timed]


def statuses_named(raws: list[bytes], name: str) -> list[tuple[int, int, str, dict[str, str]]]:
    """(stamp ns, level, message, values) of each diagnostics status called `name` in raw
    DiagnosticArray messages."""
    out = []
    for raw in raws:
        msg = TYPESTORE.deserialize_cdr(raw, DIAGNOSTICS)
        stamp = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
        out += [
            (stamp, int(s.level), s.message, {kv.key: kv.value for kv in s.values})
            for s in msg.status
            if s.name == name
        ]
    return out


def pump_scene_file(tmp: Path, **sections: dict[str, Any] | None) -> Path:
    """The bundled pump's scene file with `sections` merged into its own (a section None is
    removed), written to tmp/pump.scene.yaml."""
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    for name, values in sections.items():
        if values is None:
            data.pop(name, None)
        else:
            data[name] = {**data.get(name, {}), **values}
    path = tmp / "pump.scene.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


AGEING_PUMP = {
    "input": {"gyro_filter": "none"},
    "body_sensor": {"topic": "/machine/imu", "position": [0.8, 0.3, 1.0]},
    "ageing": {"window_s": 20.0},
}
"""The pump with its body IMU on /machine/imu and ageing tracked in windows of 20 s."""


def disk_full_after(monkeypatch: Any, bags: int) -> list[str]:
    """`commands.common.write_signal` (synthesize's and qualify's bag writer) writes `bags`
    bags, then fails at the next as a full disk does (OSError ENOSPC naming it): a run that
    fails part-way. Returns the bags written, as they are."""
    import errno

    from mount_twin.commands import common

    written: list[str] = []
    real = common.write_signal

    def write_signal(sig: Any, out: str, *args: Any) -> int:
        if len(written) == bags:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), out)
        written.append(out)
        return real(sig, out, *args)

    monkeypatch.setattr(common, "write_signal", write_signal)
    return written


def unmeetable_design(path: Path) -> Path:
    """A design no synthesis meets within -1.5/+3 dB: 100 g at 20 Hz between 1 g at 10 and
    40 Hz. An oscillator an octave off a 20 Hz motion still responds to it (one at 40 Hz
    follows it, its peak at least the motion's; one at 10 Hz is moved by about a third of it),
    where the design asks for 40 dB less."""
    path.write_text("frequency_hz,accel_g\n10,1\n20,100\n40,1\n", encoding="utf-8")
    return path


def unprovided_imu(raws: list[bytes], field: str) -> list[bytes]:
    """`raws` (Imu) with `field` (linear_acceleration or angular_velocity) marked not provided
    (REP-145: its covariance[0] = -1) and holding a value a sensor without it might send."""
    out = []
    for raw in raws:
        msg = TYPESTORE.deserialize_cdr(raw, "sensor_msgs/msg/Imu")
        covariance = np.zeros(9)
        covariance[0] = -1.0
        setattr(msg, f"{field}_covariance", covariance)
        value = getattr(msg, field)
        value.x, value.y, value.z = (
            (0.0, 0.0, 0.0) if field == "linear_acceleration" else (5.0,) * 3
        )
        out.append(bytes(TYPESTORE.serialize_cdr(msg, "sensor_msgs/msg/Imu")))
    return out


def without_scene_topic(bag: Path, out: Path, custom: dict[str, str]) -> Path:
    """`bag` rewritten at `out` without its ~/scene topic, its metadata's custom_data
    `custom`: a replay's bag with the topic filtered out by its user (`custom`: the replay's
    own), as a mount_twin wrote it before it wrote the scene's topic and keys (`custom`: the
    one text naming the file, and the digest), or a recording of the node's topics by one
    that did not publish its scene (`custom` empty)."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    with (
        AnyReader([bag], default_typestore=TYPESTORE) as reader,
        Writer(out, version=Writer.VERSION_LATEST, storage_plugin=StoragePlugin.MCAP) as writer,
    ):
        kept = [c for c in reader.connections if c.topic != "/mount_twin/scene"]
        assert len(kept) == len(reader.connections) - 1
        conns = {
            c.id: writer.add_connection(
                c.topic,
                c.msgtype,
                typestore=TYPESTORE,
                offered_qos_profiles=c.ext.offered_qos_profiles,
            )
            for c in kept
        }
        for conn, t, raw in reader.messages(connections=kept):
            writer.write(conns[conn.id], t, raw)
        for key, value in custom.items():
            writer.set_custom_data(key, value)
    return out
