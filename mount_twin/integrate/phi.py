"""The φ functions of a matrix, φ_k(hJ) for k = 1, 2, 3, compiled and allocation-free: what an
exponential integrator multiplies by (`exprb32`).

φ_0(z) = e^z, φ_k(z) = Σ_{i≥0} z^i/(i + k)!; the solution of y' = Jy + b + c·t from y_0 over h
is y_0 + hφ_1(hJ)(Jy_0 + b) + h²φ_2(hJ)c, exactly.

How (Higham, *Functions of Matrices*, §10.3; Skaflestad & Wright, "The scaling and modified
squaring method for matrix functions related to the exponential", Appl. Numer. Math. 59 (2009)):
1. balance A = hJ by a diagonal similarity of powers of two, D⁻¹AD (Parlett & Reinsch, as
   LAPACK's gebal): a mechanical Jacobian mixes rows of 1 (dx/dt = v) with rows of k/m (1e8 for
   a light body on bolts); balanced, its norm is near its spectral radius;
2. scale by 2^−s until the 1-norm is at most THETA, and sum TERMS terms of each Taylor series
   (truncation below 1e-18 of the norm);
3. square back s times: e^(2z) = (e^z)², φ_k(2z) = 2^−k [e^z φ_k(z) + Σ_{j=1..k} φ_j(z)/(k−j)!];
4. undo the balancing: φ_k(A) = D φ_k(D⁻¹AD) D⁻¹.

Work: blocks of n rows in the caller's 2-D work array, given by their first row (`Blocks`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

from mount_twin.physics.compiled import kernel

THETA = 1.0
"""Largest 1-norm of the scaled matrix summed by Taylor series."""
TERMS = 19
"""Taylor terms z^0 … z^18: the remainder of e^z at ‖z‖ ≤ 1 is below 1/19! ≈ 8e-18."""
MAX_BALANCE_SWEEPS = 64
"""Sweeps of the balancing at most (it converges in a few)."""


class Blocks(NamedTuple):
    """First rows of the n-row blocks of a work array the φ functions use (each row n wide).

    j: the matrix J (read); p1: φ_1, φ_2, φ_3 of hJ, in three consecutive blocks (written);
    z: four consecutive work blocks (the scaled matrix, its power, a product, e^z);
    scale: one row for the balancing's diagonal.
    """

    j: int
    p1: int
    z: int
    scale: int


@njit(cache=True, inline="always")
def _matmul(k, a, b, out, n) -> None:
    """k[out:out+n] = k[a:a+n] @ k[b:b+n] (out distinct from a and b)."""
    for r in range(n):
        for c in range(n):
            k[out + r, c] = 0.0
        for q in range(n):
            x = k[a + r, q]
            if x != 0.0:
                for c in range(n):
                    k[out + r, c] += x * k[b + q, c]


@njit(cache=True, inline="always")
def _balance(k, z, sc, n) -> None:
    """Balance k[z:z+n] in place by a diagonal similarity D⁻¹ A D of powers of two; D's
    diagonal into k[sc]."""
    for i in range(n):
        k[sc, i] = 1.0
    for _ in range(MAX_BALANCE_SWEEPS):
        done = True
        for i in range(n):
            c, r = 0.0, 0.0
            for j in range(n):
                if j != i:
                    c += abs(k[z + j, i])
                    r += abs(k[z + i, j])
            if c == 0.0 or r == 0.0:
                continue
            total, f = c + r, 1.0
            while c < r / 2.0:
                f *= 2.0
                c *= 4.0
            while c > r * 2.0:
                f /= 2.0
                c /= 4.0
            if (c + r) / f < 0.95 * total:
                done = False
                k[sc, i] *= f
                for j in range(n):
                    k[z + i, j] /= f
                    k[z + j, i] *= f
        if done:
            return


@kernel
def phi_functions(k, n, h, b) -> bool:
    """φ_1, φ_2, φ_3 of h·J into the blocks from b.p1 (J at b.j, `Blocks`); False if they are
    not finite (J with NaN or inf)."""
    z, pw, tmp, e, sc = b.z, b.z + n, b.z + 2 * n, b.z + 3 * n, b.scale
    p1, p2, p3 = b.p1, b.p1 + n, b.p1 + 2 * n
    for r in range(n):
        for c in range(n):
            k[z + r, c] = h * k[b.j + r, c]
    _balance(k, z, sc, n)
    norm = 0.0
    for c in range(n):
        col = 0.0
        for r in range(n):
            col += abs(k[z + r, c])
        norm = max(norm, col)
    if not math.isfinite(norm):
        return False
    squarings = max(0, math.ceil(math.log2(norm / THETA))) if norm > THETA else 0
    shrink = 2.0**-squarings
    for r in range(n):
        for c in range(n):
            k[z + r, c] *= shrink
            k[pw + r, c] = 1.0 if r == c else 0.0  # z^0
            k[e + r, c] = 0.0
            k[p1 + r, c] = 0.0
            k[p2 + r, c] = 0.0
            k[p3 + r, c] = 0.0
    # Taylor: term i adds z^i/i!, z^i/(i+1)!, z^i/(i+2)!, z^i/(i+3)!
    fact = 1.0  # i!
    for i in range(TERMS):
        if i > 0:
            fact *= i
            _matmul(k, pw, z, tmp, n)
            for r in range(n):
                for c in range(n):
                    k[pw + r, c] = k[tmp + r, c]
        w0 = 1.0 / fact
        w1 = w0 / (i + 1)
        w2 = w1 / (i + 2)
        w3 = w2 / (i + 3)
        for r in range(n):
            for c in range(n):
                x = k[pw + r, c]
                k[e + r, c] += w0 * x
                k[p1 + r, c] += w1 * x
                k[p2 + r, c] += w2 * x
                k[p3 + r, c] += w3 * x
    # square back: each doubling uses the old φ_1, φ_2 in the higher ones, so φ_3 goes first
    for _ in range(squarings):
        _matmul(k, e, p3, tmp, n)
        for r in range(n):
            for c in range(n):
                k[p3 + r, c] = (
                    k[tmp + r, c] + 0.5 * k[p1 + r, c] + k[p2 + r, c] + k[p3 + r, c]
                ) / 8.0
        _matmul(k, e, p2, tmp, n)
        for r in range(n):
            for c in range(n):
                k[p2 + r, c] = (k[tmp + r, c] + k[p1 + r, c] + k[p2 + r, c]) / 4.0
        _matmul(k, e, p1, tmp, n)
        for r in range(n):
            for c in range(n):
                k[p1 + r, c] = (k[tmp + r, c] + k[p1 + r, c]) / 2.0
        _matmul(k, e, e, tmp, n)
        for r in range(n):
            for c in range(n):
                k[e + r, c] = k[tmp + r, c]
    finite = True
    for r in range(n):  # undo the balancing: φ(A) = D φ(D⁻¹AD) D⁻¹
        for c in range(n):
            ratio = k[sc, r] / k[sc, c]
            k[p1 + r, c] *= ratio
            k[p2 + r, c] *= ratio
            k[p3 + r, c] *= ratio
            finite = finite and math.isfinite(k[p3 + r, c]) and math.isfinite(k[p1 + r, c])
    return finite
