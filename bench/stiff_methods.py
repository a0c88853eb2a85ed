"""The integration methods on a stiff scene, side by side in one run: error against run time.

Per method and rtol: the mount-force error against a reference (the same twin at rtol 1e-12 on
the input refined 8×), the error of the peaks, the error estimate over that error, the engine's
real-time factor without the error estimate, and the substeps per sample. The scenes
(`--case`, the cases of test/test_error_estimate.py):

- `stiff_light`: 10 kg on 4 × 1e9 N/m (modes of 2–6 kHz) under 1 kHz ship motion, `--seconds`
  of it (linear mounts: `auto` takes the exponential method);
- `stiff_snubbed`: the same with a fifth, soft mount on a snubber (a law with pieces:
  `ros34pw2`), 0.1 s;
- `stiff_hysteretic`: the same with a soft Bouc–Wen elastomer instead (no pieces, the
  stiffness the linear mounts': `exprb32`), 0.3 s;
- `stiff_bouc_wen`: 10 kg on four 1e9 N/m Bouc–Wen elastomers of strong hysteresis (the
  stiffness non-linear: `ros34pw2`), 0.3 s;
- `key`: 5 kg on soft mounts beside a 1e9 N/m shear key 0.5 mm off, pushed into it by a 3 g
  half-sine at 1 kHz (ρ·Δt 17.3 bearing: `ros34pw2` from the start);
- `snubber`: the same beside a 1e9 N/m snubber (`auto` goes to `ros34pw2` at its contact).

    python3 bench/stiff_methods.py [--case stiff_light] [--seconds 2]
        [--rtol 1e-3 1e-4 1e-5 1e-6 1e-7] [--methods dopri54 ros34pw2 exprb32 auto]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from test_error_estimate import (
    _ship_motion,
    _soft_beside_a_snubber,
    _soft_beside_a_stiff_key,
    _stiff_hysteretic_mounts,
    _stiff_light,
    _stiff_with_a_hysteretic_mount,
    _stiff_with_a_snubbed_mount,
)

from mount_twin.analysis.accuracy import measure, reference_run
from mount_twin.engine.batch import SampleBatch
from mount_twin.integrate.methods import AUTO, METHODS
from mount_twin.scene.description import Scene

CASES: dict[str, Callable[[float], tuple[Scene, SampleBatch]]] = {
    "stiff_light": lambda seconds: _ship_motion(_stiff_light()[0], seconds),
    "stiff_snubbed": lambda _: _stiff_with_a_snubbed_mount(),
    "stiff_hysteretic": lambda _: _stiff_with_a_hysteretic_mount(),
    "stiff_bouc_wen": lambda _: _stiff_hysteretic_mounts(),
    "key": lambda _: _soft_beside_a_stiff_key(),
    "snubber": lambda _: _soft_beside_a_snubber(),
}
"""Each case's scene and record from `--seconds` (which only `stiff_light` takes)."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7])
    methods = [*METHODS, AUTO]
    parser.add_argument("--methods", nargs="+", default=list(METHODS), choices=methods)
    parser.add_argument("--case", default="stiff_light", choices=list(CASES))
    args = parser.parse_args()
    scene, samples = CASES[args.case](args.seconds)
    ref = reference_run(scene, samples, 1_000_000)
    head = ("method", "rtol", "force err", "peak err", "est/true", "x real", "substeps")
    print("{:<9} {:>6} {:>10} {:>9} {:>8} {:>7} {:>8}".format(*head))
    for method in args.methods:
        integration = dataclasses.replace(scene.integration, method=method)
        run = dataclasses.replace(scene, integration=integration)
        for rtol in args.rtol:
            a = measure(run, samples, rtol, 100_000, ref)
            print(
                f"{method:<9} {rtol:>6.0e} {a.force_error:>10.2e} {a.peak_force_error:>9.2e} "
                f"{a.est_force_error / a.force_error:>8.2f} {1 / a.wall_s_per_sim_s:>7.1f} "
                f"{a.substeps_per_sample:>8.2f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
