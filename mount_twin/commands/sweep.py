"""`mount-twin sweep SWEEP.yaml -o RESULTS.csv`: many scene variants × inputs on Dask."""

from __future__ import annotations

import argparse

from mount_twin.commands.common import positive_int

NAME = "sweep"
HELP = "run a design sweep (scene variants × inputs) on a local or remote Dask cluster"
STOPPED_OUTPUT = (
    "holds the rows of the cases finished before the stop, each whole (nothing marks the "
    "file: a rerun skips them and runs the rest)"
)
"""What the results CSV holds when a signal stopped the sweep (mount_twin.cli)."""
EXIT_STATUS = (
    "exit status: 0 every case ran (whatever its verdict); 6 a case FAILED (its row and the "
    "summary say why); 2 bad input or configuration"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("sweep", help="sweep YAML (see mount_twin.sweeps.spec)")
    parser.add_argument(
        "-o", "--output", required=True, help="results CSV (appended; a rerun skips done cases)"
    )
    parser.add_argument("--scheduler", help="Dask scheduler address (default: a local cluster)")
    parser.add_argument(
        "--workers",
        type=positive_int,
        help="local cluster worker processes (default: one per core)",
    )
    parser.add_argument(
        "--parquet", metavar="FILE", help="also write this sweep's rows as Parquet"
    )
    parser.add_argument(
        "--plot",
        metavar="PNG",
        help="largest peak mount force and largest utilisation against the first varied value, "
        "one line per input",
    )
    parser.add_argument("--no-progress", action="store_true")


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import check_targets
    from mount_twin.commands.extras import require
    from mount_twin.commands.replay import EXIT_FAILED

    check_targets(output=args.output, plot=args.plot, parquet=args.parquet, reads=(args.sweep,))
    require("dask.distributed", "mount-twin sweep")
    if args.plot:
        require("matplotlib", "--plot")
    if args.parquet:
        require("pyarrow", "--parquet")
    from tqdm import tqdm

    from mount_twin.sweeps.cases import check
    from mount_twin.sweeps.runner import FAILED, read_results, run_sweep, summary
    from mount_twin.sweeps.spec import load_sweep

    spec = load_sweep(args.sweep)
    cases = check(spec)
    bar = tqdm(total=len(cases), unit="case", disable=args.no_progress)

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(1)

    run_sweep(spec, args.output, scheduler=args.scheduler, workers=args.workers, progress=progress)
    bar.close()
    ids = {c.case_id for c in cases}
    table = read_results(args.output)
    rows = [r for r in table if r["case"] in ids]
    print(f"{len(rows)} cases in {args.output}{_others(len(table) - len(rows))}")
    print(summary(rows, spec))
    if args.parquet:
        import pyarrow as pa
        import pyarrow.parquet as pq

        from mount_twin.textfiles import replacing

        # whole or not at all, as the CSV and PNG outputs: a write that failed part-way had
        # left a truncated file in place of the last good one
        with replacing(args.parquet) as tmp:
            pq.write_table(pa.Table.from_pylist(rows), str(tmp))
        print(f"parquet: {args.parquet}")
    if args.plot:
        from mount_twin.sweeps.plot import plot_sweep

        print(f"plot: {plot_sweep(rows, spec, args.plot)}")
    return 0 if all(r["verdict"] != FAILED for r in rows) else EXIT_FAILED


def _others(n: int) -> str:
    """What the results CSV holds beside this sweep's cases (n of other cases' ids), which the
    summary, the exit status, --parquet and --plot leave out."""
    if not n:
        return ""
    return (
        f" (and {n} of cases this sweep no longer has: run with another base scene, input or "
        "value; not counted here)"
    )
