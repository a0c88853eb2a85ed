"""The twin's integrator against its peers, scipy and MuJoCo, on the same model in one run.

For a scene and bag, a reference run (the twin at rtol 1e-12, or 1e-10, on the input refined
8×), then the largest mount-force error relative to the largest force and the wall time per
simulated second of:

- the twin's engine (`auto` method, no error estimate), per tolerance;
- scipy's `solve_ivp` (RK45, DOP853, Radau, LSODA) integrating the twin's own compiled
  right-hand side interval by interval (the held input is linear between samples, with a kink
  at each: restarting at each sample is how it is integrated exactly), with the mounts'
  discrete switches applied between samples as the twin does, per tolerance. Same model, same
  input, same outputs: only the integration differs. scipy pays a Python call per right-hand
  side and a restart per sample;
- MuJoCo (`pip install .[bench]`; `--peers`), per integrator (Euler, RK4, implicitfast) and
  timestep (steps landing on every sample). Its model is built from the scene
  (bench/mujoco_peer.py): the body on three slides and a ball joint, each mount three spatial
  tendons along its axes to anchors 1 km away on the foundation (a lateral stiffness of
  tension/length, a few 1e-6 of the force), the mounts' isotropic rotational stiffness and
  damping as the ball joint's, all in the deck frame F with −m·f(t) and the rotating frame's
  fictitious forces and moments applied at every integrator stage from a control callback (the
  Python work a MuJoCo user must do, timed with it). Its error is measured against its own
  converged solution (RK4 at --mj-reference-dt): its integration error, comparable with the
  twin's against the twin's reference. The difference of that converged solution from the
  twin's reference, printed first, is the modelling difference (whether it is the same problem).

MuJoCo's limits: linear mounts only (no elastomer law, bolted joint, shear key); rotational
stiffness only as an isotropic sum (a ball joint's spring); the input is whatever Python sets
per stage or step. A bolted scene is posed only with `--closed-joints`: each bolted joint as its
closed, stuck, elastic joint (axial k_S + k_P, shear k_τ, its dampers), keys left out, for every
peer, the twin included: a different, linear model, valid while no joint opens or slips and no
key closes its clearance; `--full-reference` also runs the full scene's reference and prints
how far the closed-joint model is from it (on the genset's shock record 0.85 of the peak
force: feet open and a key bears; only the cost of the closed-joint model compares there).

    python3 bench/peers.py [--scene config/pump_8_mounts.scene.yaml --bag bags/ship_motion_1khz]
        [--seconds 2] [--rtol 1e-4 1e-6 1e-8] [--max-substeps 100000] [--peers scipy mujoco]
        [--mj-integrators Euler RK4 implicitfast] [--mj-timesteps 1e-3 5e-4 2e-4 1e-4 5e-5]
        [--mj-reference-dt 1e-5] [--mj-hold stage step] [--closed-joints [--full-reference]]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from importlib.util import find_spec

import numpy as np
from scipy.integrate import solve_ivp

from mount_twin.analysis.accuracy import Run, measure, raw_gyro, reference_run
from mount_twin.engine.batch import SampleBatch
from mount_twin.io.input_samples import read_samples
from mount_twin.kinds import N_EVENTS
from mount_twin.model.assemble import Model, assemble, initial_state
from mount_twin.physics import pose_row
from mount_twin.physics.dynamics import INPUT_SIZE, evaluate, mount_monitors, rhs
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file


@dataclass(frozen=True)
class Foundation:
    """The record as every peer takes it: stamps (s), specific force f (m/s², F, gravity
    included) and rate Ω (rad/s, F) at the samples, held linear between them."""

    t: np.ndarray
    f: np.ndarray
    w: np.ndarray

    @property
    def duration(self) -> float:
        """Simulated time, s."""
        return float(self.t[-1] - self.t[0])

    @property
    def rotating(self) -> bool:
        """Whether the deck turns at all in the record."""
        return bool(np.any(self.w))

    def line(self, j: int, u: np.ndarray) -> None:
        """The twin's input vector u[:13] over interval j (samples j − 1 to j): t0, f0, f',
        Ω0, Ω'."""
        t, f, w = self.t, self.f, self.w
        dt = t[j] - t[j - 1]
        u[0], u[1:4], u[4:7] = t[j - 1], f[j - 1], (f[j] - f[j - 1]) / dt
        u[7:10], u[10:13] = w[j - 1], (w[j] - w[j - 1]) / dt


def foundation(model: Model, samples: SampleBatch) -> Foundation:
    """`samples` (sensor frame) in F, with g added if the input does not include it."""
    scene = model.scene
    f = samples.accel @ model.sensor_rotation.T
    if not scene.input.includes_gravity:
        f = f + np.array([0.0, 0.0, scene.input.g])
    return Foundation(samples.stamps, f, samples.gyro @ model.sensor_rotation.T)


def force_error(got: np.ndarray, want: np.ndarray) -> float:
    """Largest |F − F_want| over samples, mounts, axes over the largest |F_want| (forces only)."""
    return float(np.abs(got[:, :, :3] - want[:, :, :3]).max() / np.abs(want[:, :, :3]).max())


def scipy_run(scene: Scene, samples: SampleBatch, method: str, rtol: float) -> np.ndarray:
    """Mount wrenches (k, n_mounts, 6) at the samples, the twin's model integrated by scipy."""
    model = assemble(scene)
    arrays, scratch = model.arrays, model.new_scratch()
    deck = foundation(model, samples)
    t = deck.t
    y = initial_state(model, deck.f[0], deck.w[0])
    u = np.zeros(INPUT_SIZE)
    out = np.zeros(y.shape[0])
    wrenches = np.zeros((t.shape[0], model.n_mounts, 6))
    pose = np.zeros(pose_row.WIDTH)
    evaluate(y, arrays, scratch, pose, wrenches[0])
    nl = arrays.nl
    g = np.full((0 if nl is None else nl.kind.shape[0], N_EVENTS), -1.0)
    util = np.zeros(g.shape[0])
    if nl is not None:
        mount_monitors(y, y, nl, scratch, g, util)

    def f_rhs(time_s: float, state: np.ndarray) -> np.ndarray:
        rhs(time_s, state, arrays, scratch, u, out)
        return out.copy()

    for j in range(1, t.shape[0]):
        deck.line(j, u)
        sol = solve_ivp(f_rhs, (t[j - 1], t[j]), y, method=method, rtol=rtol, atol=rtol * 1e-3)
        if not sol.success:
            msg = f"scipy {method} failed at {t[j]:.6f} s: {sol.message}"
            raise RuntimeError(msg)
        y_prev, y = y, sol.y[:, -1].copy()
        evaluate(y, arrays, scratch, pose, wrenches[j])
        if nl is not None:
            mount_monitors(y, y_prev, nl, scratch, g, util)
    return wrenches


@dataclass(frozen=True)
class Row:
    """One measured configuration: its error against its own reference, wall s per s."""

    name: str
    setting: str
    error: float
    wall_s_per_s: float


HEADER = f"{'integrator':<28} {'setting':>8} {'force err':>10} {'wall s/s':>9} {'vs twin':>8}"
"""`vs twin`: wall time over that of the cheapest twin row at no larger error; marked * where
every twin row's error is larger (then over the twin's most accurate row)."""


def show(row: Row, twin: list[Row], note: str = "") -> None:
    """Print `row`, with its wall time against the twin's (see HEADER)."""
    better = [r.wall_s_per_s for r in twin if r.error <= row.error]
    if better:
        ratio = f"{row.wall_s_per_s / min(better):>7.1f}×"
    else:
        best = min(twin, key=lambda r: (r.error, r.wall_s_per_s))
        ratio = f"{row.wall_s_per_s / best.wall_s_per_s:>6.1f}×*"
    print(
        f"{row.name:<28} {row.setting:>8} {row.error:>10.2e} {row.wall_s_per_s:>9.4f} "
        f"{ratio}{note}",
        flush=True,
    )


def twin_rows(
    scene: Scene, samples: SampleBatch, ref: Run, rtols: list[float], max_substeps: int
) -> list[Row]:
    """The twin at each rtol against `ref`."""
    rows = []
    for rtol in rtols:
        acc = measure(scene, samples, rtol, max_substeps, ref)
        rows.append(Row("twin (auto)", f"{rtol:.0e}", acc.force_error, acc.wall_s_per_sim_s))
        show(rows[-1], rows)
    return rows


def scipy_rows(
    scene: Scene,
    samples: SampleBatch,
    ref: Run,
    rtols: list[float],
    methods: list[str],
    twin: list[Row],
) -> None:
    """scipy's methods at each rtol against `ref`."""
    duration = float(samples.stamps[-1] - samples.stamps[0])
    for rtol in rtols:
        for method in methods:
            t0 = time.perf_counter()
            got = scipy_run(scene, samples, method, rtol)
            wall = (time.perf_counter() - t0) / duration
            error = force_error(got, ref.out.wrenches)
            show(Row(f"scipy {method}", f"{rtol:.0e}", error, wall), twin)


def mujoco_rows(
    scene: Scene, samples: SampleBatch, ref: Run, args: argparse.Namespace, twin: list[Row]
) -> None:
    """MuJoCo per hold, integrator and timestep against its own converged solution, after the
    modelling difference of that solution from the twin's reference."""
    from mujoco_peer import MujocoTwin, mujoco_run

    deck = foundation(assemble(scene), samples)
    peer = MujocoTwin.build(scene, deck.rotating, args.anchor_length)
    converged = mujoco_run(peer, deck, "RK4", args.mj_reference_dt).forces
    check = mujoco_run(peer, deck, "RK4", 2.0 * args.mj_reference_dt).forces
    print(
        f"MuJoCo: {peer.model.ntendon} tendons, converged solution RK4 at "
        f"{args.mj_reference_dt:g} s (its own error ~{force_error(check, converged):.1e}: "
        f"against {2 * args.mj_reference_dt:g} s); modelling difference from the twin's "
        f"reference {force_error(converged, ref.out.wrenches):.2e}",
        flush=True,
    )
    for hold in args.mj_hold:
        for integrator in args.mj_integrators:
            for dt in args.mj_timesteps:
                run = mujoco_run(peer, deck, integrator, dt, hold)
                finite = np.isfinite(run.forces).all()
                error = force_error(run.forces, converged) if finite else np.inf
                note = (
                    f"   {run.steps / (deck.t.shape[0] - 1):.0f} steps/sample, stepping alone "
                    f"{run.engine_s / deck.duration:.4f} s/s"
                )
                name = f"MuJoCo {integrator} ({hold})"
                show(Row(name, f"{dt:.0e}", error, run.wall_s / deck.duration), twin, note)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="config/pump_8_mounts.scene.yaml")
    parser.add_argument("--bag", default="bags/ship_motion_1khz")
    parser.add_argument("--seconds", type=float, default=2.0, help="of the record, from its start")
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-4, 1e-6, 1e-8])
    parser.add_argument("--methods", nargs="+", default=["RK45", "DOP853", "Radau", "LSODA"])
    parser.add_argument("--max-substeps", type=int, default=100_000)
    have_mujoco = find_spec("mujoco") is not None
    parser.add_argument(
        "--peers",
        nargs="+",
        choices=["scipy", "mujoco"],
        default=["scipy", "mujoco"] if have_mujoco else ["scipy"],
        help="default: scipy, and mujoco where it imports (pip install .[bench])",
    )
    parser.add_argument("--mj-integrators", nargs="+", default=["Euler", "RK4", "implicitfast"])
    parser.add_argument(
        "--mj-timesteps", type=float, nargs="+", default=[1e-3, 5e-4, 2e-4, 1e-4, 5e-5]
    )
    parser.add_argument("--mj-reference-dt", type=float, default=1e-5)
    parser.add_argument(
        "--mj-hold",
        nargs="+",
        choices=["stage", "step"],
        default=["stage"],
        help="input and frame forces set at every integrator stage, or once per step",
    )
    parser.add_argument("--anchor-length", type=float, default=1000.0, help="tendon length, m")
    parser.add_argument(
        "--closed-joints",
        action="store_true",
        help="pose bolted joints as closed linear joints and leave keys out, for every peer",
    )
    parser.add_argument(
        "--full-reference",
        action="store_true",
        help="with --closed-joints: how far the closed-joint reference is from the full scene's",
    )
    args = parser.parse_args()
    loaded = load_scene_file(args.scene)
    full = read_samples(args.bag, loaded.input)
    keep = full.stamps - full.stamps[0] <= args.seconds
    cut = SampleBatch(
        full.stamps[keep], full.accel[keep], full.gyro[keep], list(np.array(full.frame_ids)[keep])
    )
    scene, samples = raw_gyro(loaded), cut
    if args.closed_joints:
        from mujoco_peer import closed_joints

        whole = scene
        scene, dropped = closed_joints(scene)
        print(f"closed joints: bolted joints linear, keys left out: {', '.join(dropped) or '-'}")
    duration = float(samples.stamps[-1] - samples.stamps[0])
    ref = reference_run(scene, samples, args.max_substeps)
    print(f"{scene.name} on {args.bag}, {duration:.3f} s; reference at rtol {ref.rtol:g}")
    if args.closed_joints and args.full_reference:
        full_ref = reference_run(whole, samples, args.max_substeps).out.wrenches
        names = [mt.name for mt in whole.mounts]
        kept = [names.index(mt.name) for mt in scene.mounts]
        left_out = np.abs(np.delete(full_ref, kept, axis=1)[:, :, :3]).max(initial=0.0)
        kept_peak = np.abs(full_ref[:, kept, :3]).max()
        print(
            f"closed-joint reference against the full scene's, on the mounts it keeps: "
            f"{force_error(ref.out.wrenches, full_ref[:, kept]):.2e}; largest force of those "
            f"left out {left_out:.3g} N, of those kept {kept_peak:.3g} N",
            flush=True,
        )
    print(HEADER)
    twin = twin_rows(scene, samples, ref, args.rtol, args.max_substeps)
    if "scipy" in args.peers:
        scipy_rows(scene, samples, ref, args.rtol, args.methods, twin)
    if "mujoco" in args.peers:
        mujoco_rows(scene, samples, ref, args, twin)


if __name__ == "__main__":
    main()
