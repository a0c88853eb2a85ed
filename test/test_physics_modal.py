"""Linear mounts: static equilibrium and small-motion natural frequencies (notes §7, §8).

Truth: my own 6×6 stiffness K6 = Σ Tᵢᵀ Kᵢ Tᵢ (Kᵢ = Q diag(k) Qᵀ, Tᵢ = [I, −[pᵢ]×]) plus the
rotational springs plus the geometric stiffness of the gravity preload, with the mass matrix
diag(m, m, m, I), solved as a generalized eigenproblem (scipy.linalg.eigh); my own force and
moment balance; and Z = −m g / Σ k_z for symmetric vertical mounts. The twin side is the
numerical state Jacobian of its right-hand side about its static equilibrium, damping zero:
eigenvalues ±iω. At the equilibrium the chart coordinates' Jacobian to small rotations is a
constant similarity, so the frequencies must match.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from physics_helpers import (
    G,
    base_scene,
    build,
    chart_to_matrix_ref,
    gravity_u,
    inertia_tensor,
    mount,
    mount_frames,
    mount_wrench_ref,
    natural_frequencies_from_jacobian,
    rpy,
    skew,
    spring_couple_ref,
    spring_tangent_ref,
    twin_jacobian,
)
from scipy.spatial.transform import Rotation

from mount_twin.model.assemble import initial_state
from mount_twin.physics.dynamics import evaluate

MASS = 300.0
CG = [0.05, -0.03, 0.45]  # CG 0.45 m above the mount plane, off-centre
INERTIA6 = [60.0, 90.0, 110.0, -4.0, 7.0, 3.0]
SCALE = 0.5  # softness of the mounts: static sag ~2 mm, geometric stiffness ~0.3 %
ASYMMETRIC_MOUNTS = [
    mount(
        "a",
        [0.6, 0.35, 0.0],
        [3e5 * SCALE, 2.5e5 * SCALE, 8e5 * SCALE, 300, 200, 100],
        rpy_=(-0.5, 0.0, 0.0),
    ),
    mount(
        "b",
        [0.55, -0.4, 0.0],
        [3e5 * SCALE, 2.5e5 * SCALE, 8e5 * SCALE, 300, 200, 100],
        rpy_=(0.5, 0.1, 0.0),
    ),
    mount("c", [-0.5, 0.3, 0.02], [2e5 * SCALE, 2e5 * SCALE, 6e5 * SCALE, 0, 0, 0]),
    mount(
        "d",
        [-0.6, -0.35, 0.0],
        [2e5 * SCALE, 3e5 * SCALE, 7e5 * SCALE, 50, 80, 20],
        rpy_=(0.0, -0.3, 0.4),
    ),
    mount(
        "e",
        [0.0, 0.0, 0.1],
        [1e5 * SCALE, 1e5 * SCALE, 2e5 * SCALE, 400, 400, 400],
        rpy_=(0.2, 0.3, 0.1),
    ),
]


@pytest.fixture(scope="module")
def asymmetric():
    data = base_scene(MASS, CG, INERTIA6, ASYMMETRIC_MOUNTS)
    model = build(data)
    y_eq = initial_state(model, np.array([0.0, 0.0, G]))
    jac = twin_jacobian(model, y_eq, gravity_u())
    return {
        "data": data,
        "y_eq": y_eq,
        "r0": y_eq[:3].copy(),
        "rot0": chart_to_matrix_ref(*y_eq[3:6]),
        "twin_omegas": natural_frequencies_from_jacobian(jac),
        "jac": jac,
    }


def stiffness_6x6(frames, rot0, r0, geometric: bool, arms_at_equilibrium: bool) -> np.ndarray:
    """K6 about the CG (F) per the notes §7; arms pᵢ at the reference pose, or R0·pᵢ."""
    _, _, preload = mount_wrench_ref(frames, r0, rot0)
    k6 = np.zeros((6, 6))
    for fr, f0 in zip(frames, preload, strict=True):
        p = rot0 @ fr["p"] if arms_at_equilibrium else fr["p"]
        t = np.hstack([np.eye(3), -skew(p)])
        k6 += t.T @ fr["kt"] @ t
        k6[3:, 3:] += fr["kr"]
        if geometric:
            k6[3:, 3:] += (f0 @ p) * np.eye(3) - np.outer(p, f0)
    return k6


def mass_6x6(rot0: np.ndarray) -> np.ndarray:
    m6 = np.zeros((6, 6))
    m6[:3, :3] = MASS * np.eye(3)
    m6[3:, 3:] = rot0 @ inertia_tensor(*INERTIA6) @ rot0.T
    return m6


def test_static_equilibrium_balances_gravity_with_an_independent_mount_model(asymmetric):
    frames = mount_frames(asymmetric["data"])
    force, moment, _ = mount_wrench_ref(frames, asymmetric["r0"], asymmetric["rot0"])
    weight = MASS * G
    np.testing.assert_allclose(force, [0.0, 0.0, weight], rtol=0, atol=1e-9 * weight)
    np.testing.assert_allclose(moment, np.zeros(3), rtol=0, atol=1e-9 * weight * 1.0)
    # the scene is asymmetric enough that the body settles tilted
    assert np.max(np.abs(asymmetric["y_eq"][3:6])) > 1e-4


def test_published_mount_wrenches_equal_the_independent_mount_law_in_mount_axes(asymmetric):
    """Notes §7: force on the body and the mount's own couple −J_l⁻ᵀ(φ)·Q K_r Qᵀ φ, in the
    mount's axes."""
    data = asymmetric["data"]
    model = build(data)
    pose = np.zeros(10)
    wrenches = np.zeros((len(data["mounts"]), 6))
    ct = evaluate(asymmetric["y_eq"].copy(), model.arrays, model.new_scratch(), pose, wrenches)
    assert ct > 0.0
    frames = mount_frames(data)
    rot0 = asymmetric["rot0"]
    _, _, forces = mount_wrench_ref(frames, asymmetric["r0"], rot0)
    weight = MASS * G
    for mt, fr, f, w in zip(data["mounts"], frames, forces, wrenches, strict=True):
        q = rpy(*mt["orientation_rpy"])
        np.testing.assert_allclose(w[:3], q.T @ f, rtol=0, atol=1e-9 * weight)
        couple = spring_couple_ref(fr["kr"], rot0)
        np.testing.assert_allclose(w[3:], q.T @ couple, rtol=0, atol=1e-12)
    # their forces, back in F, carry the weight
    total = sum(
        rpy(*mt["orientation_rpy"]) @ w[:3] for mt, w in zip(data["mounts"], wrenches, strict=True)
    )
    np.testing.assert_allclose(total, [0.0, 0.0, weight], rtol=0, atol=1e-9 * weight)
    # the published pose is the equilibrium: CG, quaternion and chart angles agree
    np.testing.assert_allclose(pose[:3], np.array(CG) + asymmetric["r0"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(pose[7:10], asymmetric["y_eq"][3:6], rtol=0, atol=0)
    angle = np.linalg.norm(
        (Rotation.from_quat(pose[3:7]).inv() * Rotation.from_matrix(rot0)).as_rotvec()
    )
    assert angle < 1e-14


def test_small_motion_frequencies_match_the_6x6_eigenproblem_with_geometric_stiffness(asymmetric):
    frames = mount_frames(asymmetric["data"])
    k6 = stiffness_6x6(
        frames, np.eye(3), asymmetric["r0"], geometric=True, arms_at_equilibrium=False
    )
    # the preload's geometric stiffness is symmetric only up to the static moment balance
    omega2 = scipy.linalg.eigh(0.5 * (k6 + k6.T), mass_6x6(np.eye(3)), eigvals_only=True)
    omegas = np.sqrt(omega2)
    rel = np.abs(asymmetric["twin_omegas"] - omegas) / omegas
    assert np.all(omegas / (2 * np.pi) > 2.0) and np.all(omegas / (2 * np.pi) < 20.0)
    assert rel.max() < 1e-4, (
        f"twin frequencies {asymmetric['twin_omegas'] / (2 * np.pi)} Hz vs 6×6 eigenproblem "
        f"{omegas / (2 * np.pi)} Hz: relative error {rel.max():.3g}"
    )


def test_frequencies_match_the_exact_linearization_about_the_tilted_equilibrium(asymmetric):
    """Same K6 taken about the actual equilibrium: arms R0·pᵢ, inertia R0 I R0ᵀ, and the
    tangent of the rotational springs' couples there (`spring_tangent_ref`), so the agreement
    is exact."""
    frames = mount_frames(asymmetric["data"])
    rot0 = asymmetric["rot0"]
    k6 = stiffness_6x6(frames, rot0, asymmetric["r0"], geometric=True, arms_at_equilibrium=True)
    for fr in frames:
        k6[3:, 3:] += spring_tangent_ref(fr["kr"], rot0) - fr["kr"]
    omegas = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(mass_6x6(rot0), k6)).real))
    rel = np.abs(asymmetric["twin_omegas"] - omegas) / omegas
    assert rel.max() < 1e-8, f"relative frequency error {rel.max():.3g}"


def test_the_twin_reproduces_the_geometric_stiffness_of_the_preload(asymmetric):
    """Leaving K_geo out must make the reference miss by far more than the tolerance above."""
    frames = mount_frames(asymmetric["data"])
    k6 = stiffness_6x6(
        frames, np.eye(3), asymmetric["r0"], geometric=False, arms_at_equilibrium=False
    )
    omegas = np.sqrt(scipy.linalg.eigh(k6, mass_6x6(np.eye(3)), eigvals_only=True))
    rel = np.abs(asymmetric["twin_omegas"] - omegas) / omegas
    assert rel.max() > 1e-3, (
        f"without preload stiffness the reference still agrees ({rel.max():.3g})"
    )


def test_undamped_twin_has_no_modal_damping_or_instability(asymmetric):
    real = np.linalg.eigvals(asymmetric["jac"]).real
    scale = asymmetric["twin_omegas"].max()
    assert np.max(np.abs(real)) < 1e-6 * scale, f"largest |Re λ| = {np.max(np.abs(real)):.3g} 1/s"


@pytest.mark.parametrize("cg_height", [0.0, 0.6])
def test_static_sag_on_symmetric_vertical_mounts_is_weight_over_total_vertical_stiffness(
    cg_height,
):
    # front pair softer but farther out than the rear pair: Σ k_z·x = 4e5·0.6·2 − 6e5·0.4·2 = 0,
    # so the elastic centre is under the CG and the sag is a pure translation
    layout = [(0.6, 0.3, 4.0e5), (0.6, -0.3, 4.0e5), (-0.4, 0.3, 6.0e5), (-0.4, -0.3, 6.0e5)]
    kz = [k for _, _, k in layout]
    mounts = [
        mount(f"m{i}", [x, y, 0.0], [2e5, 2e5, k, 100.0, 100.0, 100.0])
        for i, (x, y, k) in enumerate(layout)
    ]
    mass = 500.0
    data = base_scene(mass, [0.0, 0.0, cg_height], [40.0, 60.0, 80.0, 0.0, 0.0, 0.0], mounts)
    model = build(data)
    y_eq = initial_state(model, np.array([0.0, 0.0, G]))
    expected = -mass * G / sum(kz)
    assert y_eq[2] == pytest.approx(expected, rel=1e-9), (
        f"Z = {y_eq[2]!r} m, expected −m g/Σk_z = {expected!r} m"
    )
    np.testing.assert_allclose(y_eq[[0, 1, 3, 4, 5]], 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(y_eq[6:], 0.0, rtol=0, atol=0)
