"""A new machine's hysteretic mounts at the start: loaded slowly from unloaded.

A Bouc–Wen state z (`kinds.elastomer`) records its axis's history, and at rest every z is one:
ż = A·ẋ − β·|ẋ|·|z|ⁿ⁻¹·z − γ·ẋ·|z|ⁿ vanishes with ẋ whatever z is, so the static equilibrium
alone does not say where a start's z lies. Taken as zero, the elastic share a·F_el alone carries
the weight, and a mount with a = 0.3 starts sagging 3.3 times its tangent's sag. A machine is
set down on its mounts slowly: each hysteretic axis loads monotonically from (x, z) = (0, 0),
along which ẋ·z ≥ 0 and

    dz/dx = A − (β + γ)·|z|ⁿ,

the virgin loading curve z = Z(x) (odd in x). Its inverse has a closed form,

    x(z) = (z / A) · ₂F₁(1, 1/n; 1 + 1/n; (β + γ)·|z|ⁿ / A),

(n = 1: −ln(1 − (β + γ)·z/A)/(β + γ); n = 2: artanh(z/z_u)/√(A·(β + γ)), z_u = √(A/(β + γ))),
taken here by bisection on z/z_u ∈ [0, 1), z_u = (A/(β + γ))^(1/n) the curve's asymptote.
The start's equilibrium then solves for the pose with each z at Z(x) of its axis's deflection
(`model.assemble.static_equilibrium`); a restart keeps the z its run left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.kinds import ELASTOMER, elastomer
from mount_twin.physics.dynamics import ModelArrays, Scratch, mount_deflections

BISECTIONS = 64
"""Halvings of the bracket of z/z_u: past the 53 bits of a double."""


@dataclass(frozen=True)
class VirginAxes:
    """The hysteretic axes of a model (h of them), as the start's equilibrium loads them.

    state: int64 (h,) index of each z in the state y; mount: int64 (h,) its row among the
    non-linear mounts; axis: int64 (h,) its local axis (0 x, 1 y, 2 z); a, c, n: (h,) its
    Bouc–Wen A, β + γ (1/mⁿ) and n.
    """

    state: np.ndarray
    mount: np.ndarray
    axis: np.ndarray
    a: np.ndarray
    c: np.ndarray
    n: np.ndarray

    def z(self, x: np.ndarray) -> np.ndarray:
        """Z(x): each axis's z after loading monotonically from (0, 0) to deflection x (m)."""
        return virgin_z(self.a, self.c, self.n, x)

    def slope(self, z: np.ndarray) -> np.ndarray:
        """dz/dx on the loading curve at z: A − (β + γ)·|z|ⁿ."""
        return self.a - self.c * np.abs(z) ** self.n

    def deflections(self, y: np.ndarray, m: ModelArrays, s: Scratch, d: np.ndarray) -> np.ndarray:
        """Each axis's deflection (m) at y (d: (k, 3) work); NaN off the chart."""
        if not mount_deflections(y, m, s, d) > 0.0:
            return np.full(self.state.shape[0], np.nan)
        return d[self.mount, self.axis]


def virgin_z(a: np.ndarray, c: np.ndarray, n: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Bouc–Wen z after loading monotonically from (x, z) = (0, 0) to x (m), per element:
    the inverse of the module docstring's x(z) (A > 0, β + γ = c > 0 (1/mⁿ), n ≥ 1)."""
    from scipy.special import hyp2f1  # 0.2 s to import: only scenes with hysteresis

    z_u = (a / c) ** (1.0 / n)
    target = np.abs(x)
    # z/z_u is bracketed by n = 1's curve below (dz/dx = A·(1 − (z/z_u)ⁿ) ≥ A·(1 − z/z_u)) and
    # the tangent at 0 above: a bracket as narrow as z is small, so the halvings resolve z
    # relative to itself, not to z_u
    reach = a * target / z_u
    lo, hi = -np.expm1(-reach), np.minimum(reach, 1.0)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        reached = z_u * mid / a * hyp2f1(1.0, 1.0 / n, 1.0 + 1.0 / n, mid**n)
        below = reached < target
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return np.copysign(z_u * 0.5 * (lo + hi), x)


def virgin_axes(m: ModelArrays) -> VirginAxes | None:
    """The model's hysteretic axes; None without any."""
    nl = m.nl
    if nl is None:
        return None
    rows: list[tuple[int, int, int, float, float, float]] = []
    for i in np.flatnonzero(nl.kind == ELASTOMER).tolist():
        p = nl.par[i]
        for j in range(3):
            b = j * elastomer.N_AXIS
            slot = int(p[b + elastomer.ZSLOT])
            if slot >= 0:
                a, n = p[b + elastomer.BW_A], p[b + elastomer.N_EXP]
                c = p[b + elastomer.BETA] + p[b + elastomer.GAMMA]
                rows.append((int(nl.state[i]) + slot, i, j, a, c, n))
    if not rows:
        return None
    cols = list(zip(*rows, strict=True))
    index = [np.array(col, dtype=np.int64) for col in cols[:3]]
    values = [np.array(col, dtype=float) for col in cols[3:]]
    return VirginAxes(*index, *values)
