"""Whole-process start-up of `mount-twin`: the first run of a fresh copy against warm runs.

    python3 bench/bench_start.py [--warm-runs 3] [--module] [--only help demo genset]

Runs on a COPY of the package (its compiled core included, with config/ and the two bags used)
in a temporary directory, imported through PYTHONPATH, so nothing of the working tree's caches
is used. First = the copy's first process, without any `__pycache__` (Python compiles the
package's bytecode then: more than after a pip install, which writes it); warm = the median of
the next runs. Nothing compiles the twin at run time: the core was built at install.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BAGS = ("ship_motion_1khz", "genset_shock_10khz")


def make_copy(tmp: Path) -> Path:
    """The package, config/ and the bags used, copied under `tmp` (no caches)."""
    tree = tmp / "tree"
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(ROOT / "mount_twin", tree / "mount_twin", ignore=skip)
    shutil.copytree(ROOT / "config", tree / "config")
    for bag in BAGS:
        shutil.copytree(ROOT / "bags" / bag, tree / "bags" / bag)
    return tree


def timed(cmd: list[str], tree: Path, env: dict[str, str]) -> tuple[float, str]:
    """Wall time (s) of one whole process, and its stderr; a failure stops the bench."""
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return wall, done.stderr


def main() -> None:
    """Print cold and warm whole-process times of help, demo and the genset replay."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--warm-runs", type=int, default=3, help="warm runs per command")
    parser.add_argument(
        "--module",
        action="store_true",
        help="run `python -m mount_twin.cli` rather than the `mount-twin` console script",
    )
    parser.add_argument(
        "--only", nargs="+", choices=["help", "demo", "genset"], default=["help", "demo", "genset"]
    )
    args = parser.parse_args()
    script = shutil.which("mount-twin")
    prefix = [sys.executable, "-m", "mount_twin.cli"] if args.module or not script else [script]
    with tempfile.TemporaryDirectory(prefix="bench_start_") as tmp_name:
        tmp = Path(tmp_name)
        tree = make_copy(tmp)
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(tree), env.get("PYTHONPATH", "")]).rstrip(
            os.pathsep
        )
        where = subprocess.run(
            [sys.executable, "-c", "import mount_twin; print(mount_twin.__file__)"],
            cwd=tmp,
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        if not Path(where).is_relative_to(tree):
            sys.exit(f"the copy is not what Python imports ({where}): not measured")
        label = "mount-twin" if prefix == [script] else "python3 -m mount_twin.cli"
        commands = {
            "help": (f"{label} --help", ["--help"]),
            "demo": (f"{label} demo", ["demo", "-o", "{out}"]),
            "genset": (
                f"{label} replay bags/genset_shock_10khz --scene "
                "config/genset_bolted_keyed.scene.yaml",
                [
                    "replay",
                    "bags/genset_shock_10khz",
                    "--scene",
                    "config/genset_bolted_keyed.scene.yaml",
                    "-o",
                    "{out}",
                ],
            ),
        }
        print(
            f"python {platform.python_version()}, {os.cpu_count()} cores, copy at {tree}, "
            f"{args.warm_runs} warm runs (median)"
        )
        print(f"{'command':<92} {'first s':>7} {'warm s':>7} {'ratio':>6}")
        run = 0
        for key in args.only:
            title, argv = commands[key]

            def one(argv: list[str] = argv) -> tuple[float, str]:
                nonlocal run
                run += 1
                cmd = [*prefix, *(a.replace("{out}", str(tmp / f"out{run}")) for a in argv)]
                return timed(cmd, tree, env)

            first, _ = one()
            warm = statistics.median(one()[0] for _ in range(args.warm_runs))
            print(f"{title:<92} {first:7.2f} {warm:7.2f} {first / warm:6.2f}")


if __name__ == "__main__":
    main()
