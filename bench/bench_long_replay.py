"""CPU time of a long replay end to end, as a user runs it: a whole `mount-twin replay` process
(start-up, reading, the twin with its error estimate, encoding, writing) of a generated 1 kHz
ship-motion bag through the default scene at an output decimation of 10 (100 Hz rows).

    python3 bench/bench_long_replay.py [--seconds 3600] [--decimation 10] [--keep DIR]

Generating the input takes longer than replaying it (about 40 s and 6 GB of memory for an
hour: `generate` holds the record); `--keep DIR` keeps (or reuses) it there. Prints the
replay's user + system CPU seconds, its wall time, its verdict and its input counts. Side by
side with another tree: run that tree's copy of this script with `PYTHONPATH=<tree>`.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "config" / "pump_8_mounts.scene.yaml"


def _child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main() -> None:
    """Generate (or reuse) the bag, replay it in a child process, print its CPU time."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=3600.0, help="input length, s")
    parser.add_argument("--decimation", type=int, default=10, help="outputs.decimation")
    parser.add_argument("--keep", type=Path, help="directory to keep (or reuse) the input in")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        bag = work / f"ship_motion_{args.seconds:g}s"
        scene = yaml.safe_load(SCENE.read_text())
        if not bag.exists():
            gen = ["generate", "ship-motion", "-o", str(bag), "--rate", "1000"]
            gen += ["--topic", scene["input"]["topic"], "--frame-id", scene["input"]["frame_id"]]
            subprocess.run(
                [sys.executable, "-m", "mount_twin.cli", *gen, "--duration", f"{args.seconds:g}"],
                check=True,
                cwd=tmp,
            )
        scene["outputs"]["decimation"] = args.decimation
        scene_file = Path(tmp) / "scene.yaml"
        scene_file.write_text(yaml.safe_dump(scene, sort_keys=False))
        out = Path(tmp) / "out"
        cmd = [sys.executable, "-m", "mount_twin.cli", "replay", str(bag), "--scene"]
        cmd += [str(scene_file), "-o", str(out), "--no-progress", "--json", str(work / "s.json")]
        cpu0, wall0 = _child_cpu(), time.perf_counter()
        # cwd: `python -m` puts the working directory first on sys.path, ahead of PYTHONPATH:
        # run from a tree, the child would replay that tree's code, whatever the side by side
        done = subprocess.run(cmd, capture_output=True, text=True, check=False, cwd=tmp)
        cpu, wall = _child_cpu() - cpu0, time.perf_counter() - wall0
        if done.returncode != 0:
            sys.exit(f"replay failed ({done.returncode}):\n{done.stderr[-2000:]}")
        summary = yaml.safe_load((work / "s.json").read_text())
    print(
        f"{args.seconds:g} s of 1 kHz input at decimation {args.decimation}: replay "
        f"{cpu:.1f} s CPU (user + system), {wall:.1f} s wall; "
        f"verdict {summary['verdict']}, counts {summary['counts']}"
    )


if __name__ == "__main__":
    main()
