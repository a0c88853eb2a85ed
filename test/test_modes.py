"""Modal analysis (`mount_twin.analysis.modes`, `mount-twin modes`) against independent truth:
a 6×6 generalized eigenproblem assembled here from the scene's numbers, closed forms (symmetric
layouts, a high CG's −m·g·h, inclined pairs, the tangents of the non-linear kinds), a textbook
bounce–pitch case, a verification-manual style case, the twin's own state Jacobian, and the
sums that must hold; then the command on the bundled scenes."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest
from io_helpers import CONFIG, run_python
from kinds_helpers import kind_mount
from physics_helpers import (
    G,
    base_scene,
    build,
    gravity_u,
    inertia_tensor,
    mount,
    mount_frames,
    mount_wrench_ref,
    natural_frequencies_from_jacobian,
    skew,
    spring_tangent_ref,
    twin_jacobian,
)
from scipy.linalg import eig, eigh
from scipy.optimize import brentq, least_squares
from scipy.spatial.transform import Rotation

from mount_twin.analysis.modes import Mode, Modes, modes
from mount_twin.cli import main
from mount_twin.model.assemble import initial_state
from mount_twin.scene.loader import scene_from_dict

TWO_PI = 2.0 * math.pi
MASS = 900.0
CG = [0.05, 0.02, 0.0]
INERTIA = [180.0, 260.0, 300.0, 12.0, -20.0, 6.0]
LAYOUT = [  # asymmetric, inclined, 0.25–0.35 m below the CG
    mount("a", (0.7, 0.45, -0.3), (4e5, 5e5, 1.3e6, 300, 200, 100), rpy_=(0.3, 0.0, 0.2)),
    mount("b", (0.6, -0.5, -0.35), (6e5, 3e5, 1.1e6, 0, 0, 0), rpy_=(-0.4, 0.1, 0.0)),
    mount("c", (-0.8, 0.4, -0.25), (5e5, 5e5, 0.9e6, 0, 0, 0), rpy_=(0.0, -0.3, 0.5)),
    mount("d", (-0.7, -0.45, -0.3), (3e5, 6e5, 1.4e6, 0, 0, 0)),
]


def analyse(data: dict[str, Any], geometric: bool = True) -> Modes:
    return modes(scene_from_dict(data, "<modes test>"), geometric=geometric)


def frequencies(result: Modes) -> np.ndarray:
    return np.array([m.frequency_hz for m in result.modes])


def by_dominant(result: Modes, dof: str) -> Mode:
    (found,) = [m for m in result.modes if m.dominant_dof == dof]
    return found


def corners(a: float, b: float) -> list[tuple[float, float, float]]:
    return [(a, b, 0.0), (a, -b, 0.0), (-a, b, 0.0), (-a, -b, 0.0)]


def independent_eigenproblem(data: dict[str, Any], geometric: bool) -> tuple[np.ndarray, ...]:
    """M and K about the CG in F (translation, rotation vector), from the scene's numbers only.

    Equilibrium: force and moment balance of the mounts (physics notes §7, `mount_wrench_ref`)
    against the weight, solved here for (r, φ). About it, with arms aᵢ = R₀·pᵢ:
    K = Σ Tᵢᵀ·K_t,i·Tᵢ (Tᵢ = [1, −[aᵢ]×]) + the tangents of the rotational springs' couples
    −J_l⁻ᵀ(φ)·K_r,i·φ (φ the rotation vector of R, `spring_tangent_ref`) + [if geometric]
    Σ (F₀ᵢ·aᵢ)·1 − aᵢ·F₀ᵢᵀ; M = diag(m·1, R₀·I·R₀ᵀ).
    """
    frames = mount_frames(data)
    mass = data["body"]["mass"]
    weight = np.array([0.0, 0.0, mass * G])

    def unbalance(x: np.ndarray) -> np.ndarray:
        force, moment, _ = mount_wrench_ref(frames, x[:3], Rotation.from_rotvec(x[3:]).as_matrix())
        return np.concatenate([force - weight, moment])

    x0 = least_squares(unbalance, np.zeros(6), xtol=1e-15, ftol=1e-15, gtol=1e-15).x
    rot = Rotation.from_rotvec(x0[3:]).as_matrix()
    _, _, preload = mount_wrench_ref(frames, x0[:3], rot)
    k = np.zeros((6, 6))
    for fr, f0 in zip(frames, preload, strict=True):
        arm = rot @ fr["p"]
        t = np.hstack([np.eye(3), -skew(arm)])
        k += t.T @ fr["kt"] @ t
        k[3:, 3:] += spring_tangent_ref(fr["kr"], rot)
        if geometric:
            k[3:, 3:] += (f0 @ arm) * np.eye(3) - np.outer(arm, f0)
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[3:, 3:] = rot @ inertia_tensor(*data["body"]["inertia"]) @ rot.T
    return m, k


# ------------------------------------------------------------------ (a) independent eigenproblem
@pytest.mark.parametrize("geometric", [True, False])
def test_frequencies_and_shapes_equal_an_independent_6x6_eigenproblem(geometric: bool) -> None:
    data = base_scene(MASS, CG, INERTIA, LAYOUT)
    m, k = independent_eigenproblem(data, geometric)
    w2 = np.sort(eig(k, m, right=False).real)
    result = analyse(data, geometric)
    np.testing.assert_allclose(frequencies(result), np.sqrt(w2) / TWO_PI, rtol=1e-6)
    # mass-normalised shapes in F: the same vectors up to sign
    _, vectors = eigh(0.5 * (k + k.T), m)
    for mode, ref in zip(result.modes, vectors.T, strict=True):
        mine = np.array(list(mode.shape_in_f.values()))
        assert abs(mine @ m @ ref) == pytest.approx(1.0, abs=1e-6)
    # the preload's geometric stiffness (CG 0.3 m above the mounts) moves every frequency by
    # over a hundred times the tolerance
    other = analyse(data, not geometric)
    assert np.abs(frequencies(other) / frequencies(result) - 1.0).min() > 1e-4


def test_without_gravity_the_modes_are_the_eigenproblem_of_k_and_m_alone() -> None:
    """input.g: 0: the body rests at its reference pose under no preload, so with or without
    the geometric stiffness the frequencies are those of K = Σ Tᵢᵀ·K_t,i·Tᵢ + Σ K_r,i (arms pᵢ
    at the reference pose) and M = diag(m·1, I). At g > 0, --no-geometric still linearises
    about the sagged pose: its frequencies differ from these by far more than the tolerance."""
    data = base_scene(MASS, CG, INERTIA, LAYOUT)
    data["input"]["g"] = 0.0
    k, m = np.zeros((6, 6)), np.zeros((6, 6))
    for fr in mount_frames(data):
        t = np.hstack([np.eye(3), -skew(fr["p"])])
        k += t.T @ fr["kt"] @ t
        k[3:, 3:] += fr["kr"]
    m[:3, :3] = MASS * np.eye(3)
    m[3:, 3:] = inertia_tensor(*INERTIA)
    textbook = np.sqrt(eigh(k, m, eigvals_only=True)) / TWO_PI
    for geometric in (True, False):
        np.testing.assert_allclose(frequencies(analyse(data, geometric)), textbook, rtol=1e-7)
    data["input"]["g"] = G
    sagged = frequencies(analyse(data, geometric=False))
    assert np.abs(sagged / textbook - 1.0).max() > 1e-5


# ------------------------------------------------------------------ (b) closed forms
def test_symmetric_four_mounts_give_the_closed_form_bounce_pitch_and_damping() -> None:
    """Four equal mounts at (±a, ±b) in the plane of the CG: bounce √(4k/m)/2π, pitch
    √(k·Σx²/I_yy)/2π = √(4k·a²/I_yy)/2π, roll √(4k·b²/I_xx)/2π, each uncoupled, so its
    modal damping 4c/(2mω) (and 4c·a²/(2·I_yy·ω) in pitch) is exact, as is the complex
    eigenvalue's. The weight's arms stay level: the geometric stiffness vanishes."""
    m_, a, b, kz, cz = 500.0, 0.6, 0.4, 3.0e5, 800.0
    inertia = [40.0, 70.0, 90.0, 0.0, 0.0, 0.0]
    layout = [
        mount(f"m{i}", p, (1e5, 1.2e5, kz, 0, 0, 0), damping=(0, 0, cz, 0, 0, 0))
        for i, p in enumerate(corners(a, b))
    ]
    for geometric in (True, False):
        result = analyse(base_scene(m_, [0.0, 0.0, 0.0], inertia, layout), geometric)
        bounce, pitch = by_dominant(result, "z"), by_dominant(result, "gamma")
        roll = by_dominant(result, "alpha")
        w_bounce, w_pitch = math.sqrt(4 * kz / m_), math.sqrt(4 * kz * a * a / inertia[1])
        assert bounce.frequency_hz == pytest.approx(w_bounce / TWO_PI, rel=1e-6)
        assert pitch.frequency_hz == pytest.approx(w_pitch / TWO_PI, rel=1e-6)
        assert roll.frequency_hz == pytest.approx(
            math.sqrt(4 * kz * b * b / inertia[0]) / TWO_PI, rel=1e-6
        )
        zeta_bounce = 4 * cz / (2 * m_ * w_bounce)
        assert bounce.damping_ratio == pytest.approx(zeta_bounce, rel=1e-6)
        assert pitch.damping_ratio == pytest.approx(
            4 * cz * a * a / (2 * inertia[1] * w_pitch), rel=1e-6
        )
        exact = [c for c in result.complex_modes if c.damping_ratio > 0.0]
        assert min(abs(c.damping_ratio - zeta_bounce) for c in exact) < 1e-6 * zeta_bounce
        np.testing.assert_allclose(result.geometric_stiffness, 0.0, atol=1e-6 * kz)


def rocking_pairs(
    m_: float,
    inertia: list[float],
    a: float,
    b: float,
    h: float,
    kh: float,
    kv: float,
    geometric: bool,
) -> np.ndarray:
    """Closed form of a body with its CG h above four mounts at (±a, ±b) (k_h along x and y,
    k_v along z). A rotation θ about x moves a mount point by (0, h·θ, y·θ), so lateral and
    roll couple: K = [[4k_h, 4k_h·h], [4k_h·h, 4k_h·h² + 4k_v·b² − m·g·h]] with M = diag(m,
    I_xx), the −m·g·h being the weight's geometric stiffness (physics notes §7); pitch likewise
    with a and I_yy; bounce 4k_v/m and yaw 4k_h(a² + b²)/I_zz stay alone. Returns the six
    signed ω² (negative: unstable), sorted."""
    geo = m_ * G * h if geometric else 0.0
    w2 = [4 * kv / m_, 4 * kh * (a * a + b * b) / inertia[2]]
    for arm, inert in ((b, inertia[0]), (a, inertia[1])):
        k2 = np.array([[4 * kh, 4 * kh * h], [4 * kh * h, 4 * kh * h * h + 4 * kv * arm**2 - geo]])
        # det(K − ω²·diag(m, I)) = 0: m·I·ω⁴ − (m·K₂₂ + I·K₁₁)·ω² + det K = 0
        w2 += list(np.roots([m_ * inert, -(m_ * k2[1, 1] + inert * k2[0, 0]), np.linalg.det(k2)]))
    return np.sort(np.real(w2))


@pytest.mark.parametrize(
    ("b", "h", "geometric"),
    [(0.4, 0.5, True), (0.4, 0.5, False), (0.1, 1.0, True)],
    ids=["high-cg", "high-cg-without-geometric", "unstable-roll"],
)
def test_a_high_cg_rocks_as_the_closed_form_with_minus_m_g_h(
    b: float, h: float, geometric: bool
) -> None:
    """`rocking_pairs`. The last case is an inverted pendulum: m·g·h = 4.9 kN·m exceeds
    4k_v·b² = 4 kN·m, so the upright equilibrium is unstable in roll however stiff the mounts
    are laterally."""
    m_, a, kh, kv = 500.0, 0.5, 2.0e5, 1.0e5
    inertia = [60.0, 80.0, 90.0, 0.0, 0.0, 0.0]
    layout = [mount(f"m{i}", p, (kh, kh, kv, 0, 0, 0)) for i, p in enumerate(corners(a, b))]
    result = analyse(base_scene(m_, [0.0, 0.0, h], inertia, layout), geometric)
    w2 = rocking_pairs(m_, inertia, a, b, h, kh, kv, geometric)
    want = np.sign(w2) * np.sqrt(np.abs(w2)) / TWO_PI
    np.testing.assert_allclose(frequencies(result), want, rtol=1e-6)
    assert (frequencies(result)[0] < 0.0) == (m_ * G * h > 4 * kv * b * b and geometric)
    # equal mounts: their centroid, h below the CG, is an exact elastic centre
    centre = result.centre
    np.testing.assert_allclose(centre.point_m, [0.0, 0.0, 0.0], rtol=0, atol=1e-9)
    assert centre.residual_m is not None and centre.residual_m < 1e-9


def test_a_body_hanging_below_its_mount_swings_as_a_compound_pendulum() -> None:
    """A body hanging from one point spring (k_x, k_z) a length L above its CG, free in x, z
    and pitch θ. The point moves by t_x + L·θ, so the elastic stiffness k_x·[[1, L], [L, L²]]
    leaves the swing about the point free; the weight hanging from the turning arm adds its
    geometric stiffness +m·g·L (physics notes §7; a stable preload, the opposite of a CG
    above the mounts). det([[k_x − m·ω², k_x·L], [k_x·L, k_x·L² + m·g·L − I·ω²]]) = 0, whose
    lower root tends to the compound pendulum's m·g·L/(I + m·L²) as k_x grows. Without the
    weight's stiffness the swing has zero frequency, and there is no stiffness centre."""
    m_, i_yy, length, kx, kz = 20.0, 0.8, 0.5, 2.0e5, 3.0e5
    spring = [mount("hook", (0.0, 0.0, length), (kx, 0, kz, 0, 0, 0))]
    data = base_scene(m_, [0.0, 0.0, 0.0], [0.5, i_yy, 0.6, 0, 0, 0], spring, ["x", "z", "gamma"])
    k2 = np.array([[kx, kx * length], [kx * length, kx * length**2 + m_ * G * length]])
    w2 = np.roots([m_ * i_yy, -(m_ * k2[1, 1] + i_yy * k2[0, 0]), np.linalg.det(k2)]).real
    want = np.sqrt(np.sort([*w2, kz / m_])) / TWO_PI
    result = analyse(data)
    np.testing.assert_allclose(frequencies(result), want, rtol=1e-6)
    pendulum = math.sqrt(m_ * G * length / (i_yy + m_ * length**2)) / TWO_PI
    assert frequencies(result)[0] == pytest.approx(pendulum, rel=1e-3)
    elastic = analyse(data, geometric=False)
    assert frequencies(elastic)[0] == 0.0
    swing_free = [kz / m_, kx * (i_yy + m_ * length**2) / (m_ * i_yy)]  # det with g = 0
    np.testing.assert_allclose(frequencies(elastic)[1:], np.sqrt(swing_free) / TWO_PI, rtol=1e-6)
    assert elastic.centre.force_lines_m == {} and elastic.centre.point_m is None


# ------------------------------------------------------------------ (c) textbook bounce–pitch
RAO = {"m": 1000.0, "r": 0.9, "l1": 1.0, "l2": 1.5, "kf": 18.0e3, "kr": 22.0e3}


def rao_car(g: float) -> dict[str, Any]:
    springs = [
        mount("front", (RAO["l1"], 0.0, 0.0), (0, 0, RAO["kf"], 0, 0, 0)),
        mount("rear", (-RAO["l2"], 0.0, 0.0), (0, 0, RAO["kr"], 0, 0, 0)),
    ]
    j = RAO["m"] * RAO["r"] ** 2
    data = base_scene(
        RAO["m"], [0.0, 0.0, 0.0], [500.0, j, 900.0, 0, 0, 0], springs, ["z", "gamma"]
    )
    data["input"]["g"] = g
    return data


def test_bounce_and_pitch_of_an_automobile_are_the_textbook_case() -> None:
    """S. S. Rao, Mechanical Vibrations (two-degree-of-freedom systems), the worked example of
    an automobile's pitch and bounce: m = 1000 kg, radius of gyration 0.9 m, front spring
    18 kN/m at l1 = 1.0 m ahead of the CG, rear 22 kN/m at l2 = 1.5 m behind. Characteristic
    equation m·J·ω⁴ − (m(k_f·l1² + k_r·l2²) + J(k_f + k_r))·ω² + (k_f + k_r)(k_f·l1² + k_r·l2²)
    − (k_r·l2 − k_f·l1)² = 0; published ω = 5.8593 and 9.4341 rad/s, nodes 2.6461 m behind and
    0.3061 m ahead of the CG. The textbook's springs keep their lever arms: nominal gravity 0
    (under 1 g this car sags 0.25 m and pitches 0.06 rad, and its lever arms shorten)."""
    m_, j = RAO["m"], RAO["m"] * RAO["r"] ** 2
    kf, kr, l1, l2 = RAO["kf"], RAO["kr"], RAO["l1"], RAO["l2"]
    p2 = m_ * (kf * l1**2 + kr * l2**2) + j * (kf + kr)
    p0 = (kf + kr) * (kf * l1**2 + kr * l2**2) - (kr * l2 - kf * l1) ** 2
    omega = np.sqrt(np.sort(np.roots([m_ * j, -p2, p0]).real))
    result = analyse(rao_car(0.0))
    np.testing.assert_allclose(frequencies(result) * TWO_PI, omega, rtol=1e-6)
    np.testing.assert_allclose(frequencies(result) * TWO_PI, [5.8593, 9.4341], atol=1e-4)
    # node: where Z + γ·x = 0 (γ > 0 lifts the nose), x forward from the CG
    nodes = [-m.shape["z"] / m.shape["gamma"] for m in result.modes]
    np.testing.assert_allclose(nodes, [-2.6461, 0.3061], atol=1e-4)
    # the vertical stiffness centre: (k_f·l1 − k_r·l2)/(k_f + k_r) from the CG
    (x_c, y_c, _) = result.centre.force_lines_m["z"]
    assert x_c == pytest.approx((kf * l1 - kr * l2) / (kf + kr), rel=1e-9)
    assert y_c == pytest.approx(0.0, abs=1e-12)  # y is not free: under the CG


def test_static_mount_loads_of_a_two_spring_body_are_its_statics() -> None:
    """Two vertical springs: statically determinate, front load m·g·l2/(l1 + l2) and rear
    m·g·l1/(l1 + l2) whatever the springs (vertical forces on arms turned alike); each
    spring's deflection along its axis is its load over its stiffness."""
    result = analyse(rao_car(G))
    weight, span = RAO["m"] * G, RAO["l1"] + RAO["l2"]
    front, rear = result.mounts
    assert front.force_n[2] == pytest.approx(weight * RAO["l2"] / span, rel=1e-9)
    assert rear.force_n[2] == pytest.approx(weight * RAO["l1"] / span, rel=1e-9)
    assert front.deflection_m[2] == pytest.approx(-front.force_n[2] / RAO["kf"], rel=1e-9)
    assert rear.deflection_m[2] == pytest.approx(-rear.force_n[2] / RAO["kr"], rel=1e-9)


# ------------------------------------------------------------------ (d) inclined springs
def test_mass_on_two_inclined_springs_is_the_verification_case() -> None:
    """A mass m on two axial springs k through one point, inclined ±θ from the vertical in the
    y–z plane (the two-spring mass of FE codes' verification manuals). Spring i has the unit
    axis nᵢ = (∓sin θ, cos θ) (local z of a mount rolled by ±θ), so the stiffness is
    K = k·Σ nᵢ·nᵢᵀ = k·[[2 sin²θ, 0], [0, 2 cos²θ]]: the ±sin θ·cos θ cross terms cancel. The
    modes are lateral, f = √(2k·sin²θ/m)/2π, and vertical, f = √(2k·cos²θ/m)/2π. Point springs
    have no lever arm: gravity changes nothing."""
    m_, k, th = 10.0, 1.0e5, math.radians(30.0)
    springs = [
        mount(n, (0.0, 0.0, 0.0), (0, 0, k, 0, 0, 0), rpy_=(s * th, 0, 0))
        for n, s in (("l", 1), ("r", -1))
    ]
    result = analyse(
        base_scene(m_, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 0, 0, 0], springs, ["y", "z"])
    )
    assert by_dominant(result, "y").frequency_hz == pytest.approx(
        math.sqrt(2 * k * math.sin(th) ** 2 / m_) / TWO_PI, rel=1e-6
    )
    assert by_dominant(result, "z").frequency_hz == pytest.approx(
        math.sqrt(2 * k * math.cos(th) ** 2 / m_) / TWO_PI, rel=1e-6
    )


# ------------------------------------------------------------------ (e) the twin's own dynamics
def test_frequencies_equal_those_of_the_twins_linearised_right_hand_side() -> None:
    """The physics tests' route: |Im λ| of the central-difference state Jacobian of the twin
    (test/physics_helpers.py) about its equilibrium, damping zero."""
    data = base_scene(MASS, CG, INERTIA, LAYOUT)
    model = build(data)
    y_eq = initial_state(model, np.array([0.0, 0.0, G]))
    omegas = natural_frequencies_from_jacobian(twin_jacobian(model, y_eq, gravity_u()))
    np.testing.assert_allclose(frequencies(analyse(data)), omegas / TWO_PI, rtol=1e-6)


# ------------------------------------------------------------------ non-linear kinds
def test_elastomers_enter_by_their_tangent_with_the_bouc_wen_branch() -> None:
    """Four elastomers (cubic backbone, Bouc–Wen share 1 − a) at (±a, ±b) in the CG's plane,
    set down slowly: at rest z₀ = Z(x₀) on the loading curve (n = 1: Z(x) = (A/c)·(1 − e^(−c·x))
    for x ≥ 0, odd, c = β + γ), and a·(k₁x₀ + k₃x₀³) + (1 − a)·k₁·z₀ = −m·g/4. ż's slope in ẋ
    there is A − (β + γ)·|z₀| loading and A + (β − γ)·|z₀| unloading, entering with their mean
    A − γ·|z₀|: the vertical tangent is a·(k₁ + 3k₃x₀²) + (1 − a)·k₁·(A − γ·|z₀|): bounce
    √(4k_t/m)/2π, pitch √(4k_t·a²/I_yy)/2π. The same frequencies come from the twin's state
    Jacobian at its start with the z states in it (their zero eigenvalues left out)."""
    m_, a, b, k1, k3, share, big_a = 400.0, 0.5, 0.3, 4.0e5, 1.0e10, 0.7, 1.2
    beta, gamma = 40.0, 30.0
    inertia = [30.0, 50.0, 70.0, 0.0, 0.0, 0.0]
    layout = [
        kind_mount(
            "elastomer",
            f"e{i}",
            p,
            stiffness_linear=[2.0e5, 2.0e5, k1],
            stiffness_cubic=[0.0, 0.0, k3],
            hysteresis={"ratio": share, "A": big_a, "beta": beta, "gamma": gamma},
        )
        for i, p in enumerate(corners(a, b))
    ]
    data = base_scene(m_, [0.0, 0.0, 0.0], inertia, layout)

    def z_of(x: float) -> float:
        return math.copysign(big_a / (beta + gamma) * -math.expm1(-(beta + gamma) * abs(x)), x)

    x0 = brentq(
        lambda x: share * (k1 * x + k3 * x**3) + (1 - share) * k1 * z_of(x) + m_ * G / 4,
        -0.1,
        0.0,
        xtol=1e-16,
    )
    assert abs(z_of(x0)) > 0.8 * abs(x0) * big_a  # off the curve's linear start: it counts
    kt = share * (k1 + 3 * k3 * x0 * x0) + (1 - share) * k1 * (big_a - gamma * abs(z_of(x0)))
    result = analyse(data)
    assert by_dominant(result, "z").frequency_hz == pytest.approx(
        math.sqrt(4 * kt / m_) / TWO_PI, rel=1e-6
    )
    assert by_dominant(result, "gamma").frequency_hz == pytest.approx(
        math.sqrt(4 * kt * a * a / inertia[1]) / TWO_PI, rel=1e-6
    )
    model = build(data)
    y_eq = initial_state(model, np.array([0.0, 0.0, G]))
    lam = np.linalg.eigvals(twin_jacobian(model, y_eq, gravity_u()))
    scale = np.abs(lam).max()
    twin = np.sort(lam.imag[lam.imag > 1e-6 * scale]) / TWO_PI
    np.testing.assert_allclose(frequencies(result), twin, rtol=1e-6)


def test_bolted_joints_enter_closed_with_a_stuck_face_and_keys_in_their_clearance_do_not() -> None:
    """Four bolted feet at (±a, ±b) in the CG's plane plus a shear key in its clearance. While
    the joint is closed (VDI 2230 joint diagram) the foot's axial force is
    (F_V − k_P·u) − (F_V + k_S·u): stiffness k_S + k_P; the stuck face holds shear with k_τ.
    Bounce √(4(k_S + k_P)/m), fore-aft and lateral √(4k_τ/m), roll √(4(k_S + k_P)·b²/I_xx),
    pitch √(4(k_S + k_P)·a²/I_yy), yaw √(4k_τ·(a² + b²)/I_zz), all over 2π; bounce damping
    4c_ax/(2m·ω)."""
    m_, a, b, ks, kp, ktau, c_ax = 2000.0, 1.0, 0.4, 7.0e8, 3.5e9, 1.0e9, 5.0e4
    inertia = [400.0, 900.0, 1100.0, 0.0, 0.0, 0.0]
    bolt = {
        "bolt_stiffness": ks,
        "clamp_stiffness": kp,
        "preload": 1.0e5,
        "yield_force": 1.57e5,
        "ultimate_force": 1.96e5,
        "shear_stiffness": ktau,
        "axial_damping": c_ax,
        "shear_damping": 2.0e4,
    }
    layout = [kind_mount("bolted_joint", f"f{i}", p, **bolt) for i, p in enumerate(corners(a, b))]
    layout.append(kind_mount("shear_key", "key", stiffness=[1.0e9, 0.0, 0.0], clearance=2.0e-4))
    result = analyse(base_scene(m_, [0.0, 0.0, 0.0], inertia, layout))
    axial = ks + kp
    w2 = [4 * axial / m_, 4 * ktau / m_, 4 * ktau / m_, 4 * axial * b * b / inertia[0]]
    w2 += [4 * axial * a * a / inertia[1], 4 * ktau * (a * a + b * b) / inertia[2]]
    np.testing.assert_allclose(frequencies(result), np.sqrt(np.sort(w2)) / TWO_PI, rtol=1e-6)
    bounce = by_dominant(result, "z")
    zeta = 4 * c_ax / (2 * m_ * bounce.frequency_hz * TWO_PI)
    assert bounce.damping_ratio == pytest.approx(zeta, rel=1e-6)
    assert result.mounts[-1].force_n == (0.0, 0.0, 0.0)


def test_a_face_the_weight_slid_enters_settled_on_its_bound_as_the_twin_starts() -> None:
    """A block hung on a wall by four bolts along x of F, a light preload: the weight shears
    each face past μ·F_V, so the faces slide and the shanks bear past their clearance c, each
    foot s = c + (m·g/4 − μ·F_V)/k_b down. The twin starts such a face with its stick point on
    its friction bound (`kinds.bolted_joint.settle`); modes were taken about the stick point
    zero, a face past its bound, which holds a lateral motion along y with μ·F_V/s (the
    capped force turning) instead of the stuck face's k_τ: 15.7 Hz where it is 24.5. Lateral
    y by hand: ω² = 4·(k_τ + k_b·(s − c)/s)/m (the shank bears radially)."""
    m_, ktau, mu, preload, kb, clear = 2000.0, 1.0e7, 0.3, 1.0e4, 5.0e8, 1.0e-3
    bolt = {
        "bolt_stiffness": 7.0e8,
        "clamp_stiffness": 3.5e9,
        "preload": preload,
        "yield_force": 1.57e5,
        "ultimate_force": 1.96e5,
        "friction": mu,
        "shear_stiffness": ktau,
        "hole_clearance": clear,
        "bearing_stiffness": kb,
    }
    feet = [(0.0, y, z) for y, z in ((0.4, 0.3), (-0.4, 0.3), (0.4, -0.3), (-0.4, -0.3))]
    wall = (0.0, math.pi / 2.0, 0.0)  # each bolt's axis (local z) along x of F
    layout = [kind_mount("bolted_joint", f"f{i}", p, wall, **bolt) for i, p in enumerate(feet)]
    result = analyse(base_scene(m_, [0.0, 0.0, 0.0], [300.0, 200.0, 250.0, 0.0, 0.0, 0.0], layout))
    shear = m_ * G / 4.0
    assert shear > mu * preload  # the faces slide: the shanks bear
    s = clear + (shear - mu * preload) / kb
    w2 = 4.0 * (ktau + kb * (s - clear) / s) / m_
    assert by_dominant(result, "y").frequency_hz == pytest.approx(math.sqrt(w2) / TWO_PI, rel=1e-6)


# ------------------------------------------------------------------ stiffness centre
def test_the_vertical_stiffness_centre_is_the_stiffness_weighted_centroid() -> None:
    """Vertical springs k_i at (x_i, y_i) (with lateral stiffness, CG high and off-centre): a
    vertical load through (Σk_i·x_i, Σk_i·y_i)/Σk_i meets the spring forces k_i·t in pure
    translation t, with no horizontal force, so it tilts nothing. About the unloaded pose
    (nominal gravity 0): under load the arms would turn with the body's tilt."""
    spots = [(0.7, 0.5, 3e5), (0.6, -0.4, 5e5), (-0.8, 0.45, 2e5), (-0.5, -0.5, 4e5)]
    layout = [
        mount(f"m{i}", (x, y, 0.0), (1e5, 1.5e5, k, 0, 0, 0)) for i, (x, y, k) in enumerate(spots)
    ]
    data = base_scene(MASS, [0.1, -0.05, 0.6], INERTIA, layout)
    data["input"]["g"] = 0.0
    result = analyse(data)
    total = sum(k for _, _, k in spots)
    want = [sum(k * x for x, _, k in spots) / total, sum(k * y for _, y, k in spots) / total]
    np.testing.assert_allclose(result.centre.force_lines_m["z"][:2], want, rtol=0, atol=1e-9)


def test_inclined_pairs_lower_the_lateral_force_line_as_the_closed_form() -> None:
    """Pairs at y = ±b with axial stiffness k_a along n = (0, ±sin φ, cos φ) (tops leaning
    outward, as in the bundled pump) and shear k_s across it, plus vertical mounts (k_s
    laterally). A lateral translation of the point at height z_c above the mounts loads each
    inclined mount with (k_a − k_s)·n_y·n_z vertically and k_a·n_y² + k_s·n_z² laterally; the
    moment about that point vanishes when z_c = −Σ y_i·K_zy,i / Σ K_yy,i (mirror and fore-aft
    symmetry keep the other couplings zero), a force along y through it neither rolls nor yaws
    the body."""
    b, phi, k_a, k_s = 0.4, math.radians(30.0), 1.2e6, 5.0e5
    layout = []
    for i, (x, y, _) in enumerate([*corners(0.9, b), *corners(0.3, b)]):
        roll = -math.copysign(phi, y) if abs(x) > 0.5 else 0.0
        layout.append(
            mount(f"m{i}", (x, y, 0.0), (k_s, k_s, k_a, 500, 500, 500), rpy_=(roll, 0, 0))
        )
    # CG over the layout's centre: the body sags without tilting, its arms stay as given
    result = analyse(base_scene(1200.0, [0.0, 0.0, 0.5], [250, 450, 500, 0, 0, 0], layout))
    ny, nz = math.sin(phi), math.cos(phi)
    k_yy = 4 * (k_a * ny * ny + k_s * nz * nz) + 4 * k_s
    k_zy = 4 * b * (k_a - k_s) * ny * nz
    x_line, _, z_line = result.centre.force_lines_m["y"]
    assert z_line == pytest.approx(-k_zy / k_yy, rel=1e-6)
    assert x_line == pytest.approx(0.0, abs=1e-9)


# ------------------------------------------------------------------ (f) sums
def test_energy_fractions_and_effective_masses_sum_as_they_must() -> None:
    data = base_scene(MASS, CG, INERTIA, LAYOUT)
    result = analyse(data)
    m, _ = independent_eigenproblem(data, True)
    for md in result.modes:
        assert sum(md.energy_fraction.values()) == pytest.approx(1.0, abs=1e-12)
        f = np.array(list(md.shape_in_f.values()))
        assert f @ m @ f == pytest.approx(1.0, rel=1e-9)  # mass-normalised about the CG in F
    for axis in "xyz":
        total = sum(md.effective_mass_kg[axis] for md in result.modes)
        assert total == pytest.approx(MASS, rel=1e-9)
    # about the axes of F through the CG: the inertia turned by the equilibrium's small tilt
    for j, axis in enumerate("xyz"):
        total = sum(md.effective_inertia_kg_m2[axis] for md in result.modes)
        assert total == pytest.approx(m[3 + j, 3 + j], rel=1e-9)
        assert total == pytest.approx(INERTIA[j], rel=1e-3)


def test_a_reduced_scene_sums_the_masses_of_its_free_directions_only() -> None:
    result = analyse(rao_car(G))
    assert sum(m.effective_mass_kg["z"] for m in result.modes) == pytest.approx(RAO["m"], rel=1e-9)
    for axis in "xy":
        assert sum(m.effective_mass_kg[axis] for m in result.modes) == 0.0


# ------------------------------------------------------------------ (g) the command
@pytest.mark.parametrize("scene", ["pump_8_mounts", "genset_bolted_keyed"])
def test_the_command_on_the_bundled_scenes(scene: str, capsys: pytest.CaptureFixture[str]) -> None:
    path = str(CONFIG / f"{scene}.scene.yaml")
    assert main(["modes", path]) == 0
    text = capsys.readouterr().out
    for heading in ("kinetic energy % by DOF", "effective mass kg", "static mount loads"):
        assert heading in text
    assert "elastic centre (least squares" in text and "vertical stiffness centre" in text
    assert main(["modes", path, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    freqs = [md["frequency_hz"] for md in doc["modes"]]
    assert len(freqs) == 6 and freqs == sorted(freqs) and freqs[0] > 0.0
    for md in doc["modes"]:
        assert sum(md["energy_fraction"].values()) == pytest.approx(1.0, abs=1e-9)
    mass = {"pump_8_mounts": 1200.0, "genset_bolted_keyed": 3000.0}[scene]
    for axis in "xyz":
        total = sum(md["effective_mass_kg"][axis] for md in doc["modes"])
        assert total == pytest.approx(mass, rel=1e-9)
    carried = np.sum([m["force_in_f_n"] for m in doc["mounts"]], axis=0)
    np.testing.assert_allclose(carried, [0.0, 0.0, mass * G], rtol=0, atol=1e-6 * mass * G)
    assert main(["modes", path, "--json", "--no-geometric"]) == 0
    elastic = json.loads(capsys.readouterr().out)
    assert elastic["geometric_stiffness"] is False
    # the weight on arms below the CG softens the rocking modes: the lowest one rises without it
    assert elastic["modes"][0]["frequency_hz"] > freqs[0]


def test_the_mounts_load_line_says_a_frozen_z_holds_the_weight(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The shake-table block (x free alone): its mounts carry none of the weight, and the line
    said "0.0, 0.0, 0.0 N (the weight, up)"."""
    block = CONFIG.parent / "test/data/shake_table_1story/block.scene.yaml"
    assert main(["modes", str(block)]) == 0
    said = capsys.readouterr().out
    assert "0.0 N (z is frozen: its constraint holds the weight, less what the mounts" in said


def test_modes_help_imports_no_numerics() -> None:
    """`--help` must answer at once: the command module imports only the standard library."""
    code = (
        "import sys\n"
        "from mount_twin.cli import main\n"
        "try:\n"
        "    main(['modes', '--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(sorted(m for m in ('mount_twin._core', 'numpy', 'scipy') if m in sys.modules))"
    )
    done = run_python("-c", code)
    assert done.returncode == 0, done.stderr
    assert "--no-geometric" in done.stdout
    assert done.stdout.splitlines()[-1] == "[]"
