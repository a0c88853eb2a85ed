"""Past the chart's limit the twin never replays an old motion: a scene with a given initial
motion whose stepper fails stops following (no pose, angles or wrenches) and says so at ERROR in
every report, until the record restarts; a scene started at equilibrium restarts there. A
machine a shock damaged restarts at its own equilibrium, as damaged; where it has none, the twin
publishes nothing and says why."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from io_helpers import CONFIG, REST, ROOT, G, batch, pump_scene_file, read_bag
from physics_helpers import free_body

from mount_twin.commands.common import write_signal
from mount_twin.engine.batch import ERROR, OK
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.health_texts import ATTITUDE, INTEGRATION, MOUNT
from mount_twin.io.signals import Signal
from mount_twin.model.assemble import assemble
from mount_twin.replay import replay
from mount_twin.scene import load_scene_file
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import scene_from_dict
from mount_twin.scene.yaml_reading import read_scene_yaml

OMEGA0 = np.array([4.0, 0.3, 0.5])  # rad/s in B, about the axis of least inertia: tips over


def _tumbling_engine() -> TwinEngine:
    data = free_body([2.0, 3.0, 4.0, 0.0, 0.0, 0.0], OMEGA0)
    data["outputs"] = {"diagnostics_period_s": 0.5}
    return TwinEngine(assemble(scene_from_dict(data, "<tumble>")))


def _integration_status(report):
    (s,) = [s for s in report.statuses if s.name == "mount_twin: integration"]
    return s


def test_a_given_motion_past_the_chart_stops_and_is_not_replayed() -> None:
    engine = _tumbling_engine()
    free_fall = np.zeros((2000, 3))  # specific force 0: torque-free
    out = engine.run(batch(1.0 + np.arange(2000) * 1e-3, free_fall, frame_ids=""))
    assert engine.counts["integration_failures"] == 1
    followed = len(out)
    assert 10 < followed < 2000
    tilt_end = np.degrees(
        np.arccos(1 - 2 * (out.quaternion[-1, 0] ** 2 + out.quaternion[-1, 1] ** 2))
    )
    assert tilt_end > 60.0, "it stopped while tipping over, not somewhere at rest"
    assert engine.counts["samples_not_followed"] == 2000 - followed - 1  # the failing sample
    assert engine.counts["restarts"] == 0 and not engine.running
    later = engine.push(batch(3.0 + np.arange(100) * 1e-3, np.zeros((100, 3)), frame_ids=""))
    assert len(later) == 0
    reports = [*out.health, *later.health]
    after = [r for r in reports if r.stamp > out.stamps[-1]]
    assert after and all(_integration_status(r).level == ERROR for r in after)
    assert all("not following since" in _integration_status(r).message for r in after)


def test_a_restart_of_the_record_follows_again() -> None:
    engine = _tumbling_engine()
    engine.push(batch(1.0 + np.arange(2000) * 1e-3, np.zeros((2000, 3)), frame_ids=""))
    again = engine.run(batch(1.0 + np.arange(50) * 1e-3, np.zeros((50, 3)), frame_ids=""))
    assert len(again) == 50 and engine.counts["reset_stamp_jumped_back"] == 1


# A damaged machine restarts at its own equilibrium, or publishes nothing.

GENSET = CONFIG / "genset_bolted_keyed.scene.yaml"
RATE = 10_000.0  # Hz
GAP_S = 1.0  # > the genset's input.max_gap_s: the twin restarts after it


def _breaking_stream() -> tuple[np.ndarray, np.ndarray]:
    """Stamps (s) and specific forces (m/s², F): rest, a downward deck half-sine of 80 g for
    10 ms (the frame pulls its bolts apart), rest; a gap; rest again."""
    t1 = np.arange(0.0, 0.3, 1.0 / RATE)
    pulse = (t1 > 0.05) & (t1 < 0.06)
    f1 = np.tile(REST, (t1.shape[0], 1))
    f1[pulse, 2] += -800.0 * np.sin(np.pi * (t1[pulse] - 0.05) / 0.01)
    t2 = t1[-1] + GAP_S + np.arange(0.0, 0.2, 1.0 / RATE)
    return np.concatenate([t1, t2]), np.vstack([f1, np.tile(REST, (t2.shape[0], 1))])


def _broken(engine: TwinEngine) -> set[str]:
    return {e.mount for e in engine.events if e.event == "bolt_fractured"}


def test_a_machine_whose_bolts_broke_restarts_resting_on_its_feet() -> None:
    scene = load_scene_file(GENSET)
    engine = TwinEngine(assemble(scene))
    t, f = _breaking_stream()
    out = engine.run(batch(t, f))
    feet = [i for i, m in enumerate(scene.mounts) if m.kind == "bolted_joint"]
    assert _broken(engine) == {scene.mounts[i].name for i in feet} and len(feet) == 6
    assert engine.counts["restarts"] == 1 and engine.counts["starts_without_equilibrium"] == 0
    after = out.stamps > t[0] + 0.3 + 0.5 * GAP_S
    assert after.sum() == 2000  # every sample after the gap is published
    # Static balance of the frame on its feet (closed form): the clamp forces carry the
    # weight and its moment about the CG, nothing pulls (no bolt), nothing acts sideways.
    weight = scene.body.mass * G
    fz = out.wrenches[after][:, feet, 2]  # feet axes are F's
    x = np.array([scene.mounts[i].position for i in feet])[:, :2] - np.array(scene.body.cg[:2])
    np.testing.assert_allclose(fz.sum(axis=1), weight, rtol=1e-6)
    np.testing.assert_allclose(fz @ x, 0.0, atol=1e-6 * weight)
    np.testing.assert_allclose(out.wrenches[after][:, :, :2].sum(axis=1), 0.0, atol=1e-6 * weight)
    assert (fz >= 0.0).all() and fz.max() < weight, "no spike: no foot carries more than all"
    # at rest: the pose does not move
    pose = out.pose[after]
    np.testing.assert_allclose(pose - pose[0], 0.0, atol=1e-9)


def _hanging_genset() -> tuple[Scene, np.ndarray, np.ndarray]:
    """The genset hung from a ceiling by its six bolted feet (their z, where the joint opens,
    points down; no keys): once the bolts break nothing holds it. With `_breaking_stream`'s
    kick, now pulling the frame off the ceiling."""
    data = read_scene_yaml(GENSET)
    data["mounts"] = [m for m in data["mounts"] if m["kind"] == "bolted_joint"]
    for mount in data["mounts"]:
        mount["orientation_rpy"] = [np.pi, 0.0, 0.0]
    data["body"]["cg"] = [0.1, 0.0, -0.8]
    t, f = _breaking_stream()
    f[:, 2] = 2.0 * G - f[:, 2]
    return scene_from_dict(data, "<hanging genset>"), t, f


def test_a_machine_nothing_holds_any_more_publishes_nothing_and_says_why() -> None:
    scene, t, f = _hanging_genset()
    engine = TwinEngine(assemble(scene))
    out = engine.run(batch(t, f))
    assert len(_broken(engine)) == 6
    restart = t[0] + 0.3 + 0.5 * GAP_S
    assert not (out.stamps > restart).any(), "nothing published for a machine in no state"
    assert engine.counts["starts_without_equilibrium"] == 1
    assert engine.counts["samples_not_followed"] == 2000 and not engine.running
    # the restart is taken once the gyro delay has passed; the reports from then on say why
    started = t[t > restart][0] + engine.health.latency[1]
    reports = [r for r in out.health if r.stamp > started]
    assert reports
    for report in reports:
        status = _integration_status(report)
        assert status.level == ERROR
        assert "not following since" in status.message
        assert "no static equilibrium" in status.message and "bolt_fractured" in status.message


def test_the_periods_a_twin_follows_no_more_say_they_computed_no_attitude_nor_load() -> None:
    """A twin stopped by a failure (a given motion) publishes nothing in the periods after,
    yet their attitude and mount statuses read "ok" with a tilt and peaks of 0, as a machine
    at rest. They say nothing was computed in the period and why (the stop, whose stamp the
    engine holds), figures "n/a"; the periods that published rows read as they did."""
    engine = _tumbling_engine()
    out = engine.run(batch(1.0 + np.arange(2000) * 1e-3, np.zeros((2000, 3)), frame_ids=""))
    stop = engine.health.stopped_at
    assert stop is not None and not engine.running
    published = [r for r in out.health if (out.stamps > r.stamp - 0.5).any()]
    silent = [r for r in out.health if r.stamp - 0.5 > out.stamps[-1]]
    assert published and silent and len(published) + len(silent) == len(out.health)
    why = f"not computed in this period: the twin follows no more since {stop:.6f} s"
    for report in published:
        (attitude,) = [s for s in report.statuses if s.name == ATTITUDE]
        assert attitude.message != why and float(attitude.values["tilt_max_rad"]) > 0.0
    for report in silent:
        figures = [s for s in report.statuses if s.name == ATTITUDE or s.name.startswith(MOUNT)]
        assert len(figures) == 1 + len(engine.scene.mounts)
        for status in figures:
            assert (status.level, status.message) == (OK, why), status
            measured = {k: v for k, v in status.values.items() if "peak" in k or "max" in k}
            assert measured and set(measured.values()) == {"n/a"}, status


def test_the_replay_summary_says_what_was_not_followed_and_why(tmp_path: Path) -> None:
    scene, t, f = _hanging_genset()
    bag = tmp_path / "hanging"
    write_signal(
        Signal(t, f, np.zeros_like(f)),
        str(bag),
        scene.input.topic,
        scene.input.frame_id,
        1_700_000_000_000_000_000,
        "mcap",
    )
    summary = replay(scene, bag, tmp_path / "out", progress=False)
    assert summary.counts["samples_not_followed"] == 2000
    assert "not followed: 2000 samples, nothing published for them" in summary.text()
    status = summary.worst[INTEGRATION]
    assert status.level == ERROR and "no static equilibrium" in status.message
    assert summary.to_dict()["diagnostics_worst"][INTEGRATION]["message"] == status.message
    # the bag's last period, after the stop, computed nothing and says so; the run's worst
    # attitude is still of a period that computed one (a figure, not "n/a")
    *_, last = [m for _, m in read_bag(tmp_path / "out")[1]["/diagnostics"]]
    (attitude,) = [s for s in last.status if s.name == ATTITUDE]
    assert attitude.message.startswith("not computed in this period: the twin follows no more")
    assert [v.value for v in attitude.values] == ["n/a"]
    assert float(summary.worst[ATTITUDE].values["tilt_max_rad"]) >= 0.0
    assert summary.to_dict()["diagnostics_worst"][ATTITUDE]["level"] == "OK"


def test_a_period_decimation_left_without_a_row_has_no_tilt_nor_peak_of_0(tmp_path: Path) -> None:
    """outputs.decimation above a period's samples: the period integrates them and publishes
    no row, and its attitude and mount statuses read a tilt and peaks of 0, as a machine at
    rest, while its peaks went into the next row published. Its tilt and peaks (figures of
    published rows) are "n/a" and it says why; its utilisation, folded in at every sample, is
    its own; a period that published rows has its figures."""
    path = pump_scene_file(
        tmp_path,
        # rows at their samples' stamps, each in its period: no delay, no start window held
        input={"gyro_filter": "none"},
        initial_state={"gravity_window_s": 0.0},
        outputs={"decimation": 1000, "diagnostics_period_s": 0.01},  # 100 samples at 10 kHz
    )
    replay(
        load_scene_file(path),
        ROOT / "bags" / "half_sine_shock_10khz",
        tmp_path / "out",
        progress=False,
    )
    _, msgs = read_bag(tmp_path / "out")
    rows = np.array([t for t, _ in msgs["/mount_twin/pose"]])
    seen = {"without": 0, "with": 0}
    before = 0
    for stamp, report in msgs["/diagnostics"]:
        published = int(np.count_nonzero((rows > before) & (rows <= stamp)))
        before = stamp
        statuses = {s.name: s for s in report.status}
        integrated = statuses[INTEGRATION].values
        if any(v.key == "substeps_per_sample" and v.value == "n/a" for v in integrated):
            continue  # integrated nothing: "not computed" (tested elsewhere)
        seen["with" if published else "without"] += 1
        for name, status in statuses.items():
            if name != ATTITUDE and not name.startswith(MOUNT):
                continue
            values = {v.key: v.value for v in status.values}
            figures = {
                v for k, v in values.items() if k.startswith("peak_") or k == "tilt_max_rad"
            }
            if published:
                assert "n/a" not in figures, (name, values)
                continue
            assert figures == {"n/a"}, (name, values)
            assert "no row published in this period" in status.message, status
            if name.startswith(MOUNT):
                assert float(values["utilisation_max"]) > 0.0, values
    assert seen["without"] > 0 and seen["with"] > 0, seen
