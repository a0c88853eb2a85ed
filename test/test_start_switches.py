"""A discrete switch that a start makes is an event there: a bolt broken at the start is counted.

A bolt already past its ultimate force where the twin starts (its preload and its share of the
weight at the start's equilibrium) breaks in the start's own monitor call. Its event function
was then already past 0 when the loop first looked, so no crossing was ever seen: the bolt
read `bolt_fractured` under `now` only, with no event, no count, no first stamp, nothing in the
summary's "mount events" nor in the output bag's events, while the body dropped. The start now
logs the switch as the loop logs an event: at the start's stamp, with the force the mount
carried there (its force on the body, the figure the loop's log takes), once; a restart keeps
the break and does not report it again. Conditions that merely hold at a start without a switch
(a key bearing or past its allowable force, a joint open, a bolt past its yield) are states
there, not events, as before.

Truths written here, independently of the package: MASS hangs from one bolted joint below its
CG (local z down, along the bolt: the weight pulls the foot off its face) and rests on four
vertical springs K at the corners and a fitted vertical key K_KEY under the CG, all symmetric
about the CG, so the body sinks straight down by s. With the joint closed (F_V = 5 kN), the
bolt and the clamped parts act in parallel:
    4·K·s + K_KEY·s + (K_S + K_P)·s = m·g,
F_S = F_V + K_S·s, and the joint's force on the body F_K − F_S = −(K_S + K_P)·s.
With the joint open (F_V = 0.5 kN, s > F_V/K_P) the bolt alone carries the foot:
    4·K·s + K_KEY·s + F_V + K_S·s = m·g,
and the joint's force on the body is −F_S.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from hung_helpers import K_KEY, K_P, K_S, MASS, K, hung_scene
from physics_helpers import G

from mount_twin.cli import main
from mount_twin.engine.batch import ERROR, MountEvent, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.messages import IMU
from mount_twin.io.output_bag import write_bag
from mount_twin.io.output_encoding import imu_messages as imu_msgs
from mount_twin.io.output_tables import read_output_bag
from mount_twin.model.assemble import Model, assemble
from mount_twin.scene.loader import scene_from_dict

PRELOAD = {"closed": 5000.0, "open": 500.0}  # N: the joint closed or open at the start
ORIGIN_NS = 1_700_000_000 * 10**9
T0_NS = ORIGIN_NS + 7 * 10**6  # the first sample's stamp
DT_NS = 10**6  # 1 kHz
GAP_NS = 20 * 10**9  # past the scene's input.max_gap_s (10 s): a restart
TOPIC = "/imu/data"
STATUS = "mount_twin: mount "


def sag(joint: str) -> float:
    """s (m, down) where the springs, the key and the joint carry the weight."""
    f_v = PRELOAD[joint]
    if joint == "closed":
        s = MASS * G / (4.0 * K + K_KEY + K_S + K_P)
        assert s < f_v / K_P
    else:
        s = (MASS * G - f_v) / (4.0 * K + K_KEY + K_S)
        assert s > f_v / K_P
    return s


def bolt_force(joint: str) -> float:
    """F_S at the start, N."""
    return PRELOAD[joint] + K_S * sag(joint)


def joint_force(joint: str) -> float:
    """|F_K − F_S| at the start, N: the joint's force on the body (F_S where it is open)."""
    s = sag(joint)
    return (K_S + K_P) * s if joint == "closed" else PRELOAD[joint] + K_S * s


def hung(joint: str, yield_force: float, ultimate_force: float, allowable: float = 0.0) -> dict:
    """The scene of this file's truths; the key allowed `allowable` (N, 0: not monitored)."""
    return hung_scene(PRELOAD[joint], yield_force, ultimate_force, {"allowable_force": allowable})


def broken_at_start(joint: str) -> dict:
    """F_u at 98 % of the start's F_S, F_y at 90 %."""
    f_s = bolt_force(joint)
    return hung(joint, 0.9 * f_s, 0.98 * f_s)


def stamps_ns(n: int, gap_after: int | None = None) -> np.ndarray:
    """n stamps at 1 kHz from T0_NS, a gap of GAP_NS after sample `gap_after` (None: none)."""
    out = T0_NS + np.arange(n, dtype=np.int64) * DT_NS
    if gap_after is not None:
        out[gap_after + 1 :] += GAP_NS
    return out


def at_rest(stamps: np.ndarray) -> SampleBatch:
    """A deck at rest under gravity at `stamps` (ns), as the engine takes them: s from
    ORIGIN_NS, as a replay takes them (its reports' stamps then count from there too)."""
    n = len(stamps)
    f = np.zeros((n, 3))
    f[:, 2] = G
    t = (stamps - ORIGIN_NS) / 1e9
    return SampleBatch(t, f, np.zeros((n, 3)), ["imu"] * n)


def mount_statuses(engine_out) -> list[dict[str, dict[str, str]]]:
    """Each health report's mount statuses: {mount name: values}, with level and message."""
    return [
        {
            s.name.removeprefix(STATUS): {**s.values, "level": s.level, "message": s.message}
            for s in report.statuses
            if s.name.startswith(STATUS)
        }
        for report in engine_out.health
    ]


def model_of(data: dict) -> Model:
    return assemble(scene_from_dict(data, "<hung>"))


@pytest.mark.parametrize("joint", ["closed", "open"])
def test_a_bolt_broken_at_the_start_is_one_bolt_fractured_event_at_the_first_stamp(joint):
    """Exactly one event, the bolt's bolt_fractured at the first sample's stamp, with the
    joint's force on the body there (F_S where the joint is open; the closed joint's
    (k_S + k_P)·s beside F_S otherwise, as the loop's log takes any event's force); counted,
    and in the first report's status with its first stamp and force; then a restart after a
    gap keeps the break and reports it no more."""
    model = model_of(broken_at_start(joint))
    # the start is this file's equilibrium, with the bolt intact and past F_u
    assert model.nominal_state[2] == pytest.approx(-sag(joint), rel=1e-9)
    assert any(w.path == "mounts[5].ultimate_force" for w in model.scene.warnings)
    force = joint_force(joint)
    if joint == "open":
        assert force == pytest.approx(bolt_force(joint), rel=1e-12)
    t0 = (T0_NS - ORIGIN_NS) / 1e9

    stamps = stamps_ns(10, gap_after=4)
    engine = TwinEngine(model)
    out = engine.run(at_rest(stamps))
    assert engine.counts["restarts"] == 1 and engine.counts["starts"] == 2
    assert engine.counts["starts_without_equilibrium"] == 0
    (event,) = engine.events
    assert event == MountEvent(t0, "bolt", "bolt_fractured", event.force, True)
    assert event.force == pytest.approx(force, rel=1e-9)
    assert engine.counts["mount_events"] == 1
    assert engine.state[model.state_names.index("bolt.fractured")] == 1.0

    reports = mount_statuses(out)
    first, later = reports[0], reports[1:]
    bolt = first["bolt"]
    assert bolt["level"] == ERROR
    assert bolt["events"] == "1"
    assert bolt["bolt_fractured.count"] == "1"
    assert bolt["bolt_fractured.first_stamp_ns"] == str(T0_NS - ORIGIN_NS)  # engine seconds
    assert float(bolt["bolt_fractured.force_max_N"]) == pytest.approx(force, rel=1e-9)
    assert f"bolt_fractured ×1 (first {t0:.6f} s, |F| max {force:.4g} N)" in bolt["message"]
    # nothing else is an event at the start: the key bearing, the joint's state, the bolt past
    # its yield force are conditions there
    assert all(v["events"] == "0" for name, v in first.items() if name != "bolt")
    assert "bolt_fractured" in bolt["now"].split(", ")
    # the restart after the gap, and any report after it: the break held, not reported again
    assert later, "a report after the restart"
    for report in later:
        assert report["bolt"]["events"] == "0"
        assert "bolt_fractured.count" not in report["bolt"]
        assert "bolt_fractured" in report["bolt"]["now"].split(", ")


def test_a_bolt_broken_at_the_start_is_the_same_event_whatever_the_batching():
    """Pushed one sample at a time (live), the events and mount statuses are the run's."""
    model = model_of(broken_at_start("closed"))
    batch = at_rest(stamps_ns(10, gap_after=4))
    whole = TwinEngine(model)
    out = whole.run(batch)
    live = TwinEngine(model)
    outs = [live.push(batch.part(slice(i, i + 1))) for i in range(len(batch))] + [live.flush()]
    assert live.events == whole.events and len(whole.events) == 1
    assert live.counts["mount_events"] == 1
    got = [r for o in outs for r in mount_statuses(o)]
    assert [r["bolt"] for r in got] == [r["bolt"] for r in mount_statuses(out)]


@pytest.mark.parametrize("joint", ["closed", "open"])
def test_a_start_within_the_bolt_s_ultimate_force_reports_no_event(joint):
    """The bolt 20 % below its ultimate force (and 3 % below its yield force): no event, no
    count. Nor where the start holds conditions without a switch (the bolt past its yield
    force, the key past its allowable force, the joint open): those are states, shown under
    `now`, not events."""
    f_s = bolt_force(joint)
    key_force = K_KEY * sag(joint)
    for data in (
        hung(joint, 1.03 * f_s, 1.2 * f_s, allowable=2.0 * key_force),
        hung(joint, 0.9 * f_s, 1.2 * f_s, allowable=0.9 * key_force),
    ):
        model = model_of(data)
        engine = TwinEngine(model)
        out = engine.run(at_rest(stamps_ns(10, gap_after=4)))
        assert engine.events == []
        assert engine.counts["mount_events"] == 0
        assert engine.state[model.state_names.index("bolt.fractured")] == 0.0
        for report in mount_statuses(out):
            assert all(v["events"] == "0" for v in report.values())
    # the second scene holds conditions without a switch: ERROR states, not events
    first = mount_statuses(out)[0]
    assert first["key"]["level"] == ERROR and first["bolt"]["level"] == ERROR


def _bag(path: Path, stamps: np.ndarray) -> Path:
    """A bag of deck IMU samples at rest at `stamps` (ns)."""
    accel = np.zeros((len(stamps), 3))
    accel[:, 2] = G
    gyro = np.zeros((len(stamps), 3))
    write_bag(path, TOPIC, IMU, iter(imu_msgs(stamps, accel, gyro, "deck_imu")))
    return path


def test_a_replay_lists_the_bolt_broken_at_the_start_in_its_summary_and_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The replay summary's "mount events" (text and JSON) and the output bag's events table
    hold the start's bolt_fractured once, at the first stamp, with its force; the restart
    after the gap adds none. (The body dropping on its broken bolt then opens the joint in
    the loop: those are the loop's own events.)"""
    scene = tmp_path / "hung.scene.yaml"
    scene.write_text(yaml.safe_dump(broken_at_start("closed")), encoding="utf-8")
    bag = _bag(tmp_path / "in", stamps_ns(40, gap_after=19))
    out, doc_path = tmp_path / "out", tmp_path / "summary.json"
    args = ["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]
    assert main([*args, "--json", str(doc_path)]) == 0
    text = capsys.readouterr().out
    force = joint_force("closed")
    doc = json.loads(doc_path.read_text(encoding="utf-8"))
    assert doc["counts"]["restarts"] == 1
    assert doc["events"][0]["event"] == "bolt_fractured"
    (event,) = [e for e in doc["events"] if e["event"] == "bolt_fractured"]
    assert (event["mount"], event["event"], event["level"]) == ("bolt", "bolt_fractured", "ERROR")
    assert event["t_s"] == 0.0
    assert event["stamp_s"] == pytest.approx(T0_NS / 1e9, abs=1e-6)  # a float of header s
    assert event["force_N"] == pytest.approx(force, rel=1e-9)
    assert f"  mount events: {len(doc['events'])} (times from the first output" in text
    listed = text.split("  mount events: ")[1].splitlines()[1 : 1 + len(doc["events"])]
    (line,) = [s for s in listed if "bolt_fractured" in s]
    assert re.fullmatch(  # at the first stamp: 0 s from the first output
        rf"\s+ERROR\s+bolt bolt_fractured\s+×1\s+first 0\.000000 s "
        rf"\(stamp {T0_NS / 1e9:.6f} s\)\s+\|F\| max {force:.4g} N",
        line,
    ), line
    tables = {t.name: t for t in read_output_bag(out)}
    events = tables["events"].columns
    (row,) = np.flatnonzero(events["event"] == "bolt_fractured")
    assert events["mount"][row] == "bolt"
    assert events["stamp_ns"][row] == T0_NS
    assert events["count"][row] == 1
    assert events["force_max_N"][row] == pytest.approx(force, rel=1e-9)
