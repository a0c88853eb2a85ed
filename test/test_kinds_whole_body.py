"""The new mount kinds on a whole body: config/genset_bolted_keyed.scene.yaml (a 3 t diesel
generator set on six M20 8.8 bolted feet and two shear keys) through an escalating deck shock,
and the bundled bag bags/genset_shock_10khz replayed.

One engine run takes three naval double half-sines of rising severity, 0.1 s apart (each an
upward kick, then a longer downward rebound that leaves the deck at rest; the rebound lifts the
body off its feet quasi-statically):
  1. 500 m/s² / 5 ms, rebound 150 m/s²: the front joints open (the CG is 0.1 m forward of the
     middle feet), no bolt yields;
  2. 500 m/s² / 5 ms, rebound 300 m/s²: four bolts yield;
  3. 1000 m/s² / 5 ms, rebound 600 m/s²: every bolt stretches to its ultimate plastic
     elongation and breaks.
Checks against the VDI 2230 joint diagram are made from the published pose (foot lift u from
the CG pose and the foot's lever arm) and closed forms, not from the kind's code.
"""

from __future__ import annotations

import dataclasses
import math
import re
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG, ROOT, G, batch, read_bag, split
from scipy.spatial.transform import Rotation

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, HealthStatus, MountEvent
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.signals import half_sine_shock
from mount_twin.kinds.bolted_joint import BoltedJoint
from mount_twin.kinds.shear_key import ShearKey
from mount_twin.model.assemble import assemble
from mount_twin.replay import replay
from mount_twin.scene import Scene, load_scene_file

SCENE_FILE = CONFIG / "genset_bolted_keyed.scene.yaml"
BAG = ROOT / "bags" / "genset_shock_10khz"
RATE = 10_000.0  # Hz
DT = 1.0 / RATE
PULSES = (  # onset s, kick peak m/s², kick length s, rebound peak m/s²
    (0.02, 500.0, 0.005, 150.0),
    (0.12, 500.0, 0.005, 300.0),
    (0.22, 1000.0, 0.005, 600.0),
)
TOTAL = 0.32  # s of shock record; then LATER s at rest in a separate push
LATER = 0.1
FEET = ("foot_fl", "foot_fr", "foot_ml", "foot_mr", "foot_rl", "foot_rr")
KEYS = ("key_x", "key_y")


@cache
def scene() -> Scene:
    return load_scene_file(SCENE_FILE)


def joint(name: str) -> BoltedJoint:
    mount = next(m for m in scene().mounts if m.name == name)
    assert isinstance(mount, BoltedJoint)
    return mount


def pulse_end(i: int) -> float:
    """End of pulse i's rebound, s."""
    onset, peak, length, rebound = PULSES[i]
    return onset + length + peak * length / rebound


def pulse_of(stamp: float) -> int:
    """Index of the pulse whose 0.1 s window holds `stamp` (−1 before the first)."""
    return max((i for i, p in enumerate(PULSES) if stamp >= p[0]), default=-1)


@dataclasses.dataclass
class Run:
    engine: TwinEngine
    stamps: np.ndarray  # every input stamp, s
    out_stamps: np.ndarray  # published rows (all samples: decimation 1)
    pose: np.ndarray
    wrenches: np.ndarray
    reports: list[HealthReport]
    accepted_before_later: int
    later_rows: int


def shock_record() -> tuple[np.ndarray, np.ndarray]:
    """Stamps (s) and specific force (m/s²) of the three pulses."""
    t = np.arange(round(TOTAL * RATE)) / RATE
    accel = np.zeros((t.size, 3))
    accel[:, 2] = G
    for onset, peak, length, rebound in PULSES:
        sig = half_sine_shock(peak, length, RATE, onset, TOTAL, G, rebound=rebound)
        accel += sig.accel - (0.0, 0.0, G)
    return t, accel


@cache
def escalation() -> Run:
    """The three pulses in one engine, pushed in 0.05 s chunks, then LATER s at rest."""
    t, accel = shock_record()
    engine = TwinEngine(assemble(scene()))
    outs = []
    for part in split(batch(t, accel), [500] * round(TOTAL / 0.05)):
        outs.append(engine.push(part))
    accepted = engine.counts["accepted"]
    later = np.arange(1, round(LATER * RATE) + 1) / RATE + t[-1]
    outs.append(engine.push(batch(later)))
    final = engine.flush()  # the end: the rows the gyro delay holds (its report not kept)
    out_stamps = np.concatenate([*(o.stamps for o in outs), final.stamps])
    return Run(
        engine,
        np.concatenate([t, later]),
        out_stamps,
        np.concatenate([*(o.pose for o in outs), final.pose]),
        np.concatenate([*(o.wrenches for o in outs), final.wrenches]),
        [r for o in outs for r in o.health],
        accepted,
        int((out_stamps > t[-1]).sum()),
    )


def events(name: str, mount: str | None = None) -> list[MountEvent]:
    return [
        e
        for e in escalation().engine.events
        if e.event == name and (mount is None or e.mount == mount)
    ]


def foot_lift(name: str) -> np.ndarray:
    """u (m) of a foot at every published row: the foot's motion along its bolt (+z of F, the
    feet are not inclined) from the preloaded rest position, from the CG pose."""
    run, sc = escalation(), scene()
    arm = np.array(joint(name).position) - np.array(sc.body.cg)
    foot = run.pose[:, :3] + Rotation.from_quat(run.pose[:, 3:7]).apply(arm)
    return foot[:, 2] - joint(name).position[2]


def revealing_row(stamp: float) -> int:
    """Row of the first sample at or after `stamp` (the sample whose evaluation found it)."""
    return int(np.searchsorted(escalation().out_stamps, stamp))


def status(report: HealthReport, mount: str) -> HealthStatus:
    return next(s for s in report.statuses if s.name == f"mount_twin: mount {mount}")


def report_after(i: int) -> HealthReport:
    """The first /diagnostics report after pulse i's rebound (it holds that pulse's events)."""
    return next(r for r in escalation().reports if r.stamp >= pulse_end(i))


def test_escalating_shock_opens_then_yields_then_breaks_the_bolts_in_that_order() -> None:
    run = escalation()
    opened, yielded, broken = (
        events(e) for e in ("joint_opened", "bolt_yielded", "bolt_fractured")
    )
    assert opened and yielded and broken, [(e.mount, e.event) for e in run.engine.events]
    # Each limit is first passed by the pulse meant to pass it: during its kick or rebound, or
    # within 2 ms after (the body's vertical period on the closed joints is ~2.2 ms).
    for first, i in ((opened[0], 0), (yielded[0], 1), (broken[0], 2)):
        assert PULSES[i][0] < first.stamp < pulse_end(i) + 0.002, (first, PULSES[i])
    assert {e.mount for e in opened if pulse_of(e.stamp) == 0} == {"foot_fl", "foot_fr"}
    assert not [e for e in yielded + broken if pulse_of(e.stamp) < 1], "pulse 1 only opens"
    assert {e.mount for e in yielded if pulse_of(e.stamp) == 1} == set(FEET[:4])
    assert not [e for e in broken if pulse_of(e.stamp) < 2], "pulse 2 does not break a bolt"
    assert sorted(e.mount for e in broken) == sorted(FEET), "each bolt breaks once, for good"
    for foot in FEET:  # per bolt: opened, then yielded, then broken; nothing after the break
        first = [events(e, foot)[0].stamp for e in ("joint_opened", "bolt_yielded")]
        (fracture,) = events("bolt_fractured", foot)
        assert first[0] < first[1] < fracture.stamp, (foot, first, fracture.stamp)
        assert not events("bolt_yielded", foot)[-1].stamp > fracture.stamp
    # Every event time is interpolated inside the interval of the sample that revealed it.
    for e in run.engine.events:
        k = revealing_row(e.stamp)
        assert run.out_stamps[k - 1] < e.stamp <= run.out_stamps[k], e
    assert all(e.error for e in opened + yielded + broken)


def test_joint_opening_is_located_where_the_foot_lift_reaches_fv_over_kp() -> None:
    """F_K = F_V − k_P·u reaches 0 at u = F_V/k_P: the crossing of u (linear between the two
    samples) must be where the event says, to a hundredth of the sample interval."""
    run = escalation()
    checked = 0
    for e in events("joint_opened"):
        u = foot_lift(e.mount)
        k = revealing_row(e.stamp)
        u_open = joint(e.mount).preload / joint(e.mount).clamp_stiffness
        assert u[k - 1] < u_open <= u[k], (e, u[k - 1], u[k], u_open)
        frac = (u_open - u[k - 1]) / (u[k] - u[k - 1])
        t_cross = run.out_stamps[k - 1] + frac * (run.out_stamps[k] - run.out_stamps[k - 1])
        assert abs(t_cross - e.stamp) < 0.01 * DT, (e, t_cross)
        checked += 1
    assert checked >= 6


def test_event_forces_agree_with_the_joint_diagram() -> None:
    # First opening of a bolt still at its full preload (pulses 1 and 2, rebound ≥ 8 ms against
    # a 2.2 ms period: quasi-static): the bolt alone carries F_A = F_V/(1 − Φ) = 120 kN; the
    # event reports the force at the revealing sample, ≤ 0.1 ms later, so a few % more.
    fresh = [events("joint_opened", f)[0] for f in FEET]
    for e in fresh:
        j = joint(e.mount)
        assert j.opening_load == pytest.approx(1.0e5 / (1.0 - 7.0 / 42.0))
        assert pulse_of(e.stamp) in (0, 1)
        assert 1.0 <= e.force / j.opening_load < 1.05, (e, j.opening_load)
    # First yield: F_S = F_y (then hardening α·k_S and damping c·u̇ add a little by the sample).
    for e in (events("bolt_yielded", f)[0] for f in FEET):
        assert 1.0 <= e.force / joint(e.mount).yield_force < 1.06, e
    # Fracture at the ultimate plastic elongation ε_u (before F_u): the hardened yield force
    # F_y + α/(1 − α)·k_S·ε_u = 185.6 kN, plus c·u̇ (u̇ from the published pose) in the wrench.
    run = escalation()
    names = [m.name for m in scene().mounts]
    state = dict(zip(run.engine.model.state_names, run.engine.state, strict=True))
    for e in events("bolt_fractured"):
        j = joint(e.mount)
        f_break = j.yield_force + j.hardening / (1.0 - j.hardening) * (
            j.bolt_stiffness * j.ultimate_plastic_elongation
        )
        assert f_break == pytest.approx(185.6e3, rel=1e-3) and f_break < j.ultimate_force
        k = revealing_row(e.stamp)
        u = foot_lift(e.mount)
        u_dot = (u[k] - u[k - 1]) / DT
        axial = -run.wrenches[k, names.index(e.mount), 2] - j.axial_damping * u_dot
        assert axial == pytest.approx(f_break, rel=0.02), (e, axial, u_dot)
        assert e.force >= 0.99 * f_break
        assert state[f"{e.mount}.fractured"] == 1.0
        assert (
            j.ultimate_plastic_elongation
            <= state[f"{e.mount}.plastic_elongation"]
            < 1.05 * j.ultimate_plastic_elongation
        )


def test_first_yield_is_located_where_u_reaches_the_yield_lift() -> None:
    run = escalation()
    for foot in FEET[:4]:
        e = events("bolt_yielded", foot)[0]
        j = joint(foot)
        u = foot_lift(foot)
        k = revealing_row(e.stamp)
        u_yield = (j.yield_force - j.preload) / j.bolt_stiffness  # F_S = F_V + k_S·u = F_y
        assert u[k - 1] < u_yield <= u[k], (e, u[k - 1], u[k], u_yield)
        frac = (u_yield - u[k - 1]) / (u[k] - u[k - 1])
        assert abs(run.out_stamps[k - 1] + frac * DT - e.stamp) < 0.1 * DT, (foot, frac, e)


def test_the_twin_keeps_running_after_the_bolts_break() -> None:
    run = escalation()
    counts = run.engine.counts
    n = round(TOTAL * RATE) + round(LATER * RATE)
    assert counts["accepted"] == counts["received"] == n
    assert counts["accepted"] - run.accepted_before_later == run.later_rows == round(LATER * RATE)
    assert counts["integration_failures"] == 0 and counts["restarts"] == 0
    assert run.engine.running
    assert len(run.out_stamps) == n and np.array_equal(run.out_stamps, run.stamps)
    assert np.isfinite(run.pose).all() and np.isfinite(run.wrenches).all()
    assert np.isfinite(run.engine.state).all()
    for r in run.reports:
        for s in r.statuses:
            assert "nan" not in s.message.lower(), (s.name, s.message)
            assert not [v for v in s.values.values() if v.lower() in ("nan", "inf", "-inf")], s
    # Loose on the deck after the rebound, the body hops (15 mm here; 45 mm once the dashpots of
    # broken, lifted feet stop pulling it down, see below) and rocks, but stays on the deck.
    assert np.abs(run.pose[:, :3] - scene().body.cg).max() < 0.1


def test_a_broken_bolt_stays_an_error_in_later_periods_without_new_events() -> None:
    """Fracture is for good: in the last period, long after the fractures were reported, every
    foot must still be ERROR and say its bolt is broken now."""
    run = escalation()
    last = run.reports[-1]
    assert last.stamp > run.stamps[round(TOTAL * RATE) - 1], "a report in the quiet tail"
    for foot in FEET:
        s = status(last, foot)
        assert "bolt_fractured" in s.values["now"].split(", "), (s.name, s.values)
        assert s.level == ERROR, (s.name, s.message)
        assert "bolt_fractured ×" not in s.message, "the fracture itself is not reported again"


def test_a_restart_does_not_re_bolt_the_machine() -> None:
    """After the bolts broke, a 2 s gap restarts the twin at equilibrium (gap_policy reset):
    the bolts stay broken (no preload comes back), and the feet stay ERROR."""
    t, accel = shock_record()
    engine = TwinEngine(assemble(scene()))
    engine.push(batch(t, accel))
    assert len({e.mount for e in engine.events if e.event == "bolt_fractured"}) == len(FEET)
    later = t[-1] + 2.0 + np.arange(2000) / RATE
    out = engine.run(batch(later))
    assert (engine.counts["gaps"], engine.counts["restarts"]) == (1, 1)
    report = out.health[-1]
    names = [m.name for m in scene().mounts]
    for foot in FEET:
        s = status(report, foot)
        assert "bolt_fractured" in s.values["now"].split(", "), (foot, s.values)
        assert s.level == ERROR
        # Resting on its broken feet the frame is pressed down by its weight only: no foot
        # carries the bolt preload (a re-bolted foot would clamp with preload + its share).
        fz = out.wrenches[-1, names.index(foot), 2]
        assert abs(fz) < joint(foot).preload / 2, (foot, fz)


def test_a_broken_bolt_whose_foot_is_off_the_deck_carries_no_force() -> None:
    run = escalation()
    names = [m.name for m in scene().mounts]
    for foot in FEET:
        (e,) = events("bolt_fractured", foot)
        j = joint(foot)
        gone = run.out_stamps > run.out_stamps[revealing_row(e.stamp)]  # switched at that row
        lifted = gone & (foot_lift(foot) > j.preload / j.clamp_stiffness)
        assert lifted.any(), foot
        force = np.linalg.norm(run.wrenches[lifted, names.index(foot), :3], axis=1)
        assert force.max() < 1.0, (foot, force.max())


def test_a_key_carries_no_force_once_the_frame_is_lifted_past_its_engagement_height() -> None:
    """The bundled keys are 40 mm tall (`engagement_height`): hopping loose after its bolts
    broke, the frame clears them, and a cleared key bears nothing, whatever the sideways
    motion (that the keys still stop the frame below that height: the bundled bag's test)."""
    run, sc = escalation(), scene()
    names = [m.name for m in sc.mounts]
    cleared_rows = 0
    for name in KEYS:
        key = next(m for m in sc.mounts if m.name == name)
        assert isinstance(key, ShearKey) and key.engagement_height == 0.04
        arm = np.array(key.position) - np.array(sc.body.cg)
        lift = (run.pose[:, :3] + Rotation.from_quat(run.pose[:, 3:7]).apply(arm))[:, 2]
        lift -= key.position[2]
        cleared = lift > key.engagement_height
        cleared_rows += int(cleared.sum())
        force = np.abs(run.wrenches[:, names.index(name), :3]).max(axis=1)
        assert force[cleared].max(initial=0.0) == 0.0, name
    assert cleared_rows > 0, "the escalation lifts the frame past 40 mm"


def test_diagnostics_name_the_events_of_each_period_at_error_for_the_affected_mounts() -> None:
    run = escalation()
    assert [round(r.stamp, 3) for r in run.reports] == [0.1, 0.2, 0.3, 0.4]
    first, second, third = (report_after(i) for i in range(3))
    for foot in FEET:
        s = status(first, foot)
        if foot in ("foot_fl", "foot_fr"):
            assert s.level == ERROR and "joint_opened" in s.message, (s.name, s.message)
        else:  # slipped on the rocking, but held
            assert s.level == WARN and "joint_opened" not in s.message, (s.name, s.message)
            assert "joint_slipped" in s.message
        assert "bolt_yielded" not in s.message
        assert float(s.values["utilisation_max"]) < 1.0
        s = status(second, foot)
        assert s.level == ERROR and "joint_opened" in s.message, (s.name, s.message)
        if foot in FEET[:4]:
            assert "bolt_yielded" in s.message and float(s.values["utilisation_max"]) > 1.0
        else:
            assert "bolt_yielded" not in s.message
        s = status(third, foot)
        assert s.level == ERROR and "bolt_fractured ×1" in s.message, (s.name, s.message)
        # '… (first 0.230932 s, |F| max 2.309e+05 N)': the first fracture of this foot
        m = re.search(
            r"bolt_fractured ×1 \(first ([0-9.]+) s, \|F\| max ([0-9.e+]+) N\)", s.message
        )
        assert m, s.message
        (e,) = events("bolt_fractured", foot)
        assert float(m.group(1)) == pytest.approx(e.stamp, abs=1e-6)
        assert float(m.group(2)) == pytest.approx(e.force, rel=1e-3)
    for report in (first, second):
        for key in KEYS:
            assert status(report, key).level == OK, status(report, key)
    # Peaks per axis: a key pushes along its own axis only.
    for r in run.reports:
        x, y = (status(r, k).values for k in KEYS)
        assert float(x["peak_fy_N"]) == float(x["peak_fz_N"]) == 0.0
        assert float(y["peak_fx_N"]) == float(y["peak_fz_N"]) == 0.0


def test_replayed_genset_shock_bag_reports_the_joints_opening(tmp_path: Path) -> None:
    out = tmp_path / "genset_out"
    summary = replay(scene(), BAG, out, progress=False)
    assert summary.counts["accepted"] == summary.counts["received"] == 2500
    assert summary.counts.get("integration_failures", 0) == 0
    types, msgs = read_bag(out)
    assert types["/diagnostics"] == "diagnostic_msgs/msg/DiagnosticArray"
    assert {f"/mount_twin/mounts/{f}/wrench" for f in (*FEET, *KEYS)} <= set(types)
    opened = {}
    for _, arr in msgs["/diagnostics"]:
        for s in arr.status:
            m = re.search(
                r"joint_opened ×(\d+) \(first ([0-9.]+) s, \|F\| max ([0-9.e+]+) N\)", s.message
            )
            if m and s.name.startswith("mount_twin: mount foot_"):
                assert s.level == ERROR, (s.name, s.message)
                # diagnostics give header stamps: from the bag's start (1.7e9 s) back to the pulse
                at = float(m[2]) - summary.origin_s
                opened.setdefault(s.name.rsplit(" ", 1)[1], (at, float(m[3])))
    # The deck pulse: 50 ms at rest, a 400 m/s² 5 ms kick with 30 % athwartships, a 100 m/s²
    # 20 ms rebound. The kick rolls the body onto its right feet and the left joints open; the
    # rebound lifts it and the right ones open too. No bolt yields.
    assert set(opened) == set(FEET), opened
    for foot, (first, force) in opened.items():
        assert 0.05 < first < 0.075 + 0.002, (foot, first)
        assert force / joint(foot).opening_load == pytest.approx(1.0, abs=0.06), (foot, force)
    left = [opened[f][0] for f in ("foot_fl", "foot_ml", "foot_rl")]
    right = [opened[f][0] for f in ("foot_fr", "foot_mr", "foot_rr")]
    assert max(left) < min(right), (left, right)
    assert not [e for e in summary.events if e.event in ("bolt_yielded", "bolt_fractured")]
    assert max(summary.utilisation_max[f] for f in FEET) < 1.0
    wrench = msgs["/mount_twin/mounts/key_y/wrench"]
    assert max(abs(m.wrench.force.y) for _, m in wrench) > 1.0e5, "key_y stops the frame"
    assert math.isfinite(summary.tilt_max_rad)
