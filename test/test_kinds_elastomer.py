"""Rubber-metal mount: backbone, force table, snubber, Bouc–Wen hysteresis, passivity.

Truths written here, independently of the package:
- the polynomial backbone k₁x + k₃x³ + cẋ per axis, and a PCHIP table through scipy's own
  PchipInterpolator with linear extension at the end slopes;
- the snubber k_s⟨|x| − g⟩ᵖ·⟨1 + h·δ̇⟩ (Hunt–Crossley that never pulls);
- Bouc–Wen under monotone loading, dz/dx = A − (β + γ)zⁿ: z = z_max(1 − e^{−(β+γ)x}) for n = 1,
  z = z_max·tanh(√(A(β+γ))·x) for n = 2, z_max = (A/(β + γ))^(1/n);
- a single-DOF body on a hysteretic mount under a base motion pushed through TwinEngine, against
  solve_ivp of m z'' = −[a·F_el(z) + (1 − a)k₀w + c z'] − m(g + a(t)) with the Bouc–Wen w;
- dissipation over prescribed cycles: π·c·ω·X² for viscous damping, h∫k_s⟨|x| − g⟩ᵖẋ² dt for
  Hunt–Crossley; Bouc–Wen dissipates ẋz − d/dt(z²/2A) ≥ 0 (β ≥ |γ|);
- a free 6-DOF body on polynomial mounts: kinetic + elastic energy (+ the Bouc–Wen store) is
  conserved without damping and never rises with it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from kinds_helpers import drive, kind_mount, law_of, sine_path
from physics_helpers import (
    G,
    base_scene,
    build,
    chart_to_matrix_ref,
    inertia_tensor,
    integrate_twin,
    kinematic_matrix_ref,
    rpy,
)
from scipy.integrate import quad, solve_ivp
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine

K1 = [2.0e5, 3.0e5, 8.0e5]  # N/m
K3 = [4.0e9, 6.0e9, 2.0e10]  # N/m³
TABLE_X = [-0.012, -0.006, -0.002, 0.0, 0.002, 0.005, 0.009, 0.014]  # m, progressive rubber
TABLE_F = [-9000.0, -2500.0, -500.0, 0.0, 450.0, 1500.0, 4200.0, 12000.0]  # N
BOUC_WEN = {  # A, β, γ with z_max = 5 mm
    1: {"A": 1.0, "beta": 120.0, "gamma": 80.0, "n": 1.0},
    2: {"A": 1.0, "beta": 2.4e4, "gamma": 1.6e4, "n": 2.0},
}
Z_MAX = 5e-3


def rubber(**keys):
    """An elastomer law with the polynomial backbone unless keys say otherwise."""
    values = {"stiffness_linear": K1, "stiffness_cubic": K3, **keys}
    return law_of(kind_mount("elastomer", "r1", **values))


def backbone(x: np.ndarray, axis: int) -> np.ndarray:
    return K1[axis] * x + K3[axis] * x**3


def bouc_wen_rate(w: float, xd: float, bw: dict) -> float:
    """ż = A ẋ − β|ẋ||z|ⁿ⁻¹z − γẋ|z|ⁿ, as the literature writes it."""
    n = bw["n"]
    return (
        bw["A"] * xd
        - bw["beta"] * abs(xd) * abs(w) ** (n - 1) * w
        - bw["gamma"] * xd * abs(w) ** n
    )


# ---------------------------------------------------------------------------------- elasticity
def test_polynomial_backbone_viscous_damping_and_rotational_springs_per_axis():
    law = rubber(
        damping=[150.0, 250.0, 900.0],
        rotational_stiffness=[300.0, 400.0, 500.0],
        rotational_damping=[2.0, 3.0, 4.0],
    )
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(200):
        d, v = rng.uniform(-0.01, 0.01, 3), rng.uniform(-0.5, 0.5, 3)
        phi, w = rng.uniform(-0.05, 0.05, 3), rng.uniform(-1.0, 1.0, 3)
        f, c, _ = law.load(d, v, phi=phi, w=w)
        f_ref = -np.array([backbone(d[j], j) for j in range(3)]) - np.array([150, 250, 900]) * v
        c_ref = -(np.array([300.0, 400.0, 500.0]) * phi + np.array([2.0, 3.0, 4.0]) * w)
        worst = max(worst, np.max(np.abs(f - f_ref) / (np.abs(f_ref) + 1.0)))
        np.testing.assert_allclose(c, c_ref, rtol=1e-14, atol=1e-14)
    assert worst < 1e-13


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_force_table_is_the_pchip_interpolant_extended_linearly(axis):
    name = "xyz"[axis]
    k1 = [1e5, 1e5, 1e5]
    k1[axis] = 0.0
    law = rubber(
        stiffness_linear=k1,
        stiffness_cubic=[0.0, 0.0, 0.0],
        force_table={name: {"deflection": TABLE_X, "force": TABLE_F}},
    )
    pchip = PchipInterpolator(TABLE_X, TABLE_F)
    slope = pchip.derivative()
    x0, xn = TABLE_X[0], TABLE_X[-1]
    inside = np.concatenate([np.linspace(x0, xn, 2001), TABLE_X])
    below, above = np.linspace(x0 - 0.02, x0, 101), np.linspace(xn, xn + 0.02, 101)
    cases = [
        (inside, pchip(inside)),
        (below, pchip(x0) + slope(x0) * (below - x0)),
        (above, pchip(xn) + slope(xn) * (above - xn)),
    ]
    for xs, ref in cases:
        got = np.array([-law.load(np.eye(3)[axis] * x)[0][axis] for x in xs])
        assert np.max(np.abs(got - ref)) <= 1e-10 * max(TABLE_F)
    # the other axes keep their linear springs
    f = law.load([0.004, -0.003, 0.002])[0]
    others = [j for j in range(3) if j != axis]
    np.testing.assert_allclose(f[others], -1e5 * np.array([0.004, -0.003, 0.002])[others])


def test_hysteretic_share_of_a_table_axis_uses_the_pchip_slope_at_zero():
    law = rubber(
        stiffness_linear=[1e5, 1e5, 0.0],
        force_table={"z": {"deflection": TABLE_X, "force": TABLE_F}},
        hysteresis={"ratio": 0.6, "beta": 120.0, "gamma": 80.0, "axes": ["z"]},
    )
    z = 1e-3
    f = law.load([0.0, 0.0, 0.0], y=law.states(z))[0]
    k0 = float(PchipInterpolator(TABLE_X, TABLE_F).derivative()(0.0))
    assert f[2] == pytest.approx(-(1.0 - 0.6) * k0 * z, rel=1e-13)


# -------------------------------------------------------------------------------------- snubber
SNUB_GAP, SNUB_H = 3e-3, 2.0  # m, s/m


def snubbed(exponent: float, damping: float = SNUB_H, axes=("z",)):
    k_s = 5e3 / 1e-3**exponent  # 5 kN at 1 mm penetration
    law = rubber(
        snubber={
            "gap": SNUB_GAP,
            "stiffness": k_s,
            "exponent": exponent,
            "damping": damping,
            "axes": list(axes),
        }
    )
    return law, k_s


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("exponent", [1.0, 1.5, 2.5])
def test_snubber_engages_exactly_at_the_gap_with_power_law_contact(exponent, side):
    law, k_s = snubbed(exponent)
    xs = side * np.concatenate(
        [np.linspace(0.0, SNUB_GAP, 31), SNUB_GAP + np.geomspace(1e-9, 4e-3, 60)]
    )
    for x in xs:
        f = law.load([0.0, 0.0, x])[0][2]
        contact = k_s * max(abs(x) - SNUB_GAP, 0.0) ** exponent
        ref = -(backbone(x, 2) + math.copysign(contact, x))
        assert f == pytest.approx(ref, rel=1e-13, abs=1e-9)
        g = law.monitor([0.0, 0.0, x])[1][0]  # snubber_contact
        assert g == pytest.approx(abs(x) - SNUB_GAP, abs=1e-18)
    assert law.monitor([0.0, 0.0, side * SNUB_GAP])[1][0] == 0.0  # happening from the gap on
    at_gap = law.load([0.0, 0.0, side * SNUB_GAP])[0][2]
    assert at_gap == pytest.approx(-backbone(side * SNUB_GAP, 2), rel=1e-15)
    # an axis without a snubber never meets one
    far = 3.0 * SNUB_GAP
    assert law.load([far, 0.0, 0.0])[0][0] == pytest.approx(-backbone(far, 0), rel=1e-14)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_hunt_crossley_damping_never_pulls_when_the_snubber_separates_fast(side):
    law, k_s = snubbed(1.5)
    pen = 1e-3
    x = side * (SNUB_GAP + pen)
    for pen_rate in np.linspace(-5.0 / SNUB_H, 5.0 / SNUB_H, 101):
        v = side * pen_rate
        contact = -law.load([0.0, 0.0, x], [0.0, 0.0, v])[0][2] - backbone(x, 2)
        push = side * contact  # along the penetration: ≥ 0 means it pushes the body back out
        assert push >= 0.0
        ref = k_s * pen**1.5 * max(1.0 + SNUB_H * pen_rate, 0.0)
        assert push == pytest.approx(ref, rel=1e-11, abs=1e-9 * k_s * pen**1.5)


def test_over_travel_event_and_utilisation_follow_the_rated_deflection_per_axis():
    rated = [4e-3, 0.0, 6e-3]  # y not rated
    law = rubber(rated_deflection=rated)
    for d in np.array([[2e-3, 0.05, 0.0], [0.0, 0.0, -6e-3], [-5e-3, 0.0, 3e-3]]):
        util, g = law.monitor(d)
        expected = max(abs(d[0]) / rated[0], abs(d[2]) / rated[2])
        assert util == pytest.approx(expected, rel=1e-15)
        assert g[1] == pytest.approx(expected - 1.0, abs=1e-15)  # over_travel
        assert g[0] == -1.0  # no snubber, no contact
    assert law.monitor([0.0, 0.0, -6e-3])[1][1] == 0.0  # happening from the rated value on


# ------------------------------------------------------------------------------------- Bouc–Wen
def monotone_z(x: np.ndarray, n: int) -> np.ndarray:
    """z(x) from z(0) = 0 under monotone loading (closed forms of dz/dx = A − (β + γ)zⁿ)."""
    bw = BOUC_WEN[n]
    b = bw["beta"] + bw["gamma"]
    if n == 1:
        return bw["A"] / b * (1.0 - np.exp(-b * x))
    return math.sqrt(bw["A"] / b) * np.tanh(math.sqrt(bw["A"] * b) * x)


@pytest.mark.parametrize("direction", [1.0, -1.0])
@pytest.mark.parametrize("axis", [0, 2])
@pytest.mark.parametrize("n", [1, 2])
def test_bouc_wen_under_monotone_loading_saturates_at_z_max(n, axis, direction):
    """Hysteresis on x and z (two states, in axis order); loading along one axis moves only its
    own z, along the closed form, to z_max = (A/(β + γ))^(1/n)."""
    ratio = 0.6
    law = rubber(hysteresis={"ratio": ratio, **BOUC_WEN[n], "axes": ["x", "z"]})
    assert law.n_state == 2
    slot = [0, None, 1][axis]
    rate = np.eye(3)[axis] * direction

    def path(t):
        return rate * t, rate

    x = np.linspace(0.0, 0.05, 201)
    run = drive(law, path, (0.0, x[-1]), t_eval=x)
    z_ref = direction * monotone_z(x, n)
    assert np.max(np.abs(run.states[slot] - z_ref)) <= 1e-9 * Z_MAX
    assert np.all(run.states[1 - slot] == 0.0)
    assert abs(run.states[slot, -1]) == pytest.approx(Z_MAX, rel=1e-4)
    assert np.max(np.abs(run.states[slot])) <= Z_MAX * (1 + 1e-12)
    # force: elastic share of the backbone plus the hysteretic share of k₀ = k₁
    y = run.states[:, -1]
    f = law.load(rate * x[-1], y=y)[0][axis]
    ref = -(ratio * backbone(direction * x[-1], axis) + (1 - ratio) * K1[axis] * y[slot])
    assert f == pytest.approx(ref, rel=1e-13)


# ------------------------------------------------------------------ whole body: hysteresis loop
MASS, CG_Z, K1Z, K3Z, CZ, RATIO = 200.0, 0.3, 2.0e5, 5.0e8, 150.0, 0.7
BASE_AMP, BASE_HZ, RATE, DURATION = 4.0, 5.0, 400.0, 1.5  # m/s², Hz, samples/s, s


def virgin_w(z: float, n: int) -> float:
    """The Bouc–Wen state of a mount loaded slowly from unloaded to deflection z (m): the
    closed form of monotone loading, odd in z."""
    return math.copysign(float(monotone_z(np.array(abs(z)), n)), z)


def loop_reference(t: np.ndarray, a: np.ndarray, z0: float, w0: float, bw: dict) -> np.ndarray:
    """[z, z', w] at the stamps from rest at (z0, w0), solve_ivp per sample interval with the
    input linear in it."""

    def rhs(tt, s, t0, a0, slope):
        z, zd, w = s
        force = RATIO * (K1Z * z + K3Z * z**3) + (1.0 - RATIO) * K1Z * w + CZ * zd
        zdd = -force / MASS - (G + a0 + slope * (tt - t0))
        return [zd, zdd, bouc_wen_rate(w, zd, bw)]

    out = np.zeros((t.size, 3))
    out[0] = [z0, 0.0, w0]
    for j in range(1, t.size):
        slope = (a[j] - a[j - 1]) / (t[j] - t[j - 1])
        sol = solve_ivp(
            rhs,
            (t[j - 1], t[j]),
            out[j - 1],
            args=(t[j - 1], a[j - 1], slope),
            method="DOP853",
            rtol=1e-12,
            atol=1e-15,
        )
        out[j] = sol.y[:, -1]
    return out


@pytest.mark.parametrize("n", [1, 2])
def test_single_dof_hysteresis_loop_through_the_engine_matches_an_independent_integration(n):
    bw = BOUC_WEN[n]
    mount = kind_mount(
        "elastomer",
        "iso",
        stiffness_linear=[1e5, 1e5, K1Z],
        stiffness_cubic=[0.0, 0.0, K3Z],
        damping=[0.0, 0.0, CZ],
        hysteresis={"ratio": RATIO, **bw, "axes": ["z"]},
    )
    # the base moves from the first sample on: the start is that sample's, at rest under g (a
    # 50 ms start window would take the motion's first 0.08 g into the start gravity)
    initial = {"mode": "equilibrium", "gravity": "first_sample", "gravity_window_s": 0.0}
    scene = base_scene(MASS, [0.0, 0.0, CG_Z], [5.0, 6.0, 7.0, 0, 0, 0], [mount], ["z"])
    model = build({**scene, "initial_state": initial})
    assert model.state_names == ("z", "z_dot", "iso.z_z")
    t = np.arange(int(DURATION * RATE) + 1) / RATE
    a = BASE_AMP * np.sin(2 * math.pi * BASE_HZ * t)
    accel = np.zeros((t.size, 3))
    accel[:, 2] = G + a
    engine = TwinEngine(model)
    out = engine.run(SampleBatch(t, accel, np.zeros((t.size, 3)), ["imu"] * t.size))
    assert len(out) == t.size

    # the start: at rest under gravity, its w on the loading curve (set down slowly)
    z0 = brentq(
        lambda z: RATIO * (K1Z * z + K3Z * z**3) + (1.0 - RATIO) * K1Z * virgin_w(z, n) + MASS * G,
        -0.1,
        0.0,
        xtol=1e-16,
    )
    ref = loop_reference(t, a, z0, virgin_w(z0, n), bw)
    z_twin = out.pose[:, 2] - CG_Z
    swing = np.max(np.abs(ref[:, 0] - z0))
    assert swing > 2.0 * Z_MAX, "the base motion should drive the mount through full loops"
    assert np.max(np.abs(ref[:, 2])) > 0.9 * Z_MAX
    assert np.max(np.abs(z_twin - ref[:, 0])) <= 1e-7 * swing
    # the published mount force (on the body, mount axes) and the final hysteretic state
    z, zd, w = ref.T
    force_ref = -(RATIO * (K1Z * z + K3Z * z**3) + (1.0 - RATIO) * K1Z * w + CZ * zd)
    peak = np.max(np.abs(force_ref))
    assert np.max(np.abs(out.wrenches[:, 0, 2] - force_ref)) <= 1e-7 * peak
    assert engine.state[2] == pytest.approx(w[-1], abs=1e-7 * Z_MAX)
    # and the loop it traced encloses dissipated energy: ∮ (1 − a)k₀w dz > 0 over the last cycle
    last = t >= DURATION - 1.0 / BASE_HZ
    loop = np.trapezoid((1.0 - RATIO) * K1Z * w[last], z[last])
    assert loop > 0.0


# ------------------------------------------------------------------------------------- passivity
OMEGA = 2.0 * math.pi * 5.0
CYCLE = 2.0 * math.pi / OMEGA


def work_per_cycle(law, amplitude, cycles=3, y0=None):
    """Energy dissipated in each of `cycles` closed cycles of x = X sin ωt along z (virgin start),
    and the run itself on a fine grid."""
    t = np.linspace(0.0, cycles * CYCLE, cycles * 400 + 1)
    run = drive(law, sine_path([0.0, 0.0, amplitude], OMEGA), (0.0, t[-1]), y0=y0, t_eval=t)
    return np.diff(run.dissipated[::400]), run


def test_viscous_damping_dissipates_pi_c_omega_x_squared_per_cycle():
    c, amplitude = 900.0, 8e-3
    law = rubber(damping=[0.0, 0.0, c])
    cycles, _ = work_per_cycle(law, amplitude)
    np.testing.assert_allclose(cycles, math.pi * c * OMEGA * amplitude**2, rtol=1e-9)


def test_hunt_crossley_snubber_dissipates_h_times_contact_stiffness_times_rate_squared():
    law, k_s = snubbed(1.5, damping=SNUB_H)
    amplitude = SNUB_GAP + 2e-3
    assert SNUB_H * amplitude * OMEGA < 1.0, "then the contact never goes slack: no clipping"
    cycles, _ = work_per_cycle(law, amplitude)

    def power(t):
        x, xd = amplitude * math.sin(OMEGA * t), amplitude * OMEGA * math.cos(OMEGA * t)
        return k_s * max(abs(x) - SNUB_GAP, 0.0) ** 1.5 * SNUB_H * xd * xd

    t_in = math.asin(SNUB_GAP / amplitude) / OMEGA  # contact from t_in to half a cycle − t_in
    half = quad(power, t_in, CYCLE / 2 - t_in, epsabs=0.0, epsrel=1e-12)[0]
    np.testing.assert_allclose(cycles, 2.0 * half, rtol=1e-7)
    # with a damping that would pull, the clipped law dissipates less than the unclipped one,
    # but still a positive amount
    h_big = 50.0
    clipped, _ = work_per_cycle(snubbed(1.5, damping=h_big)[0], amplitude)
    assert np.all(clipped > 0.0)
    assert np.all(clipped < 0.9 * h_big / SNUB_H * 2.0 * half)


@pytest.mark.parametrize("amplitude", [2e-3, 1.2e-2])
@pytest.mark.parametrize("n", [1, 2])
def test_bouc_wen_never_creates_energy_over_closed_cycles(n, amplitude):
    """−∮ f·dx ≥ 0 for every closed cycle, and the dissipation ∫ẋ·F dt − E_z (E_z the Bouc–Wen
    store (1 − a)k₀z²/2A) never decreases (β ≥ |γ|), with viscous damping too."""
    bw = BOUC_WEN[n]
    ratio, c = 0.5, 40.0
    law = rubber(damping=[0.0, 0.0, c], hysteresis={"ratio": ratio, **bw, "axes": ["z"]})
    cycles, run = work_per_cycle(law, amplitude)
    assert np.all(cycles > 0.0)
    stored = (1 - ratio) * K1[2] * run.states[0] ** 2 / (2 * bw["A"])
    potential = ratio * (
        0.5 * K1[2] * (amplitude * np.sin(OMEGA * run.t)) ** 2
        + 0.25 * K3[2] * (amplitude * np.sin(OMEGA * run.t)) ** 4
    )
    lost = run.dissipated - stored - potential
    assert np.min(np.diff(lost)) >= -1e-9 * lost[-1]
    assert lost[-1] > 0.0


# ------------------------------------------------------------------- whole body: free decay energy
INERTIA6 = [30.0, 50.0, 60.0, 1.0, -2.0, 0.5]
CG = [0.1, -0.05, 0.4]
CORNERS = [(0.6, 0.4, 0.0), (0.6, -0.4, 0.0), (-0.6, 0.4, 0.0), (-0.6, -0.4, 0.0)]
ROLLS = [-0.4, 0.4, 0.0, 0.0]
K1_BODY, K3_BODY = [1e5, 1.2e5, 3e5], [1e9, 1e9, 5e9]
V0 = [0.15, -0.1, 0.3, 1.5, -1.2, 1.0]  # m/s, rad/s (chart rates)


def decay_mounts(damped: bool, hysteretic: bool) -> list[dict]:
    mounts = []
    for i, (pos, roll) in enumerate(zip(CORNERS, ROLLS, strict=True)):
        keys = {"stiffness_linear": K1_BODY, "stiffness_cubic": K3_BODY}
        if damped:
            keys["damping"] = [60.0, 60.0, 150.0]
        if hysteretic and i < 2:
            keys["hysteresis"] = {"ratio": 0.7, **BOUC_WEN[1], "axes": ["x", "y", "z"]}
        mounts.append(kind_mount("elastomer", f"e{i}", pos, (roll, 0.0, 0.0), **keys))
    return mounts


def mechanical_energy(y: np.ndarray, mounts: list[dict], mass: float) -> float:
    """½m|ṙ|² + ½ωᵀIω + Σ elastic potential (+ the Bouc–Wen stores, states after the rates)."""
    inertia = inertia_tensor(*INERTIA6)
    q, qd = y[:6], y[6:12]
    omega = kinematic_matrix_ref(q[3], q[4]) @ qd[3:]
    energy = 0.5 * mass * qd[:3] @ qd[:3] + 0.5 * omega @ inertia @ omega
    rot = chart_to_matrix_ref(*q[3:])
    z = iter(y[12:])
    for mt in mounts:
        p = np.array(mt["position"]) - np.array(CG)
        x = rpy(*mt["orientation_rpy"]).T @ (q[:3] + rot @ p - p)
        hyst = mt.get("hysteresis")
        a = hyst["ratio"] if hyst else 1.0
        energy += a * np.sum(0.5 * np.array(K1_BODY) * x**2 + 0.25 * np.array(K3_BODY) * x**4)
        if hyst:
            for k1 in K1_BODY:
                energy += (1.0 - a) * k1 * next(z) ** 2 / (2.0 * hyst["A"])
    return float(energy)


@pytest.mark.parametrize(
    ("damped", "hysteretic"), [(False, False), (True, False), (True, True)], ids=str
)
def test_free_decay_on_polynomial_mounts_never_gains_energy(damped, hysteretic):
    mounts = decay_mounts(damped, hysteretic)
    mass = 300.0
    model = build(
        base_scene(
            mass,
            CG,
            INERTIA6,
            mounts,
            initial={"mode": "given", "pose": [0.0] * 6, "velocity": V0},
        )
    )
    y0 = np.zeros(model.n_state)
    y0[6:12] = V0
    times = np.linspace(0.0, 1.5, 751)
    ys = integrate_twin(model, y0, times, np.zeros(13), rtol=1e-11, atol=1e-14)
    energy = np.array([mechanical_energy(y, mounts, mass) for y in ys])
    e0 = energy[0]
    # the motion is large enough for the cubic terms and the rotations to matter
    assert np.max(np.abs(ys[:, 3:6])) > 0.01
    assert np.max(np.diff(energy)) <= 1e-11 * e0
    if damped:
        assert energy[-1] < 0.1 * e0
    else:
        assert np.max(np.abs(energy - e0)) <= 2e-9 * e0
