"""The extreme-case matrix: each case run through the engine at the default tolerances, with
its verdict.

Verdicts, as each case allows:
- finite: nothing non-finite published, no exception, the twin still running at the end;
- energy: on linear mounts without rotational stiffness, a foundation that only translates,
  E = ½m|ṙ|² + ½ωᵀIω + Σ½dᵀK_t d (in F, gravity inside the specific force f) never exceeds its
  start plus the input work W = −m∫f·ṙ dt (equal to it without damping). E and W are computed
  here from the state, not from the twin's code, on the same held input refined 8× (so that
  the state is seen 16 times per period of a 5 kHz mode): W per interval by parts,
  [f·r] − ḟ·∫r dt, exact but for the trapezoid of ∫r dt where f ramps;
- honest: the twin's live error estimate of the mount forces within a factor 10 of the true
  error against a reference run (the same twin at rtol 1e-12 on the input refined 8×);
- the case's own: the stiff-light equilibrium, torque-free invariants, fracture kept, gaps.
The stiff-light equilibrium up to 1 kg on 1e11 N/m is test_equilibrium_stiff.py; the
estimate's own matrix is test_error_estimate.py.
"""

from __future__ import annotations

import dataclasses
import math
from functools import partial
from typing import Any

import numpy as np
import pytest
from io_helpers import batch, default_scene
from physics_helpers import (
    base_scene,
    chart_to_matrix_ref,
    free_body,
    inertia_tensor,
    kinematic_matrix_ref,
    mount,
    mount_frames,
)
from test_kinds_whole_body import FEET, escalation

from mount_twin.analysis.accuracy import measure, raw_gyro, reference_run, refined
from mount_twin.engine.batch import ERROR, OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import scene_from_dict

G = 9.80665
CORNERS = [(0.5, 0.4), (-0.5, 0.4), (-0.5, -0.4), (0.5, -0.4)]
INERTIA = [60.0, 80.0, 100.0, 0.0, 0.0, 0.0]


def _scene(data: dict[str, Any], rtol: float = 1e-6, atol: float = 1e-9) -> Scene:
    """A test scene at the bundled scenes' default tolerances, every sample published as it is
    pushed (no gyro delay, no start window held back)."""
    data["integration"].update(rtol=rtol, atol=atol)
    data["input"].update(frame_id="deck_imu", gyro_filter="none")
    data.setdefault("initial_state", {})["gravity_window_s"] = 0.0
    return scene_from_dict(data, "<extreme matrix>")


def _rubber_beside_keys(key_stiffness: float) -> dict[str, Any]:
    """500 kg on four 1e5 N/m rubber mounts beside two keys of `key_stiffness` N/m along x and
    y: stiffness ratio key/rubber 1e4 or 1e5."""
    rubber = [
        mount(f"r{i}", (x, y, -0.3), (1e5, 1e5, 1e5, 0, 0, 0), (800.0,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(CORNERS)
    ]
    keys = [
        mount("key_x", (0.0, 0.4, -0.3), (key_stiffness, 1.0, 1.0, 0, 0, 0), (2e4, 0, 0, 0, 0, 0)),
        mount("key_y", (0.5, 0.0, -0.3), (1.0, key_stiffness, 1.0, 0, 0, 0), (0, 2e4, 0, 0, 0, 0)),
    ]
    return base_scene(500.0, [0.0, 0.0, 0.0], INERTIA, rubber + keys)


def _light_on_stiff() -> dict[str, Any]:
    """10 kg on 4 × 1e9 N/m (modes 2–6 kHz)."""
    mounts = [
        mount(f"m{i}", (x, y, 0.0), (1e9,) * 3 + (0,) * 3, (2e3,) * 3 + (0,) * 3)
        for i, (x, y) in enumerate(CORNERS)
    ]
    return base_scene(10.0, [0.0, 0.0, 0.1], [0.5, 0.6, 0.8, 0, 0, 0], mounts)


def _rubber(damping: float) -> dict[str, Any]:
    """300 kg on four inclined 3e5/3e5/1e6 N/m mounts (modes 5–15 Hz)."""
    mounts = [
        mount(
            f"m{i}",
            (x, y, -0.25),
            (3e5, 3e5, 1e6, 0, 0, 0),
            (damping, damping, 3 * damping, 0, 0, 0),
            rpy_=(0.3 * math.copysign(1, y), 0.0, 0.0),
        )
        for i, (x, y) in enumerate(CORNERS)
    ]
    return base_scene(300.0, [0.02, -0.01, 0.05], [40.0, 60.0, 70.0, 2.0, -3.0, 1.0], mounts)


def _half_sine(rate_hz: float, peak_g: float, width_s: float, seconds: float) -> SampleBatch:
    """At rest, then a vertical half-sine of `peak_g` over width_s with a lateral third."""
    t = np.arange(int(seconds * rate_hz) + 1) / rate_hz
    pulse = np.where(
        (t > 0.005) & (t < 0.005 + width_s),
        peak_g * G * np.sin(math.pi * (t - 0.005) / width_s),
        0.0,
    )
    accel = np.column_stack([0.3 * pulse, -0.2 * pulse, G + pulse])
    return batch(1.0 + t, accel)


def _spike(rate_hz: float, peak_g: float, seconds: float) -> SampleBatch:
    """At rest but for one sample of `peak_g` vertical (a dropped bit, a hammer blow)."""
    t = np.arange(int(seconds * rate_hz) + 1) / rate_hz
    accel = np.tile([0.0, 0.0, G], (t.shape[0], 1))
    accel[int(0.01 * rate_hz), 2] += peak_g * G
    return batch(1.0 + t, accel)


# ---------------------------------------------------------------------------------- verdicts
def _push_sample_by_sample(scene: Scene, samples: SampleBatch) -> tuple[OutputBatch, np.ndarray]:
    """The engine's outputs, and its state after each sample (one push per sample)."""
    engine = TwinEngine(assemble(scene))
    outs, states = [], []
    for i in range(len(samples)):
        outs.append(engine.push(samples.part(slice(i, i + 1))))
        states.append(engine.state)
    assert engine.running and engine.counts["integration_failures"] == 0
    joined = OutputBatch(
        np.concatenate([o.stamps for o in outs]),
        np.concatenate([o.sample for o in outs]),
        np.concatenate([o.pose for o in outs]),
        np.concatenate([o.wrenches for o in outs]),
    )
    return joined, np.array(states)


def _assert_finite(out: OutputBatch) -> None:
    for field in ("position", "angles", "quaternion", "wrenches"):
        assert np.isfinite(getattr(out, field)).all(), field


def _energy_balance(data: dict[str, Any], samples: SampleBatch, states: np.ndarray):
    """(E − E0, W) per sample for a 6-DOF linear-mount scene without rotational stiffness."""
    mass = data["body"]["mass"]
    inertia = inertia_tensor(*data["body"]["inertia"])
    frames = mount_frames(data)
    q, qd = states[:, :6], states[:, 6:12]
    energy = np.empty(q.shape[0])
    for k in range(q.shape[0]):
        omega = kinematic_matrix_ref(q[k, 3], q[k, 4]) @ qd[k, 3:]
        rot = chart_to_matrix_ref(*q[k, 3:])
        elastic = 0.0
        for fr in frames:
            d = q[k, :3] + rot @ fr["p"] - fr["p"]
            elastic += 0.5 * d @ fr["kt"] @ d
        energy[k] = 0.5 * mass * qd[k, :3] @ qd[k, :3] + 0.5 * omega @ inertia @ omega + elastic
    f, r, h = samples.accel, q[:, :3], np.diff(samples.stamps)
    f_dot = np.diff(f, axis=0) / h[:, None]
    by_parts = (
        np.einsum("ij,ij->i", f[1:], r[1:])
        - np.einsum("ij,ij->i", f[:-1], r[:-1])
        - np.einsum("ij,ij->i", f_dot, 0.5 * (r[1:] + r[:-1])) * h
    )
    work = np.concatenate([[0.0], np.cumsum(-mass * by_parts)])
    return energy - energy[0], work


def _assert_energy(data, samples, states, undamped: bool) -> None:
    gained, work = _energy_balance(data, samples, states)
    scale = max(np.abs(work).max(), np.abs(gained).max())
    assert scale > 0.0
    excess = gained - work  # −(energy dissipated): ≤ 0, and 0 without damping
    assert excess.max() <= 2e-3 * scale, (excess.max(), scale)
    if undamped:
        assert np.abs(excess).max() <= 2e-3 * scale, (np.abs(excess).max(), scale)
    else:
        assert excess.min() < -1e-2 * scale, "the dampers dissipate"


def _assert_honest(scene: Scene, samples: SampleBatch, figure: str = "force_error") -> None:
    """The estimate of `figure` (force_error, or attitude_error_rad) within 10× of the truth."""
    scene = raw_gyro(scene)  # the integration's error alone
    ref = reference_run(scene, samples, 1_000_000)
    acc = measure(scene, samples, scene.integration.rtol, scene.integration.max_substeps, ref)
    assert acc.failures == 0
    # rounding: an error below it has no ratio to speak of (the sampled estimator's floor is
    # the checks' rounding, 1e-16 of the state, times the sixteen intervals one stands for,
    # carried over thousands of intervals: 5e-12 of the force where the truth is 1e-13)
    floor = 1e-11
    true, est = getattr(acc, figure), getattr(acc, f"est_{figure}")
    assert 0.1 < max(est, floor) / max(true, floor) < 10.0, (figure, true, est)


def _shock_500g(rate_hz: float, seconds: float) -> SampleBatch:
    """500 g over 0.5 ms: a severe underwater-shock deck pulse."""
    return _half_sine(rate_hz, 500.0, 5e-4, seconds)


RUBBER = partial(_rubber, 2000.0)
SHORT_500G = partial(_shock_500g, 1e4, 0.05)
LINEAR_CASES = {  # name: (scene mapping, input record, undamped)
    "stiffness_ratio_1e4": (partial(_rubber_beside_keys, 1e9), SHORT_500G, False),
    "stiffness_ratio_1e5": (partial(_rubber_beside_keys, 1e10), SHORT_500G, False),
    "10kg_on_4x1e9_100g": (_light_on_stiff, partial(_half_sine, 1e4, 100.0, 5e-4, 0.02), False),
    "500g_0.5ms_at_10kHz": (RUBBER, partial(_shock_500g, 1e4, 0.1), False),
    "500g_0.5ms_at_50kHz": (RUBBER, partial(_shock_500g, 5e4, 0.04), False),
    "1000g_single_sample_spike": (RUBBER, partial(_spike, 1e4, 1000.0, 0.1), False),
    "zero_damping_500g": (partial(_rubber, 0.0), partial(_shock_500g, 1e4, 0.1), True),
}


@pytest.mark.parametrize("case", list(LINEAR_CASES))
def test_linear_extremes_stay_finite_conserve_energy_and_estimate_honestly(case: str) -> None:
    build, record, undamped = LINEAR_CASES[case]
    data, samples = build(), record()
    scene = _scene(data)
    engine = TwinEngine(assemble(scene))
    out = engine.push(samples)
    _assert_finite(out)
    assert len(out) == len(samples) and engine.counts["integration_failures"] == 0
    fine = refined(scene, samples)
    _, states = _push_sample_by_sample(scene, fine)
    _assert_energy(data, fine, states, undamped)
    _assert_honest(scene, samples)


# ----------------------------------------------------------------------- tilt and the chart
OMEGA0 = np.array([4.0, 0.3, 0.5])  # rad/s in B, near the axis of least inertia: it tips over
TUMBLER_INERTIA = [2.0, 3.0, 4.0, 0.0, 0.0, 0.0]


def _tumbler() -> tuple[Scene, SampleBatch]:
    scene = _scene(free_body(TUMBLER_INERTIA, OMEGA0))
    t = 1.0 + np.arange(1201) * 1e-3
    return scene, batch(t, np.zeros((t.shape[0], 3)))  # free fall: torque-free


def _tilt(out: OutputBatch) -> np.ndarray:
    q = out.quaternion
    return np.degrees(np.arccos(np.clip(1 - 2 * (q[:, 0] ** 2 + q[:, 1] ** 2), -1, 1)))


@pytest.mark.parametrize("tilt_deg", [60.0, 80.0])
def test_a_tumble_to_high_tilt_keeps_energy_and_momentum_and_estimates_honestly(
    tilt_deg: float,
) -> None:
    """Torque-free: ½ωᵀIω and the angular momentum R·I·ω (in F, inertial here) stay put up to
    `tilt_deg` of tilt, where the α/γ/δ chart is far from its comfort."""
    scene, samples = _tumbler()
    full, states = _push_sample_by_sample(scene, samples.part(slice(0, 375)))  # to 86°
    tilt = _tilt(full)
    assert tilt.max() > tilt_deg, "the tumble reaches the tilt under test"
    upto = int(np.argmax(tilt > tilt_deg)) + 1
    inertia = inertia_tensor(*TUMBLER_INERTIA)
    q, qd = states[:upto, 3:6], states[:upto, 9:12]
    omega = np.array([kinematic_matrix_ref(a, g) @ r for (a, g, _), r in zip(q, qd, strict=True)])
    rot = np.array([chart_to_matrix_ref(*row) for row in q])
    energy = 0.5 * np.einsum("ij,jk,ik->i", omega, inertia, omega)
    momentum = np.einsum("nij,jk,nk->ni", rot, inertia, omega)
    assert np.abs(energy / energy[0] - 1).max() < 1e-9
    assert np.abs(momentum - momentum[0]).max() < 1e-9 * np.linalg.norm(momentum[0])
    _assert_finite(full)
    _assert_honest(scene, samples.part(slice(0, upto)), "attitude_error_rad")


def test_past_90_degrees_the_twin_stops_following_and_says_so() -> None:
    """A given motion past the chart's limit: no fiction (test_engine_no_fiction.py has more)."""
    scene, samples = _tumbler()
    engine = TwinEngine(assemble(scene))
    out = engine.run(samples)
    _assert_finite(out)
    assert _tilt(out).max() > 85.0
    assert engine.counts["samples_not_followed"] > 0 and not engine.running
    last = out.health[-1]
    (status,) = [s for s in last.statuses if s.name == "mount_twin: integration"]
    assert status.level == ERROR and "not following since" in status.message


# ----------------------------------------------------------------------- fracture and gaps
def test_bolts_fracturing_mid_run_keep_the_twin_finite_and_broken() -> None:
    """The bundled genset under three rising double half-sines (test_kinds_whole_body.py: the
    third breaks all six bolts): finite to the end, running, the breaks kept in the state, and
    an estimate on the record (no reference converges affordably across fracture to judge it:
    the genset's figures are in docs/benchmarks.md)."""
    run = escalation()
    assert np.isfinite(run.pose).all() and np.isfinite(run.wrenches).all()
    broken = {e.mount for e in run.engine.events if e.event == "bolt_fractured"}
    assert broken == set(FEET)
    assert run.engine.running and run.later_rows > 0
    state = dict(zip(run.engine.model.state_names, run.engine.state, strict=True))
    assert all(state[f"{m}.fractured"] == 1.0 for m in broken)
    estimate = run.engine.error_estimate
    assert estimate is not None and math.isfinite(estimate.force_error_rel)


@pytest.mark.parametrize("policy", ["bridge", "reset"])
def test_a_one_second_gap_is_bridged_or_reset(policy: str) -> None:
    scene = default_scene()
    scene = dataclasses.replace(
        scene, input=dataclasses.replace(scene.input, max_gap_s=0.5, gap_policy=policy)
    )
    stamps = np.concatenate([1.0 + np.arange(500) * 1e-3, 2.5 + np.arange(500) * 1e-3])
    samples = batch(stamps, frame_ids=scene.input.frame_id)
    engine = TwinEngine(assemble(scene))
    out = engine.run(samples)
    _assert_finite(out)
    assert len(out) == len(samples)
    assert engine.counts["gaps"] == 1
    assert engine.counts["restarts"] == (1 if policy == "reset" else 0)
    # at rest across the gap either way: the pose after it is the pose before it
    np.testing.assert_allclose(out.position[-1], out.position[499], atol=1e-9)
