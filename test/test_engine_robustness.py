"""TwinEngine robustness: bad samples, stamp trouble, gaps, decimation, holds, integration failure.

Every rejected sample must be counted under its own key, reported on the diagnostics (WARN on the
input status for the period it happened in), and never produce a NaN; integration failures are
reported as ERROR and the twin restarts at the next sample.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from itertools import pairwise

import numpy as np
import pytest
from io_helpers import (
    REST,
    batch,
    default_model,
    default_scene,
    engine_for,
    push_all,
    scene_with,
    split,
)

from mount_twin.engine.batch import ERROR, OK, WARN, HealthReport, OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.signals import half_sine_shock, ship_motion
from mount_twin.model.assemble import gravity_input
from mount_twin.physics.dynamics import OFF_CHART, rhs

RATE = 1000.0
POSE_TOL = 1e-12  # m, rad: same arithmetic, so only round-off may differ


def stamps(n: int, t0: float = 0.0, rate: float = RATE) -> np.ndarray:
    return t0 + np.arange(n) / rate


def assert_finite(out: OutputBatch) -> None:
    assert np.isfinite(out.pose).all(), "NaN/inf in OutputBatch.pose"
    assert np.isfinite(out.wrenches).all(), "NaN/inf in OutputBatch.wrenches"


def status(report: HealthReport, which: str):
    (st,) = [s for s in report.statuses if s.name == f"mount_twin: {which}"]
    return st


def equilibrium_pose(scene=None) -> np.ndarray:
    """Pose row of a fresh twin started at rest."""
    return engine_for(scene).run(batch([0.0])).pose[0]


def ship_batch(total: float = 0.5, frame_id: str = "deck_imu") -> SampleBatch:
    sig = ship_motion(rate_hz=RATE, total=total)
    shock = half_sine_shock(peak=120.0, duration=0.01, rate_hz=RATE, pre=0.1, total=total)
    accel = sig.accel + shock.accel - REST  # ship motion plus a vertical half-sine shock
    return batch(sig.t, accel, sig.gyro, frame_id)


# --------------------------------------------------------------------------- rejected samples

# Each fault is applied to sample 30 or 31 of the third of five 100-sample batches (0.1 s each).
# With diagnostics every 0.05 s, exactly the report whose period holds the fault warns.


def _nan_accel(b: SampleBatch) -> int:
    b.accel[30, 2] = np.nan
    return 30


def _inf_gyro(b: SampleBatch) -> int:
    b.gyro[30, 0] = np.inf
    return 30


def _nan_stamp(b: SampleBatch) -> int:
    b.stamps[30] = np.nan
    return 30


def _wrong_frame(b: SampleBatch) -> int:
    b.frame_ids[30] = "base_link"
    return 30


def _duplicate(b: SampleBatch) -> int:
    b.stamps[31] = b.stamps[30]
    return 31


def _back_a_little(b: SampleBatch) -> int:
    b.stamps[31] = b.stamps[30] - 0.0005
    return 31


FAULTS: list[tuple[str, Callable[[SampleBatch], int], str]] = [
    ("nan_accel", _nan_accel, "rejected_non_finite"),
    ("inf_gyro", _inf_gyro, "rejected_non_finite"),
    ("nan_stamp", _nan_stamp, "rejected_non_finite"),
    ("wrong_frame_id", _wrong_frame, "rejected_wrong_frame"),
    ("duplicate_stamp", _duplicate, "rejected_duplicate_stamp"),
    ("stamp_back_by_half_a_sample", _back_a_little, "rejected_stamp_went_back"),
]


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize(("fault", "key"), [f[1:] for f in FAULTS], ids=[f[0] for f in FAULTS])
def test_bad_sample_is_rejected_counted_reported_as_warn_and_never_yields_nan(
    fault: Callable[[SampleBatch], int], key: str
) -> None:
    scene = scene_with(outputs={"diagnostics_period_s": 0.05})
    engine = engine_for(scene)
    full = ship_batch(0.5)
    clean = full.stamps.copy()
    parts = split(full, [100] * 5)
    bad = fault(parts[2])
    out, reports = push_all(engine, parts)

    assert engine.counts[key] == 1, f"{key} not counted: {dict(engine.counts)}"
    rejected = {k: v for k, v in engine.counts.items() if k.startswith("rejected_")}
    assert rejected == {key: 1}, f"counted under other keys too: {rejected}"
    assert (engine.counts["received"], engine.counts["accepted"]) == (500, 499)
    assert engine.counts["restarts"] == 0
    expected = np.delete(clean, 200 + bad)
    np.testing.assert_array_equal(
        out.stamps, expected, err_msg="outputs must answer accepted samples"
    )
    assert_finite(out)

    flat = [r for rs in reports for r in rs]
    assert len(flat) in (9, 10), "one diagnostics report per 0.05 s of stamps expected"
    k = next(i for i, r in enumerate(flat) if r.stamp >= clean[200 + bad])
    levels = [status(r, "input").level for r in flat]
    assert levels == [OK] * k + [WARN] + [OK] * (len(flat) - k - 1), (
        f"input levels per period: {levels}"
    )
    warn = status(flat[k], "input")
    detail = " (wrong_frame 1: expected frame_id 'deck_imu', got 'base_link')"
    expected_message = f"1 samples rejected{detail if key == 'rejected_wrong_frame' else ''}"
    assert warn.message == f"{expected_message}, 0 gaps in this period"
    assert warn.values[key] == "1"
    assert warn.values["lost_in_period"] == "0", "a rejected sample was received, not lost"
    received = int(np.searchsorted(clean, flat[k].stamp, side="right"))
    assert (warn.values["received"], warn.values["accepted"]) == (str(received), str(received - 1))
    assert all(status(r, "integration").level == OK for r in flat)


def test_frame_id_is_not_checked_when_the_scene_leaves_it_empty() -> None:
    engine = engine_for(scene_with(input={"frame_id": ""}))
    b = batch(stamps(10), frame_ids=["a", "b", "deck_imu", "", "x"] * 2)
    out = engine.run(b)
    assert len(out) == 10
    assert engine.counts["accepted"] == 10


def test_a_batch_of_only_rejected_samples_returns_empty_outputs() -> None:
    engine = engine_for()
    out = engine.run(batch(stamps(5), frame_ids="wrong"))
    assert len(out) == 0 and out.pose.shape == (0, 10) and out.wrenches.shape == (0, 8, 6)
    assert engine.counts["rejected_wrong_frame"] == 5
    assert not engine.running


# --------------------------------------------------------------------------- stamp jumps and gaps


@pytest.mark.parametrize(
    "pieces",
    [[1500, 300], [700, 900, 200], [1] * 5 + [1795]],
    ids=["at_boundary", "inside_batch", "tiny_batches"],
)
def test_stamp_jumping_back_more_than_the_limit_restarts_the_twin(pieces: list[int]) -> None:
    scene = default_scene()
    assert scene.input.back_jump_reset_s == 1.0
    first = ship_batch(1.5)
    again = batch(stamps(300))  # bag --loop: back to t = 0 s, 1.499 s earlier
    full = SampleBatch.concat([first, again])
    engine = engine_for(scene)
    out, _ = push_all(engine, split(full, pieces))
    assert engine.counts["reset_stamp_jumped_back"] == 1
    assert engine.counts["restarts"] == 1 and engine.counts["starts"] == 2
    assert engine.counts["accepted"] == 1800
    np.testing.assert_array_equal(out.stamps, full.stamps)
    assert_finite(out)
    # The restart starts again at equilibrium: the row of the jumped-back sample is the rest pose.
    np.testing.assert_allclose(out.pose[1500], equilibrium_pose(), rtol=0, atol=POSE_TOL)


def test_stamp_going_back_less_than_the_limit_is_skipped_without_restart() -> None:
    engine = engine_for()
    st = stamps(400)
    st[200:210] = st[199] - 0.5 + np.arange(10) * 1e-3  # ten samples 0.5 s in the past
    out = engine.run(batch(st))
    assert engine.counts["rejected_stamp_went_back"] == 10
    assert engine.counts["restarts"] == 0 and engine.counts["reset_stamp_jumped_back"] == 0
    np.testing.assert_array_equal(out.stamps, np.delete(st, np.arange(200, 210)))
    assert np.all(np.diff(out.stamps) > 0)


def _gap_run(policy: str) -> tuple[TwinEngine, SampleBatch, OutputBatch, list[list[HealthReport]]]:
    scene = scene_with(input={"gap_policy": policy}, outputs={"diagnostics_period_s": 0.05})
    before = ship_batch(0.2)  # moving when the gap begins (shock at 0.1 s)
    after = batch(stamps(200, t0=0.2 + 0.7))  # 0.701 s without samples > max_gap_s = 0.5 s
    engine = engine_for(scene)
    full = SampleBatch.concat([before, after])
    out, reports = push_all(engine, split(full, [100, 100, 100, 100]))
    return engine, full, out, reports


def _gap_reported(report: HealthReport) -> None:
    """The period of the gap: an ERROR naming the gap and the 700 samples a 1 kHz sensor sent
    in its 0.701 s that never came (past 1 % of the period lost)."""
    st = status(report, "input")
    assert st.level == ERROR, st
    assert st.message.startswith("0 samples rejected, 1 gaps in this period; ~700 samples lost")
    assert st.values["lost_in_period"] == "700"


def test_gap_with_reset_policy_restarts_at_equilibrium_and_reports_the_input_lost() -> None:
    engine, full, out, reports = _gap_run("reset")
    assert engine.counts["gaps"] == 1 and engine.counts["restarts"] == 1
    np.testing.assert_array_equal(out.stamps, full.stamps)
    assert_finite(out)
    np.testing.assert_allclose(out.pose[200], equilibrium_pose(), rtol=0, atol=POSE_TOL)
    levels = [status(r[0], "input").level for r in reports]  # per push, then the flush
    assert levels == [OK, OK, ERROR, OK, OK], f"input levels per period: {levels}"
    _gap_reported(reports[2][0])


@pytest.mark.parametrize("gyro_filter", ["none", "linear_phase"])
@pytest.mark.parametrize("pieces", [None, [1] * 400, [7] * 58])
def test_a_restart_gathering_several_samples_is_not_lost_at_a_push_or_a_held_sample(
    gyro_filter: str, pieces: list[int] | None
) -> None:
    """With initial_state.gravity_samples 5 a restart cut short (by a push, or by the engine's
    own hold of the sample after a stamp jump: every batching under gyro_filter none) was
    dropped: the twin integrated across the 0.7 s gap from the state before it, moving, and
    counted no restart. It restarts at rest in equilibrium on the fifth sample after the gap."""
    scene = scene_with(
        input={"gap_policy": "reset", "gyro_filter": gyro_filter},
        initial={"gravity_samples": 5},
    )
    full = SampleBatch.concat([ship_batch(0.2), batch(stamps(200, t0=0.2 + 0.7))])
    engine = engine_for(scene)
    out, _ = push_all(engine, [full] if pieces is None else split(full, pieces))
    assert engine.counts["gaps"] == 1 and engine.counts["restarts"] == 1
    after = np.flatnonzero(out.stamps > 0.5)
    np.testing.assert_array_equal(out.stamps[after], full.stamps[204:])  # 4 gathered first
    np.testing.assert_allclose(out.pose[after[0]], equilibrium_pose(), rtol=0, atol=POSE_TOL)


def test_restarts_after_failures_answer_the_same_samples_in_any_batching() -> None:
    """With gravity_samples 3, a failure within a push restarted at the next sample, one on a
    push's last sample gathered three afresh in the next: 198 rows pushed whole, 109 pushed
    one sample at a time. A restart after a failure takes the next sample alone, wherever
    the push ends."""
    scene = scene_with(
        integration={"method": "dopri54", "rtol": 1e-13, "atol": 1e-15, "max_substeps": 1},
        initial={"gravity_samples": 3},
    )
    full = ship_batch(0.4)
    runs = []
    for pieces in (None, [1] * 400, [7] * 58):
        engine = engine_for(scene)
        out, _ = push_all(engine, [full] if pieces is None else split(full, pieces))
        runs.append((out, engine.counts))
    (want, counts), *others = runs
    assert counts["integration_failures"] > 100 and counts["restarts"] > 100
    for out, got in others:
        np.testing.assert_array_equal(out.stamps, want.stamps)
        np.testing.assert_array_equal(out.pose, want.pose)
        assert got == counts


def test_gap_with_bridge_policy_integrates_across_it_without_restart() -> None:
    engine, full, out, reports = _gap_run("bridge")
    assert engine.counts["gaps"] == 1 and engine.counts["restarts"] == 0
    np.testing.assert_array_equal(out.stamps, full.stamps)
    assert_finite(out)
    moved = np.abs(out.pose[200, :3] - equilibrium_pose()[:3]).max()
    assert moved > 1e-7, (
        f"bridged twin should still carry the shock's motion, differs by {moved} m"
    )
    _gap_reported(reports[2][0])


# --------------------------------------------------------------------------- streaming equivalence


@pytest.mark.parametrize(
    "pieces",
    [[600], [1] * 600, [3, 1, 50, 7, 200, 1, 1, 99, 238]],
    ids=["one_batch", "one_sample_each", "ragged"],
)
def test_outputs_do_not_depend_on_how_the_samples_are_batched(pieces: list[int]) -> None:
    full = ship_batch(0.6)
    full.accel[100, 0] = np.nan
    full.frame_ids[150] = "wrong"
    full.stamps[301] = full.stamps[300]
    reference, _ = push_all(engine_for(), [full])
    engine = engine_for()
    out, _ = push_all(engine, split(full, pieces))
    np.testing.assert_array_equal(out.stamps, reference.stamps)
    np.testing.assert_allclose(out.pose, reference.pose, rtol=0, atol=POSE_TOL)
    np.testing.assert_allclose(out.wrenches, reference.wrenches, rtol=1e-12, atol=1e-9)
    accepted = np.delete(full.stamps, [100, 150, 301])
    np.testing.assert_array_equal(
        out.stamps, accepted, err_msg="decimation 1: one row per accepted sample"
    )


def test_a_push_of_read_only_or_strided_arrays_gives_the_bits_of_its_own_copies() -> None:
    """A decoder may push views of its buffers, read-only or strided: the engine reads them
    as it reads arrays of its own (the compiled loop takes writable, contiguous ones only)."""
    full = ship_batch(0.6)
    reference, _ = push_all(engine_for(), [full])
    arrays = full.stamps.copy(), full.accel.copy(), full.gyro.copy()
    for a in arrays:
        a.flags.writeable = False
    read_only = SampleBatch(*arrays, full.frame_ids)
    strided = SampleBatch(
        np.repeat(full.stamps, 2)[::2],
        np.repeat(full.accel, 2, axis=0)[::2],
        np.repeat(full.gyro, 2, axis=0)[::2],
        full.frame_ids,
    )
    for pushed in (read_only, strided):
        out, _ = push_all(engine_for(), [pushed])
        np.testing.assert_array_equal(out.stamps, reference.stamps)
        np.testing.assert_array_equal(out.pose, reference.pose)
        np.testing.assert_array_equal(out.wrenches, reference.wrenches)


# --------------------------------------------------------------------------- decimation


@pytest.mark.parametrize("n", [2, 5, 8, 7])
def test_decimation_publishes_every_nth_sample_with_peak_hold_wrenches(n: int) -> None:
    full = ship_batch(0.5)
    every = engine_for().run(full)  # decimation 1: the independent reference
    engine = engine_for(scene_with(outputs={"decimation": n}))
    out, _ = push_all(engine, split(full, [7] * 100))  # windows straddle batch boundaries

    # the start sample, then every nth, then the last (its window partial where n does not
    # divide the record: its peaks are not lost at the stream's end)
    rows = np.unique([*range(0, len(full), n), len(full) - 1])
    np.testing.assert_array_equal(out.stamps, full.stamps[rows])
    np.testing.assert_allclose(out.pose, every.pose[rows], rtol=0, atol=POSE_TOL)
    np.testing.assert_allclose(out.wrenches[0], every.wrenches[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        np.abs(out.wrenches).max(axis=0), np.abs(every.wrenches).max(axis=0), rtol=1e-12
    )
    for k, (before, row) in enumerate(pairwise(rows), start=1):
        window = every.wrenches[before + 1 : row + 1]  # (≤ n, mounts, 6)
        pick = np.abs(window).argmax(axis=0)
        peak = np.take_along_axis(window, pick[None], axis=0)[0]
        np.testing.assert_allclose(
            out.wrenches[k],
            peak,
            rtol=1e-12,
            atol=1e-9,
            err_msg=f"row {k}: wrench must hold each component's largest magnitude (with sign)",
        )
    assert_finite(out)


def test_decimation_counts_again_from_a_restart() -> None:
    n = 4
    first = batch(stamps(10))
    after_gap = batch(stamps(10, t0=2.0))
    engine = engine_for(scene_with(outputs={"decimation": n}))
    out = engine.run(SampleBatch.concat([first, after_gap]))
    assert engine.counts["restarts"] == 1
    # each run's last sample too, its window partial: before the restart and at the end
    expected = np.concatenate([first.stamps[[0, 4, 8, 9]], after_gap.stamps[[0, 4, 8, 9]]])
    np.testing.assert_array_equal(out.stamps, expected)


def test_a_runs_last_sample_stays_answerable_however_many_rejected_samples_follow() -> None:
    """The stream keeps the stamps of `pending_ids` only: the run's last sample, which the
    flush publishes after 3000 rejected samples pushed one by one, and the gyro delay's."""
    n = 4
    good = ship_batch(0.2)
    engine = engine_for(scene_with(outputs={"decimation": n}))
    for piece in split(good, [1] * len(good)):
        engine.push(piece)
    bad = ship_batch(3.0, frame_id="another_imu")
    bad.stamps[:] += good.stamps[-1] + 1e-3
    for piece in split(bad, [1] * len(bad)):
        engine.push(piece)
        assert len(engine.pending_ids) <= engine.latency + 2
    out = engine.flush()
    last = len(good) - 1
    assert last % n, "the last good sample is not a decimation row"
    assert engine.pushed - len(good) == len(bad)
    np.testing.assert_array_equal(out.stamps[-1:], good.stamps[-1:])
    assert out.sample[-1] == last - engine.pushed, "counted back from the end of the stream"


# --------------------------------------------------------------------------- input hold


def test_zero_and_first_order_hold_both_run_and_differ_only_slightly() -> None:
    full = ship_batch(0.5)
    foh = engine_for(scene_with(input={"hold": "first_order"})).run(full)
    zoh = engine_for(scene_with(input={"hold": "zero_order"})).run(full)
    for out in (foh, zoh):
        assert_finite(out)
        np.testing.assert_array_equal(out.stamps, full.stamps)
    diff = np.abs(foh.pose[:, :3] - zoh.pose[:, :3]).max()
    assert 1e-9 < diff < 1e-3, (
        f"hold changes the CG path by {diff} m: expected a small, nonzero effect"
    )


def test_zero_and_first_order_hold_agree_for_a_constant_input() -> None:
    b = batch(stamps(200), accel=np.tile([0.3, -0.2, 9.9], (200, 1)))
    foh = engine_for(scene_with(input={"hold": "first_order"})).run(b)
    zoh = engine_for(scene_with(input={"hold": "zero_order"})).run(b)
    np.testing.assert_allclose(foh.pose, zoh.pose, rtol=0, atol=POSE_TOL)


# --------------------------------------------------------------------------- integration failures


def _failure_stamps(report: HealthReport) -> list[float]:
    return [
        float(t) for t in re.findall(r"(-?\d+\.\d{6}) s: ", status(report, "integration").message)
    ]


def test_shock_tipping_the_body_off_the_chart_is_an_error_and_the_twin_restarts() -> None:
    scene = scene_with(outputs={"diagnostics_period_s": 0.05})
    full = batch(stamps(500))
    full.accel[200, 1] += 1.0e5  # one absurd lateral sample: ~10 000 g
    engine = engine_for(scene)
    out, reports = push_all(engine, split(full, [100] * 5))

    assert engine.counts["integration_failures"] == 1
    assert engine.counts["restarts"] == 1
    assert_finite(out)
    missing = np.setdiff1d(full.stamps, out.stamps)
    assert missing.shape == (1,), f"exactly the failing sample has no output, missing: {missing}"
    fail_index = int(np.flatnonzero(full.stamps == missing[0])[0])
    assert 200 <= fail_index < 300

    flat = [r for rs in reports for r in rs]
    # the sample is integrated once the gyro delay has passed: the next report says so
    k = next(i for i, r in enumerate(flat) if r.stamp >= missing[0] + engine.latency / RATE)
    level_per_period = [status(r, "integration").level for r in flat]
    assert level_per_period == [OK] * k + [ERROR] + [OK] * (len(flat) - k - 1), level_per_period
    err = status(flat[k], "integration")
    assert "attitude left the α/γ/δ chart" in err.message
    assert _failure_stamps(flat[k]) == pytest.approx([missing[0]], abs=1e-6)
    assert err.values["failures_total"] == "1"
    # Restarted at the next sample, at equilibrium (rest input), and kept running.
    np.testing.assert_allclose(out.pose[fail_index], equilibrium_pose(), rtol=0, atol=POSE_TOL)
    assert out.stamps[fail_index] == full.stamps[fail_index + 1]
    later = engine.run(batch(stamps(50, t0=0.5)))
    assert len(later) == 50 and engine.running


def test_too_many_substeps_is_an_error_and_the_twin_keeps_running() -> None:
    rate = 100.0
    scene = scene_with(integration={"max_substeps": 1}, outputs={"diagnostics_period_s": 1.0})
    full = batch(stamps(600, rate=rate))
    full.accel[300:303, 2] += 300.0
    engine = engine_for(scene)
    out, reports = push_all(engine, split(full, [200, 200, 200]))
    assert engine.counts["integration_failures"] >= 1
    assert engine.counts["restarts"] == engine.counts["integration_failures"]
    flat = [r for rs in reports for r in rs]
    errors = [status(r, "integration") for r in flat if status(r, "integration").level == ERROR]
    assert errors, "no ERROR integration status after TOO_MANY_STEPS"
    assert "too many substeps in one input interval" in errors[0].message
    assert_finite(out)
    assert len(out) == 600 - engine.counts["integration_failures"]
    np.testing.assert_array_equal(out.stamps[-200:], full.stamps[-200:])  # running afterwards


def _push_must_not_raise(engine: TwinEngine, b: SampleBatch) -> OutputBatch:
    try:
        return engine.run(b)
    except Exception as err:
        pytest.fail(
            f"TwinEngine.push raised {type(err).__name__}: {err} (counts {dict(engine.counts)}); "
            "an integration failure must be counted, reported as ERROR and followed by a restart"
        )


def test_shock_still_on_at_the_restart_sample_is_reported_not_raised() -> None:
    """The stepper fails inside a long shock; the restart sample is still in the shock, where
    no static equilibrium exists. That must not kill the twin (in the node: the callback)."""
    full = batch(stamps(600))
    full.accel[300:350, 0] += 5.0e4  # 50 ms at ~5000 g along x
    engine = engine_for()
    out = _push_must_not_raise(engine, full)
    assert engine.counts["integration_failures"] >= 1
    assert_finite(out)


@pytest.mark.parametrize("cos_tilt", [0.0, 1e-10, 1e-7])
def test_state_at_the_edge_of_the_chart_is_off_chart_not_a_crash(cos_tilt: float) -> None:
    """Near θ = π/2 the reduced mass matrix Jᵀ I J is singular in floating point: the right-hand
    side must say OFF_CHART (the stepper then fails and the engine restarts), never divide by 0."""
    model = default_model()
    y = np.zeros(model.n_state)
    gamma = model.state_names.index("gamma")
    y[gamma] = math.acos(cos_tilt)
    dydt = np.zeros(model.n_state)
    status = rhs(0.0, y, model.arrays, model.new_scratch(), gravity_input(0.0, REST), dydt)
    assert status == OFF_CHART


# --------------------------------------------------------------------------- diagnostics cadence


def test_diagnostics_keep_coming_after_a_loop_back_of_the_stamps() -> None:
    """`ros2 bag play --loop`: stamps jump back, the twin resets, diagnostics must go on."""
    scene = scene_with(outputs={"diagnostics_period_s": 0.05})
    engine = engine_for(scene)
    per_push = []
    for _loop in range(2):
        for k in range(15):  # 1.5 s per loop, 0.1 s per push
            per_push.append(len(engine.push(batch(stamps(100, t0=k * 0.1))).health))
    assert engine.counts["reset_stamp_jumped_back"] == 1
    first, second = per_push[:15], per_push[15:]
    assert all(first), f"reports per push in the first pass: {first}"
    assert all(second), (
        f"no diagnostics after the loop-back reset: reports per push in the second pass {second} "
        "(HealthWindow._next_due stays at the pre-jump stamp)"
    )


@pytest.mark.parametrize("period", [0.05, 0.0137, 1.0])
def test_batched_diagnostics_cadence_equals_the_per_sample_one(period: float) -> None:
    """HealthWindow.ticks (the in-order fast path) reports after exactly the samples that
    HealthWindow.tick, applied sample by sample, would."""
    from mount_twin.engine.health import HealthWindow

    scene = scene_with(outputs={"diagnostics_period_s": period})
    stamps = np.cumsum(np.random.default_rng(8).uniform(1e-4, 3e-3, 3000))
    one = HealthWindow(scene, "dopri54")
    per_sample = [i for i, t in enumerate(stamps.tolist()) if one.tick(t)]
    batched = HealthWindow(scene, "dopri54")
    parts = np.split(np.arange(stamps.size), [1, 7, 500, 2999])
    got = [int(p[0]) + k for p in parts for k in batched.ticks(stamps[p])]
    assert got == per_sample and len(per_sample) > 1
