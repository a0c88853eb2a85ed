"""Real recordings nobody on the team shaped: replay them, the twin stays sane.

The vehicle IMU (130 s of a car driving, test/data/vehicle_imu_30hz_excerpt.md says where from)
has gravity on +y of its frame: the scene rotates the sensor frame into F by configuration
(input.sensor_rpy), the data is not edited.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from io_helpers import DATA_DIR, G, default_scene, read_bag, read_raw, scene_with, stamp_ns

from mount_twin.io.input_decoding import decode_inputs
from mount_twin.io.messages import IMU
from mount_twin.physics.rotations import rpy_matrix
from mount_twin.replay import replay

VEHICLE = DATA_DIR / "vehicle_imu_30hz_excerpt"
N_MESSAGES = 3902

# Roll +90° about x maps the sensor's +y (up at rest) onto +z of F.
SENSOR_RPY = (math.pi / 2, 0.0, 0.0)


def vehicle_scene():
    """The default pump fed a car's IMU. Its mounts' ratings are cleared: the car's bumps take
    the pump past them (1.4× the rated load: `test_linear_ratings.py` covers ratings), while
    these tests are about the input's handling and the twin's stability."""
    base = default_scene()
    unrated = tuple(
        dataclasses.replace(m, rated_travel=(0.0,) * 3, rated_load=(0.0,) * 3) for m in base.mounts
    )
    return scene_with(
        dataclasses.replace(base, mounts=unrated),
        input={
            "topic": "/imu/data",
            "frame_id": "imu_link",
            "sensor_rpy": SENSOR_RPY,
            "max_gap_s": 1.0,
        },
        outputs={"diagnostics_period_s": 10.0},
    )


@pytest.fixture(scope="module")
def vehicle_run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("vehicle") / "out"
    summary = replay(vehicle_scene(), VEHICLE, out, progress=False)
    types, msgs = read_bag(out)
    return summary, types, msgs


def test_sensor_rotation_puts_the_recorded_gravity_on_plus_z_of_f() -> None:
    rot = rpy_matrix(*SENSOR_RPY)
    np.testing.assert_allclose(rot @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], rtol=0, atol=1e-15)
    raws = [raw for _, raw in read_raw(VEHICLE, ["/imu/data"])["/imu/data"]]
    dec = decode_inputs(raws, IMU)
    assert dec.undecodable == 0 and set(dec.frame_ids) == {"imu_link"}
    mean_f = (dec.accel @ rot.T).mean(axis=0)
    assert mean_f[2] == pytest.approx(G, rel=0.01), f"mean specific force in F: {mean_f}"
    assert np.hypot(mean_f[0], mean_f[1]) < 0.5, f"gravity must not leak into x/y of F: {mean_f}"


def test_vehicle_replay_accepts_every_sample_and_never_fails(vehicle_run) -> None:
    summary, types, msgs = vehicle_run
    c = summary.counts
    assert (c["received"], c["accepted"]) == (N_MESSAGES, N_MESSAGES)
    rejected = {k: v for k, v in c.items() if k.startswith("rejected_")}
    assert not rejected, f"rejected samples: {rejected}"
    assert (c.get("gaps", 0), c.get("restarts", 0), c.get("integration_failures", 0)) == (0, 0, 0)
    assert types["/mount_twin/pose"] == "geometry_msgs/msg/PoseStamped"
    assert len(msgs["/mount_twin/pose"]) == N_MESSAGES
    # 30 Hz is too slow for the gyro filter (stopband 100 Hz): said once, in the first period
    raw_note = "is below 4 × input.gyro_stopband_hz (100 Hz): the gyro is taken raw"
    notes = []
    for _, diag in msgs["/diagnostics"]:
        bad = [(s.name, s.message) for s in diag.status if s.level != 0]
        notes += [b for b in bad if raw_note in b[1]]
        bad = [b for b in bad if raw_note not in b[1]]
        assert not bad, f"diagnostics at {stamp_ns(diag)}: {bad}"
    assert len(notes) == 1 and notes[0][0] == "mount_twin: integration"


def test_vehicle_replay_stays_stable_with_plausible_displacement(vehicle_run) -> None:
    summary, _, msgs = vehicle_run
    scene = vehicle_scene()
    pose = np.array(
        [
            [
                m.pose.position.x,
                m.pose.position.y,
                m.pose.position.z,
                m.pose.orientation.x,
                m.pose.orientation.y,
                m.pose.orientation.z,
                m.pose.orientation.w,
            ]
            for _, m in msgs["/mount_twin/pose"]
        ]
    )
    assert np.isfinite(pose).all(), "NaN in the replayed pose"
    disp = np.linalg.norm(pose[:, :3] - np.array(scene.body.cg), axis=1)
    assert disp.max() < 0.03, f"CG moved {disp.max():.4f} m on rubber mounts of a driving vehicle"
    moved = np.linalg.norm(pose[:, :3] - pose[0, :3], axis=1)  # from the start, sag aside
    assert summary.displacement_max_m == pytest.approx(moved.max(), rel=1e-9)
    tilt = 2.0 * np.arccos(np.clip(np.abs(pose[:, 6]), 0.0, 1.0))
    assert tilt.max() < math.radians(5.0), f"body tilted {math.degrees(tilt.max()):.2f}°"
    # No drift: the last minute sits as close to the static position as the first one.
    assert abs(disp[-1800:].mean() - disp[:1800].mean()) < 0.005


def test_vehicle_replay_mount_forces_carry_the_weight_on_average(vehicle_run) -> None:
    _, _, msgs = vehicle_run
    scene = vehicle_scene()
    axes = np.array([rpy_matrix(*m.orientation_rpy) for m in scene.mounts])  # mount axes in F
    forces = []
    for mount in scene.mounts:
        topic = f"/mount_twin/mounts/{mount.name}/wrench"
        assert {m.header.frame_id for _, m in msgs[topic]} == {mount.name}
        forces.append(
            [[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z] for _, m in msgs[topic]]
        )
    forces = np.array(forces)  # (mounts, samples, 3), mount axes
    assert np.isfinite(forces).all()
    in_f = np.einsum("nij,nkj->nki", axes, forces)  # into F
    total = in_f.sum(axis=0)  # (samples, 3): mount force on the body, N, in F
    weight = scene.body.mass * G
    assert total[:, 2].mean() == pytest.approx(weight, rel=0.02), (
        f"mean vertical mount force {total[:, 2].mean():.1f} N vs m·g {weight:.1f} N"
    )
    assert np.abs(total[:, :2].mean(axis=0)).max() < 0.05 * weight
