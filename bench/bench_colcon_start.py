"""`colcon build` (it compiles the C++ core) and the installed `mount-twin demo`'s first start
against its warm starts.

    python3 bench/bench_colcon_start.py [--warm-runs 2]

Builds the tracked files (`git ls-files`) in a fresh colcon workspace, timing the build, then
times the installed `mount-twin demo` first and then warm (median). Needs colcon and pybind11
(`pip install colcon-common-extensions pybind11`, or the rosdep key pybind11-dev).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def timed(cmd: list[str], cwd: Path, env: dict[str, str]) -> float:
    """Wall time (s) of one whole process; a failure stops the bench."""
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return time.perf_counter() - t0


def build_and_start(ws: Path, warm_runs: int) -> tuple[float, float, float]:
    """(colcon build s, first demo s, warm demo s) for a fresh workspace at `ws`."""
    src = ws / "src" / "mount_twin"
    files = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    for name in files:
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    env = dict(os.environ)
    build = timed(["colcon", "build", "--event-handlers", "console_cohesion-"], ws, env)
    inst = ws / "install" / "mount_twin"
    lib = next((inst / "lib").glob("python3*/site-packages"))
    env["PYTHONPATH"] = os.pathsep.join([str(lib), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    script = str(inst / "lib" / "mount_twin" / "mount-twin")
    runs = [
        timed([script, "demo", "-o", str(ws / f"demo{i}")], ws, env) for i in range(1 + warm_runs)
    ]
    return build, runs[0], statistics.median(runs[1:])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--warm-runs", type=int, default=2)
    args = parser.parse_args()
    print(
        f"{'colcon build':<28} {'build s':>8} {'first demo s':>13} {'warm demo s':>12} "
        f"{'first/warm':>11}"
    )
    with tempfile.TemporaryDirectory(prefix="bench_colcon_") as tmp:
        build, first, warm = build_and_start(Path(tmp), args.warm_runs)
    print(
        f"{'fresh workspace':<28} {build:>8.1f} {first:>13.2f} {warm:>12.2f} {first / warm:>11.2f}"
    )


if __name__ == "__main__":
    main()
