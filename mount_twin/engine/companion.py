"""The live error estimate where the model has non-linear mounts: a companion solution of the
twin of a smaller error (models of linear mounts take the cheaper `engine.estimator`, which is
not cheaper here: on the bolted genset at rtol 1e-6 it read 0.92 of the true error at 2.8–3.3×
the engine's time against this one's 0.95 at 2.1×, 0.99 since it holds its step after a
rejection, 1.00 at 2.0× since it runs Verner's pair; see there).

Richardson's global error estimate (Hairer, Nørsett & Wanner, *Solving Ordinary Differential
Equations I*, §II.4 and §II.12): integrate the same problem twice, the published solution y and
a companion ŷ of smaller error e/r; then y − ŷ = (1 − 1/r)·e: the difference is the published
solution's error, not a bound on a local error norm (which is what the stepper's `error_norm`
is: it tracks rtol, not the error). The companion runs with rtol and atol divided by
TOLERANCE_DIVISOR = 8 (an adaptive step's error, hence the global error, 8× smaller: r ≈ 8, the
estimate 0.88·e). Where the twin's steps are set by the samples, not its tolerance (one step an
interval), one step of the twin's own method would be the twin again (r = 1, the estimate 0):
where the twin runs Dormand–Prince 5(4) the companion runs Verner's 6(5) pair
(`integrate.verner65`) at least one step an interval (a 6th-order step of the same length: its
error a small share of the twin's; 8 new right-hand sides a step against the 12 of the two
Dormand–Prince steps it replaced, which halved the step, r = 2⁵); where `auto` moved the twin to
a linearising method (`ros34pw2`, `exprb32`) it runs that method at least MIN_STEPS = 2 steps an
interval (HIGHER, `own_method`; `switch` follows the twin). Right after a rejected step it grows
no step (`integrate.settings` HOLD_AFTER_REJECT, the rule of Hairer, Nørsett & Wanner's DOPRI5
code), which the twin's stepper does not: on the bolted genset under its shock the joints' faces
between sticking and sliding make the error of a step jump with its length, and a step grown at
once from one accepted with a tiny error was rejected again, and again (two Dormand–Prince
steps: its right-hand sides 13.9 a sample without the rule, 13.5 with it; the twin's 7.4, which
the rule would not have changed; docs/benchmarks.md). Verner's "most efficient" 6(5) pair was
tried first and dropped: its weights of ±176 on stages 0.05 % of a step apart make its error
estimate's rounding, ε·176·|f|·h, dominate at tight tolerances (the genset at rtol 1e-9: 115
right-hand sides a sample where two Dormand–Prince steps take 34, the robust pair 29). Measured
against a reference on the non-smooth scenes the companion serves (hysteretic rubber on
snubbers, the genset's joints and keys, Bouc–Wen elastomers) at rtol 1e-3 … 1e-9, the estimate
is 0.69–1.08 of the true error (test/test_error_estimate.py, docs/scene.md "Error estimate";
0.69–0.75 where both take one step an interval at loose tolerances, Verner's error a quarter of
the twin's). With two Dormand–Prince steps a divisor of 32 gave 0.93–1.3 but cost 10× the
integration on the bolted genset, where tight tolerances hunt across switches; 4 cost 3× there
and gave 0.54. With Verner's pair a divisor of 4 saves 0.7 of its 12.6 right-hand sides a sample
on the genset at rtol 1e-6 and reads 0.71 of the true error at rtol 1e-3 (8: 0.89); 2 saves 1.2
and reads 0.57 (docs/benchmarks.md). The companion reads the same held input, takes the same
discrete mount switches between samples, and restarts with the twin.

Cost: the engine takes 2.0× as long with it on the bolted genset at rtol 1e-6, 2.1× on 256
Bouc–Wen elastomers (bench/error_estimate.py, docs/scene.md "Error estimate"; 2.1× and 2.3× with
two Dormand–Prince steps): its right-hand sides, 12.6 a sample on the genset against the twin's
7.7 (floor 8: the rest are rejections and extra steps at the joints' switches under the shock),
are more than the twin's work, whatever the mounts. Followed on a second thread it would hide in
wall time only up to its own loop, the slower one: measured on the genset, the run's wall time
fell from 48–53 to 41 ms and its CPU time rose to 59–60 ms (not kept; a live node's runs of one
sample would gain nothing). `integration.error_estimate: false` turns it off. It never touches
the twin's state: the published numbers are identical with it on or off
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
from mount_twin.integrate.methods import AUTO, DOPRI54, METHODS, VERNER65
from mount_twin.integrate.settings import MAX_SUBSTEPS
from mount_twin.integrate.settings import MIN_STEPS as MIN_STEPS_SLOT
from mount_twin.integrate.stepper import forget, tighter_arrays
from mount_twin.physics.dynamics import Scratch

TOLERANCE_DIVISOR = 8.0
"""The companion's rtol and atol are the twin's over this (see the module docstring)."""
MIN_STEPS = 2
"""The companion's fewest steps per input interval where it runs the twin's own method."""
HIGHER = {DOPRI54: VERNER65}
"""The companion's method where the twin's is a key (ids): one step of it an interval is a
different solution of a smaller error, where one of the twin's own would be the twin again."""


def own_method(twin: int) -> tuple[int, int]:
    """(method id, fewest steps per input interval) of the companion of a twin running the
    method `twin` (an id): a higher-order method at one step (HIGHER), else the twin's at
    MIN_STEPS."""
    return (HIGHER[twin], 1) if twin in HIGHER else (twin, MIN_STEPS)


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
    twin = METHODS["dopri54" if method == AUTO else method].id
    own, min_steps = own_method(twin)
    name = AUTO if method == AUTO else next(k for k, m in METHODS.items() if m.id == own)
    arrays = tighter_arrays(
        name,
        n,
        rtol,
        atol,
        max_substeps,
        TOLERANCE_DIVISOR,
        min_steps,
        hold_after_reject=True,
    )
    return Companion(
        own,
        *arrays[1:],
        np.zeros(n),
        scratch,
        np.zeros(n),
        np.full(g_shape, -1.0),
        np.zeros(g_shape[0]),
        np.zeros((n_mounts, 6)),
        np.zeros(N_FIGURES),
    )


def switch(c: Companion, method: int) -> Companion:
    """The companion of a twin now running `method` (an id; its work arrays were made for AUTO)
    afresh: its own method and fewest steps (`own_method`), at most MAX_SUBSTEPS of the twin's
    per step of its fewest."""
    own, min_steps = own_method(method)
    settings = c.settings
    settings[MAX_SUBSTEPS] *= min_steps / settings[MIN_STEPS_SLOT]
    settings[MIN_STEPS_SLOT] = float(min_steps)
    forget(settings)
    return c._replace(method=own)


def restart(c: Companion, y: np.ndarray) -> None:
    """Start the companion again from the twin's state y (a twin start or restart)."""
    c.y[:] = y
    c.y_prev[:] = y
    forget(c.settings)
