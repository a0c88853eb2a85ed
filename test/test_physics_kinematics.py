"""The α/γ/δ chart (mount_twin.physics.chart) against finite differences, scipy and the notes.

Truth: vee(Rᵀ dR/dt) by central differences of R(t) along smooth random trajectories, scipy's
REP-103 roll/pitch/yaw construction (notes §2), and the closed forms of the notes §2–§3.
"""

from __future__ import annotations

import decimal
import math

import numpy as np
import pytest
from physics_helpers import (
    base_scene,
    build,
    chart_to_matrix_ref,
    kinematic_matrix_ref,
    mount,
    vee,
)

from mount_twin.physics.chart import (
    chart_from_rotation,
    chart_rates,
    kinematic_matrix,
    kinematic_matrix_rate,
    rotation_matrix,
)
from mount_twin.physics.dynamics import body_motion

H_FD = 1e-5  # s, central-difference step (truncation ~h²·|q'|³ ≈ 1e-10, roundoff ~1e-11)


class Trajectory:
    """α, γ, δ as sums of random sines, kept inside |α| + |γ| < `max_tilt`."""

    def __init__(self, seed: int, max_tilt: float) -> None:
        rng = np.random.default_rng(seed)
        self.amp = rng.uniform(0.2, 1.0, size=(3, 3))
        self.freq = rng.uniform(0.3, 3.0, size=(3, 3))
        self.phase = rng.uniform(0.0, 2 * math.pi, size=(3, 3))
        self.offset = rng.uniform(-1.0, 1.0, size=3)
        # scale α, γ so that |α| + |γ| never exceeds max_tilt
        bound = np.abs(self.offset[:2]) + self.amp[:2].sum(axis=1)
        scale = max_tilt / bound.sum()
        self.amp[:2] *= scale
        self.offset[:2] *= scale
        self.amp[2] *= 3.0  # δ may wander anywhere

    def q(self, t: float) -> np.ndarray:
        return self.offset + (self.amp * np.sin(self.freq * t + self.phase)).sum(axis=1)

    def qd(self, t: float) -> np.ndarray:
        return (self.amp * self.freq * np.cos(self.freq * t + self.phase)).sum(axis=1)


def kin(alpha: float, gamma: float) -> np.ndarray:
    sa, ca, sg, cg = math.sin(alpha), math.cos(alpha), math.sin(gamma), math.cos(gamma)
    out = np.zeros((3, 3))
    kinematic_matrix(sa, ca, sg, cg, math.sqrt(cg * cg - sa * sa), out)
    return out


def kin_rate(alpha: float, gamma: float, alpha_dot: float, gamma_dot: float) -> np.ndarray:
    sa, ca, sg, cg = math.sin(alpha), math.cos(alpha), math.sin(gamma), math.cos(gamma)
    out = np.zeros((3, 3))
    kinematic_matrix_rate(sa, ca, sg, cg, math.sqrt(cg * cg - sa * sa), alpha_dot, gamma_dot, out)
    return out


TRAJECTORIES = [(seed, tilt) for seed in range(4) for tilt in (0.3, 1.0, 1.3)]
TIMES = np.linspace(0.0, 7.0, 23)


def worst_relative(pair) -> float:
    """Largest |value − finite-difference reference| / max(1, |reference|) over TIMES, for
    pair(t) = (value, reference)."""
    worst = 0.0
    for t in TIMES:
        value, ref = pair(t)
        worst = max(worst, np.max(np.abs(value - ref)) / max(1.0, np.linalg.norm(ref)))
    return worst


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_kinematic_matrix_times_chart_rates_equals_finite_difference_body_rate(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)

    def pair(t: float) -> tuple[np.ndarray, np.ndarray]:
        rp, rm = rotation_matrix(*traj.q(t + H_FD)), rotation_matrix(*traj.q(t - H_FD))
        omega_fd = vee(rotation_matrix(*traj.q(t)).T @ (rp - rm) / (2 * H_FD))
        return kin(*traj.q(t)[:2]) @ traj.qd(t), omega_fd

    worst = worst_relative(pair)
    assert worst < 1e-7, f"B·q' differs from vee(RᵀṘ) by {worst:.3g} (relative)"


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_kinematic_matrix_matches_the_closed_form_of_the_notes(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)
    for t in TIMES:
        a, g, _ = traj.q(t)
        np.testing.assert_allclose(kin(a, g), kinematic_matrix_ref(a, g), rtol=1e-13, atol=1e-13)
        det_ref = -math.cos(a) * math.cos(g) / math.sqrt(math.cos(g) ** 2 - math.sin(a) ** 2)
        assert np.linalg.det(kin(a, g)) == pytest.approx(det_ref, rel=1e-12)


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_chart_rates_inverts_the_kinematic_matrix(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)
    rng = np.random.default_rng(100 + seed)
    for t in TIMES:
        a, g, _ = traj.q(t)
        ct = math.sqrt(math.cos(g) ** 2 - math.sin(a) ** 2)
        omega = rng.normal(size=3)
        rates = np.array(chart_rates(a, g, ct, omega))
        bmat = kin(a, g)
        # B·(B⁻¹ω) = ω and the rates equal a direct linear solve
        np.testing.assert_allclose(bmat @ rates, omega, rtol=0, atol=1e-12 * np.linalg.cond(bmat))
        np.testing.assert_allclose(
            rates, np.linalg.solve(bmat, omega), rtol=0, atol=1e-12 * np.linalg.cond(bmat)
        )


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_kinematic_matrix_rate_equals_finite_difference_of_b_along_the_trajectory(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)

    def pair(t: float) -> tuple[np.ndarray, np.ndarray]:
        a, g, _ = traj.q(t)
        qd = traj.qd(t)
        bdot_fd = (kin(*traj.q(t + H_FD)[:2]) - kin(*traj.q(t - H_FD)[:2])) / (2 * H_FD)
        return kin_rate(a, g, qd[0], qd[1]) @ qd, bdot_fd @ qd

    worst = worst_relative(pair)
    # B' grows like 1/cos³θ near the chart edge; 1e-7 relative covers the FD error there
    assert worst < 1e-7, f"B'·q' differs from the finite-difference dB/dt·q' by {worst:.3g}"


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_chart_from_rotation_round_trips_rotation_matrix(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)
    for t in TIMES:
        a, g, d = traj.q(t)
        d_wrapped = math.atan2(math.sin(d), math.cos(d))
        back = np.array(chart_from_rotation(rotation_matrix(a, g, d)))
        np.testing.assert_allclose(back, [a, g, d_wrapped], rtol=0, atol=1e-12)


@pytest.mark.parametrize(("seed", "max_tilt"), TRAJECTORIES)
def test_rotation_matrix_is_rep103_yaw_delta_pitch_minus_gamma_roll_from_alpha(seed, max_tilt):
    traj = Trajectory(seed, max_tilt)
    for t in TIMES:
        a, g, d = traj.q(t)
        rot = rotation_matrix(a, g, d)
        np.testing.assert_allclose(rot, chart_to_matrix_ref(a, g, d), rtol=0, atol=1e-14)
        # the defining entries of the notes §2
        assert rot[2, 0] == pytest.approx(math.sin(g), abs=1e-15)
        assert rot[2, 1] == pytest.approx(math.sin(a), abs=1e-15)
        assert math.atan2(rot[1, 0], rot[0, 0]) == pytest.approx(
            math.atan2(math.sin(d), math.cos(d)), abs=1e-13
        )
        np.testing.assert_allclose(rot.T @ rot, np.eye(3), rtol=0, atol=1e-14)
        assert np.linalg.det(rot) == pytest.approx(1.0, abs=1e-14)


def test_rotation_matrix_is_nan_off_the_chart():
    rot = rotation_matrix(0.8, 0.8, 0.1)  # |α| + |γ| > π/2: cos θ would be imaginary
    assert np.isnan(rot).all()


def _series_sin_cos(x: float) -> tuple[float, float]:
    """sin x and cos x of the double x to 40 digits: their Taylor series in exact decimal
    arithmetic (an independent evaluation: no floating point, no C library)."""
    with decimal.localcontext() as ctx:
        ctx.prec = 40
        d = decimal.Decimal(x)  # exact: a double is a finite binary fraction
        s, c, term, k = decimal.Decimal(0), decimal.Decimal(0), decimal.Decimal(1), 0
        while term != 0 and k < 200:  # term = d^k / k!
            if k % 2:
                s += term if k % 4 == 1 else -term
            else:
                c += term if k % 4 == 0 else -term
            k += 1
            term = term * d / k
        return float(s), float(c)


@pytest.mark.parametrize("seed", [0, 1])
def test_the_cores_sines_and_cosines_of_the_angles_are_within_an_ulp_and_a_half(seed):
    """The body's sines and cosines as the core takes them (`body_motion`'s trig: by series
    within ±π/4, the C library beyond) against 40-digit series, rounded: within 1.5 ulp at
    small angles, across (−π/4, π/4) up to its edges and beyond them."""
    rng = np.random.default_rng(seed)
    edge = math.pi / 4
    angles = np.concatenate(
        [
            rng.uniform(-1e-3, 1e-3, 200),
            rng.uniform(-edge, edge, 400),
            [edge, -edge, np.nextafter(edge, 0.0), np.nextafter(edge, 1.0), 1e-300, 0.0],
            rng.uniform(-3.0, 3.0, 100),
        ]
    )
    model = build(
        base_scene(
            10.0,
            [0.0, 0.0, 0.3],
            [1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
            [mount("m", [0.0] * 3, [1e5] * 6)],
        )
    )
    s = model.new_scratch()
    y = np.zeros(model.n_state)
    worst = 0.0
    for a, g, d in angles[: 3 * (angles.size // 3)].reshape(-1, 3):
        y[3:6] = (a * 0.1, g * 0.1, d)  # α, γ small enough to stay on the chart
        body_motion(y, model.arrays, s)
        for x, (got_s, got_c) in zip(y[3:6], s.trig.reshape(2, 3).T, strict=True):
            want_s, want_c = _series_sin_cos(float(x))
            for got, want in ((got_s, want_s), (got_c, want_c)):
                worst = max(worst, abs(got - want) / math.ulp(want) if want else abs(got))
    assert worst <= 1.5
