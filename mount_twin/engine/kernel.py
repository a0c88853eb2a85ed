"""The compiled per-sample loop: integrate a run of accepted samples and evaluate outputs.

One call handles a whole batch, so the Python-to-compiled call cost (µs) is paid once per batch,
not per sample; a live node passes batches of one through the same function.
"""

from __future__ import annotations

from numba import njit

from mount_twin.integrate.stepper import advance
from mount_twin.physics.dynamics import evaluate


@njit(cache=True)
def run_samples(
    method,
    settings,
    work2d,
    work1d,
    result,
    m,
    s,
    u,
    y,
    t,
    f,
    w,
    zero_order,
    decimation,
    counter,
    peak,
    pose,
    wrenches,
    publish,
    step_log,
) -> tuple[int, int]:
    """Advance y through samples 1..n−1 of (t, f, w); sample 0 is the last one already done.

    Args:
        t: (n,) stamps, s; f: (n, 3) specific force, m/s², F; w: (n, 3) foundation Ω, rad/s, F.
        zero_order: hold each sample until the next instead of interpolating linearly.
        decimation: publish every Nth sample; counter[0] counts samples since the last publish.
        peak: (nm, 6) wrench components of largest magnitude since the last publish.
        pose: out (n, 10) pose rows (see `evaluate`); wrenches: out (n, nm, 6) published wrenches.
        publish: out (n,) True where the sample is published.
        step_log: out (n, 3) per sample: error norm, accepted and rejected substeps.

    Returns:
        (index of the last sample done, stepper status: 0, or the failure at the next sample).
    """
    n, nm = t.shape[0], peak.shape[0]
    hold = 0.0 if zero_order else 1.0
    for j in range(1, n):
        dt = t[j] - t[j - 1]
        u[0] = t[j - 1]
        for i in range(3):
            u[1 + i] = f[j - 1, i]
            u[4 + i] = hold * (f[j, i] - f[j - 1, i]) / dt
            u[7 + i] = w[j - 1, i]
            u[10 + i] = hold * (w[j, i] - w[j - 1, i]) / dt
        status = advance(method, y, t[j - 1], t[j], settings, m, s, u, work2d, work1d, result)
        if status != 0:
            return j - 1, status
        step_log[j, 0], step_log[j, 1], step_log[j, 2] = result[0], result[1], result[2]
        evaluate(y, m, s, pose[j], wrenches[j])
        counter[0] += 1
        for a in range(nm):
            for b in range(6):
                if abs(wrenches[j, a, b]) > abs(peak[a, b]):
                    peak[a, b] = wrenches[j, a, b]
        publish[j] = counter[0] >= decimation
        if publish[j]:
            for a in range(nm):
                for b in range(6):
                    wrenches[j, a, b] = peak[a, b]
                    peak[a, b] = 0.0
            counter[0] = 0
    return n - 1, 0
