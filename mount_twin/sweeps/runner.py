"""Running a sweep: one case as a pure function of its inputs, many on a Dask cluster.

`run_case` is what a worker runs: it builds the case's scene, reads (once per worker process)
or generates its input, pushes it through a `TwinEngine` and returns one row of figures, with
the digest of the scene it ran (`SCENE_DIGEST`, as a replay of that scene records it). No bag
is written. `run_sweep` submits the unfinished cases to a `dask.distributed` client (a local
cluster on this machine's cores by default, or a scheduler address) and appends each row to a
CSV as it completes, so an interrupted sweep resumes where it stopped; a case that fails is a
row with verdict FAILED and its error, and never stops the sweep.
"""

from __future__ import annotations

import csv
import json
import math
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager, suppress
from functools import lru_cache
from pathlib import Path
from typing import Any

from mount_twin.analysis.figures import (
    DISPLACEMENT,
    PEAK_FORCE,
    displacement_from_start,
    peak_magnitudes,
    peak_text,
    utilisation_text,
)
from mount_twin.engine.batch import FAILED, LEVEL_NAMES, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.tilt import tilt_from_quaternions
from mount_twin.errors import MountTwinError
from mount_twin.model.assemble import assemble
from mount_twin.physics import pose_row
from mount_twin.scene.description import InputSpec, Scene, scene_digest
from mount_twin.scene.loader import scene_from_dict
from mount_twin.sweeps.cases import Case, apply, expand, key_unit
from mount_twin.sweeps.cluster import dask_client, results_as_completed
from mount_twin.sweeps.spec import InputCase, SweepSpec, bag_digest
from mount_twin.textfiles import directories_above

UTILISATION = "utilisation"
"""The result table's per-mount utilisation columns are UTILISATION.<mount> (NaN: unrated)."""
SCENE_DIGEST = "scene_sha256"
"""The result table's column of the scene a case ran: its digest (`scene.description.scene_digest`,
the sha256 a replay of that scene records as `mount_twin.scene_sha256` and `report --scene`
checks), '' where the case's scene did not load."""
BATCHES_PER_WORKER = 4
"""Tasks per worker a sweep is cut into: few enough to share the scheduling cost, enough to
balance the load and to report progress."""


def columns(spec: SweepSpec) -> list[str]:
    """The result table's columns: case, input, one per varied key, the scene's digest
    (SCENE_DIGEST), then the figures."""
    names = [m["name"] for m in spec.base["mounts"]]
    return [
        "case",
        "input",
        *(v.key if v.op == "set" else f"{v.key} (scale)" for v in spec.variations),
        SCENE_DIGEST,
        "verdict",
        "error",
        *(f"{PEAK_FORCE}.{n}" for n in names),
        *(f"{UTILISATION}.{n}" for n in names),
        "events",
        "first_event",
        "first_event_s",
        DISPLACEMENT,
        "max_tilt_rad",
        "est_force_error_rel",
        "wall_s",
    ]


def column_units(spec: SweepSpec) -> dict[str, str]:
    """The unit of each varied column whose key's unit the scene's tables state (`key_unit`):
    a set value's (a scale's column holds a factor)."""
    units = {v.key: key_unit(v.key, spec.base) for v in spec.variations if v.op == "set"}
    return {key: unit for key, unit in units.items() if unit is not None}


def value_text(column: str, value: Any, units: dict[str, str]) -> str:
    """A varied value as the summary and the plot give it: with its column's unit, if known."""
    return f"{value} {units[column]}" if column in units else f"{value}"


@lru_cache(maxsize=8)
def _input_samples(case: InputCase, spec: InputSpec) -> SampleBatch:
    """The input of a case (read once per worker process, input and input spec: a bag recorded
    again is another input, `InputCase.content`, read anew by a worker that read the old).
    A bag is read only as the sweep loaded it: its digest is taken again once the read ends (or
    fails), and a bag recorded again since the load, before the read or during it (its cases'
    ids hash the old content), is a MountTwinError, the case's FAILED row, not the new
    record's figures under the old ids. (Taken before the read as well, it cost every worker a
    third pass over the bag for the one change it alone sees: a record replaced and put back
    while the worker read it.)"""
    if case.bag:
        from mount_twin.io.input_samples import read_samples

        try:
            samples = read_samples(case.bag, spec)
        except Exception:
            # a record replaced since the load is why, not what its read met; a bag gone or
            # unreadable: the read's own error says so
            with suppress(OSError):
                _same_bag(case)
            raise
        _same_bag(case)
        return samples
    from mount_twin.io.signals import half_sine_shock, ship_motion

    g = dict(case.generate)
    if g["kind"] == "half-sine":
        sig = half_sine_shock(
            peak=g.get("peak", 150.0),
            duration=g.get("pulse", 0.008),
            rate_hz=g.get("rate", 10000.0),
            total=g.get("duration", 0.4),
            lateral=g.get("lateral", 0.0),
            rebound=g.get("rebound", 0.0),
        )
    else:
        sig = ship_motion(rate_hz=g.get("rate", 1000.0), total=g.get("duration", 5.0))
    stamps = 1.0 + sig.t  # engine seconds; the record's origin is immaterial to a case
    return SampleBatch(stamps, sig.accel, sig.gyro, [spec.frame_id] * stamps.shape[0])


def _same_bag(case: InputCase) -> None:
    """MountTwinError unless the bag at case.bag still has the content the sweep loaded."""
    now = bag_digest(Path(case.bag), {})
    if now != case.content:
        msg = (
            f"{case.bag}: recorded again since the sweep was loaded (content SHA-256 "
            f"{now[:12]}…, loaded as {case.content[:12]}…): load the sweep again to run it "
            "on the new record"
        )
        raise MountTwinError(msg)


def run_case(base: dict[str, Any], source: str, case: Case) -> dict[str, Any]:
    """One row of figures for `case` (never raises: a failure is a FAILED row), with the
    digest of its scene (SCENE_DIGEST) wherever that scene loaded, a failed case's too."""
    row: dict[str, Any] = {"case": case.case_id, "input": case.input.name}
    for key, op, value in case.settings:
        row[key if op == "set" else f"{key} (scale)"] = setting_text(value)
    row[SCENE_DIGEST] = ""
    t0 = time.perf_counter()
    try:
        scene = scene_from_dict(
            apply(base, case.settings), f"{source} case {case.case_id}", refuse_unheld=True
        )
        row[SCENE_DIGEST] = scene_digest(scene)
        samples = _input_samples(case.input, scene.input)
        row.update(_figures(scene, samples))
    except (MountTwinError, ValueError, KeyError, OSError) as err:
        row.update(verdict=FAILED, error=f"{type(err).__name__}: {err}")
    row["wall_s"] = time.perf_counter() - t0
    return row


def setting_text(value: Any) -> str:
    """A varied value as a row holds it: JSON (a number, true, "text", [0.9, 0.4, 0.0])."""
    return json.dumps(value)


def run_cases(base: dict[str, Any], source: str, cases: list[Case]) -> list[dict[str, Any]]:
    """`run_case` of each case, in order (one Dask task)."""
    return [run_case(base, source, case) for case in cases]


def _figures(scene: Scene, samples: SampleBatch) -> dict[str, Any]:
    engine = TwinEngine(assemble(scene))
    out = engine.run(samples)
    if nothing := engine.followed_nothing:  # no figures, as a case that raised
        return {"verdict": FAILED, "error": nothing}
    reports = out.health
    worst = max((s.level for r in reports for s in r.statuses), default=0)
    force = peak_magnitudes(out.wrenches)[:, 0] if len(out) else None
    util = engine.utilisation_max
    first = engine.events[0] if engine.events else None
    position = out.pose[:, pose_row.POSITION_COLS]
    row: dict[str, Any] = {
        # FAILED: its figures are not the machine's (`engine.failure_text`), and stay out of
        # the summary's lowest and highest
        "verdict": FAILED if engine.failure_text else LEVEL_NAMES[worst],
        "error": engine.failure_text,
        "events": engine.counts["mount_events"],
        "first_event": f"{first.mount}:{first.event}" if first else "",
        "first_event_s": first.stamp - float(samples.stamps[0]) if first else math.nan,
        DISPLACEMENT: displacement_from_start(position, position[0]) if len(out) else math.nan,
        "max_tilt_rad": float(tilt_from_quaternions(out.quaternion).max())
        if len(out)
        else math.nan,
        # the twin's own estimate of its mount-force error (NaN: integration.error_estimate
        # off, or no input interval integrated: `ErrorEstimate.estimated`)
        "est_force_error_rel": engine.error_estimate.force_error_rel
        if engine.error_estimate
        else math.nan,
    }
    for i, m in enumerate(scene.mounts):
        row[f"{PEAK_FORCE}.{m.name}"] = float(force[i]) if force is not None else math.nan
        row[f"{UTILISATION}.{m.name}"] = util.get(m.name, math.nan)
    return row


def finished_cases(results: Path, head: list[str]) -> set[str]:
    """Ids of the cases already in a results CSV (FAILED ones are run again). MountTwinError
    if it has other columns than `head` (this sweep's): another sweep's, an older mount_twin's
    or no results at all, refused before any case runs (a CSV without a `case` column died
    with a KeyError, the cases already run)."""
    if not results.exists():
        return set()
    if not results.is_file():  # /dev/full, /dev/zero: read back for ever
        msg = f"{results}: the results CSV is no regular file (it is read back and appended to)"
        raise ValueError(msg)
    with results.open(encoding="utf-8", newline="") as fh:
        had = next(csv.reader(fh), None)
        if had is None:  # empty: new
            return set()
        if had != head:
            msg = (
                f"{results}: its columns are not this sweep's (another sweep, or an older "
                f"mount_twin's column names); missing {sorted(set(head) - set(had))}, not "
                f"ours {sorted(set(had) - set(head))}: write to a new file"
            )
            raise MountTwinError(msg)
        return {r["case"] for r in csv.DictReader(fh, had) if r.get("verdict") != FAILED}


def run_sweep(
    spec: SweepSpec,
    results: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Run every unfinished case of `spec`, appending rows to the CSV `results`; returns the
    rows run now. `scheduler`: a Dask scheduler address (default: a local cluster of
    `workers` processes, one thread each; default one per core). `progress(done, total)` is
    called after each case."""
    path = Path(results)
    head = columns(spec)
    todo = [c for c in expand(spec) if c.case_id not in finished_cases(path, head)]
    if not todo:
        return []
    rows = []
    with dask_client(scheduler, workers) as client:
        # Cases go out in batches, a few per worker, so that the scheduler's cost per task is
        # shared by several cases (a case takes ~40 ms: one task each cost a third of that).
        n_workers = max(len(client.scheduler_info()["workers"]), 1)
        size = max(1, math.ceil(len(todo) / (BATCHES_PER_WORKER * n_workers)))
        batches = [todo[k : k + size] for k in range(0, len(todo), size)]
        n = len(batches)
        done = results_as_completed(client, run_cases, [spec.base] * n, [spec.source] * n, batches)
        with _appender(path, head) as append:
            for batch_rows in done:
                for row in batch_rows:
                    append(row)
                    rows.append(row)
                    if progress:
                        progress(len(rows), len(todo))
    return rows


@contextmanager
def _appender(path: Path, head: list[str]) -> Iterator[Callable[[dict[str, Any]], None]]:
    """Append rows to a CSV (header written if the file is new), flushed row by row; its
    columns were checked by `finished_cases`. The directories missing above a new one are
    made; a new one that a sweep stopped before its first row leaves is removed with them
    (`textfiles.directories_above`): it held only the header this run wrote."""
    made = not (path.exists() or path.is_symlink())  # nor a dangling symlink
    new = made or path.stat().st_size == 0
    appended = 0
    with directories_above(path):
        try:
            with path.open("a", encoding="utf-8", newline="") as fh:
                writer = csv.DictWriter(fh, head, extrasaction="raise")
                if new:
                    writer.writeheader()

                def append(row: dict[str, Any]) -> None:
                    nonlocal appended
                    writer.writerow({k: _cell(row.get(k, "")) for k in head})
                    fh.flush()
                    appended += 1

                yield append
        except BaseException:
            if made and not appended:
                path.unlink(missing_ok=True)
            raise


def _cell(value: Any) -> Any:
    return repr(value) if isinstance(value, float) else value


TEXT_COLUMNS = frozenset({"case", "input", SCENE_DIGEST, "verdict", "error", "first_event"})
"""Columns that hold text whatever they look like (a case id or a digest of digits stays one)."""


def read_results(results: str | Path) -> list[dict[str, Any]]:
    """The rows of a results CSV, one per case: a case run again (a rerun retries the FAILED
    ones, appending their new rows) is its latest row, in its first row's place. Typed: each
    column but `TEXT_COLUMNS` whose every non-empty cell is an integer holds ints, one whose
    every non-empty cell is a number floats (an empty cell, a failed case's figure: None), any
    other text; so `DataFrame(rows)` has numeric columns."""
    with Path(results).open(encoding="utf-8", newline="") as fh:
        latest = {r["case"]: r for r in csv.DictReader(fh)}
    rows: list[dict[str, Any]] = list(latest.values())
    for name in rows[0] if rows else ():
        if name not in TEXT_COLUMNS:
            convert = _column_type([r[name] for r in rows if r[name] != ""])
            for r in rows:
                r[name] = None if r[name] == "" else convert(r[name])
    return rows


def _column_type(cells: list[str]) -> Callable[[str], Any]:
    """int, float or str: the narrowest that reads every cell."""
    for kind in (int, float):
        try:
            for cell in cells:
                kind(cell)
        except ValueError:
            continue
        return kind
    return str


def largest_peak_force(row: dict[str, Any], mounts: list[str]) -> float:
    """The largest of a row's peak mount forces |F| (N)."""
    return max(float(row[f"{PEAK_FORCE}.{n}"]) for n in mounts)


def largest_utilisation(row: dict[str, Any], mounts: list[str]) -> float:
    """The largest of a row's mount utilisations (NaN where no mount is rated)."""
    rated = [u for u in (float(row[f"{UTILISATION}.{n}"]) for n in mounts) if not math.isnan(u)]
    return max(rated, default=math.nan)


NAMED_FAILURES = 3
"""Failed cases the summary names with their errors (the rest it counts)."""


def summary(rows: Iterable[dict[str, Any]], spec: SweepSpec) -> str:
    """The verdict counts, the first NAMED_FAILURES failed cases with their errors, the cases
    of the lowest and highest peak mount force, and per input the case whose largest mount
    utilisation is lowest (the design that input favours)."""
    rows = list(rows)
    names = [m["name"] for m in spec.base["mounts"]]
    varied = columns(spec)[2 : 2 + len(spec.variations)]
    units = column_units(spec)

    def setting(r: dict[str, Any]) -> str:
        return ", ".join(f"{k} = {value_text(k, r[k], units)}" for k in varied)

    counts: dict[str, int] = {}
    for r in rows:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    lines = ["verdicts: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))]
    failed = [r for r in rows if r["verdict"] == FAILED]
    lines += [
        f"  FAILED case {r['case']} ({r['input']}; {setting(r)}): {r['error']}"
        for r in failed[:NAMED_FAILURES]
    ]
    if len(failed) > NAMED_FAILURES:
        lines.append(
            f"  and {len(failed) - NAMED_FAILURES} more FAILED (the table's error column)"
        )
    done = [r for r in rows if r["verdict"] != FAILED]
    if done:

        def peak(r: dict[str, Any]) -> float:
            return largest_peak_force(r, names)

        for label, r in (("lowest", min(done, key=peak)), ("highest", max(done, key=peak))):
            lines.append(
                f"{label} peak mount force: {peak_text(peak(r))} N, case {r['case']} "
                f"({r['input']}; {setting(r)}) {r['verdict']}"
            )

        def utilisation(r: dict[str, Any]) -> float:
            return largest_utilisation(r, names)

        best = []
        for case in spec.inputs:
            rated = [r for r in done if r["input"] == case.name and not math.isnan(utilisation(r))]
            if rated:
                r = min(rated, key=utilisation)
                best.append(
                    f"  {case.name}: {utilisation_text(utilisation(r))}, case {r['case']} "
                    f"({setting(r)}) {r['verdict']}"
                )
        if best:
            lines += ["lowest largest utilisation, per input:", *best]
    return "\n".join(lines)


def sweep(
    sweep_file: str | Path,
    results: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
) -> list[dict[str, Any]]:
    """Load, check and run a sweep file (cases already in `results` are skipped) and return
    every row of `results`, typed (`read_results`): one dict per case, columns as `columns`
    names them (the `pandas.DataFrame(rows)` of it is the table)."""
    from mount_twin.sweeps.cases import check
    from mount_twin.sweeps.spec import load_sweep

    spec = load_sweep(sweep_file)
    check(spec)
    run_sweep(spec, results, scheduler=scheduler, workers=workers)
    return read_results(results)
