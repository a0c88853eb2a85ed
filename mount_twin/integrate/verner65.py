"""Verner's "most robust" 6(5) pair with error control, advancing across one input interval.

J. H. Verner, "Strategies for deriving new explicit Runge–Kutta pairs", Annals of Numerical
Mathematics 1 (1994) 225–244; his table RKV65.IIIXb.Robust (nine stages, first-same-as-last:
the ninth row of A is the sixth-order weights, so a step costs eight new right-hand sides). The
state advances with the 6th-order solution; the embedded 5th-order one estimates the local
error (error norm: RMS of err / (atol + rtol·|y|), as `dopri54`'s). Its coefficients are at
most 3.3 in magnitude; his "most efficient" pair's reach ±207 and weigh stages 0.05 % of a step
apart by ±176, whose rounding (ε·176·|f|·h in the error estimate, defects of 3e-11 in the order
conditions of its table in doubles) made it hunt at tight tolerances (`engine.companion`).

The error estimate's companion runs it where the twin runs `dopri54` (`engine.companion`): one
step of it an interval has a much smaller error than the twin's one step of Dormand–Prince. Its
error norm is not a bound on its error everywhere: on the twin's linear oscillator its embedded
weights err at the 7th order too, 0.56–0.64 of its true error (test/test_integrate_methods.py).
The
coefficients are Verner's 40-digit ones rounded to doubles; src/core/integrate/verner65.hpp
holds the same table over the core's explicit step (src/core/integrate/explicit_rk.hpp).
"""

from __future__ import annotations

import numpy as np

from mount_twin import _core

C = np.array([0.0, 0.18, 1 / 6, 0.25, 0.53, 0.6, 0.8, 1.0, 1.0])
B = np.array(
    [
        0.7638888888888888888888888888888888888889e-1,
        0.0,
        0.0,
        0.3694083694083694083694083694083694083694,
        0.0,
        0.2480158730158730158730158730158730158730,
        0.2367424242424242424242424242424242424242,
        0.6944444444444444444444444444444444444444e-1,
    ]
)
"""6th-order weights (the ninth stage's weight is 0: it is the next step's first)."""
A = np.array(
    [
        [0.0] * 8,
        [0.18, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            0.8950617283950617283950617283950617283951e-1,
            0.7716049382716049382716049382716049382716e-1,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [0.625e-1, 0.0, 0.1875, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.316516, 0.0, -1.044948, 1.258432, 0.0, 0.0, 0.0, 0.0],
        [
            0.2723261273648562625722506556667430550251,
            0.0,
            -0.8251336032388663967611336032388663967611,
            1.048091767881241565452091767881241565452,
            0.1047157079927685687367911796908817762840,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.1669941859971651431432960727896179733320,
            0.0,
            0.6317085020242914979757085020242914979757,
            0.1746104455277387608214675883848816179643,
            -1.066535645908606612252519473401868067778,
            1.227210884353741496598639455782312925170,
            0.0,
            0.0,
        ],
        [
            0.3642375168690958164642375168690958164642,
            0.0,
            -0.2040485829959514170040485829959514170040,
            -0.3488373781606864313631230924464007170774,
            3.261932303285686744333360874714258172905,
            -2.755102040816326530612244897959183673469,
            0.6818181818181818181818181818181818181818,
            0.0,
        ],
        B,
    ]
)
B_HAT = np.array(
    [
        0.5870020964360587002096436058700209643606e-1,
        0.0,
        0.0,
        0.4807256235827664399092970521541950113379,
        -0.8534124207691908557883209486122831308356,
        1.204648526077097505668934240362811791383,
        0.0,
        -0.5924237307216030620285939434875605088371e-1,
        0.1685804345378813463919846898570302825622,
    ]
)
"""The embedded 5th-order weights (its last stage, the FSAL one, weighs in)."""
E = np.append(B, 0.0) - B_HAT
"""6th-order weights minus the embedded 5th-order ones (each a double subtraction, as the core's
table computes it)."""
FSAL = True
"""The last stage is evaluated at (t + h, y_new): it is the next step's first."""
ORDER = 5
"""Order of the error estimate (the step-size controller's exponent is −1/(ORDER + 1))."""
MAX_FACTOR = 10.0


advance = _core.verner65_advance
"""advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> status: Verner 6(5) across one
input interval (src/core/integrate/verner65.hpp: this table over the core's explicit step); the
arguments as `dopri54.advance`'s, k (9, n)."""
