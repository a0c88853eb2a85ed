"""The integration methods on a stiff scene, side by side in one run: error against run time.

10 kg on 4 × 1e9 N/m (modes of 2–6 kHz) under 1 kHz ship motion (the `stiff_light` case of
test/test_error_estimate.py): per method and rtol, the mount-force error against a reference
(the same twin at rtol 1e-12 on the input refined 8×), the error of the peaks, the engine's
real-time factor without the error estimate, and the substeps per sample.

    python3 bench/stiff_methods.py [--seconds 2] [--rtol 1e-3 1e-4 1e-5 1e-6 1e-7]
        [--methods dopri54 ros34pw2 exprb32]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from test_error_estimate import _ship_motion, _stiff_light

from mount_twin.analysis.accuracy import measure, reference_run
from mount_twin.integrate.methods import METHODS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7])
    parser.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    args = parser.parse_args()
    head = ("method", "rtol", "force err", "peak err", "x real", "substeps")
    print("{:<9} {:>6} {:>10} {:>9} {:>7} {:>8}".format(*head))
    for method in args.methods:
        scene, _ = _stiff_light(method)
        scene, samples = _ship_motion(scene, args.seconds)
        ref = reference_run(scene, samples, 1_000_000)
        for rtol in args.rtol:
            a = measure(scene, samples, rtol, 100_000, ref)
            print(
                f"{method:<9} {rtol:>6.0e} {a.force_error:>10.2e} {a.peak_force_error:>9.2e} "
                f"{1 / a.wall_s_per_sim_s:>7.1f} {a.substeps_per_sample:>8.2f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
