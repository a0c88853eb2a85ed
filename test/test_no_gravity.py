"""Scenes without gravity (`input.g: 0`: a test rig, a textbook case) run through the engine and
a replay to completion, and their physics is checked against independent truth:
- with no input the body stays exactly at its unloaded reference pose, every mount force zero
  (nothing loads the mounts, so the equilibrium is the reference pose, where they are
  unstressed: notes §7);
- a free vertical oscillation after a pulse has the frequency √(Σ k_zz / m) of the mounts'
  stiffness along z of F, k_zz = (Q·diag(k)·Qᵀ)_zz with Q built here by scipy.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import yaml
from io_helpers import SCENE_FILE, batch, default_scene, engine_for, read_bag, scene_with, split
from scipy.spatial.transform import Rotation

from mount_twin.cli import main
from mount_twin.engine.batch import OK
from mount_twin.io.messages import IMU
from mount_twin.io.output_bag import write_bag
from mount_twin.io.output_encoding import imu_messages

RATE_HZ = 1000.0


def _push_all(scene, accel: np.ndarray, chunk: int):
    """Push `accel` (n, 3) at RATE_HZ in batches of `chunk`; (pose rows, wrench rows, reports)."""
    engine = engine_for(scene)
    stamps = 1.0 + np.arange(accel.shape[0]) / RATE_HZ
    poses, wrenches, reports = [], [], []
    for part in split(batch(stamps, accel), [chunk] * (accel.shape[0] // chunk)):
        out = engine.push(part)
        poses.append(out.pose)
        wrenches.append(out.wrenches)
        reports.extend(out.health)
    final = engine.flush()  # the end: the rows the gyro delay holds, the last report
    poses.append(final.pose)
    wrenches.append(final.wrenches)
    reports.extend(final.health)
    return np.concatenate(poses), np.concatenate(wrenches), reports


def test_without_input_the_body_stays_at_its_unloaded_pose_with_zero_mount_forces() -> None:
    scene = scene_with(input={"g": 0.0})
    pose, wrenches, reports = _push_all(scene, np.zeros((2000, 3)), 300)
    assert pose.shape[0] == 2000
    np.testing.assert_array_equal(pose[:, :3], np.tile(scene.body.cg, (2000, 1)))
    np.testing.assert_array_equal(pose[:, 3:7], np.tile([0.0, 0.0, 0.0, 1.0], (2000, 1)))
    np.testing.assert_array_equal(wrenches, 0.0)
    assert reports and all(s.level == OK for r in reports for s in r.statuses)


def test_a_free_vertical_oscillation_has_the_closed_form_frequency() -> None:
    """The pump held in z alone, undamped, struck by a 5 ms half-sine of 20 m/s² (specific
    force along z of F), then free for 3 s."""
    base = default_scene()
    undamped = tuple(dataclasses.replace(m, damping=(0.0,) * 6) for m in base.mounts)
    scene = dataclasses.replace(scene_with(input={"g": 0.0}), mounts=undamped, dofs=("z",))
    k_zz = 0.0
    for m in base.mounts:
        q = Rotation.from_euler("xyz", m.orientation_rpy).as_matrix()
        k_zz += (q @ np.diag(m.stiffness[:3]) @ q.T)[2, 2]
    omega = np.sqrt(k_zz / base.body.mass)
    n = 3001
    t = np.arange(n) / RATE_HZ
    accel = np.zeros((n, 3))
    pulse = (t > 0.01) & (t < 0.015)
    accel[pulse, 2] = 20.0 * np.sin(np.pi * (t[pulse] - 0.01) / 0.005)
    pose, _, _ = _push_all(scene, accel, 1000)
    z = pose[:, 2] - base.body.cg[2]
    free = t > 0.02
    tf, zf = t[free], z[free]
    up = np.flatnonzero((zf[:-1] < 0.0) & (zf[1:] >= 0.0))
    crossings = tf[up] - zf[up] * (tf[up + 1] - tf[up]) / (zf[up + 1] - zf[up])
    assert crossings.shape[0] > 30 and np.ptp(zf) > 1e-6
    measured = 2.0 * np.pi * (crossings.shape[0] - 1) / (crossings[-1] - crossings[0])
    assert abs(measured / omega - 1.0) < 1e-6, (measured, omega)


def test_a_scene_without_gravity_replays_to_completion(tmp_path: Path) -> None:
    """`mount-twin replay` of the bundled pump with input.g: 0 over a bag of no specific force:
    every sample answered, every mount force zero."""
    data = yaml.safe_load(SCENE_FILE.read_text(encoding="utf-8"))
    data["input"]["g"] = 0.0
    scene = tmp_path / "rig.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    n = 300
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 1_000_000
    write_bag(
        tmp_path / "in",
        "/deck/imu",
        IMU,
        iter(imu_messages(stamps, np.zeros((n, 3)), np.zeros((n, 3)), "deck_imu")),
    )
    args = ["replay", str(tmp_path / "in"), "--scene", str(scene), "-o", str(tmp_path / "out")]
    assert main([*args, "--no-progress"]) == 0
    _, msgs = read_bag(tmp_path / "out")
    wrench_topics = [topic for topic in msgs if topic.endswith("/wrench")]
    assert len(wrench_topics) == len(data["mounts"])
    for topic in wrench_topics:
        assert len(msgs[topic]) == n
        for _, msg in msgs[topic]:
            w = msg.wrench
            assert (w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z) == (
                0,
            ) * 6
