"""The paper's attitude chart (α, γ, δ) with its corrected kinematics (physics notes §2–§4).

R is the rotation of the body frame B relative to F; R = Rz(δ)·Ry(−γ)·Rx(β) with
sin β = sin α / cos γ, cos β = cos θ / cos γ, and cos θ = R33 = √(cos²γ − sin²α) on the chart,
which is regular exactly where cos θ > 0 (|α| + |γ| < π/2). Angles in rad, rates in rad/s,
ω the body angular velocity relative to F in B.
"""

from __future__ import annotations

import math

import numpy as np


def rotation_matrix(alpha: float, gamma: float, delta: float) -> np.ndarray:
    """R(α, γ, δ) as a new array (NaN-filled off the chart); for use outside the hot path."""
    out = np.full((3, 3), math.nan)
    rotation_from_chart(
        math.sin(alpha), math.sin(gamma), math.cos(gamma), math.sin(delta), math.cos(delta), out
    )
    return out


def rotation_from_chart(
    sa: float, sg: float, cg: float, sd: float, cd: float, out: np.ndarray
) -> float:
    """Write R into `out` (3×3) from sin α, sin γ, cos γ, sin δ, cos δ; return cos θ.

    Off the chart (cos θ ≤ 0) returns NaN and leaves `out` untouched.
    """
    c2 = cg * cg - sa * sa
    if not (c2 > 0.0 and cg > 0.0):  # |γ| < π/2 too: cos γ < 0 would alias another attitude
        return math.nan
    ct = math.sqrt(c2)
    sb, cb = sa / cg, ct / cg
    # Ry(−γ)·Rx(β), then rotate its first two rows by δ about z.
    r1 = (cg, -sg * sb, -sg * cb)
    r2 = (0.0, cb, -sb)
    for j in range(3):
        out[0, j] = cd * r1[j] - sd * r2[j]
        out[1, j] = sd * r1[j] + cd * r2[j]
    out[2, 0] = sg
    out[2, 1] = sa
    out[2, 2] = ct
    return ct


def chart_from_rotation(rot: np.ndarray) -> tuple[float, float, float]:
    """(α, γ, δ) of a rotation matrix with R33 > 0 (caller checks)."""
    return math.asin(rot[2, 1]), math.asin(rot[2, 0]), math.atan2(rot[1, 0], rot[0, 0])


def kinematic_matrix(
    sa: float, ca: float, sg: float, cg: float, ct: float, out: np.ndarray
) -> None:
    """B with ω = B·[α', γ', δ'] (physics notes §3; the paper's eq. 15 lacks a 1/cos γ).

    Takes sin α, cos α, sin γ, cos γ, cos θ: the caller has them, and trigonometry dominates.
    """
    out[0, 0] = ca / ct
    out[0, 1] = sa * sg / (cg * ct)
    out[0, 2] = sg
    out[1, 0] = 0.0
    out[1, 1] = -ct / cg
    out[1, 2] = sa
    out[2, 0] = 0.0
    out[2, 1] = sa / cg
    out[2, 2] = ct


def kinematic_matrix_rate(
    sa: float,
    ca: float,
    sg: float,
    cg: float,
    ct: float,
    alpha_dot: float,
    gamma_dot: float,
    out: np.ndarray,
) -> None:
    """dB/dt along the motion (entry-wise chain rule of `kinematic_matrix`), 1/s."""
    ct_dot = -(alpha_dot * sa * ca + gamma_dot * sg * cg) / ct
    sa_dot, sg_dot = ca * alpha_dot, cg * gamma_dot
    ca_dot, cg_dot = -sa * alpha_dot, -sg * gamma_dot
    out[0, 0] = (ca_dot * ct - ca * ct_dot) / ct**2
    num, den = sa * sg, cg * ct
    out[0, 1] = ((sa_dot * sg + sa * sg_dot) * den - num * (cg_dot * ct + cg * ct_dot)) / den**2
    out[0, 2] = sg_dot
    out[1, 0] = 0.0
    out[1, 1] = -(ct_dot * cg - ct * cg_dot) / cg**2
    out[1, 2] = sa_dot
    out[2, 0] = 0.0
    out[2, 1] = (sa_dot * cg - sa * cg_dot) / cg**2
    out[2, 2] = ct_dot


def chart_rates(
    alpha: float, gamma: float, ct: float, omega: np.ndarray
) -> tuple[float, float, float]:
    """[α', γ', δ'] = B⁻¹·ω in closed form (physics notes §3)."""
    sa, ca = math.sin(alpha), math.cos(alpha)
    sg, cg = math.sin(gamma), math.cos(gamma)
    delta_dot = (omega[1] * sa + omega[2] * ct) / cg**2
    gamma_dot = cg * (delta_dot * sa - omega[1]) / ct
    alpha_dot = (omega[0] * ct - gamma_dot * sa * sg / cg - delta_dot * ct * sg) / ca
    return alpha_dot, gamma_dot, delta_dot
