"""Bolted joint (VDI 2230 joint diagram) driven quasi-statically and along prescribed cycles.

An M20 property class 8.8 bolt (A_s = 245 mm², R_p0.2 = 640 MPa, R_m = 800 MPa) clamps a foot
with preload F_V = 100 kN. Truths, written here from the joint diagram and textbook plasticity:
- before opening the bolt takes Φ = k_S/(k_S + k_P) of the external load F_A, after opening all
  of it; the joint opens at F_A = F_V/(1 − Φ), i.e. u = F_V/k_P;
- the bilinear bolt with linear hardening α: e_p = (1 − α)·⟨max past u − u_y⟩ and
  F_S = ⟨F_V + k_S(u − e_p)⟩, so the post-yield slope is α·k_S, reloading is elastic up to the
  previous maximum, and after unloading the preload drops by k_S·e_p;
- fracture once F_S reaches F_u (u_f = u_y + (F_u − F_y)/(α k_S)) or e_p the ultimate plastic
  elongation, for good;
- the shear face is a Jenkins element (stick spring k_τ, Coulomb slider μ·F_K): its slip is the
  stop (play) operator of the deflection with half-width μF_K/k_τ, its loop area
  4μF_K(D − μF_K/k_τ), and a circular slide of radius R dissipates μF_K·2π√(R² − (μF_K/k_τ)²)
  per turn once steady; past the hole clearance the shank bears with k_b, elastically.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from kinds_helpers import Law, along, drive, kind_mount, law_of, leg, nodes, quasi_static
from scipy.integrate import quad

from mount_twin.kinds import BOLTED_JOINT, N_PAR, kind_carry
from mount_twin.kinds.bolted_joint import SLIP_FLOOR

A_S, R_P02, R_M = 245e-6, 640e6, 800e6  # m², Pa, Pa: M20 8.8
F_Y, F_U = A_S * R_P02, A_S * R_M  # 156.8 kN, 196 kN
K_S, K_P, F_V = 7e8, 3.5e9, 1e5  # N/m, N/m, N
MU, K_T, CLEAR, K_B = 0.15, 1e9, 1e-3, 5e8
PHI = K_S / (K_S + K_P)
U_OPEN = F_V / K_P  # axial deflection at which the clamp force vanishes
U_Y = (F_Y - F_V) / K_S  # first yield (after opening: F_S = F_V + k_S·u)
D_STICK = MU * F_V / K_T  # stick deflection of the closed, unloaded joint face
EVENT = {"bolt_yielded": 0, "joint_opened": 1, "joint_slipped": 2, "bolt_fractured": 3}
E_P, SLIP_X, SLIP_Y, BROKEN = range(4)


def joint(**keys: float) -> Law:
    """The M20 joint's law (keys override the defaults above)."""
    values = {
        "bolt_stiffness": K_S,
        "clamp_stiffness": K_P,
        "preload": F_V,
        "yield_force": F_Y,
        "ultimate_force": F_U,
        "hardening": 0.02,
        "friction": MU,
        "shear_stiffness": K_T,
        "hole_clearance": CLEAR,
        "bearing_stiffness": K_B,
        "ultimate_plastic_elongation": 5e-3,
        **keys,
    }
    return law_of(kind_mount("bolted_joint", "b1", **values))


def bolt_force(law: Law, u: float, e_p: float = 0.0, broken: float = 0.0) -> float:
    return float(law.module.bolt_force(law.p, u, e_p, broken))


def clamp_force(u: np.ndarray) -> np.ndarray:
    """F_K = ⟨F_V − k_P·u⟩."""
    return np.maximum(F_V - K_P * np.asarray(u), 0.0)


def plastic_truth(u: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """(e_p, F_S) along an axial path from the virgin state: linear hardening on tension."""
    e_p = (1.0 - alpha) * np.maximum(np.maximum.accumulate(u) - U_Y, 0.0)
    return e_p, np.maximum(F_V + K_S * (u - e_p), 0.0)


def stop_operator(x: np.ndarray, half_width: float) -> np.ndarray:
    """Slip s of a Jenkins element along a path sampled at its turning points (and anywhere
    else): s stays put while |x − s| ≤ half_width and is dragged along at that distance."""
    s = np.zeros_like(x)
    for k in range(1, x.shape[0]):
        s[k] = min(max(s[k - 1], x[k] - half_width), x[k] + half_width)
    return s


# --------------------------------------------------------------------------- axial: joint diagram
def test_the_bolt_takes_phi_of_the_external_load_until_the_joint_opens_then_all_of_it():
    law = joint()
    u = np.concatenate([np.linspace(-0.6 * U_OPEN, 0.98 * U_Y, 401), [U_OPEN]])
    f_a = np.array([-law.load([0.0, 0.0, x])[0][2] for x in u])  # external load = −body force
    f_s = np.array([bolt_force(law, x) for x in u])
    f_open = F_V / (1.0 - PHI)
    expected = np.where(f_a <= f_open, F_V + PHI * f_a, f_a)
    assert np.max(np.abs(f_s - expected)) <= 1e-9 * F_V
    assert f_a.min() < 0.0 < f_open < f_a.max(), "the path must compress, close and open"
    # the opening load and its deflection
    assert f_a[-1] == pytest.approx(f_open, rel=1e-12)
    assert f_s[-1] - f_a[-1] == pytest.approx(0.0, abs=1e-9 * F_V)  # clamp force gone


def test_the_joint_opened_event_crosses_zero_exactly_at_preload_over_clamp_stiffness():
    law = joint()
    below = law.monitor([0.0, 0.0, U_OPEN * (1 - 1e-9)])[1][EVENT["joint_opened"]]
    at = law.monitor([0.0, 0.0, U_OPEN])[1][EVENT["joint_opened"]]
    above = law.monitor([0.0, 0.0, U_OPEN * (1 + 1e-9)])[1][EVENT["joint_opened"]]
    assert below < 0.0 <= above
    assert abs(at) <= 1e-9 * F_V
    # and it is the clamp that lets go there: the body force is the bolt's alone beyond it
    u = np.linspace(U_OPEN, 0.99 * U_Y, 50)
    f_body = np.array([law.load([0.0, 0.0, x])[0][2] for x in u])
    np.testing.assert_allclose(-f_body, F_V + K_S * u, rtol=1e-13)


# --------------------------------------------------------------------- axial: plasticity, fracture
@pytest.mark.parametrize("alpha", [0.0, 0.02, 0.2])
def test_yield_hardening_and_permanent_set_follow_the_bilinear_bolt(alpha):
    law = joint(hardening=alpha)
    u_max, u_max2 = U_Y + 1.0e-4, U_Y + 1.5e-4
    up = leg(0.0, u_max, 200, U_OPEN, U_Y)
    u = nodes(up, leg(u_max, 0.0, 150), leg(0.0, u_max2, 300, u_max))
    forces, states = quasi_static(law, along(2, u))
    e_p_ref, f_s_ref = plastic_truth(u, alpha)
    f_s = np.array([bolt_force(law, x, e) for x, e in zip(u, states[:, E_P], strict=True)])
    assert np.max(np.abs(states[:, E_P] - e_p_ref)) <= 1e-9 * e_p_ref.max()
    assert np.max(np.abs(f_s - f_s_ref)) <= 1e-9 * F_Y
    assert np.max(np.abs(forces[:, 2] - (clamp_force(u) - f_s_ref))) <= 1e-9 * F_Y
    # named consequences of the closed form
    post = np.flatnonzero(up >= U_Y)
    slope = np.diff(f_s[post]) / np.diff(u[post])
    np.testing.assert_allclose(slope, alpha * K_S, rtol=1e-5, atol=1e-6 * K_S)
    at_zero = np.flatnonzero(u == 0.0)[1]  # after the first unloading
    e_p = (1.0 - alpha) * (u_max - U_Y)
    assert states[at_zero, E_P] == pytest.approx(e_p, rel=1e-9)
    assert F_V - f_s[at_zero] == pytest.approx(K_S * e_p, rel=1e-9)
    # the yield event and the utilisation F_S/F_y at first yield
    util, g = law.monitor([0.0, 0.0, U_Y])
    assert util == pytest.approx(1.0, rel=1e-12)
    assert abs(g[EVENT["bolt_yielded"]]) <= 1e-9 * F_Y
    assert law.monitor([0.0, 0.0, 0.999 * U_Y])[1][EVENT["bolt_yielded"]] < 0.0


@pytest.mark.parametrize("limit", ["ultimate_force", "ultimate_plastic_elongation"])
def test_the_bolt_breaks_for_good_at_its_ultimate_limit_and_only_the_clamp_remains(limit):
    alpha = 0.02
    if limit == "ultimate_force":
        law = joint(hardening=alpha, ultimate_plastic_elongation=1e-2)
        u_f = U_Y + (F_U - F_Y) / (alpha * K_S)
    else:
        law = joint(hardening=alpha, ultimate_plastic_elongation=1e-3)
        u_f = U_Y + 1e-3 / (1.0 - alpha)
    delta = 1e-9
    u_end = u_f + 2e-4
    u = nodes(
        leg(0.0, u_end, 300, U_OPEN, U_Y, u_f - delta, u_f + delta),
        leg(u_end, -U_OPEN, 200, U_OPEN, 0.0),
        leg(-U_OPEN, u_end, 100),
    )
    forces, states = quasi_static(law, along(2, u))
    broken_at = int(np.argmax(states[:, BROKEN] > 0.5))
    assert u[broken_at] == pytest.approx(u_f + delta, abs=1e-15), "broke at the wrong place"
    assert u[broken_at - 1] == pytest.approx(u_f - delta, abs=1e-15)
    assert np.all(states[broken_at:, BROKEN] == 1.0), "a broken bolt must stay broken"
    # before: the hardening bolt; after: no bolt, the clamped parts push the foot up alone
    _, f_s_ref = plastic_truth(u[:broken_at], alpha)
    intact = clamp_force(u[:broken_at]) - f_s_ref
    assert np.max(np.abs(forces[:broken_at, 2] - intact)) <= 1e-9 * F_U
    np.testing.assert_array_equal(forces[broken_at:, 2], clamp_force(u[broken_at:]))
    assert bolt_force(law, u_end, states[-1, E_P], states[-1, BROKEN]) == 0.0
    # the fracture event function, just before and after; the utilisation drops to zero
    y = states[broken_at - 1].copy()
    g_before = law.monitor([0.0, 0.0, u[broken_at - 1]], y=y)[1][EVENT["bolt_fractured"]]
    util, g_after = law.monitor([0.0, 0.0, u[-1]], y=states[-1])
    assert g_before < 0.0 <= g_after[EVENT["bolt_fractured"]]
    assert util == 0.0
    if limit == "ultimate_force":
        assert F_Y + alpha * K_S * (u_f - U_Y) == pytest.approx(F_U, rel=1e-12)
    else:
        assert states[broken_at, E_P] >= 1e-3 > states[broken_at - 1, E_P]
    # a broken bolt no longer bears in its hole: past the clearance only friction is left
    f_shear = law.load([3 * CLEAR, 0.0, 0.0], y=np.array([0.0, 3 * CLEAR - D_STICK, 0.0, 1.0]))[0]
    assert f_shear[0] == pytest.approx(-MU * F_V, rel=1e-12)


# ------------------------------------------------------------------------ shear: friction, bearing
@pytest.mark.parametrize("axis", [0, 1])
@pytest.mark.parametrize("u_axial", [-0.5 * U_OPEN, 0.0, 0.5 * U_OPEN, 1.5 * U_OPEN])
def test_the_joint_face_sticks_then_slides_at_mu_times_the_clamp_force(axis, u_axial):
    law = joint()
    f_k = float(clamp_force(u_axial))
    half = MU * f_k / K_T
    big = 0.4 * CLEAR
    x = nodes(
        leg(0.0, big, 100, half),
        leg(big, -big, 200, big - 2 * half),
        leg(-big, 0.5 * big, 150, -big + 2 * half),
    )
    path = along(axis, x)
    path[:, 2] = u_axial
    forces, states = quasi_static(law, path)
    slip = stop_operator(x, half)
    np.testing.assert_allclose(states[:, SLIP_X + axis], slip, rtol=0, atol=1e-12 * big)
    ref = -K_T * (x - slip)
    assert np.max(np.abs(forces[:, axis] - ref)) <= 1e-9 * MU * F_V
    assert np.all(forces[:, 1 - axis] == 0.0)
    if f_k > 0.0:
        assert np.max(np.abs(forces[:, axis])) == pytest.approx(MU * f_k, rel=1e-12)
    # the axial force does not feel the shear; nothing yields
    np.testing.assert_allclose(forces[:, 2], clamp_force(u_axial) - (F_V + K_S * u_axial))
    assert np.all(states[:, E_P] == 0.0)
    # the slip event: stuck before the stick deflection, on the bound while sliding
    g = np.array(
        [law.monitor(d, y=y)[1][EVENT["joint_slipped"]] for d, y in zip(path, states, strict=True)]
    )
    stuck = np.abs(x - slip) < half * (1 - 1e-9)
    assert np.all(g[stuck] < 0.0)
    if f_k > 0.0:
        # on the bound: the slip function's floor below 0 (SLIP_FLOOR: rounding is no slip)
        assert np.max(np.abs(g[~stuck] + K_T * SLIP_FLOOR)) <= 1e-9 * MU * F_V
        return
    # open: the face carries no shear once it has slid; the engine judges the trial state
    # (slip frozen at the previous sample), on which every move slides
    trial = np.array(
        [
            law.monitor(d, y=y, y0=y0)[1][EVENT["joint_slipped"]]
            for d, y, y0 in zip(path[1:], states[1:], states[:-1], strict=True)
        ]
    )
    assert np.all(trial[np.diff(x) != 0.0] > 0.0)


def test_an_open_face_with_no_shear_on_it_does_not_slip() -> None:
    """Opened, the face's friction bound is 0: with no shear on it the slip function was
    0 − 0 = 0, and every joint_opened came with a joint_slipped (a WARN, stamped at the
    sample, not at a crossing). Any shear on an open face past SLIP_FLOOR slips."""
    law = joint()
    for u in (U_OPEN, 2.0 * U_OPEN):
        g = law.monitor([0.0, 0.0, u], y=law.states())[1]
        assert g[EVENT["joint_opened"]] >= 0.0 and g[EVENT["joint_slipped"]] < 0.0
        g = law.monitor([1e-9, 0.0, u], y=law.states())[1]
        assert g[EVENT["joint_slipped"]] == pytest.approx(K_T * (1e-9 - SLIP_FLOOR), rel=1e-9)
        g = law.monitor([1e-13, 0.0, u], y=law.states())[1]
        assert g[EVENT["joint_slipped"]] < 0.0, "rounding's shear on an open face is no slip"
    closed = law.monitor([0.0, 0.0, 0.5 * U_OPEN], y=law.states())[1]
    assert closed[EVENT["joint_slipped"]] == pytest.approx(
        -MU * 0.5 * F_V - K_T * SLIP_FLOOR, rel=1e-12
    )


def test_a_frictionless_face_never_slips() -> None:
    """With friction 0 the face has no grip to lose: it slides with the foot by design, closed
    or open, so its slip function stays below 0 however far the foot moved in a sample (it read
    the foot's travel, k_τ·|Δd| past the floor: every start of motion WARNed, and the event
    held throughout); with friction, the same move on the open face slips."""
    frictionless, rough = joint(friction=0.0), joint()
    for u in (0.0, 0.5 * U_OPEN, 2.0 * U_OPEN):
        for move in (1e-13, 1e-9, 1e-6, 2.0 * CLEAR):
            y0 = frictionless.states()
            g = frictionless.monitor([move, -move, u], y=y0, y0=y0)[1]
            assert g[EVENT["joint_slipped"]] < 0.0, (u, move)
    g = rough.monitor([1e-6, 0.0, 2.0 * U_OPEN], y=rough.states())[1]
    assert g[EVENT["joint_slipped"]] > 0.0


def play_operator(x: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """Slip of a Jenkins element whose half-width changes along the path (the clamp force
    moves the friction bound): s_k = clip(s_{k−1}, x_k − h_k, x_k + h_k)."""
    s = np.zeros_like(x)
    for k in range(1, x.shape[0]):
        s[k] = min(max(s[k - 1], x[k] - half_width[k]), x[k] + half_width[k])
    return s


def test_sliding_follows_the_friction_bound_as_the_clamp_force_moves():
    """Slide out while the clamp force falls to 30 %, reverse, slide again while it rises
    back: the slip is the play operator of half-width μF_K(u)/k_τ, the face force −k_τ(x − s)
    never exceeds μF_K. The bound's rate is in the law: with |e| frozen while sliding (its
    old form) the spring stayed loaded at the first bound, the reversal slid on for 0.7 of a
    stick deflection instead of sticking at once, and a rising bound chattered."""
    law = joint()
    n = 400
    x = nodes(
        leg(0.0, 3 * D_STICK, n),
        leg(3 * D_STICK, 6 * D_STICK, n),
        leg(6 * D_STICK, 4 * D_STICK, n),
        leg(4 * D_STICK, 8 * D_STICK, n),
    )
    falls = np.linspace(0.0, 0.7 * U_OPEN, n + 1)[1:]
    u = np.concatenate([np.zeros(n + 1), falls, np.full(n, 0.7 * U_OPEN), falls[::-1]])
    path = along(0, x)
    path[:, 2] = u
    forces, states = quasi_static(law, path)
    half = MU * clamp_force(u) / K_T
    slip = play_operator(x, half)
    step = 3 * D_STICK / n  # a switch inside a segment costs at most its length
    np.testing.assert_allclose(states[:, SLIP_X], slip, rtol=0, atol=2 * step)
    np.testing.assert_allclose(forces[:, 0], -K_T * (x - slip), rtol=0, atol=2 * K_T * step)
    assert np.all(np.abs(forces[:, 0]) <= MU * clamp_force(u) * (1 + 1e-12))
    reversal = 3 * n + 1  # the first node of the way back: stuck, the force off the bound
    assert abs(forces[reversal, 0]) < MU * clamp_force(u[reversal]) - 0.5 * K_T * step


@pytest.mark.parametrize("angle", [0.0, math.pi / 4, 2.0 * math.pi / 3])
def test_past_the_hole_clearance_the_shank_bears_radially(angle):
    law = joint()
    direction = np.array([math.cos(angle), math.sin(angle), 0.0])
    r = leg(0.0, 2.5 * CLEAR, 250, D_STICK, CLEAR)
    forces, _ = quasi_static(law, r[:, None] * direction)
    magnitude = np.minimum(K_T * r, MU * F_V) + K_B * np.maximum(r - CLEAR, 0.0)
    ref = -magnitude[:, None] * direction
    assert np.max(np.abs(forces - ref)) <= 1e-9 * magnitude.max()


# ------------------------------------------------------------------------------------- passivity
def test_an_axial_cycle_through_yield_dissipates_the_elasto_plastic_loop_area():
    """u = u_max·sin²t, one closed cycle, e_p integrated by solve_ivp with the law's rate; truth:
    ∫₀^u_max (F_S loading − F_S unloading) du (the clamp force is elastic and cancels)."""
    alpha = 0.02
    law = joint(hardening=alpha)
    u_max = U_Y + 2e-4
    e_p = (1.0 - alpha) * (u_max - U_Y)
    slack = e_p - F_V / K_S  # the unloading bolt goes slack below this deflection
    assert 0.0 < slack < u_max

    def path(t):
        return np.array([0.0, 0.0, u_max * math.sin(t) ** 2]), np.array(
            [0.0, 0.0, u_max * math.sin(2.0 * t)]
        )

    run = drive(law, path, (0.0, math.pi), t_eval=np.array([0.0, math.pi / 2, math.pi]))

    def loading(u):
        return F_V + K_S * u if u <= U_Y else F_Y + alpha * K_S * (u - U_Y)

    def unloading(u):
        return max(F_V + K_S * (u - e_p), 0.0)

    area = quad(lambda u: loading(u) - unloading(u), 0.0, u_max, points=[U_Y, slack])[0]
    assert run.states[E_P, -1] == pytest.approx(e_p, rel=1e-7)
    assert run.dissipated[-1] > 0.0
    assert run.dissipated[-1] == pytest.approx(area, rel=1e-7)


@pytest.mark.parametrize("amplitude", [0.4 * CLEAR, 1.8 * CLEAR], ids=["stick_slip", "bearing"])
def test_a_shear_cycle_dissipates_the_jenkins_loop_area_bearing_adds_nothing(amplitude):
    """x = D·sin t; over the closed cycle t ∈ [π/2, 5π/2] the dissipated energy is the
    parallelogram 4μF_V(D − μF_V/k_τ); the bearing spring past the clearance is conservative."""
    law = joint()

    def path(t):
        return np.array([amplitude * math.sin(t), 0.0, 0.0]), np.array(
            [amplitude * math.cos(t), 0.0, 0.0]
        )

    run = drive(law, path, (0.0, 2.5 * math.pi), t_eval=np.array([0.5 * math.pi, 2.5 * math.pi]))
    cycle = run.dissipated[1] - run.dissipated[0]
    assert cycle == pytest.approx(4.0 * MU * F_V * (amplitude - D_STICK), rel=1e-8)


def test_a_circular_slide_dissipates_friction_times_the_slip_circle_per_turn():
    """d on a circle of radius R: once steady, the slip point runs on the concentric circle of
    radius √(R² − d_stick²) with the stick spring tangent to it, so one turn dissipates
    μF_V·2π√(R² − d_stick²); energy is never created along the way."""
    law = joint()
    radius = 0.5 * CLEAR

    def path(t):
        return radius * np.array([math.cos(t), math.sin(t), 0.0]), radius * np.array(
            [-math.sin(t), math.cos(t), 0.0]
        )

    y0 = law.states(0.0, radius - D_STICK, 0.0, 0.0)  # already sliding outward along x
    t_eval = np.linspace(0.0, 6.0 * math.pi, 301)
    run = drive(law, path, (0.0, 6.0 * math.pi), y0=y0, t_eval=t_eval)
    assert np.all(np.diff(run.dissipated) >= -1e-12 * run.dissipated[-1])
    turn = run.dissipated[-1] - run.dissipated[200]  # third turn
    expected = MU * F_V * 2.0 * math.pi * math.sqrt(radius**2 - D_STICK**2)
    assert turn == pytest.approx(expected, rel=1e-8)
    # the stick deflection stays on the friction bound while sliding
    ends = np.stack([radius * np.cos(t_eval), radius * np.sin(t_eval)])
    stick = np.linalg.norm(ends - run.states[SLIP_X : SLIP_Y + 1], axis=0)
    np.testing.assert_allclose(stick[100:], D_STICK, rtol=1e-7)


def carried(
    twin: tuple[tuple[float, float, float], tuple[float, float]],
    before: tuple[float, float],
    after: tuple[float, float],
    d: tuple[float, float, float],
) -> np.ndarray:
    """The core's carry of the M20 joint: the companion's stick point `after` its error's kick,
    `before` it, at deflection d (m), beside the twin's deflection and stick point `twin`.
    Returns the companion's states (e_p 1e-6 and broken 0 as kicked: kept)."""
    law = joint()
    p = np.zeros(N_PAR)  # the core's row: every kind's columns
    p[: law.p.shape[0]] = law.p
    y = law.states(1e-6, *after, 0.0)
    y0 = law.states(2e-6, *before, 0.0)
    yt = law.states(0.0, *twin[1], 0.0)
    kind_carry(BOLTED_JOINT, p, y, y0, yt, 0, np.array(d), np.array(twin[0]))
    return y


def test_beside_a_sliding_twin_the_companions_face_slides_on_its_bound_along_its_own_e():
    """The twin's face on its bound (k_τ·|e| = μ·F_K): the companion's stick point, its kick
    undone, is put on its own bound along its own e, whatever side of it it stood."""
    twin = ((2 * D_STICK, 0.0, 0.0), (D_STICK, 0.0))
    for before in ((D_STICK + 3e-6, 1e-6), (D_STICK - 4e-6, -2e-6)):
        d = (2 * D_STICK + 1e-6, 0.0, 0.0)
        y = carried(twin, before, (5e-3, 5e-3), d)
        e = np.array(d[:2]) - np.array(before)
        s = np.array(d[:2]) - D_STICK * e / np.hypot(*e)
        assert y[SLIP_X : SLIP_Y + 1] == pytest.approx(s, rel=1e-12, abs=1e-18)
        assert np.hypot(d[0] - y[SLIP_X], d[1] - y[SLIP_Y]) == pytest.approx(D_STICK, rel=1e-12)
        assert (y[E_P], y[BROKEN]) == (1e-6, 0.0)


def test_beside_a_sticking_twin_the_companions_face_keeps_its_carried_stick_point():
    """The twin's face inside its bound: the companion's stick point is the one it carried,
    its kick undone, inside its bound; past it, radial return onto it (`settle`)."""
    twin = ((D_STICK / 2, 0.0, 0.0), (0.0, 0.0))
    y = carried(twin, (1e-6, 0.0), (5e-3, 5e-3), (D_STICK / 2, 0.0, 0.0))
    assert (y[SLIP_X], y[SLIP_Y]) == (1e-6, 0.0)
    y = carried(twin, (0.0, 0.0), (5e-3, 5e-3), (0.0, 3 * D_STICK, 0.0))
    assert (y[SLIP_X], y[SLIP_Y]) == pytest.approx((0.0, 2 * D_STICK), rel=1e-12)


def test_an_open_companion_face_keeps_its_kick():
    """Past U_OPEN nothing holds the face (μ·F_K = 0): its stick point moves with the foot at
    a rate, and the companion keeps what the kick gave it."""
    twin = ((0.0, 0.0, 2 * U_OPEN), (0.0, 0.0))
    y = carried(twin, (1e-6, 0.0), (4e-6, -3e-6), (0.0, 0.0, 2 * U_OPEN))
    assert (y[SLIP_X], y[SLIP_Y]) == (4e-6, -3e-6)


def test_beside_a_flowing_twin_the_companions_bolt_is_put_on_its_yield_line():
    """The twin's bolt at its yield force: the companion's plastic elongation is put where its
    own bolt force equals its own hardened yield force at its deflection (F_V + k_S·(u − e_p)
    = F_y + α·k_S/(1 − α)·e_p), whatever the kick gave it; an elastic twin leaves it alone."""
    law = joint()
    p = np.zeros(N_PAR)
    p[: law.p.shape[0]] = law.p
    u_t = U_Y + 2e-4  # the twin past first yield, its e_p on the line
    e_t = (F_V + K_S * u_t - F_Y) / (K_S + 0.02 * K_S / 0.98)
    u = u_t + 1e-5
    for e_kicked in (0.0, 5e-3):
        y = law.states(e_kicked, 0.0, 0.0, 0.0)
        yt = law.states(e_t, 0.0, 0.0, 0.0)
        kind_carry(
            BOLTED_JOINT, p, y, y.copy(), yt, 0, np.array([0.0, 0.0, u]), np.array([0.0, 0.0, u_t])
        )
        hardened = F_Y + 0.02 * K_S / 0.98 * y[E_P]
        assert F_V + K_S * (u - y[E_P]) == pytest.approx(hardened, rel=1e-12)
    y = law.states(1e-6, 0.0, 0.0, 0.0)
    kind_carry(BOLTED_JOINT, p, y, y.copy(), law.states(), 0, np.zeros(3), np.zeros(3))
    assert y[E_P] == 1e-6
