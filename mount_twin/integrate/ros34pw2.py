"""ROS34PW2: a linearly implicit (Rosenbrock–Wanner) method for stiff scenes, L-stable.

Rang & Angermann, "New Rosenbrock W-methods of order 3 for partial differential algebraic
equations of index 1", BIT 45 (2005) 761–787: 4 stages, order 3 with an embedded order-2
estimate, stiffly accurate, L-stable (R(∞) = 0), and a W-method: its order holds with any
approximation of the Jacobian. A stiff mode (keys and bolts at 1e9–1e10 N/m under a light body)
is then damped, not resolved: the explicit Dormand–Prince must take steps shorter than about
3.3/ω_max whatever the tolerance, this method takes the steps the accuracy asks for.

The Jacobian J = ∂f/∂y is taken by finite differences of the compiled right-hand side
(`fd_jacobian`) at the start of an interval once the one held has served JACOBIAN_MAX_AGE
intervals (or none is held: `control.forget`), and again at the first rejected step of an
interval it did not start; ∂f/∂t (the input's slopes) every
interval (1 evaluation). Each step solves, for its four stages,
(I − hγJ)·k_i = h·f(t + α_i h, y + Σ α_ij k_j) + h·J·Σ γ_ij k_j + h²·γ_i·∂f/∂t
through one LU factorisation (partial pivoting, in place); y ← y + Σ b_i k_i, and
Σ (b_i − b̂_i)·k_i estimates the local error (RMS norm as Dormand–Prince).
After each accepted step the right-hand side is evaluated at the new state, so on success the
scratch holds the body motion at (t1, y) as `outputs` requires. Not first-same-as-last: the
chain flag is always left at 0.

Work arrays: `work_rows(n)` rows of n (stages, f, the stage state, Σγk, ∂f/∂t, pivots, J, LU).
"""

from __future__ import annotations

import numpy as np

from mount_twin import _core

GAMMA = 0.435866521508459
ALPHA = np.array(
    [
        [0.0, 0.0, 0.0],
        [0.87173304301691801, 0.0, 0.0],
        [0.84457060015369423, -0.11299064236484185, 0.0],
        [0.0, 0.0, 1.0],
    ]
)
"""α_ij, j < i: the stage states y + Σ α_ij k_j."""
GAMMAS = np.array(
    [
        [0.0, 0.0, 0.0],
        [-0.87173304301691801, 0.0, 0.0],
        [-0.90338057013044082, 0.054180672388095326, 0.0],
        [0.24212380706095346, -1.2232505839045147, 0.54526025533510214],
    ]
)
"""γ_ij, j < i (γ_ii = GAMMA)."""
B = np.array([0.24212380706095346, -1.2232505839045147, 1.5452602553351020, GAMMA])
B_HAT = np.array([0.37810903145819369, -0.096042292212423178, 0.5, 0.2179332607542295])
C = ALPHA.sum(axis=1)
"""α_i = Σ_j α_ij: the stage times t + α_i h."""
D = GAMMA + GAMMAS.sum(axis=1)
"""γ_i = γ + Σ_j γ_ij: the weights of h²·∂f/∂t."""
ORDER = 2
"""Order of the error estimate (the step-size controller's exponent is −1/(ORDER + 1))."""
STAGES = 4
MAX_FACTOR = 6.0
JACOBIAN_MAX_AGE = 20.0
"""Input intervals a Jacobian serves at most (a W-method keeps its order with a stale one)."""
F, YS, ACC, FT, PIV, FTMP = range(STAGES, STAGES + 6)
"""Rows of the work array after the stages: f at the step's start, the stage state, Σ γ_ij k_j,
∂f/∂t, the pivots (as floats), a right-hand side's scratch row; then J and LU (n rows each)."""
J0 = FTMP + 1


def work_rows(n: int) -> int:
    """Rows of n of the work array for n states."""
    return J0 + 2 * n


advance = _core.ros34pw2_advance
"""advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> status: the Rosenbrock-W step
across one input interval (src/core/integrate/ros34pw2.hpp), the signature and statuses of
`dopri54.advance` (k: `work_rows(n)` × n)."""
