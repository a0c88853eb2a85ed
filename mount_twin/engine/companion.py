"""The live error estimate where the model has non-linear mounts: a companion solution of the
twin at half the step (models of linear mounts take the cheaper `engine.estimator`, which is
not cheaper here: on the bolted genset at rtol 1e-6 it read 0.92 of the true error at 2.8–3.3×
the engine's time against this one's 0.95 at 2.1×, 0.99 since it holds its step after a
rejection; see there).

Richardson's global error estimate (Hairer, Nørsett & Wanner, *Solving Ordinary Differential
Equations I*, §II.4 and §II.12): integrate the same problem twice, the published solution y and
a companion ŷ of smaller error e/r; then y − ŷ = (1 − 1/r)·e: the difference is the published
solution's error, not a bound on a local error norm (which is what the stepper's `error_norm`
is: it tracks rtol, not the error). The companion runs the twin's own method with rtol and atol
divided by TOLERANCE_DIVISOR = 8 (an adaptive step's error, hence the global error, 8× smaller:
r ≈ 8, the estimate 0.88·e) and at least two steps per input interval (the one step an interval
bounds is halved: r = 2⁵ for Dormand–Prince 5, the estimate 0.97·e); right after a rejected
step it grows no step (`integrate.settings` HOLD_AFTER_REJECT, the rule of Hairer, Nørsett &
Wanner's DOPRI5 code), which the twin's stepper does not: on the bolted genset under its shock
the joints' faces between sticking and sliding make the error of a step jump with its length,
and a step grown at once from one accepted with a tiny error was rejected again, and again
(its right-hand sides 13.9 a sample without the rule, 13.5 with it; the twin's 7.4, which the
rule would not have changed; docs/benchmarks.md). Measured against a
reference on smooth, stiff and non-smooth scenes, the estimate is 0.77–1.03 of the true error
(test/test_error_estimate.py, docs/scene.md "Error estimate"). A divisor of 32 gave 0.93–1.3
but cost 10× the integration on the bolted genset, where tight tolerances hunt across
switches; 4 cost 3× there and gave 0.54. The companion reads the same held input, takes the
same discrete mount switches between samples, and restarts with the twin.

Cost: the engine takes 2.1× as long with it on the bolted genset at rtol 1e-6, 2.3–2.7× on 4 to
256 Bouc–Wen elastomers (bench/error_estimate.py, docs/scene.md "Error estimate"): its two steps
an interval are about the twin's work again, whatever the mounts. Followed on a second thread it
would hide in wall time only up to its own loop, the slower one: measured on the genset, the
run's wall time fell from 48–53 to 41 ms and its CPU time rose to 59–60 ms (not kept; a live
node's runs of one sample would gain nothing). `integration.error_estimate: false` turns it
off. It never touches the twin's state: the published numbers are identical with it on or off
(test/test_error_estimate.py).

Its figures, kept as `engine.estimate` lays them out, are running maxima since the engine last
read them: the largest |ΔF| over mounts and force components (N, mount axes), the largest
|Δα|, |Δγ|, |Δδ| (rad), the largest |F| component of the twin (N: the scale of a relative
error), and the intervals where the companion's own stepper failed (FAILURES: it is then
re-synchronised to the twin, the error carried until then is lost, and the estimate counts
it); it carries every state (UNCARRIED stays 0).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin.engine.estimate import (
    N_FIGURES,
)
from mount_twin.integrate.stepper import forget, tighter_arrays
from mount_twin.physics.dynamics import Scratch

TOLERANCE_DIVISOR = 8.0
"""The companion's rtol and atol are the twin's over this (see the module docstring)."""
MIN_STEPS = 2
"""The companion's fewest steps per input interval."""


class Companion(NamedTuple):
    """The companion solution's stepper, state and work arrays (the core's loop advances it
    after the twin at every sample: `follow` in src/core/engine/kernel.hpp).

    method, settings, work2d, work1d, result: its stepper (`integrate.stepper.Stepper`).
    y: (n_state,) its state; s: its scratch (its angles at the last sample: s.q[3:6]);
    y_prev, g, util: its mount monitors' arrays (its switches are taken with them).
    wrenches: (n_mounts, 6): its mount wrenches at the last sample.
    figures: (N_FIGURES,) running maxima (see the module docstring), reset by the reader.
    """

    method: int
    settings: np.ndarray
    work2d: np.ndarray
    work1d: np.ndarray
    result: np.ndarray
    y: np.ndarray
    s: Scratch
    y_prev: np.ndarray
    g: np.ndarray
    util: np.ndarray
    wrenches: np.ndarray
    figures: np.ndarray


def new_companion(
    method: str,
    n: int,
    rtol: float,
    atol: float,
    max_substeps: int,
    scratch: Scratch,
    n_mounts: int,
    g_shape: tuple[int, int],
) -> Companion:
    """A companion of a twin of n states integrated by `method` (a name, or AUTO: then
    `switch` it with the twin) at the twin's tolerances rtol, atol; `scratch`: fresh work
    arrays of the model; g_shape: the shape of the twin's mount event functions (non-linear
    mounts × events)."""
    own = tighter_arrays(
        method,
        n,
        rtol,
        atol,
        max_substeps,
        TOLERANCE_DIVISOR,
        MIN_STEPS,
        hold_after_reject=True,
    )
    return Companion(
        *own,
        np.zeros(n),
        scratch,
        np.zeros(n),
        np.full(g_shape, -1.0),
        np.zeros(g_shape[0]),
        np.zeros((n_mounts, 6)),
        np.zeros(N_FIGURES),
    )


def switch(c: Companion, method: int) -> Companion:
    """The companion running `method` (an id; its work arrays were made for AUTO) afresh."""
    forget(c.settings)
    return c._replace(method=method)


def restart(c: Companion, y: np.ndarray) -> None:
    """Start the companion again from the twin's state y (a twin start or restart)."""
    c.y[:] = y
    c.y_prev[:] = y
    forget(c.settings)
