"""Design sweeps: key paths, the sweep file's checks, and a sweep on a real local Dask cluster
whose rows equal single runs of the same cases; resumable, a failing case is a row."""

from __future__ import annotations

import csv
import hashlib
import math
import shutil
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
import yaml
from io_helpers import CONFIG, ROOT

from mount_twin.analysis.figures import peak_text, utilisation_text
from mount_twin.cli import main
from mount_twin.errors import SceneError
from mount_twin.scene.yaml_reading import read_scene_yaml
from mount_twin.sweeps.cases import apply, check
from mount_twin.sweeps.cluster import dask_client
from mount_twin.sweeps.plot import plot_sweep, trade_off
from mount_twin.sweeps.runner import (
    FAILED,
    NAMED_FAILURES,
    columns,
    read_results,
    run_case,
    run_sweep,
)
from mount_twin.sweeps.spec import load_sweep

PUMP = CONFIG / "pump_8_mounts.scene.yaml"
SWEEP = f"""\
base: {PUMP}
vary:
  - key: mounts[*].stiffness
    scale: [0.5, 2.0]
  - key: body.mass
    values: [1100.0, -5.0]
inputs:
  - bag: {ROOT / "bags" / "half_sine_shock_10khz"}
  - name: dhs
    generate: {{kind: half-sine, peak: 300.0, pulse: 0.005, rebound: 100.0, rate: 4000.0,
               duration: 0.15}}
"""


def _sweep_file(tmp_path: Path, text: str = SWEEP) -> Path:
    path = tmp_path / "sweep.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_key_paths_set_and_scale_what_they_name() -> None:
    base = read_scene_yaml(PUMP)
    data = apply(
        base,
        (("mounts[*].stiffness", "scale", 2.0), ("mounts[fl].position", "set", [1.0, 0.4, 0.0])),
    )
    for before, after in zip(base["mounts"], data["mounts"], strict=True):
        assert after["stiffness"] == [2.0 * v for v in before["stiffness"]]
        want = [1.0, 0.4, 0.0] if before["name"] == "fl" else before["position"]
        assert after["position"] == want
    assert base["mounts"][0]["stiffness"][2] == 1.2e6, "the base is not changed"


def test_a_key_path_the_scene_lacks_fails_at_load_naming_it(tmp_path: Path) -> None:
    spec = load_sweep(_sweep_file(tmp_path, SWEEP.replace("body.mass", "body.mas")))
    with pytest.raises(SceneError, match=r"vary\[1\]\.key: body\.mas: unknown key \(known"):
        check(spec)
    with pytest.raises(SceneError, match=r"sweep.yaml: inputs: required key is missing"):
        load_sweep(_sweep_file(tmp_path, SWEEP.split("inputs:", maxsplit=1)[0]))


def test_a_key_the_base_leaves_at_its_default_can_be_set(tmp_path: Path) -> None:
    """spec.py's own example, input.gyro_stopband_hz, was refused as "no 'gyro_stopband_hz'
    here" against the bundled base, which leaves it at its default; a misspelt one is still
    refused at load."""
    varied = "input.gyro_stopband_hz\n    values: [90.0, 110.0]"
    spec = load_sweep(
        _sweep_file(tmp_path, SWEEP.replace("body.mass\n    values: [1100.0, -5.0]", varied))
    )
    stopbands = {c.settings[1][2] for c in check(spec)}
    assert stopbands == {90.0, 110.0}
    data = apply(spec.base, (("input.gyro_stopband_hz", "set", 90.0),))
    assert data["input"]["gyro_stopband_hz"] == 90.0
    typo = load_sweep(_sweep_file(tmp_path, SWEEP.replace("body.mass", "input.gyro_stopbnd_hz")))
    with pytest.raises(SceneError, match=r"vary\[1\]\.key: input\.gyro_stopbnd_hz: unknown key"):
        check(typo)


@pytest.mark.parametrize(
    ("edit", "says"),
    [
        (  # every case ran and FAILED, exit 5, none naming the key
            ("half_sine_shock_10khz", "no_such_bag"),
            r"inputs\[0\]\.bag: no such file or directory: .*no_such_bag",
        ),
        (("scale: [0.5, 2.0]", "scale: [true, 2.0]"), r"vary\[0\]\.scale: expected numbers"),
        (  # its digest read it for ever
            (str(ROOT / "bags" / "half_sine_shock_10khz"), "/dev/zero"),
            r"inputs\[0\]\.bag: /dev/zero: no bag \(neither a directory nor a regular file\)",
        ),
    ],
    ids=["missing-bag", "boolean-scale", "device"],
)
def test_a_bad_input_or_scale_fails_at_load_naming_it(
    tmp_path: Path, edit: tuple[str, str], says: str
) -> None:
    with pytest.raises(SceneError, match=says):
        load_sweep(_sweep_file(tmp_path, SWEEP.replace(*edit)))


@pytest.mark.parametrize(
    ("edit", "says"),
    [
        ((f"base: {PUMP}", "base: /dev/zero"), "/dev/zero: cannot read: larger than"),
        (
            ("values: [1100.0, -5.0]", "range: {start: 1.0, stop: 2.0, num: 1000000000}"),
            "vary[1].range.num: must be in [1, 100000], got 1000000000",
        ),
        (
            ("values: [1100.0, -5.0]", "range: {start: 1.0, stop: 2.0, num: 100000}"),
            "vary: 400000 cases, more than MAX_CASES (100000) allows",
        ),
    ],
    ids=["base-dev-zero", "range-num", "cases"],
)
def test_a_sweep_beyond_a_limit_fails_at_load_naming_it(
    tmp_path: Path, edit: tuple[str, str], says: str
) -> None:
    """Each was a MemoryError traceback (a base read for ever, 10⁹ values, 4·10⁵ cases)."""
    with pytest.raises((SceneError, ValueError)) as err:
        load_sweep(_sweep_file(tmp_path, SWEEP.replace(*edit)))
    assert says in str(err.value)


@pytest.mark.parametrize(
    ("options", "says"),
    [
        ("rate: 0.0, duration: 0.15", "rate must be > 0 Hz and finite, got 0.0"),
        (
            "rate: 1.0e6, duration: 1.0e6",
            "must give 1 to 10000000 samples (MAX_SAMPLES), got 1000000.0 s × 1000000.0 Hz",
        ),
    ],
    ids=["rate-0", "1e12-samples"],
)
def test_a_generated_input_of_no_or_too_many_samples_is_a_failed_case(
    tmp_path: Path, options: str, says: str
) -> None:
    """At rate 0 a case ran on nothing and was reported OK; 10¹² samples were a MemoryError."""
    text = SWEEP.replace("rate: 4000.0,\n               duration: 0.15", options)
    spec = load_sweep(_sweep_file(tmp_path, text))
    case = next(c for c in check(spec) if c.input.generate)
    row = run_case(spec.base, spec.source, case)
    assert row["verdict"] == FAILED and says in row["error"]


def test_a_case_where_no_input_sample_is_accepted_is_a_failed_row(tmp_path: Path) -> None:
    """Every sample of the bag refused (another frame_id): the row read ERROR with utilisation
    0.0 and a NaN peak force, which the summary took for both the lowest and the highest."""
    varied = "input.frame_id\n    values: [x]"
    text = SWEEP.replace("body.mass\n    values: [1100.0, -5.0]", varied)
    spec = load_sweep(_sweep_file(tmp_path, text))
    case = next(c for c in check(spec) if not c.input.generate)
    row = run_case(spec.base, spec.source, case)
    assert row["verdict"] == FAILED
    assert row["error"].startswith("no input sample was accepted (")
    assert "rejected: wrong_frame" in row["error"]
    assert not [k for k in row if k.startswith(("peak_force", "utilisation"))]  # none made


def test_results_that_are_no_regular_file_are_an_error_before_any_case_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """-o /dev/full was read back as results for ever (a MemoryError traceback)."""
    sweep = str(_sweep_file(tmp_path))
    assert main(["sweep", sweep, "-o", "/dev/full", "--workers", "1", "--no-progress"]) == 2
    assert "/dev/full: the results CSV is no regular file" in capsys.readouterr().err


@pytest.mark.parametrize("where", ["other_csv", "the_sweep_file", "under_a_file"])
def test_results_no_sweep_can_append_to_are_an_error_naming_them_before_any_case_runs(
    tmp_path: Path,
    where: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """-o of a CSV without a `case` column (or the sweep file itself) died with a KeyError
    traceback (exit 1); -o under a file (no directory can be made there) started the cluster,
    then said only "FILE: Not a directory". Each is refused before the cluster starts, naming
    the file; what is there is left as it was."""
    sweep = _sweep_file(tmp_path)
    other = tmp_path / "other.csv"
    other.write_text("time,az\n0.0,1.0\n", encoding="utf-8")
    out = {"other_csv": other, "the_sweep_file": sweep}.get(where, other / "no" / "r.csv")
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}

    def no_cluster(*_: object) -> None:
        raise AssertionError("the cluster was started before the results file was checked")

    monkeypatch.setattr("mount_twin.sweeps.runner.dask_client", no_cluster)
    assert main(["sweep", str(sweep), "-o", str(out), "--workers", "1", "--no-progress"]) == 2
    said = {
        "other_csv": f"{out}: its columns are not this sweep's",
        "the_sweep_file": f"--output {out}: would replace {sweep}, which this command reads",
        "under_a_file": f"--output {out}: {other} is not a directory",
    }[where]
    assert said in capsys.readouterr().err
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before


def test_results_written_before_the_scene_digest_column_are_read_but_not_appended_to(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A results CSV of the columns before `scene_sha256`: its rows still read, and a sweep
    refuses to append rows of another layout to it, naming the column, before any case runs."""
    sweep = _sweep_file(tmp_path)
    old = tmp_path / "old.csv"
    head = [c for c in columns(load_sweep(sweep)) if c != "scene_sha256"]
    with old.open("w", encoding="utf-8", newline="") as fh:
        writer = csv.DictWriter(fh, head)
        writer.writeheader()
        writer.writerow({"case": "c0", "input": "dhs", "verdict": "OK", "events": 0})
    before = old.read_bytes()
    assert [(r["case"], r["verdict"]) for r in read_results(old)] == [("c0", "OK")]
    assert main(["sweep", str(sweep), "-o", str(old), "--workers", "1", "--no-progress"]) == 2
    assert "missing ['scene_sha256'], not ours []: write to a new file" in capsys.readouterr().err
    assert old.read_bytes() == before


@pytest.mark.parametrize("rows", [0, 1])
def test_results_in_directories_it_makes_are_removed_with_them_if_stopped_before_a_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, rows: int
) -> None:
    """-o a/b/r.csv makes the directories missing above the results, as every output does. A
    sweep stopped (Ctrl-C) before its first row leaves neither the results CSV, which would
    hold only its header, nor them; one stopped after a row keeps the row, for the rerun."""
    from contextlib import contextmanager

    from mount_twin.sweeps import runner

    @contextmanager
    def cluster(*_: object):
        yield type("Client", (), {"scheduler_info": lambda _: {"workers": {"w": None}}})()

    def stopped(*_: object):
        yield from [[{"case": "c0"}]][:rows]
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "dask_client", cluster)
    monkeypatch.setattr(runner, "results_as_completed", stopped)
    (tmp_path / "kept").mkdir()
    results = tmp_path / "kept" / "a" / "b" / "r.csv"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(load_sweep(_sweep_file(tmp_path / "kept")), results, workers=1)
    if rows:
        assert [r["case"] for r in read_results(results)] == ["c0"]
    else:
        assert sorted(tmp_path.rglob("*")) == [tmp_path / "kept", tmp_path / "kept" / "sweep.yaml"]


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory):
    tmp = tmp_path_factory.mktemp("sweep")
    spec = load_sweep(_sweep_file(tmp))
    results = tmp / "results.csv"
    rows = run_sweep(spec, results, workers=2)
    return spec, results, rows


def test_the_sweep_runs_every_case_on_the_cluster_as_a_single_run_would(swept) -> None:
    spec, results, rows = swept
    cases = check(spec)
    assert len(rows) == len(cases) == 2 * 2 * 2
    table = {r["case"]: r for r in read_results(results)}
    assert list(next(iter(table.values()))) == columns(spec)
    for case in cases:
        single = run_case(spec.base, spec.source, case)  # in this process, no Dask
        row = table[case.case_id]
        assert row["verdict"] == single["verdict"]
        for key, value in single.items():
            if key == "wall_s" or not isinstance(value, float):
                continue
            got = float(row[key])
            assert (math.isnan(got) and math.isnan(value)) or got == value, (key, got, value)


def test_a_bad_case_is_a_failed_row_and_the_rest_still_run(swept) -> None:
    _, results, _ = swept
    rows = read_results(results)
    failed = [r for r in rows if r["verdict"] == FAILED]
    assert len(failed) == 4 and all(r["body.mass"] == -5.0 for r in failed)
    assert all("body.mass" in r["error"] for r in failed)
    assert all(r["peak_force_magnitude_N.fl"] is None for r in failed)
    good = [r for r in rows if r["verdict"] != FAILED]
    assert len(good) == 4 and all(float(r["peak_force_magnitude_N.fl"]) > 1000.0 for r in good)
    # each case's own error estimate: the pump at one step per sample is ~1e-9 off
    assert all(0.0 < float(r["est_force_error_rel"]) < 1e-6 for r in good)


def _pump_scene(scale: float, **values: Any) -> dict[str, Any]:
    """The bundled pump's scene mapping with every mount's stiffness × `scale` and each
    `values` (section → key → value) set: a sweep case's scene, built here by hand."""
    data = yaml.safe_load(PUMP.read_text(encoding="utf-8"))
    for mount in data["mounts"]:
        mount["stiffness"] = [scale * k for k in mount["stiffness"]]
    for section, keys in values.items():
        data[section].update(keys)
    return data


def _replayed_digest(tmp: Path, data: dict[str, Any]) -> str:
    """The scene digest a `mount-twin replay` of the scene `data` (written to a file) records in
    its output bag's metadata, checked to be the sha256 of the scene's value it records beside
    it (the text `report --scene` reads)."""
    tmp.mkdir(parents=True)
    bag, scene, out = tmp / "bag", tmp / "case.scene.yaml", tmp / "out"
    shock = ["--peak", "150", "--pulse", "0.008", "--rate", "4000", "--duration", "0.1"]
    assert main(["generate", "half-sine", "-o", str(bag), *shock]) == 0
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert main(["replay", str(bag), "--scene", str(scene), "-o", str(out)]) in (0, 3)
    metadata = yaml.safe_load((out / "metadata.yaml").read_text(encoding="utf-8"))
    custom = metadata["rosbag2_bagfile_information"]["custom_data"]
    digest = custom["mount_twin.scene_sha256"]
    assert hashlib.sha256(custom["mount_twin.scene_value"].encode()).hexdigest() == digest
    return digest


def test_each_row_names_its_scene_by_the_digest_a_replay_of_that_scene_records(
    swept, tmp_path: Path
) -> None:
    """A row did not say which scene it ran: a surprising one could not be checked against the
    scene its reader had in mind. Each row holds the digest of its case's scene, the one a
    replay of that scene records (and `report --scene` checks); the two inputs of one setting
    share it, the two stiffnesses differ. A case whose scene did not load (a negative mass)
    has none to name: its cell is empty, its error says why."""
    _, results, _ = swept
    digests = {
        scale: _replayed_digest(tmp_path / str(scale), _pump_scene(scale, body={"mass": 1100.0}))
        for scale in (0.5, 2.0)
    }
    assert digests[0.5] != digests[2.0]
    rows = read_results(results)
    for r in rows:
        if r["body.mass"] == -5.0:
            assert (r["verdict"], r["scene_sha256"]) == (FAILED, ""), r["case"]
        else:
            assert r["scene_sha256"] == digests[r["mounts[*].stiffness (scale)"]], r["case"]
    assert all(isinstance(r["scene_sha256"], str) for r in rows)  # text, as a case id


def test_a_failed_cases_row_names_the_scene_it_failed_on(tmp_path: Path) -> None:
    """A case whose scene loaded and whose run failed, on the engine's side (the bag's frame_id
    not the scene's: no sample accepted) or before it (a generated input of rate 0), keeps the
    digest of its scene: the one a replay of that scene records."""
    varied = "input.frame_id\n    values: [x]"
    text = SWEEP.replace("body.mass\n    values: [1100.0, -5.0]", varied)
    text = text.replace("rate: 4000.0,", "rate: 0.0,")
    spec = load_sweep(_sweep_file(tmp_path, text))
    rows = [(c, run_case(spec.base, spec.source, c)) for c in check(spec)]
    assert [r["verdict"] for _, r in rows] == [FAILED] * 4
    assert {c.input.name for c, _ in rows} == {"half_sine_shock_10khz", "dhs"}
    for case, row in rows:
        scale = case.settings[0][2]
        data = _pump_scene(scale, input={"frame_id": "x"})
        assert row["scene_sha256"] == _replayed_digest(tmp_path / case.case_id, data), row


def test_results_are_typed_numbers_as_numbers(swept) -> None:
    """pandas.DataFrame(rows)[column].max() must compare numbers, not strings ('9809.98' >
    '15564.19' as text)."""
    pandas = pytest.importorskip("pandas")
    _, results, _ = swept
    rows = read_results(results)
    good = [r for r in rows if r["verdict"] != FAILED]
    assert all(isinstance(r["peak_force_magnitude_N.fl"], float) for r in good)
    assert all(isinstance(r["events"], int) for r in good)
    assert all(isinstance(r["case"], str) and isinstance(r["verdict"], str) for r in rows)
    frame = pandas.DataFrame(rows)
    column = frame["peak_force_magnitude_N.fl"]
    assert column.dtype.kind == "f"
    assert column.max() == max(r["peak_force_magnitude_N.fl"] for r in good)


def test_a_rerun_skips_finished_cases_and_reruns_failed_ones(swept) -> None:
    spec, results, _ = swept
    again = run_sweep(spec, results, workers=1)
    assert len(again) == 4 and all(r["verdict"] == FAILED for r in again)


def test_the_command_reports_and_exits_6_when_a_case_failed(
    swept, capsys: pytest.CaptureFixture[str]
) -> None:
    spec, results, _ = swept

    def rows() -> int:
        with results.open(encoding="utf-8") as fh:
            return sum(1 for _ in csv.DictReader(fh))

    before = rows()  # 8 + 4, or 8 + 4 + 4 after the rerun test on this worker
    code = main(["sweep", spec.source, "-o", str(results), "--workers", "1", "--no-progress"])
    assert code == 6  # FAILED, as replay's (5 is replay's damaged bag)
    out = capsys.readouterr().out
    assert "verdicts:" in out and "FAILED" in out and "highest peak mount force" in out
    # the failed cases named with their errors: a script's exit 6 says which and why
    named = [line for line in out.splitlines() if line.startswith("  FAILED case ")]
    assert len(named) == NAMED_FAILURES
    assert all("body.mass = -5.0 kg): SceneError: " in line for line in named)
    assert "more FAILED (the table's error column)" in out
    # per input, the case of the lowest largest utilisation, from the table's own columns
    names = [m["name"] for m in spec.base["mounts"]]
    done = [r for r in read_results(results) if r["verdict"] != FAILED]
    assert "lowest largest utilisation, per input:" in out
    for name in ("half_sine_shock_10khz", "dhs"):
        best = min(
            (r for r in done if r["input"] == name),
            key=lambda r: max(r[f"utilisation.{n}"] for n in names),
        )
        value = max(best[f"utilisation.{n}"] for n in names)
        assert f"  {name}: {utilisation_text(value)}, case {best['case']} (" in out, name
    # the largest peak force, as the replay's summary and the report print a peak (it read
    # 1.337e+04 N beside their 13370.0)
    top = max(done, key=lambda r: max(r[f"peak_force_magnitude_N.{n}"] for n in names))
    force = max(top[f"peak_force_magnitude_N.{n}"] for n in names)
    assert f"highest peak mount force: {peak_text(force)} N, case {top['case']} (" in out
    assert rows() == before + 4  # the 4 failed cases rerun, their rows appended


def test_the_plot_draws_each_inputs_largest_force_and_utilisation_in_the_sweeps_order(
    swept, tmp_path: Path
) -> None:
    """One line per input in the sweep file's order (the bag, then `dhs`), its points by the
    first varied value: the largest of the mounts' peak forces (kN) and utilisations in the
    results table; the failed cases (negative mass) left out."""
    pytest.importorskip("matplotlib")
    spec, results, _ = swept
    rows = read_results(results)
    lines = trade_off(rows, spec)
    assert list(lines) == ["half_sine_shock_10khz body.mass=1100.0 kg", "dhs body.mass=1100.0 kg"]
    names = [m["name"] for m in spec.base["mounts"]]
    for label, points in lines.items():
        done = sorted(
            (r for r in rows if label.startswith(r["input"] + " ") and r["verdict"] != FAILED),
            key=lambda r: r["mounts[*].stiffness (scale)"],
        )
        assert (
            [p[0] for p in points]
            == [0.5, 2.0]
            == [r["mounts[*].stiffness (scale)"] for r in done]
        )
        for p, r in zip(points, done, strict=True):
            assert p[1] == max(r[f"peak_force_magnitude_N.{n}"] for n in names) * 1e-3
            assert p[2] == max(r[f"utilisation.{n}"] for n in names) > 0.0
            assert p[3] == r["verdict"]
    png = plot_sweep(rows, spec, tmp_path / "sweep.png")
    assert png.stat().st_size > 10_000


def test_a_cluster_of_fewer_than_one_worker_is_refused_at_once() -> None:
    """A LocalCluster of −1 workers waited for ever (`qualify --workers -1` hung)."""
    for workers in (0, -1):
        with (
            pytest.raises(ValueError, match=f"workers: must be ≥ 1, got {workers}"),
            dask_client(workers=workers),
        ):
            pytest.fail("a cluster came up")


def test_a_retried_case_that_succeeds_is_no_longer_counted_failed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A bag still being copied when the sweep ran (its folder empty) fails its cases; rerun
    once it is in place, they succeed. Their first, FAILED rows stayed in the table the summary
    and the exit status read: "4 cases" of a 2-case sweep, "ERROR 2, FAILED 2", exit 6. (Its
    files are now part of its cases' ids: the rerun's cases are new ones, and the FAILED rows
    of the empty folder are left out, counted.)"""
    bag = tmp_path / "shock"
    bag.mkdir()  # there, but not yet its files
    text = SWEEP.replace(str(ROOT / "bags" / "half_sine_shock_10khz"), str(bag))
    text = text.split("  - name: dhs", maxsplit=1)[0].replace("[1100.0, -5.0]", "[1100.0]")
    sweep, results = str(_sweep_file(tmp_path, text)), str(tmp_path / "results.csv")
    args = ["sweep", sweep, "-o", results, "--workers", "1", "--no-progress"]
    assert main(args) == 6
    assert "verdicts: FAILED 2\n" in capsys.readouterr().out
    bag.rmdir()
    shutil.copytree(ROOT / "bags" / "half_sine_shock_10khz", bag)
    assert main(args) == 0  # each case's latest run succeeded
    out = capsys.readouterr().out
    assert out.startswith(f"2 cases in {results} (and 2 of cases this sweep no longer has")
    assert "verdicts: ERROR 2\n" in out  # the bundled shock overloads the pump's mounts
    ids = {c.case_id for c in check(load_sweep(sweep))}
    assert [r["verdict"] for r in read_results(results) if r["case"] in ids] == ["ERROR", "ERROR"]


def test_a_case_run_again_is_its_latest_row(tmp_path: Path) -> None:
    """A rerun retries a FAILED case, appending its new row: the table is each case's latest
    row, in its first row's place."""
    results = tmp_path / "r.csv"
    results.write_text(
        "case,input,verdict,error,events\n"
        "a,dhs,FAILED,OSError: no bag,\n"
        "b,dhs,OK,,0\n"
        "a,dhs,ERROR,,2\n",
        encoding="utf-8",
    )
    assert [(r["case"], r["verdict"], r["events"]) for r in read_results(results)] == [
        ("a", "ERROR", 2),
        ("b", "OK", 0),
    ]


def test_the_plot_takes_a_first_varied_value_that_is_no_number_in_the_files_order(
    tmp_path: Path,
) -> None:
    """A sweep of mounts[fl].position (spec.py's own example) ran every case and then failed at
    --plot: "could not convert string to float: '[0.9, 0.4, 0.0]'" (exit 2, the sweep's own
    exit status lost). Values that are no numbers are placed side by side in the sweep file's
    order, each labelled as the table writes it."""
    pytest.importorskip("matplotlib")
    positions = "[[1.0, 0.4, 0.0], [0.9, 0.4, 0.0]]"
    text = SWEEP.replace(
        "key: mounts[*].stiffness\n    scale: [0.5, 2.0]",
        "key: mounts[fl].position\n    values: " + positions,
    )
    text = text.replace("[1100.0, -5.0]", "[1100.0]")
    sweep, results, png = _sweep_file(tmp_path, text), tmp_path / "r.csv", tmp_path / "r.png"
    args = ["sweep", str(sweep), "-o", str(results), "--plot", str(png)]
    assert main([*args, "--workers", "1", "--no-progress"]) == 0
    assert png.stat().st_size > 10_000
    spec, rows = load_sweep(sweep), read_results(results)
    lines = trade_off(rows, spec)
    assert list(lines) == ["half_sine_shock_10khz body.mass=1100.0 kg", "dhs body.mass=1100.0 kg"]
    for label, points in lines.items():
        assert [p[0] for p in points] == [0.0, 1.0]
        for p in points:
            (r,) = (  # the row of that place's position
                r
                for r in rows
                if label.startswith(r["input"] + " ")
                and r["mounts[fl].position"] == ["[1.0, 0.4, 0.0]", "[0.9, 0.4, 0.0]"][int(p[0])]
            )
            names = [m["name"] for m in spec.base["mounts"]]
            assert p[1] == max(r[f"peak_force_magnitude_N.{n}"] for n in names) * 1e-3


def test_a_stopped_sweep_says_what_its_table_holds_and_a_rerun_runs_the_rest(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C after the first case: the CSV holds that case's row, whole, and nothing marks it
    (a CSV has no metadata), yet the sweep said "holds the output so far, marked partial in its
    metadata", the replay's words for its output bag."""
    from mount_twin.sweeps import runner

    run_sweep_now = runner.run_sweep

    def stopped_after_one(*args: object, **kwargs: object) -> object:
        def progress(done: int, total: int) -> None:
            raise KeyboardInterrupt

        return run_sweep_now(*args, **{**kwargs, "progress": progress})

    monkeypatch.setattr(runner, "run_sweep", stopped_after_one)
    text = SWEEP.split("  - name: dhs", maxsplit=1)[0]
    sweep, results = str(_sweep_file(tmp_path, text)), tmp_path / "results.csv"
    args = ["sweep", sweep, "-o", str(results), "--workers", "1", "--no-progress"]
    assert main(args) == 130
    err = capsys.readouterr().err
    assert "marked partial" not in err
    assert f"; {results} holds the rows of the cases finished before the stop" in err
    with results.open(encoding="utf-8") as fh:
        assert len(list(csv.DictReader(fh))) == 1  # the one case finished, and nothing else
    monkeypatch.setattr(runner, "run_sweep", run_sweep_now)
    assert main(args) == 6  # the negative mass FAILED
    assert len(read_results(results)) == 4  # the other three run, the first kept


def test_the_local_clusters_workers_leave_ctrl_c_to_the_command() -> None:
    """Ctrl-C reaches the terminal's whole process group: each local worker printed a
    KeyboardInterrupt traceback (30 lines of asyncio and multiprocessing) beside the command's
    own "interrupted (SIGINT)" line, though the command stops them with its cluster. Their
    SIGINT is blocked; this process's is as it was."""
    import signal

    with dask_client(workers=1) as client:
        blocked = client.run(lambda: signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, []))
    assert list(blocked.values()) == [True]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # this process's own
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])


def test_a_stopped_runs_cluster_closes_without_dask_logging_beside_the_command(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Closing a local cluster under a Ctrl-C forgets the cases still running, and its
    scheduler (in this process) logged "Couldn't gather keys: {...: 'forgotten'}" at ERROR
    beside the command's own line (the Ctrl-C test below, once, under CI's load). While a
    stopped run's client and cluster close, nothing of distributed's logs reaches a handler;
    afterwards its level is what it was, and a run that ends well closes as before."""
    import logging

    from distributed import Client

    ours: list[Client] = []  # (other tests' clients may close meanwhile, collected)
    shown: list[bool] = []
    close = Client.close

    def recording(self: Client, *args: Any, **kwargs: Any) -> Any:
        if any(self is c for c in ours):
            shown.append(logging.getLogger("distributed.scheduler").isEnabledFor(logging.ERROR))
        return close(self, *args, **kwargs)

    monkeypatch.setattr(Client, "close", recording)
    level = logging.getLogger("distributed").level
    with pytest.raises(KeyboardInterrupt), dask_client(workers=1) as client:
        ours.append(client)
        raise KeyboardInterrupt
    assert shown and not any(shown)
    assert logging.getLogger("distributed").level == level
    shown.clear()
    with dask_client(workers=1) as client:
        ours.append(client)
    assert shown and all(shown)


@pytest.mark.parametrize("after_s", [0.0, 0.2, 0.5])
def test_ctrl_c_as_the_workers_start_is_the_commands_line_alone(
    tmp_path: Path, after_s: float
) -> None:
    """The workers ignored SIGINT from the cluster's first task on: a Ctrl-C in the second a
    worker takes to start (its imports) printed its KeyboardInterrupt traceback, or "Fatal
    Python error: init_import_site", and one while the cluster itself started an "AssertionError:
    Status.init" at exit. The process group is sent SIGINT `after_s` after the first worker
    process appears: the command says it was interrupted, and nothing else."""
    import os
    import signal
    import subprocess
    import sys
    import time

    import psutil  # dask.distributed's own dependency

    text = SWEEP.split("  - bag:", maxsplit=1)[0] + "  - name: dhs" + SWEEP.split("- name: dhs")[1]
    sweep = _sweep_file(tmp_path, text)
    command = [sys.executable, "-m", "mount_twin.cli", "sweep", str(sweep)]
    options = ["-o", str(tmp_path / "r.csv"), "--workers", "2", "--no-progress"]
    with subprocess.Popen(
        [*command, *options],
        cwd=ROOT,
        start_new_session=True,  # its own process group, as a terminal's foreground job
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    ) as proc:
        started = time.monotonic()
        while not [
            c
            for c in psutil.Process(proc.pid).children(recursive=True)
            if "resource_tracker" not in " ".join(c.cmdline())
        ]:
            assert proc.poll() is None and time.monotonic() - started < 60, "no worker started"
            time.sleep(0.002)
        time.sleep(after_s)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130
    lines = err.splitlines()  # (its one line names the rows held, had a case finished)
    assert len(lines) == 1 and lines[0].startswith("mount-twin: interrupted (SIGINT)"), err


def test_the_plot_says_how_many_failed_cases_it_leaves_out(
    swept, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The 4 cases of negative mass FAILED and have no figures: the plot left them out without a
    word, its title naming only the markers of OK, WARN and ERROR, so a sweep of which half
    failed looked like a sweep of half as many cases."""
    matplotlib = pytest.importorskip("matplotlib")
    monkeypatch.setitem(matplotlib.rcParams, "svg.fonttype", "none")  # text kept as text
    spec, results, _ = swept
    svg = plot_sweep(read_results(results), spec, tmp_path / "sweep.svg")
    assert "4 FAILED cases not drawn" in svg.read_text(encoding="utf-8")


def test_the_plots_force_axis_reads_the_forces_not_an_offset_from_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A variation that hardly moves the force (outputs.decimation: 7853.547 and 7853.555 N,
    the peak held between published rows) had its force axis ticked 48 … 54 beneath a small
    "1e−6+7.8535": read as 54 kN, not 7.85 kN. Its ticks are now the forces, in kN."""
    matplotlib = pytest.importorskip("matplotlib")
    monkeypatch.setitem(matplotlib.rcParams, "svg.fonttype", "none")  # text kept as text
    spec = load_sweep(_sweep_file(tmp_path, SWEEP.replace("[1100.0, -5.0]", "[1100.0]")))
    names = [m["name"] for m in spec.base["mounts"]]
    rows = [
        {
            "case": f"c{k}",
            "input": "dhs",
            "mounts[*].stiffness (scale)": scale,
            "body.mass": 1100.0,
            "verdict": "OK",
            **{f"peak_force_magnitude_N.{n}": force for n in names},
            **{f"utilisation.{n}": 0.87 for n in names},
        }
        for k, (scale, force) in enumerate(((0.5, 7853.547), (2.0, 7853.555)))
    ]
    text = plot_sweep(rows, spec, tmp_path / "sweep.svg").read_text(encoding="utf-8")
    assert "7.8535" in text and "+7.8535" not in text  # a tick reads the force itself


def test_a_rerun_after_the_base_scene_changed_runs_every_case_of_the_new_design(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A case's id hashed what it sets and its input's name only: after the base scene's mass
    was doubled, a rerun skipped every case as finished and summarised the old design. Its
    cases now run again, as a single run of the edited scene does, and the old rows are left
    out of the summary, which says how many."""
    base = tmp_path / "pump.scene.yaml"
    base.write_text(PUMP.read_text(encoding="utf-8"), encoding="utf-8")
    text = SWEEP.replace(str(PUMP), str(base)).replace(
        "  - key: body.mass\n    values: [1100.0, -5.0]\n", ""
    )
    text = text.split("  - bag:")[0] + "  - name: dhs" + text.split("  - name: dhs")[1]
    sweep, results = _sweep_file(tmp_path, text), tmp_path / "r.csv"
    args = ["sweep", str(sweep), "-o", str(results), "--workers", "1", "--no-progress"]
    assert main(args) == 0
    assert capsys.readouterr().out.startswith(f"2 cases in {results}\n")
    first = read_results(results)
    base.write_text(
        base.read_text(encoding="utf-8").replace("mass: 1200.0", "mass: 2400.0"), encoding="utf-8"
    )
    assert main(args) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"2 cases in {results} (and 2 of cases this sweep no longer has")
    spec = load_sweep(sweep)
    assert spec.base["body"]["mass"] == 2400.0
    table = read_results(results)
    assert len(table) == 4 and {r["case"] for r in first} <= {r["case"] for r in table}
    names = [m["name"] for m in spec.base["mounts"]]
    for case in check(spec):  # the edited scene's own single runs
        alone = run_case(spec.base, spec.source, case)
        (row,) = (r for r in table if r["case"] == case.case_id)
        for n in names:
            key = f"peak_force_magnitude_N.{n}"
            assert row[key] == pytest.approx(alone[key], rel=1e-12)
            old = next(
                r[key]
                for r in first
                if r["input"] == row["input"]
                and r["mounts[*].stiffness (scale)"] == row["mounts[*].stiffness (scale)"]
            )
            assert row[key] != pytest.approx(old, rel=1e-3), n  # twice the mass: not the old


def test_two_local_clusters_at_once_start_without_a_warning() -> None:
    """Each local cluster took the dashboard's port 8787 (`dashboard_address=None` does not turn
    it off), and a second one, a sweep beside another, warned "Port 8787 is already in use.
    Perhaps you already have a cluster running?"."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with dask_client(workers=1) as one, dask_client(workers=1) as two:
            assert one.submit(abs, -2).result() == 2 and two.submit(abs, -3).result() == 3
    said = [str(w.message) for w in caught if "already in use" in str(w.message)]
    assert not said, said


def test_a_rerun_after_the_bag_was_recorded_again_runs_every_case_on_the_new_record(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A case's id hashed the bag's path, not its content: a bag recorded again at the same
    path (here the same size, twice the shock) kept its ids, so a rerun skipped every case as
    finished and summarised the old record. Its cases now run again, as single runs of the new
    record (a copy elsewhere, read by no cache) do."""
    bag = tmp_path / "shock"

    def record(peak: str) -> None:
        shutil.rmtree(bag, ignore_errors=True)
        options = ["--peak", peak, "--pulse", "0.005", "--rate", "4000", "--duration", "0.15"]
        assert main(["generate", "half-sine", "-o", str(bag), *options]) == 0

    record("150")
    text = SWEEP.replace(str(ROOT / "bags" / "half_sine_shock_10khz"), str(bag))
    text = text.split("  - name: dhs", maxsplit=1)[0].replace("[1100.0, -5.0]", "[1100.0]")
    sweep, results = _sweep_file(tmp_path, text), tmp_path / "r.csv"
    args = ["sweep", str(sweep), "-o", str(results), "--workers", "1", "--no-progress"]
    assert main(args) == 0
    first = read_results(results)
    old_spec = load_sweep(sweep)
    old_single = [run_case(old_spec.base, old_spec.source, c) for c in check(old_spec)]
    sizes = {f.name: f.stat().st_size for f in bag.iterdir()}
    record("300")
    assert {f.name: f.stat().st_size for f in bag.iterdir()} == sizes  # only the content
    capsys.readouterr()
    assert main(args) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"2 cases in {results} (and 2 of cases this sweep no longer has")
    table = read_results(results)
    assert len(table) == 4
    copy = tmp_path / "copy"
    shutil.copytree(bag, copy)
    spec = load_sweep(sweep)
    names = [m["name"] for m in spec.base["mounts"]]
    for case, old in zip(check(spec), old_single, strict=True):
        (row,) = (r for r in table if r["case"] == case.case_id)
        assert case.case_id not in {r["case"] for r in first}
        moved = replace(case, input=replace(case.input, bag=str(copy)))
        for alone in (run_case(spec.base, spec.source, case), run_case(spec.base, "", moved)):
            for n in names:
                key = f"peak_force_magnitude_N.{n}"
                assert row[key] == pytest.approx(alone[key], rel=1e-12)
                assert row[key] > 1.1 * old[key], n  # twice the shock: not the old record's


def test_a_bag_recorded_again_between_load_and_run_is_a_failed_row_naming_it(
    tmp_path: Path,
) -> None:
    """A bag recorded again after the sweep was loaded (its cases' ids hash the old content)
    was run as the new record under the old ids: rows of one shock filed as another's. The
    case is now a FAILED row that names the bag; loaded again, the sweep runs the new one."""
    bag = tmp_path / "shock"
    options = ["--pulse", "0.005", "--rate", "4000", "--duration", "0.15"]
    assert main(["generate", "half-sine", "-o", str(bag), "--peak", "150", *options]) == 0
    text = SWEEP.replace(str(ROOT / "bags" / "half_sine_shock_10khz"), str(bag))
    text = text.split("  - name: dhs", maxsplit=1)[0].replace("[1100.0, -5.0]", "[1100.0]")
    sweep = _sweep_file(tmp_path, text)
    old_spec = load_sweep(sweep)
    shutil.rmtree(bag)
    assert main(["generate", "half-sine", "-o", str(bag), "--peak", "300", *options]) == 0
    for case in check(old_spec):
        row = run_case(old_spec.base, old_spec.source, case)
        assert row["verdict"] == FAILED, row
        assert row["error"].startswith(f"MountTwinError: {bag}: recorded again since the sweep")
    spec = load_sweep(sweep)
    for case in check(spec):
        assert run_case(spec.base, spec.source, case)["verdict"] != FAILED
    # replaced, after the load, by a record its read fails on: the row says it was recorded
    # again, not what the read met
    shutil.rmtree(bag)
    assert main(["generate", "half-sine", "-o", str(bag), "--peak", "200", *options]) == 0
    spec = load_sweep(sweep)
    shutil.rmtree(bag)
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {version: 9}\n")
    for case in check(spec):
        row = run_case(spec.base, spec.source, case)
        assert row["verdict"] == FAILED, row
        assert row["error"].startswith(f"MountTwinError: {bag}: recorded again since the sweep")


def _fake_pyarrow(monkeypatch: pytest.MonkeyPatch, write: object) -> None:
    """pyarrow (not installed here) as modules whose `parquet.write_table(table, where)` is
    `write` and whose `Table.from_pylist` keeps the rows."""
    import importlib.machinery
    import sys
    import types

    pa = types.ModuleType("pyarrow")
    pa.__spec__ = importlib.machinery.ModuleSpec("pyarrow", None)
    pa.Table = types.SimpleNamespace(from_pylist=list)  # type: ignore[attr-defined]
    pq = types.ModuleType("pyarrow.parquet")
    pq.__spec__ = importlib.machinery.ModuleSpec("pyarrow.parquet", None)
    pq.write_table = write  # type: ignore[attr-defined]
    pa.parquet = pq  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "pyarrow", pa)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", pq)


def test_parquet_is_written_whole_or_not_at_all(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """--parquet was written in place: a write that failed part-way (a full disk) left a
    truncated file in place of the last good one. It is written beside it and renamed over it
    when whole (as the CSV and PNG outputs are); a failure leaves the old file and no other."""
    text = SWEEP.split("  - name: dhs", maxsplit=1)[0].replace("[1100.0, -5.0]", "[1100.0]")
    sweep, results = _sweep_file(tmp_path, text), tmp_path / "r.csv"
    parquet = tmp_path / "r.parquet"
    parquet.write_bytes(b"the last good table")
    args = ["sweep", str(sweep), "-o", str(results), "--parquet", str(parquet)]

    def fails_part_way(rows: list[dict[str, object]], where: object) -> None:
        Path(str(where)).write_bytes(b"PAR1 half a table")
        raise OSError(28, "No space left on device", str(where))

    _fake_pyarrow(monkeypatch, fails_part_way)
    assert main([*args, "--workers", "1", "--no-progress"]) == 2
    assert "No space left on device" in capsys.readouterr().err
    assert parquet.read_bytes() == b"the last good table"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.parquet", "sweep.yaml"]

    def writes(rows: list[dict[str, object]], where: object) -> None:
        Path(str(where)).write_bytes(f"PAR1 {len(rows)} rows".encode())

    _fake_pyarrow(monkeypatch, writes)
    assert main([*args, "--workers", "1", "--no-progress"]) == 0
    assert parquet.read_bytes() == b"PAR1 2 rows"
    assert f"parquet: {parquet}" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.parquet", "sweep.yaml"]


@pytest.mark.parametrize(
    ("scene", "key", "unit"),
    [
        (PUMP, "body.mass", "kg"),
        (PUMP, "body.inertia", "kg·m²"),
        (PUMP, "mounts[fl].position", "m"),
        (PUMP, "mounts[*].rated_load", "N"),
        (PUMP, "input.gyro_stopband_hz", "Hz"),
        (PUMP, "input.g", "m/s²"),
        (PUMP, "body_sensor.lag_s", "s"),
        (PUMP, "mounts[fl].stiffness", None),  # N/m along, N·m/rad about its axes
        (PUMP, "integration.atol", None),  # m, rad, m/s, rad/s by state
        (PUMP, "integration.rtol", None),  # a ratio
        (PUMP, "outputs.angles", None),  # a switch whose description names rad
        (PUMP, "input.frame_id", None),
        (CONFIG / "genset_bolted_keyed.scene.yaml", "mounts[key_x].stiffness", "N/m"),
        (CONFIG / "genset_bolted_keyed.scene.yaml", "mounts[foot_fl].preload", "N"),
        (CONFIG / "genset_bolted_keyed.scene.yaml", "mounts[0].bolt_stiffness", "N/m"),
        # a shear key's N/m, a bolted joint's none: not one unit
        (CONFIG / "genset_bolted_keyed.scene.yaml", "mounts[*].stiffness", None),
    ],
)
def test_a_key_paths_unit_is_the_one_the_scene_tables_state(
    scene: Path, key: str, unit: str | None
) -> None:
    from mount_twin.sweeps.cases import key_unit

    assert key_unit(key, read_scene_yaml(scene)) == unit


def test_the_summary_and_the_plot_give_each_set_values_unit_where_the_scene_states_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The summary and the plot named key paths bare: "body.mass = 1100.0", an x axis
    "body.mass". A set value has the unit the scene's tables state for its key (kg, m); a scale
    is a factor, and a key of no one unit (a tolerance) stays bare."""
    from mount_twin.sweeps.runner import summary

    matplotlib = pytest.importorskip("matplotlib")
    monkeypatch.setitem(matplotlib.rcParams, "svg.fonttype", "none")  # text kept as text
    text = f"""\
base: {PUMP}
vary:
  - key: body.mass
    values: [1100.0, 1300.0]
  - key: mounts[fl].position
    values: [[1.0, 0.4, 0.0]]
  - key: integration.rtol
    values: [1.0e-8]
  - key: mounts[*].stiffness
    scale: [1.0]
inputs:
  - name: dhs
    generate: {{kind: half-sine, peak: 300.0}}
"""
    spec = load_sweep(_sweep_file(tmp_path, text))
    names = [m["name"] for m in spec.base["mounts"]]
    rows = [
        {
            "case": f"c{k}",
            "input": "dhs",
            "body.mass": mass,
            "mounts[fl].position": "[1.0, 0.4, 0.0]",
            "integration.rtol": 1e-08,
            "mounts[*].stiffness (scale)": 1.0,
            "verdict": "OK",
            **{f"peak_force_magnitude_N.{n}": force for n in names},
            **{f"utilisation.{n}": 0.5 for n in names},
        }
        for k, (mass, force) in enumerate(((1100.0, 9000.0), (1300.0, 9500.0)))
    ]
    settings = (
        "body.mass = 1100.0 kg, mounts[fl].position = [1.0, 0.4, 0.0] m, "
        "integration.rtol = 1e-08, mounts[*].stiffness (scale) = 1.0"
    )
    assert f"lowest peak mount force: 9000.0 N, case c0 (dhs; {settings}) OK" in summary(
        rows, spec
    )
    svg = plot_sweep(rows, spec, tmp_path / "sweep.svg").read_text(encoding="utf-8")
    assert "body.mass [kg]" in svg
    assert "dhs mounts[fl].position=[1.0, 0.4, 0.0] m integration.rtol=1e-08" in svg


def test_the_plots_legend_shows_each_verdicts_marker(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The title read "markers o OK, s WARN, v ERROR": matplotlib's marker codes, not what a
    reader sees. Each panel's legend shows the marker drawn for each verdict, by its name."""
    pytest.importorskip("matplotlib")
    from mount_twin import figure_files

    drawn: list = []
    monkeypatch.setattr(figure_files, "save_png", lambda fig, png: drawn.append(fig) or png)
    spec = load_sweep(_sweep_file(tmp_path, SWEEP.replace("[1100.0, -5.0]", "[1100.0]")))
    names = [m["name"] for m in spec.base["mounts"]]
    verdicts = ("OK", "WARN", "ERROR")
    rows = [
        {
            "case": f"c{k}",
            "input": "dhs",
            "mounts[*].stiffness (scale)": 0.5 * (k + 1),
            "body.mass": 1100.0,
            "verdict": verdict,
            **{f"peak_force_magnitude_N.{n}": 1000.0 * (k + 1) for n in names},
            **{f"utilisation.{n}": 0.5 * (k + 1) for n in names},
        }
        for k, verdict in enumerate(verdicts)
    ]
    plot_sweep(rows, spec, tmp_path / "sweep.png")
    (fig,) = drawn
    assert len(fig.axes) == 2
    for ax in fig.axes:
        # the marker of each case's point, at its x (the points drawn without a line)
        marker_at = {
            float(line.get_xdata()[0]): line.get_marker()
            for line in ax.get_lines()
            if len(line.get_xdata()) == 1
        }
        legend = ax.get_legend()
        shown = {
            text.get_text(): handle.get_marker()
            for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True)
        }
        for r in rows:
            assert shown[r["verdict"]] == marker_at[r["mounts[*].stiffness (scale)"]], r
        assert len({shown[v] for v in verdicts}) == 3
    assert "markers" not in fig.axes[0].get_title()
