"""Six-component linear Kelvin–Voigt mount (physics notes §7).

Parameters, per mount i, are pre-rotated at scene load into F: K_t = Q·diag(kx, ky, kz)·Qᵀ,
C_t, K_r, C_r likewise, with Q the mount axes in F. Deformation is measured from the reference
pose, where the mount is unstressed.

The rotational spring and damper act on the rotation vector φ of the body's attitude: they give
a generalized force g = K_r·φ + C_r·φ′ conjugate to φ, and its couple on the body is −J(φ)⁻ᵀ·g
(`rotations.couple_map`). The spring is then the gradient of ½ φᵀK_rφ, conservative at any
rotation, anisotropic or not; the couple −K_r·φ, its small-rotation limit, is not (an
undamped body on anisotropic rotational springs turned 0.4 rad drifted by 9 % of its energy).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def point_motion(
    i: int,
    point: np.ndarray,
    rot: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    omega_f: np.ndarray,
    arm: np.ndarray,
) -> tuple[float, float, float, float, float, float]:
    """Displacement d (m) and velocity ḋ (m/s) in F of body point i from its reference position:
    d = q + R·p − p, ḋ = q̇ + (R ω) × (R p). Writes the lever arm R·p (m, F) into `arm`.

    Args: point (n, 3) points p from the CG in B; rot R; q, qd (6,) coordinates and rates;
    omega_f body angular velocity relative to F in F, rad/s.
    """
    for j in range(3):
        arm[j] = rot[j, 0] * point[i, 0] + rot[j, 1] * point[i, 1] + rot[j, 2] * point[i, 2]
    return (
        q[0] + arm[0] - point[i, 0],
        q[1] + arm[1] - point[i, 1],
        q[2] + arm[2] - point[i, 2],
        qd[0] + omega_f[1] * arm[2] - omega_f[2] * arm[1],
        qd[1] + omega_f[2] * arm[0] - omega_f[0] * arm[2],
        qd[2] + omega_f[0] * arm[1] - omega_f[1] * arm[0],
    )


@njit(cache=True, inline="always")
def _generalized(
    i: int, j: int, k_r: np.ndarray, c_r: np.ndarray, phi: np.ndarray, phi_rate: np.ndarray
) -> float:
    """Component j of mount i's generalized force K_r·φ + C_r·φ′ (N·m)."""
    return (
        k_r[i, j, 0] * phi[0]
        + k_r[i, j, 1] * phi[1]
        + k_r[i, j, 2] * phi[2]
        + c_r[i, j, 0] * phi_rate[0]
        + c_r[i, j, 1] * phi_rate[1]
        + c_r[i, j, 2] * phi_rate[2]
    )


@njit(cache=True, inline="always")
def linear_mount_load(
    i: int,
    point: np.ndarray,
    k_t: np.ndarray,
    c_t: np.ndarray,
    k_r: np.ndarray,
    c_r: np.ndarray,
    rot: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    omega_f: np.ndarray,
    phi: np.ndarray,
    phi_rate: np.ndarray,
    cmap: np.ndarray,
    arm: np.ndarray,
    force: np.ndarray,
    couple: np.ndarray,
) -> None:
    """Load of mount i on the body, in F (the arrays hold every mount; indexing them, rather
    than slicing, keeps this free of array-view bookkeeping on the hot path).

    Args:
        i: mount index.
        point: (n, 3) attachment points p from the CG, m, in B.
        k_t, c_t, k_r, c_r: (n, 3, 3) stiffness (N/m, N·m/rad), damping (N·s/m, N·m·s/rad) in F.
        rot: R, body attitude relative to F.
        q, qd: (6,) generalized coordinates (m, rad) and rates; q[:3] is the CG displacement
            from the reference pose, in F.
        omega_f: body angular velocity relative to F, expressed in F (R·ω), rad/s.
        phi: rotation vector of R, rad, in F.
        phi_rate: its rate φ′, rad/s.
        cmap: J(φ)⁻ᵀ, the couple of a generalized force conjugate to φ (module docstring).
        arm: out, R·p (m, F), the lever arm of `force` about the CG.
        force: out, force on the body at the attachment point, N, in F.
        couple: out, the mount's own couple on the body, N·m, in F.
    """
    d0, d1, d2, e0, e1, e2 = point_motion(i, point, rot, q, qd, omega_f, arm)
    for j in range(3):
        force[j] = -(
            k_t[i, j, 0] * d0
            + k_t[i, j, 1] * d1
            + k_t[i, j, 2] * d2
            + c_t[i, j, 0] * e0
            + c_t[i, j, 1] * e1
            + c_t[i, j, 2] * e2
        )
    g0 = _generalized(i, 0, k_r, c_r, phi, phi_rate)
    g1 = _generalized(i, 1, k_r, c_r, phi, phi_rate)
    g2 = _generalized(i, 2, k_r, c_r, phi, phi_rate)
    for j in range(3):
        couple[j] = -(cmap[j, 0] * g0 + cmap[j, 1] * g1 + cmap[j, 2] * g2)
