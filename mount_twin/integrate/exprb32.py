"""EXPRB32: an exponential Rosenbrock method for stiff scenes, exact on their linear part.

Hochbruck, Ostermann & Schweitzer, "Exponential Rosenbrock-type methods", SIAM J. Numer. Anal.
47 (2009) 786–803, the method `exprb32`: order 3, with the exponential Rosenbrock–Euler method
(order 2) embedded. With J = ∂f/∂y, v = ∂f/∂t (taken at the interval's start; what they miss at
a later step's start goes into the remainder D) and f0 = f(t, y) at the step's start:

    U = y + h·φ1(hJ)·f0 + h²·φ2(hJ)·v                    (exponential Rosenbrock–Euler)
    D = f(t + h, U) − f0 − J·(U − y) − h·v               (the non-linear remainder's change)
    y1 = U + 2h·φ3(hJ)·D,   error estimate 2h·φ3(hJ)·D

For a linear scene under an input linear in time, which is what the twin holds between two
samples, D = 0 and y1 is the exact solution, whatever hλ: the kHz modes of a light body on bolts
are resolved, not damped, in one step per sample. The input's slope changes at every sample;
the step never crosses a sample (`stepper`), so each kink is where a step starts. That is why
this method, not the L-stable Rosenbrock (which damps the modes each kink rings), reaches 1e-5
on a stiff scene at one step per sample.

The Jacobian is taken by finite differences (`fd_jacobian`) and held up to JACOBIAN_MAX_AGE
intervals (a scene stiff enough to need this method is nearly linear in its state over 20
samples; the remainder D carries what J misses), afresh at a rejected step it did not start.
φ1, φ2, φ3 of hJ (`phi`) are kept while J and h hold (to PHI_REUSE): at a steady sample rate
they are computed once per Jacobian. The interval is divided into equal steps so that one set
serves all of them.
After each accepted step the right-hand side is evaluated at the new state, so on success the
scratch holds the body motion at (t1, y) as `outputs` requires; not first-same-as-last.

Work arrays: `work_rows(n)` rows of n: f0, v, a scratch row, U, D, the balancing's diagonal,
HALF, then J, φ1, φ2, φ3, the φ functions' four work blocks (`phi.Blocks`) and φ1, φ2, φ3 of
half the step: the doubling's last iterate but one, kept so that the error estimate's check of
an interval in two steps borrows them with the Jacobian (`engine.estimator`); HALF[0] is the
step they are for (0: none).
"""

from __future__ import annotations

from mount_twin import _core

ORDER = 2
"""Order of the error estimate (the step-size controller's exponent is −1/(ORDER + 1))."""
MAX_FACTOR = 6.0
JACOBIAN_MAX_AGE = 20.0
"""Input intervals a Jacobian (and its φ functions) serves at most."""
PHI_REUSE = 1e-9
"""φ functions computed for a step within this fraction of the one taken are used for it: the
stamps' rounding (1 ms in float seconds comes in ten values) then costs nothing, and the error
made, at most this fraction of a step's increment, is far below any tolerance. A real jitter
(µs at 1 kHz) recomputes them each interval: correct, about 2× slower."""
TYPICAL = 1.0
"""The magnitude (m, rad, m/s, rad/s) below which a Jacobian column is differenced over
JAC_STEP·TYPICAL: unlike a W-method, this one is only as exact as J, and a step scaled by
atol/rtol (1e-11 m/s for a velocity at rest) leaves rounding of f/step in J, a fake damping."""
F, FT, FTMP, U, DIFF, SCALE, HALF = range(7)
"""Rows of the work array: f0, v = ∂f/∂t, a right-hand side's scratch, the stage state U,
the remainder's change D, the balancing's diagonal, the half-step φ functions' step; then the
blocks from J0."""
ROWS = 7
J0 = ROWS
BLOCKS = 11
"""J, φ1, φ2, φ3, the φ functions' four work blocks and φ1, φ2, φ3 of half the step, n rows
each."""
HALF_P1 = 8
"""The first of the half step's φ blocks, counted in blocks from J0."""


def work_rows(n: int) -> int:
    """Rows of n of the work array for n states."""
    return ROWS + BLOCKS * n


advance = _core.exprb32_advance
"""advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> status: the exponential
Rosenbrock step across one input interval (src/core/integrate/exprb32.hpp), the signature and
statuses of `dopri54.advance` (k: `work_rows(n)` × n; settings[PHI_STEP]: the step the φ
functions held were computed for, 0 for none)."""
