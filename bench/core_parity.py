"""Parity of the compiled core with another tree of the package (issue 21: the numba core it
replaced): every bundled scene on every bundled bag, with its shipped settings and with each
integration method, replayed by both trees; their exported tables (pose, angles, wrenches,
events, diagnostics) compared per table against 1e-12 × the table's largest |value|, and their
summaries' counters compared exactly.

    git worktree add /tmp/numba_ref 588de60      # the last numba tree
    python3 bench/core_parity.py --reference /tmp/numba_ref

Each tree runs in its own `python -S` process with only that tree on the path ahead of the
site directories (an editable install's import hook must not answer for the other tree).
Exit 0 when every case agrees, 1 otherwise.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import site
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
CASES = (
    ("pump_8_mounts", "ship_motion_1khz"),
    ("pump_8_mounts", "half_sine_shock_10khz"),
    ("genset_bolted_keyed", "genset_shock_10khz"),
    ("genset_bolted_keyed", "half_sine_shock_10khz"),
)
"""(scene, bag) pairs replayed."""
METHODS = (None, "dopri54", "ros34pw2", "exprb32")
"""None: the scene as shipped; else integration.method set to this."""
REL_TOL = 1e-12
SKIPPED = {"wall_s", "input_bag", "output_bag", "real_time_factor"}
"""Summary keys that differ between any two runs (time taken, paths)."""


def run_tree(tree: Path, scene: Path, bag: Path, out: Path) -> tuple[int, dict, Path]:
    """Replay and export with the package of `tree`; (exit status, summary, csv dir)."""
    paths = [str(tree), *site.getsitepackages(), site.getusersitepackages()]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    cli = (
        "import sys, mount_twin.cli as c\n"
        f"assert c.__file__.startswith({str(tree)!r}), c.__file__\n"
        "sys.exit(c.main(sys.argv[1:]))"
    )
    summary, tables = out / "summary.json", out / "csv"
    replay = [sys.executable, "-S", "-c", cli, "replay", str(bag), "--scene", str(scene)]
    done = subprocess.run(
        [*replay, "-o", str(out / "bag"), "--no-progress", "--json", str(summary)],
        env=env,
        cwd=tree,
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode not in (0, 4, 6):
        sys.exit(f"{tree}: replay failed ({done.returncode}):\n{done.stderr}")
    subprocess.run(
        [sys.executable, "-S", "-c", cli, "export", str(out / "bag"), "--csv", str(tables)],
        env=env,
        cwd=tree,
        capture_output=True,
        check=True,
    )
    return done.returncode, json.loads(summary.read_text()), tables


def numbers(path: Path) -> tuple[list[str], list[list[str]]]:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


TIMING = re.compile(r"real[ -]time|wall|latency|processing|µs|ms per|per second", re.IGNORECASE)
"""Diagnostics columns and values that time the run (they differ between any two runs)."""


def compare_table(a: Path, b: Path) -> tuple[float, set[str]]:
    """(largest |difference| / largest |value| over the numeric cells, the columns whose text
    cells differ, timing columns aside)."""
    head_a, rows_a = numbers(a)
    head_b, rows_b = numbers(b)
    if head_a != head_b or len(rows_a) != len(rows_b):
        return math.inf, {"(shape)"}
    worst, scale, differ = 0.0, 0.0, set()
    for ra, rb in zip(rows_a, rows_b, strict=True):
        for column, x, y in zip(head_a, ra, rb, strict=True):
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                if x != y and not TIMING.search(column) and not TIMING.search(x):
                    differ.add(column)
                continue
            if math.isnan(fx) and math.isnan(fy):
                continue
            worst = max(worst, abs(fx - fy))
            scale = max(scale, abs(fx))
    return (worst / scale if scale > 0 else worst), differ


def compare_summary(a: object, b: object, where: str = "") -> list[str]:
    """Where two summaries differ: integers and text exactly, floats by REL_TOL (relative)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{where}: keys {sorted(set(a) ^ set(b))}"]
        return [
            d for k in a if k not in SKIPPED for d in compare_summary(a[k], b[k], f"{where}.{k}")
        ]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: {len(a)} vs {len(b)} items"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in compare_summary(x, y, f"{where}[{i}]")
        ]
    if isinstance(a, float) and isinstance(b, (int, float)):
        same = a == b or (math.isnan(a) and math.isnan(b)) or abs(a - b) <= REL_TOL * abs(a)
        return [] if same else [f"{where}: {a!r} vs {b!r}"]
    return [] if a == b else [f"{where}: {a!r} vs {b!r}"]


def scene_variant(scene: Path, method: str | None, where: Path) -> Path:
    if method is None:
        return scene
    data = yaml.safe_load(scene.read_text())
    data.setdefault("integration", {})["method"] = method
    path = where / f"{scene.stem}.{method}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reference", type=Path, required=True, help="the other tree")
    parser.add_argument("--quick", action="store_true", help="shipped settings only")
    args = parser.parse_args()
    failed = 0
    methods = METHODS[:1] if args.quick else METHODS
    with tempfile.TemporaryDirectory() as tmp:
        for scene_name, bag_name in CASES:
            for method in methods:
                case = Path(tmp, f"{scene_name}.{bag_name}.{method}")
                scene = scene_variant(
                    ROOT / "config" / f"{scene_name}.scene.yaml", method, Path(tmp)
                )
                bag = ROOT / "bags" / bag_name
                results = []
                for tree, label in ((args.reference.resolve(), "ref"), (ROOT, "head")):
                    (case / label).mkdir(parents=True)
                    results.append(run_tree(tree, scene, bag, case / label))
                (rc_a, sum_a, dir_a), (rc_b, sum_b, dir_b) = results
                worst, differ = 0.0, set()
                names = sorted(p.name for p in dir_a.glob("*.csv"))
                for name in names:
                    rel, columns = compare_table(dir_a / name, dir_b / name)
                    worst = max(worst, rel)
                    differ |= {f"{name}:{c}" for c in columns}
                diffs = compare_summary(sum_a, sum_b)
                ok = rc_a == rc_b and worst <= REL_TOL and not differ and not diffs
                failed += not ok
                texts = "equal" if not differ else "DIFFER in " + ", ".join(sorted(differ))
                print(
                    f"{'ok  ' if ok else 'FAIL'} {scene_name} on {bag_name}, "
                    f"method {method or 'as shipped'}: exit {rc_a}/{rc_b}, tables "
                    f"{', '.join(names)}: worst {worst:.2e} of the largest value, text cells "
                    f"{texts}, summary "
                    f"{'equal' if not diffs else '; '.join(diffs[:5])}",
                    flush=True,
                )
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
