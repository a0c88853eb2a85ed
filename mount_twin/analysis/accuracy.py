"""Error against run time: the twin at several tolerances against a tight reference run.

For one scene and one input record, each tolerance's run is compared with a reference run of
the same twin (by dopri54) at a much tighter tolerance (rtol 1e-12 by default) on the same
input refined REFINE times: the record's held input (linear between samples, or held) sampled
REFINE times as densely, so the reference takes at least REFINE steps per interval where a run
may take one, and its error is not the run's own (the physics tests tie the formulation itself to
closed forms and to an independent quaternion formulation integrated by scipy). The runs take
the gyro as the scene does (`input.gyro_filter`, the shipped default `linear_phase`); the
reference takes the record's rate as the twin takes it (`conditioned`: filtered beforehand, the
reference's own conditioning off), so the figures are the integration's error, the one the
tolerance buys down and the live estimate estimates, compared at the same stamps (a delayed run
answers every sample, late). That record is checked to give the twin's run (`reference_input`);
where it does not (samples rejected, a restart splitting the record), the reference takes the
recorded rate and the figures include the conditioning's effect. The conditioning's effect on
its own is a reference on the recorded rate against one on the conditioned record: on the pump
under ship motion the filter moves the forces by 1.0e-5 of the largest, the integration's
error at rtol 1e-6 is 1e-9.
Figures per run: the largest mount-force error relative to the largest reference mount force,
the error of each mount's peak force relative to that peak (the figure a design check uses),
the attitude (rad) and CG position (m) errors, the engine's wall time per simulated second, and
the stepper's failures. A reference run that fails (a stepper restart) is no reference: the
next looser reference tolerance is tried, and the one used is reported.

What the reference resolves (`resolution`): a second reference, the same in all but its step
grid (the input refined REFINE + 1 times), differs from it by the reference's own error and
round-off. Errors within RESOLVED times that difference are not measured by the comparison. On
the pump under ship motion it is 1.6e-13 of the largest force; on 10 kg held by 4 × 1e9 N/m it
is 4.2e-9, at 1 kHz and at 100 Hz alike, and a reference by another method (ros34pw2) differs
by as much: round-off of the position amplified by the stiffness, below which a run's error is
noise.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.delay_line import conditioned_rates, filter_bands
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.estimate import ErrorEstimate
from mount_twin.errors import MountTwinError
from mount_twin.model.assemble import assemble
from mount_twin.scene.description import Scene

DEFAULT_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
REFINE = 8
"""Reference input samples per record interval."""
REFERENCE_RTOLS = (1e-12, 1e-11, 1e-10)
REFERENCE_METHOD = "dopri54"
"""The reference's method: 5th order, resolving every mode at tight tolerances (an L-stable
method of lower order would damp what the reference must resolve, and take far more steps)."""
RESOLVED = 3.0
"""An error counts as measured where it is above this multiple of the reference's resolution."""
ATOL_PER_RTOL = 1e-3
"""atol = rtol · this (m, rad, m/s, rad/s: the state's units)."""
CHECK_RTOL = 1e-6
"""The tolerance at which the conditioned record is checked to give the twin's run."""
REPRODUCED = 1e-12
"""The twin on the conditioned record gives its run where the two differ by no more than this
(relative force, and rad of attitude): bit for bit where the sensor's axes are F's, to the
rounding of the rotation where not (1.15e-13 of the pump's force, its sensor turned 0.3, −0.2,
1.0 rad)."""
NAN = float("nan")


@dataclass(frozen=True)
class Run:
    """One run of the twin over the record at one tolerance.

    Attributes:
        rtol, atol: the stepper's tolerances (atol in state units).
        out: the engine's outputs (every sample published).
        wall_s: engine wall time, s.
        failures: stepper failures (each restarted the twin).
        substeps_per_sample: accepted + rejected steps per input interval.
        estimate: the engine's own live error estimate (None: off).
    """

    rtol: float
    atol: float
    out: OutputBatch
    wall_s: float
    failures: int
    substeps_per_sample: float
    estimate: ErrorEstimate | None


@dataclass(frozen=True)
class Accuracy:
    """Errors of one run against the reference (see the module docstring), and its cost.

    Attributes:
        rtol: the run's relative tolerance.
        force_error: max |F − F_ref| over samples, mounts, axes / max |F_ref|, −.
        peak_force_error: max over mounts of |peak|F| − peak|F_ref|| / peak|F_ref|, −
            (mounts that carry no force in the reference, such as a key that never closes its
            clearance, have no peak to compare).
        attitude_error_rad: max |Δα|, |Δγ|, |Δδ|, rad.
        position_error_m: max |ΔCG| component, m.
        wall_s_per_sim_s: engine wall time per second of record, s/s.
        substeps_per_sample, failures: from the run (each failure leaves the sample it failed
            into unanswered: the errors are over the samples the run answered).
        est_force_error, est_attitude_error_rad: the run's live error estimate of force_error
            and attitude_error_rad (NaN: not estimated).
        estimate_cost: wall time with the live estimate over wall time without (NaN: not
            estimated); wall_s_per_sim_s is without it.
    """

    rtol: float
    force_error: float
    peak_force_error: float
    attitude_error_rad: float
    position_error_m: float
    wall_s_per_sim_s: float
    substeps_per_sample: float
    failures: int
    est_force_error: float
    est_attitude_error_rad: float
    estimate_cost: float


def raw_gyro(scene: Scene) -> Scene:
    """The scene taking the gyro as its samples hold it (`gyro_filter: none`): the reference's,
    on the `conditioned` record or the recorded one."""
    return dataclasses.replace(scene, input=dataclasses.replace(scene.input, gyro_filter="none"))


def conditioned(scene: Scene, samples: SampleBatch) -> SampleBatch:
    """The record with its rate as the twin takes it where it accepts every sample
    (`input.gyro_filter`): filtered by the delay line (`delay_line.conditioned_rates`, in the
    sensor's axes), a run ending where the twin restarts after a gap (`input.max_gap_s`,
    `gap_policy: reset`); zero for `ignore`; as recorded for `none`. The
    twin of `raw_gyro(scene)` on it integrates the scene's twin's own input (`reference_input`
    checks)."""
    spec = scene.input
    bands = filter_bands(spec)
    if bands is not None:
        gaps = np.diff(samples.stamps) > spec.max_gap_s
        restarts = (np.flatnonzero(gaps) + 1).tolist() if spec.gap_policy == "reset" else []
        gyro = conditioned_rates(bands, samples.stamps, samples.gyro, restarts)
    elif not spec.reads_rate:
        gyro = np.zeros_like(samples.gyro)
    else:
        return samples
    return SampleBatch(samples.stamps, samples.accel, gyro, samples.frame_ids)


@dataclass(frozen=True)
class ReferenceInput:
    """The record a reference takes (its gyro conditioning off: `reference_run`).

    Attributes:
        samples: the `conditioned` record, or where that does not give the twin's run the
            recorded one.
        conditioned: whether `samples` is the conditioned record (else the runs' errors
            against the reference include the conditioning's effect).
        reproduction: max of the relative force and the attitude (rad) differences of the
            twin on the conditioned record from the twin as configured, at CHECK_RTOL (0 where
            nothing is conditioned; inf where they answer different samples).
    """

    samples: SampleBatch
    conditioned: bool
    reproduction: float


def reference_input(scene: Scene, samples: SampleBatch, max_substeps: int) -> ReferenceInput:
    """The record a reference of `scene` takes: the `conditioned` one where the twin of
    `raw_gyro(scene)` on it gives the scene's twin's run on `samples` to within REPRODUCED."""
    record = conditioned(scene, samples)
    if record is samples:
        return ReferenceInput(samples, True, 0.0)
    twin = run_at(scene, samples, CHECK_RTOL, max_substeps, estimate=False)
    again = run_at(raw_gyro(scene), record, CHECK_RTOL, max_substeps, estimate=False)
    off = math.inf
    if np.array_equal(twin.out.stamps, again.out.stamps):
        diff = compare(again, twin, 1.0)
        off = max(diff.force_error, diff.attitude_error_rad)
    same = off <= REPRODUCED
    return ReferenceInput(record if same else samples, same, off)


def refined(scene: Scene, samples: SampleBatch, factor: int = REFINE) -> SampleBatch:
    """The same held input sampled `factor` times as densely: values between samples as the
    scene's `input.hold` holds them (linear, or the previous sample's)."""
    t = samples.stamps
    fine = (t[:-1, None] + np.diff(t)[:, None] * (np.arange(factor) / factor)).ravel()
    fine = np.append(fine, t[-1])

    def hold(values: np.ndarray) -> np.ndarray:
        if scene.input.hold == "zero_order":
            return values[np.searchsorted(t, fine, side="right") - 1]
        return np.column_stack([np.interp(fine, t, values[:, k]) for k in range(3)])

    frames = [samples.frame_ids[0]] * fine.shape[0]
    return SampleBatch(fine, hold(samples.accel), hold(samples.gyro), frames)


def run_at(
    scene: Scene, samples: SampleBatch, rtol: float, max_substeps: int, estimate: bool = True
) -> Run:
    """The twin over `samples` at `rtol` (atol = rtol·ATOL_PER_RTOL), every sample published
    (`TwinEngine.run`), with its live error estimate if `estimate` (the wall time then
    includes the estimate's checks and propagation), started under the first sample's specific
    force (`initial_state.gravity_window_s` 0: a window's mean over a refined record is not the
    record's, and a start is no integration error). MountTwinError if it accepted no sample,
    saying why."""
    atol = rtol * ATOL_PER_RTOL
    integ = dataclasses.replace(
        scene.integration,
        rtol=rtol,
        atol=atol,
        max_substeps=max_substeps,
        error_estimate=estimate,
    )
    outputs = dataclasses.replace(scene.outputs, decimation=1)
    initial = dataclasses.replace(scene.initial, gravity_window_s=0.0)
    scene = dataclasses.replace(scene, integration=integ, outputs=outputs, initial=initial)
    engine = TwinEngine(assemble(scene))
    t0 = time.perf_counter()
    out = engine.run(samples)
    wall = time.perf_counter() - t0
    counts = engine.counts
    if nothing := engine.followed_nothing:  # no run to measure
        raise MountTwinError(nothing)
    intervals = max(counts["accepted"] - counts["starts"], 1)
    return Run(
        rtol,
        atol,
        out,
        wall,
        counts["integration_failures"],
        counts["substeps"] / intervals,
        engine.error_estimate,
    )


def reference_run(
    scene: Scene, samples: SampleBatch, max_substeps: int, factor: int = REFINE
) -> Run:
    """The tightest run of REFERENCE_RTOLS on the input `refined` `factor` times that
    completes without a stepper failure, by REFERENCE_METHOD whatever the scene's; its outputs
    at the record's own stamps, the gyro taken as `samples` holds it (`raw_gyro`: give it the
    `reference_input` to compare the scene's runs with)."""
    fine = refined(scene, samples, factor)
    integ = dataclasses.replace(scene.integration, method=REFERENCE_METHOD)
    scene = dataclasses.replace(raw_gyro(scene), integration=integ)
    for rtol in REFERENCE_RTOLS:
        ref = run_at(scene, fine, rtol, max_substeps, estimate=False)
        if ref.failures == 0:
            at_samples = np.isin(ref.out.stamps, samples.stamps)
            return dataclasses.replace(ref, out=ref.out.select(at_samples))
    msg = (
        f"no reference: the stepper failed at every reference tolerance {REFERENCE_RTOLS} "
        f"with at most {max_substeps} substeps per input interval (max_substeps, accuracy "
        "--max-substeps). The explicit stepper steps across the mounts' switches (joints "
        "opening, slip, contact): a scene that switches at every step (a chattering law) "
        "makes tight tolerances hunt; raise max_substeps, or look for the mount whose law "
        "chatters."
    )
    raise MountTwinError(msg)


def resolution(scene: Scene, samples: SampleBatch, max_substeps: int, ref: Run) -> Accuracy:
    """What `ref` (`reference_run`) resolves: a second reference on the input refined REFINE + 1
    times, compared with it (see the module docstring); its force_error, attitude_error_rad
    and position_error_m are the figures' resolutions."""
    second = reference_run(scene, samples, max_substeps, REFINE + 1)
    return compare(second, ref, float(samples.stamps[-1] - samples.stamps[0]))


def measure(
    scene: Scene, samples: SampleBatch, rtol: float, max_substeps: int, ref: Run
) -> Accuracy:
    """The twin at `rtol` against `ref`: timed without its live error estimate, then run again
    with it (the outputs are the same: the estimate never touches the twin's state)."""
    timed = run_at(scene, samples, rtol, max_substeps, estimate=False)
    estimated = run_at(scene, samples, rtol, max_substeps, estimate=True)
    duration = float(samples.stamps[-1] - samples.stamps[0])
    return compare(timed, ref, duration, estimated)


def compare(run: Run, ref: Run, duration_s: float, estimated: Run | None = None) -> Accuracy:
    """The errors of `run` against `ref`, both over the same samples; the live estimate of
    `estimated` (a run of the same twin with it on; default `run`) and its cost."""
    estimated = estimated or run
    est = estimated.estimate
    cost = estimated.wall_s / run.wall_s if est is not None and estimated is not run else NAN
    out, want = run.out, ref.out
    # a stepper failure leaves the sample it failed into unanswered (the twin restarts at the
    # next): compared over the samples the run answered, its failures counted in the figures
    answered = np.isin(want.stamps, out.stamps)
    if not np.array_equal(out.stamps, want.stamps[answered]):
        msg = "the run answers samples the reference does not"
        raise ValueError(msg)
    want = want.select(answered)
    force, force_ref = out.wrenches[:, :, :3], want.wrenches[:, :, :3]
    peak = np.linalg.norm(force, axis=2).max(axis=0)
    peak_ref = np.linalg.norm(force_ref, axis=2).max(axis=0)
    scale = np.abs(force_ref).max()
    loaded = peak_ref > 0.0
    return Accuracy(
        rtol=run.rtol,
        force_error=float(np.abs(force - force_ref).max() / scale) if scale > 0.0 else 0.0,
        peak_force_error=float(
            (np.abs(peak - peak_ref)[loaded] / peak_ref[loaded]).max(initial=0.0)
        ),
        attitude_error_rad=float(np.abs(out.angles - want.angles).max()),
        position_error_m=float(np.abs(out.position - want.position).max()),
        wall_s_per_sim_s=run.wall_s / duration_s,
        substeps_per_sample=run.substeps_per_sample,
        failures=run.failures,
        est_force_error=est.force_error_rel if est else NAN,
        est_attitude_error_rad=est.attitude_error_rad if est else NAN,
        estimate_cost=cost,
    )
