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

import math

import numpy as np

from mount_twin.integrate.control import (
    MIN_STEP_FRACTION,
    OFF_CHART_SHRINK,
    conclude,
    give_up,
    trial_step,
)
from mount_twin.integrate.fd_jacobian import linearise, renew_if_stale
from mount_twin.integrate.methods import (
    LEFT_CHART,
    SUCCESS,
)
from mount_twin.integrate.settings import (
    ATOL,
    CHAINED,
    MAX_SUBSTEPS,
    MIN_STEPS,
    RTOL,
    STEP,
)
from mount_twin.physics.compiled import kernel
from mount_twin.physics.dynamics import rhs

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


@kernel
def _lu_factor(a, first, n, piv_row) -> bool:
    """LU with partial pivoting of the n×n block of `a` starting at row `first`, in place;
    pivot indices in piv_row. False if singular."""
    for c in range(n):
        p, best = c, abs(a[first + c, c])
        for r in range(c + 1, n):
            v = abs(a[first + r, c])
            if v > best:
                p, best = r, v
        piv_row[c] = p
        if best == 0.0 or not math.isfinite(best):
            return False
        if p != c:
            for j in range(n):
                tmp = a[first + c, j]
                a[first + c, j] = a[first + p, j]
                a[first + p, j] = tmp
        inv = 1.0 / a[first + c, c]
        for r in range(c + 1, n):
            f = a[first + r, c] * inv
            a[first + r, c] = f
            if f != 0.0:
                for j in range(c + 1, n):
                    a[first + r, j] -= f * a[first + c, j]
    return True


@kernel
def _lu_solve(a, first, n, piv_row, b) -> None:
    """Solve (LU)·x = b in place (b overwritten by x)."""
    for c in range(n):
        p = int(piv_row[c])
        if p != c:
            tmp = b[c]
            b[c] = b[p]
            b[p] = tmp
    for r in range(n):
        acc = b[r]
        for j in range(r):
            acc -= a[first + r, j] * b[j]
        b[r] = acc
    for r in range(n - 1, -1, -1):
        acc = b[r]
        for j in range(r + 1, n):
            acc -= a[first + r, j] * b[j]
        b[r] = acc / a[first + r, r]


@kernel
def advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> int:
    """Advance y (in place) from t0 to t1 s with input u held over the interval: the signature
    and statuses of `dopri54.advance` (k: `work_rows(n)` × n)."""
    h, rtol, atol = settings[STEP], settings[RTOL], settings[ATOL]
    max_steps = settings[MAX_SUBSTEPS]
    n = y.shape[0]
    span = t1 - t0
    h = span if h <= 0.0 else h
    h_max = span / settings[MIN_STEPS]
    settings[CHAINED] = 0.0
    t = t0
    err_max, n_acc, n_rej = 0.0, 0, 0
    lu0 = J0 + n
    typical = min(max(atol / rtol, 1e-6), 1.0)  # where relative and absolute tolerance meet
    # W-method: a Jacobian serves up to JACOBIAN_MAX_AGE intervals, and is taken afresh at the
    # first rejected step of an interval it did not start
    rows = (F, FTMP, FT, J0)
    if not linearise(y, t, m, s, u, k, typical, rows, settings, JACOBIAN_MAX_AGE):
        settings[STEP], result[0], result[1], result[2] = h, err_max, n_acc, n_rej
        return LEFT_CHART
    not_finite = off_chart = False  # what the last rejection was for
    while t < t1:
        too_small = h < MIN_STEP_FRACTION * span
        status = give_up(n_acc + n_rej, max_steps, too_small, not_finite, off_chart)
        if status != SUCCESS:
            settings[STEP], result[0], result[1], result[2] = h, err_max, n_acc, n_rej
            return status
        step, last = trial_step(t, t1, h, h_max, span)
        for r in range(n):  # W = I − hγJ
            for c in range(n):
                k[lu0 + r, c] = -step * GAMMA * k[J0 + r, c]
            k[lu0 + r, r] += 1.0
        ok = _lu_factor(k, lu0, n, k[PIV])
        stage = 0
        while ok and stage < STAGES:
            for r in range(n):
                ys, acc = y[r], 0.0
                for j in range(stage):
                    ys += ALPHA[stage, j] * k[j, r]
                    acc += GAMMAS[stage, j] * k[j, r]
                k[YS, r], k[ACC, r] = ys, acc
            if stage == 0:
                for r in range(n):
                    k[FTMP, r] = k[F, r]
            elif rhs(t + C[stage] * step, k[YS], m, s, u, k[FTMP]) != 0:
                ok = False
                break
            for r in range(n):
                jacc = 0.0
                for c in range(n):
                    jacc += k[J0 + r, c] * k[ACC, c]
                k[stage, r] = step * (k[FTMP, r] + jacc + step * D[stage] * k[FT, r])
            _lu_solve(k, lu0, n, k[PIV], k[stage])
            stage += 1
        err = math.inf
        if ok:
            err = 0.0
            for r in range(n):
                yn, e = y[r], 0.0
                for j in range(STAGES):
                    yn += B[j] * k[j, r]
                    e += (B[j] - B_HAT[j]) * k[j, r]
                y_new[r] = yn
                scale = atol + rtol * max(abs(y[r]), abs(yn))
                err += (e / scale) ** 2
            err = math.sqrt(err / n)
        not_finite = ok and not math.isfinite(err)
        off_chart = not ok
        if not err <= 1.0:  # err is inf where a stage failed
            renew_if_stale(y, t, m, s, u, k, typical, rows, settings)
        if not ok:
            h = step * OFF_CHART_SHRINK
            n_rej += 1
            continue
        t, h, accepted = conclude(
            y,
            y_new,
            t,
            t1,
            step,
            h,
            last,
            err,
            not_finite,
            ORDER,
            MAX_FACTOR,
            m,
            s,
            u,
            k,
            (F, FTMP),
        )
        if accepted:
            err_max = max(err_max, err)
            n_acc += 1
        else:
            n_rej += 1
    settings[STEP], result[0], result[1], result[2] = h, err_max, n_acc, n_rej
    return SUCCESS
