"""The φ functions of a matrix, φ_k(hJ) for k = 1, 2, 3, compiled and allocation-free: what an
exponential integrator multiplies by (`exprb32`).

φ_0(z) = e^z, φ_k(z) = Σ_{i≥0} z^i/(i + k)!; the solution of y' = Jy + b + c·t from y_0 over h
is y_0 + hφ_1(hJ)(Jy_0 + b) + h²φ_2(hJ)c, exactly.

How (Higham, *Functions of Matrices*, §10.3; Skaflestad & Wright, "The scaling and modified
squaring method for matrix functions related to the exponential", Appl. Numer. Math. 59 (2009)):
1. balance A = hJ by a diagonal similarity of powers of two, D⁻¹AD (Parlett & Reinsch, as
   LAPACK's gebal): a mechanical Jacobian mixes rows of 1 (dx/dt = v) with rows of k/m (1e8 for
   a light body on bolts); balanced, its norm is near its spectral radius;
2. scale by 2^−s until the 1-norm is at most THETA = 1, and sum TERMS = 19 terms of each Taylor
   series (z^0 … z^18: the remainder of e^z at ‖z‖ ≤ 1 is below 1/19! ≈ 8e-18);
3. square back s times: e^(2z) = (e^z)², φ_k(2z) = 2^−k [e^z φ_k(z) + Σ_{j=1..k} φ_j(z)/(k−j)!];
4. undo the balancing: φ_k(A) = D φ_k(D⁻¹AD) D⁻¹.

Work: blocks of n rows in the caller's 2-D work array, given by their first row (`Blocks`).
The implementation and its constants are the core's: src/core/integrate/phi.hpp.
"""

from __future__ import annotations

from typing import NamedTuple

from mount_twin import _core


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


phi_functions = _core.phi_functions
"""phi_functions(k, n, h, b) -> bool: φ_1, φ_2, φ_3 of h·J (h in s, J = k[b.j : b.j + n] in 1/s)
into k[b.p1 : b.p1 + 3n], using k[b.z : b.z + 4n] and the row k[b.scale] as work (b: `Blocks`);
False if they are not finite (J with NaN or inf). src/core/integrate/phi.hpp."""
