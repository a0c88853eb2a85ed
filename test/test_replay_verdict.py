"""A failed run looks failed: integration failure is its own verdict (FAILED, exit 6, a FAILED
sweep row out of the sweep's lowest/highest); a replay that accepted nothing says so, at ERROR,
in its summary and its output bag; and the peak figures have one definition each, the same in
the summary's JSON, the report and the sweep, checked against the output bag's own messages."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import CONFIG, ROOT, read_bag

from mount_twin.analysis.figures import peak_text, utilisation_text
from mount_twin.cli import main
from mount_twin.io.messages import IMU
from mount_twin.io.output_bag import write_bag
from mount_twin.io.output_encoding import imu_messages
from mount_twin.io.output_tables import input_values, read_output_bag
from mount_twin.scene.yaml_reading import read_scene_yaml
from mount_twin.sweeps.cases import check
from mount_twin.sweeps.runner import FAILED, run_case, summary
from mount_twin.sweeps.spec import load_sweep

PUMP = CONFIG / "pump_8_mounts.scene.yaml"
GENSET = CONFIG / "genset_bolted_keyed.scene.yaml"
SHOCK = ROOT / "bags" / "half_sine_shock_10khz"
GENSET_BAG = ROOT / "bags" / "genset_shock_10khz"
FAILING = {"method": "dopri54", "rtol": 1.0e-13, "atol": 1.0e-15, "max_substeps": 1}
"""An integration that cannot meet its tolerance in one substep through the shock."""


def _failing_scene(tmp_path: Path) -> Path:
    data = read_scene_yaml(PUMP)
    data["integration"] = {**data["integration"], **FAILING}
    path = tmp_path / "failing.scene.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def _replay(tmp_path: Path, scene: Path, bag: Path, *extra: str) -> tuple[int, dict, Path]:
    out, doc = tmp_path / "out", tmp_path / "summary.json"
    args = ["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]
    code = main([*args, "--json", str(doc), *extra])
    return code, json.loads(doc.read_text(encoding="utf-8")), out


def test_a_replay_whose_integration_fails_is_failed_with_its_count_and_cause(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, doc, out = _replay(tmp_path, _failing_scene(tmp_path), SHOCK, "--fail-on", "never")
    assert code == 6, "a failed integration must not exit 0, whatever --fail-on says"
    n = doc["counts"]["integration_failures"]
    # each failing sample has no output (the twin restarts at the next one)
    published = len(read_bag(out)[1]["/mount_twin/pose"])
    assert n == len(read_bag(SHOCK)[1]["/deck/imu"]) - published > 0
    assert doc["verdict"] == FAILED
    assert f"integration failed {n} times" in doc["failure"]
    assert "too many substeps in one input interval" in doc["failure"]
    out, err = capsys.readouterr()
    assert f"FAILED: integration failed {n} times" in out and "verdict: FAILED" in out
    assert "too many substeps" in err
    help_text = _help(capsys)
    assert "6 FAILED" in help_text
    # its report says so, and exits as the replay did (it exited 0 whatever the run)
    page = tmp_path / "r.html"
    assert main(["report", str(tmp_path / "out"), "-o", str(page), "--fail-on", "never"]) == 6
    assert f"<h2>Verdict: FAILED ({n} integration failures)</h2>" in page.read_text("utf-8")
    assert f"mount-twin: error: {n} integration failures" in capsys.readouterr().err


def test_a_report_exits_as_its_runs_diagnostics_reach_fail_on(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The genset's shock opens its joints: an ERROR run, which exits 0 unless --fail-on."""
    code, doc, out = _replay(tmp_path, GENSET, GENSET_BAG)
    assert code == 0 and doc["verdict"] == "ERROR"
    page = str(tmp_path / "r.html")
    assert main(["report", str(out), "-o", page]) == 0
    assert main(["report", str(out), "-o", page, "--fail-on", "error"]) == 4
    assert "mount-twin: diagnostics reached ERROR (--fail-on error)" in capsys.readouterr().err
    assert main(["report", str(out), "-o", page, "--fail-on", "warn"]) == 4


def _help(capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit):
        main(["replay", "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_a_sweep_case_whose_integration_fails_is_a_failed_row_out_of_the_extremes(
    tmp_path: Path,
) -> None:
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(
        f"base: {PUMP}\ncombine: zip\nvary:\n"
        "  - key: integration.max_substeps\n    values: [1, 10000]\n"
        "  - key: integration.rtol\n    values: [1.0e-13, 1.0e-6]\n"
        "  - key: integration.method\n    values: [dopri54, auto]\n"
        "  - key: integration.atol\n    values: [1.0e-15, 1.0e-9]\n"
        f"inputs:\n  - bag: {SHOCK}\n",
        encoding="utf-8",
    )
    spec = load_sweep(sweep)
    rows = [run_case(spec.base, spec.source, case) for case in check(spec)]
    failed = [r for r in rows if r["integration.max_substeps"] == "1"]
    (bad,) = failed
    assert bad["verdict"] == FAILED
    assert "integration failed" in bad["error"] and "too many substeps" in bad["error"]
    (good,) = [r for r in rows if r is not bad]
    assert good["verdict"] != FAILED and good["error"] == ""
    text = summary(rows, spec)
    assert f"{FAILED} 1" in text
    # the good case is the lowest and the highest force and its input's lowest utilisation;
    # the failed one is named only as failed, with why
    assert text.count(good["case"]) == 3
    (named,) = [line for line in text.splitlines() if bad["case"] in line]
    assert named.startswith(f"  {FAILED} case {bad['case']} ") and bad["error"] in named


def test_a_replay_that_accepted_nothing_says_so_at_error_in_its_summary_and_bag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, doc, out = _replay(tmp_path, PUMP, SHOCK, "--frame-id", "not_the_imu")
    assert code == 3
    n_in = len(read_bag(SHOCK)[1]["/deck/imu"])
    assert doc["counts"]["received"] == doc["counts"]["rejected_wrong_frame"] == n_in
    assert doc["verdict"] == "ERROR" and "no input sample was accepted" in doc["nothing_accepted"]
    text = capsys.readouterr().out
    assert f"no input sample was accepted ({n_in} received" in text
    assert "worst over the run: OK" not in text and "worst over the run: ERROR" in text
    _, msgs = read_bag(out)
    (report,) = [m for _, m in msgs["/diagnostics"]]
    (status,) = [s for s in report.status if s.name == "mount_twin: input"]
    assert status.level == 2, status
    assert f"no sample accepted by the end of the input: {n_in} received, all rejected" in (
        status.message
    )


def _all_nan_bag(path: Path, n: int) -> Path:
    """A bag of `n` deck IMU samples at 1 kHz whose specific force is NaN on every axis."""
    stamps = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * 10**6
    accel = np.full((n, 3), np.nan)
    write_bag(
        path, "/deck/imu", IMU, iter(imu_messages(stamps, accel, np.zeros((n, 3)), "deck_imu"))
    )
    return path


@pytest.mark.parametrize("bad", ["non_finite", "wrong_frame"])
def test_the_report_of_a_run_that_accepted_nothing_says_so_and_why_in_its_heading(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], bad: str
) -> None:
    """Its page opened "Verdict: ERROR", its estimated error read "mount forces nan of the
    largest", its peaks table was empty and its utilisation plot flat at 0, as a machine at
    rest: nothing said that no sample had been taken. It says why as the replay did."""
    if bad == "non_finite":
        code, doc, out = _replay(tmp_path, PUMP, _all_nan_bag(tmp_path / "nan", 1000))
        why = "1000 received, rejected: non_finite 1000)"
    else:
        code, doc, out = _replay(tmp_path, PUMP, SHOCK, "--frame-id", "not_the_imu")
        n_in = len(read_bag(SHOCK)[1]["/deck/imu"])
        why = f"{n_in} received, rejected: wrong_frame {n_in}; the bag's header"
    assert code == 3
    said = doc["nothing_accepted"]
    assert said.startswith(f"no input sample was accepted ({why}")
    capsys.readouterr()
    page = tmp_path / "r.html"
    assert main(["report", str(out), "--scene", str(PUMP), "-o", str(page)]) == 3  # as replay
    assert f"mount-twin: error: {said}" in capsys.readouterr().err
    text = html.unescape(page.read_text(encoding="utf-8"))
    assert f"<h2>Verdict: ERROR: {said}</h2>" in text
    assert not re.search(r"\bnan\b", text, re.IGNORECASE)
    assert "none (no input interval was integrated)" in text
    # the gyro filter's latency is designed at the first sample's interval: never, here (the
    # page read "latency 0 s", as if outputs had followed their input at once)
    conditioning = re.search(r"<td>input conditioning</td><td>([^<]*)</td>", text)
    assert conditioning, text
    assert "gyro_filter linear_phase (no latency figure: no input sample was accepted)" in (
        conditioning.group(1)
    )
    assert "<h2>Utilisation</h2>" not in text
    assert "<h2>Peaks (largest magnitude at one instant)</h2>\n<p>none: no input sample" in text


@pytest.mark.parametrize(
    ("scene_file", "bag", "differs"),
    [(GENSET, GENSET_BAG, "extremes"), (PUMP, SHOCK, "sag")],
    ids=["genset", "pump"],
)
def test_peak_force_and_displacement_are_one_definition_in_json_report_and_sweep(
    tmp_path: Path, scene_file: Path, bag: Path, differs: str
) -> None:
    """Peak |F|: the largest magnitude of a mount's force at one instant (the genset's
    per-component extremes make a larger vector: no force that acted); displacement: of the
    CG from its first published position (the start's static equilibrium), not from the
    scene's undeformed cg (which would count the pump's static sag)."""
    code, doc, out = _replay(tmp_path, scene_file, bag)
    assert code == 0
    _, msgs = read_bag(out)
    scene = read_scene_yaml(scene_file)
    peak, of_extremes = {}, {}
    for mount in (m["name"] for m in scene["mounts"]):
        f = np.array(
            [
                [m.wrench.force.x, m.wrench.force.y, m.wrench.force.z]
                for _, m in msgs[f"/mount_twin/mounts/{mount}/wrench"]
            ]
        )
        peak[mount] = float(np.sqrt((f**2).sum(axis=1)).max())
        assert doc["mounts"][mount]["peak_force_magnitude_N"] == pytest.approx(
            peak[mount], rel=1e-12
        )
        of_extremes[mount] = float(np.linalg.norm(np.abs(f).max(axis=0)))
    # the per-component extremes come at different times: a vector of them is no force
    if differs == "extremes":
        assert any(of_extremes[m] > peak[m] * 1.01 for m in peak), (of_extremes, peak)
    p = np.array(
        [
            [m.pose.position.x, m.pose.position.y, m.pose.position.z]
            for _, m in msgs["/mount_twin/pose"]
        ]
    )
    moved = float(np.sqrt(((p - p[0]) ** 2).sum(axis=1)).max())
    assert doc["max_cg_displacement_from_start_m"] == pytest.approx(moved, rel=1e-12)
    if differs == "sag":
        sag = float(np.linalg.norm(p[0] - np.array(scene["body"]["cg"])))
        assert sag > 1e-3, "the pump sags on its rubber mounts"

    page = tmp_path / "r.html"
    assert main(["report", str(out), "-o", str(page)]) == 0
    html = page.read_text(encoding="utf-8")
    assert f"max CG displacement from start, m: {moved:.6g}" in html
    for mount, value in peak.items():
        assert f"<td>{mount}</td><td></td><td>{peak_text(value)}</td>" in html  # as the summary's
        # its utilisation, from the bag's diagnostics, as the summary's to the digits shown
        # (the genset's key_y, 0.51451, read back from four digits as 0.5145, showed 0.514)
        u = doc["mounts"][mount]["utilisation_max"]
        cells = rf"<td>{mount}</td>(<td>[^<]*</td>){{3}}<td>{utilisation_text(u)}</td>"
        assert u is not None and re.search(cells, html), (mount, u)

    row = _sweep_row(tmp_path, scene_file, scene["body"]["mass"], bag)
    assert row["max_cg_displacement_from_start_m"] == pytest.approx(moved, rel=1e-9)
    for mount, value in peak.items():
        assert row[f"peak_force_magnitude_N.{mount}"] == pytest.approx(value, rel=1e-9)


def _sweep_row(tmp_path: Path, base: Path, mass: float, bag: Path) -> dict:
    """The row of a one-case sweep of `base` (its body mass as it is) under `bag`: a sweep
    runs the case as a replay would."""
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(
        f"base: {base}\nvary:\n  - key: body.mass\n    values: [{mass}]\n"
        f"inputs:\n  - bag: {bag}\n",
        encoding="utf-8",
    )
    spec = load_sweep(sweep)
    (case,) = check(spec)
    return run_case(spec.base, spec.source, case)


def test_the_worst_mount_status_over_a_replay_reads_the_peak_utilisation_or_the_onset(
    tmp_path: Path,
) -> None:
    """Of a mount's periods at its highest level that report only the utilisation, the worst
    over the run is the largest: the summary's peak, not the first period's (the pump's front
    mounts peak later than its first period: 0.182 against 0.186); of periods with events, the
    first (the genset's feet: the period of their first joint opening)."""
    code, doc, _ = _replay(tmp_path, PUMP, ROOT / "bags" / "ship_motion_1khz")
    assert code == 0
    for mount, figures in doc["mounts"].items():
        worst = doc["diagnostics_worst"][f"mount_twin: mount {mount}"]
        assert worst == {"level": "OK", "message": f"utilisation {figures['utilisation_max']:.3g}"}
    (tmp_path / "genset").mkdir()
    code, doc, _ = _replay(tmp_path / "genset", GENSET, GENSET_BAG)
    assert code == 0 and doc["verdict"] == "ERROR"
    opened = [e for e in doc["events"] if e["event"] == "joint_opened"]
    feet = {e["mount"] for e in opened}
    assert feet == {f"foot_{f}" for f in ("fl", "fr", "ml", "mr", "rl", "rr")}
    for mount in feet:
        first = min(e["stamp_s"] for e in opened if e["mount"] == mount)
        worst = doc["diagnostics_worst"][f"mount_twin: mount {mount}"]
        assert worst["level"] == "ERROR"
        assert re.search(rf"joint_opened ×\d+ \(first {first:.6f} s", worst["message"]), worst


@pytest.mark.parametrize("set_by", ["scene", "option"])
def test_a_run_that_accepted_nothing_points_at_the_frame_id_the_user_set(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], set_by: str
) -> None:
    """A record from the hull's IMU (hull_imu) run expecting port_imu: set in the scene's
    input.frame_id, or by `replay --frame-id port_imu` over the pump's deck_imu. The replay's
    summary, its stderr, its JSON and the report's heading said "see input.frame_id" either
    way, sending a user who had typed the option to a scene key that was not what rejected
    the samples. Each names what the user set."""
    bag = tmp_path / "hull_bag"
    generate = ["generate", "half-sine", "-o", str(bag), "--peak", "150", "--pulse", "0.008"]
    assert main([*generate, "--frame-id", "hull_imu"]) == 0
    if set_by == "scene":
        data = read_scene_yaml(PUMP)
        data["input"] = {**data["input"], "frame_id": "port_imu"}
        scene = tmp_path / "port.scene.yaml"
        scene.write_text(yaml.safe_dump(data), encoding="utf-8")
        code, doc, out = _replay(tmp_path, scene, bag)
        setting, other = "input.frame_id", "replay --frame-id"
    else:
        scene = PUMP
        code, doc, out = _replay(tmp_path, scene, bag, "--frame-id", "port_imu")
        setting, other = "replay --frame-id", "input.frame_id"
    assert code == 3
    n_in = len(read_bag(bag)[1]["/deck/imu"])
    said = (
        f"no input sample was accepted ({n_in} received, rejected: wrong_frame {n_in}; the "
        f"bag's header.frame_id is 'hull_imu': see {setting})"
    )
    assert doc["nothing_accepted"] == said
    replayed = capsys.readouterr()
    assert f"  {said}\n" in replayed.out
    assert f"mount-twin: error: {said}\n" in replayed.err
    page = tmp_path / "r.html"
    assert main(["report", str(out), "--scene", str(scene), "-o", str(page)]) == 3
    assert f"mount-twin: error: {said}\n" in capsys.readouterr().err
    text = html.unescape(page.read_text(encoding="utf-8"))
    assert f"<h2>Verdict: ERROR: {said}</h2>" in text
    assert f"see {other}" not in text


def test_a_report_without_its_scene_names_the_frame_expected_and_both_settings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same runs as above, reported without --scene: the output bag's input status
    records the frame the run expected, not what set it, and the heading said "see
    input.frame_id" for both, sending the user who had typed `replay --frame-id` to a scene
    key. It names the frame expected (the bag's record) and both settings, alike for both."""
    bag = tmp_path / "hull_bag"
    generate = ["generate", "half-sine", "-o", str(bag), "--peak", "150", "--pulse", "0.008"]
    assert main([*generate, "--frame-id", "hull_imu"]) == 0
    data = read_scene_yaml(PUMP)
    data["input"] = {**data["input"], "frame_id": "port_imu"}
    port = tmp_path / "port.scene.yaml"
    port.write_text(yaml.safe_dump(data), encoding="utf-8")
    headings = []
    runs = (("scene", port, ()), ("option", PUMP, ("--frame-id", "port_imu")))
    for set_by, scene, extra in runs:
        (tmp_path / set_by).mkdir()
        code, _, out = _replay(tmp_path / set_by, scene, bag, *extra)
        assert code == 3
        diagnostics = next(t for t in read_output_bag(out) if t.name == "diagnostics")
        expected = input_values(diagnostics)["frame_id"]
        assert expected == "port_imu"
        page = tmp_path / set_by / "r.html"
        capsys.readouterr()
        assert main(["report", str(out), "-o", str(page)]) == 3
        heading = re.search(r"<h2>Verdict: ERROR: ([^<]*)</h2>", page.read_text(encoding="utf-8"))
        assert heading, set_by
        said = html.unescape(heading.group(1))
        assert f"mount-twin: error: {said}\n" in capsys.readouterr().err
        assert "header.frame_id is 'hull_imu'" in said and repr(expected) in said, said
        assert "input.frame_id" in said and "replay --frame-id" in said, said
        headings.append(said)
    assert headings[0] == headings[1]


@pytest.mark.parametrize("method", ["auto", "dopri54"])
def test_the_report_of_a_run_that_accepted_nothing_says_no_method_ran(
    tmp_path: Path, method: str
) -> None:
    """No sample accepted, no interval integrated: the page's solver row read "auto (ran:
    auto)" (the status' method before any choice), as if the twin had run. It says that no
    method ran; a run that integrated names the one it ran, as before."""
    data = read_scene_yaml(PUMP)
    data["integration"] = {**data["integration"], "method": method}
    scene = tmp_path / f"{method}.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    rows = {}
    for run, bag in (("none", _all_nan_bag(tmp_path / "nan", 1000)), ("shock", SHOCK)):
        out, page = tmp_path / f"{run}_out", tmp_path / f"{run}.html"
        status = 3 if run == "none" else 0
        args = ["replay", str(bag), "--scene", str(scene), "-o", str(out), "--no-progress"]
        assert main(args) == status
        assert main(["report", str(out), "--scene", str(scene), "-o", str(page)]) == status
        text = html.unescape(page.read_text(encoding="utf-8"))
        solver = re.search(r"<td>solver</td><td>([^<]*)</td>", text)
        assert solver, text
        rows[run] = solver.group(1)
    said = f"{method} (no method ran: no input sample was accepted), rtol 1e-06, atol 1e-09"
    assert rows["none"].startswith(said), rows["none"]
    ran = re.match(rf"{method} \(ran: (\w+)", rows["shock"])
    assert ran, rows["shock"]
    chosen = ran.group(1)  # auto names the method it chose
    assert chosen in ("dopri54", "ros34pw2", "exprb32") and method in ("auto", chosen), chosen


def test_a_replay_that_accepted_nothing_says_its_integration_did_not_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every sample rejected (another frame id), nothing integrated: the summary's diagnostics,
    its JSON and the output bag's last integration status read "ok", as if the twin had run
    clean. They say it did not run, and why; and the run has no real-time factor."""
    code, doc, out = _replay(tmp_path, PUMP, SHOCK, "--frame-id", "not_the_imu")
    assert code == 3
    said = "not run: no input sample was accepted"
    assert doc["diagnostics_worst"]["mount_twin: integration"] == {"level": "OK", "message": said}
    text = capsys.readouterr().out
    assert f"    OK    mount_twin: integration: {said}\n" in text
    assert "integration: ok" not in text
    _, msgs = read_bag(out)
    (report,) = [m for _, m in msgs["/diagnostics"]]
    (status,) = [s for s in report.status if s.name == "mount_twin: integration"]
    assert status.message == said
    # no stamp time processed: no speed (it had read "real-time factor 0.0", a twin too slow)
    assert doc["real_time_factor"] is None
    assert "s wall: no real-time factor (no stamp time processed)\n" in text


def _one_sample_bag(path: Path, n: int = 1) -> Path:
    """A bag of one deck IMU sample (or `n`, at 1 kHz), at rest."""
    stamps = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * 10**6
    accel, gyro = np.tile([0.0, 0.0, 9.80665], (n, 1)), np.zeros((n, 3))
    write_bag(path, "/deck/imu", IMU, iter(imu_messages(stamps, accel, gyro, "deck_imu")))
    return path


@pytest.mark.parametrize("gyro_filter", ["linear_phase", "none"])
def test_a_run_whose_gyro_filter_was_never_designed_has_no_latency_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], gyro_filter: str
) -> None:
    """One sample accepted: no interval to take the rate of, so `linear_phase` designed no
    filter, and the summary, its JSON and the report's page read "0 samples (0.0 ms)", "0",
    "latency 0 s", as if the outputs followed their input at once. They say there is no
    figure, and why; `none` has no latency, and says 0 as before."""
    data = read_scene_yaml(PUMP)
    data["input"] = {**data["input"], "gyro_filter": gyro_filter}
    scene = tmp_path / f"{gyro_filter}.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    code, doc, out = _replay(tmp_path, scene, _one_sample_bag(tmp_path / "one"))
    assert code == 0 and doc["counts"]["accepted"] == 1
    text = capsys.readouterr().out
    page = tmp_path / "r.html"
    assert main(["report", str(out), "--scene", str(scene), "-o", str(page)]) == 0
    conditioning = re.search(
        r"<td>input conditioning</td><td>([^<]*)</td>", html.unescape(page.read_text("utf-8"))
    )
    assert conditioning
    if gyro_filter == "none":
        assert doc["latency_samples"] == 0 and doc["latency_s"] == 0.0
        assert "  latency: outputs 0 samples (0.0 ms) after their input" in text
        assert "gyro_filter none (latency 0 s)" in conditioning.group(1)
        return
    why = "the gyro filter was never designed: no two input samples were accepted without a "
    assert doc["latency_samples"] is None and doc["latency_s"] is None
    assert f"  latency: no figure, {why}restart between them\n" in text
    assert f"gyro_filter linear_phase (no latency figure: {why}" in conditioning.group(1)


def test_a_replay_that_accepted_nothing_says_it_computed_no_attitude_nor_mount_load(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every sample rejected (another frame id), nothing integrated: the summary said "motion
    and mount loads: none", yet its diagnostics, its JSON and the output bag's statuses read
    "attitude: ok" and "mount fl: ok" with peaks of 0, as a machine at rest. They say nothing
    was computed, and why, at OK: the input status carries the run's ERROR."""
    code, doc, out = _replay(tmp_path, PUMP, SHOCK, "--frame-id", "not_the_imu")
    assert code == 3 and doc["verdict"] == "ERROR"
    said = "not computed: no input sample was accepted"
    mounts = [f"mount_twin: mount {m['name']}" for m in read_scene_yaml(PUMP)["mounts"]]
    worst = doc["diagnostics_worst"]
    assert worst["mount_twin: input"]["level"] == "ERROR"
    for name in ("mount_twin: attitude", *mounts):
        assert worst[name] == {"level": "OK", "message": said}, name
    text = capsys.readouterr().out
    assert f"    OK    mount_twin: attitude: {said}\n" in text
    assert f"    OK    mount_twin: mount fl: {said}\n" in text
    assert not re.search(r": ok$", text, re.MULTILINE), text
    _, msgs = read_bag(out)
    (report,) = [m for _, m in msgs["/diagnostics"]]
    statuses = {s.name: s for s in report.status}
    assert statuses["mount_twin: input"].level == 2
    for name in ("mount_twin: attitude", *mounts):
        status = statuses[name]
        assert (status.level, status.message) == (0, said), name
        # no figure: not a peak of 0, a machine at rest
        figures = {v.key: v.value for v in status.values if "peak" in v.key or "max" in v.key}
        assert figures and set(figures.values()) == {"n/a"}, (name, figures)


@pytest.mark.parametrize("accepted", [0, 1])
def test_a_run_that_integrated_no_interval_has_no_error_estimate_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], accepted: int
) -> None:
    """No input interval integrated (no sample accepted, or one): the summary said "none (no
    input interval was integrated)", yet its JSON's error_estimate gave force_error_n and
    attitude_error_rad 0.0 and its accuracy "estimated live: error_estimate, over the run",
    and the bag's integration status est_force_error_n_run 0: an error of 0 for what was
    never measured reads as an exact run. They are null, "nan" beside est_force_error_rel's,
    and the accuracy says what the summary says; a sweep row has no number either."""
    if accepted:
        bag = _one_sample_bag(tmp_path / "one")
        code, doc, out = _replay(tmp_path, PUMP, bag)
    else:
        bag = SHOCK
        code, doc, out = _replay(tmp_path, PUMP, bag, "--frame-id", "not_the_imu")
    assert (code, doc["counts"].get("accepted", 0)) == (0 if accepted else 3, accepted)
    said = "none (no input interval was integrated)"
    assert f"  estimated integration error: {said}\n" in capsys.readouterr().out
    estimate = doc["error_estimate"]
    assert estimate["force_error_rel"] is None
    assert estimate["force_error_n"] is None and estimate["attitude_error_rad"] is None
    assert doc["accuracy"] == said
    _, msgs = read_bag(out)
    *_, report = [m for _, m in msgs["/diagnostics"]]
    (status,) = [s for s in report.status if s.name == "mount_twin: integration"]
    values = {v.key: v.value for v in status.values}
    for key in ("est_force_error_rel_run", "est_force_error_n_run", "est_attitude_error_rad_run"):
        assert values[key] == "nan", (key, values[key])
    if accepted:  # a sweep of it: a case that ran, with no estimate (not 0)
        row = _sweep_row(tmp_path, PUMP, read_scene_yaml(PUMP)["body"]["mass"], bag)
        assert row["verdict"] != FAILED and np.isnan(row["est_force_error_rel"]), row


@pytest.mark.parametrize("accepted", [0, 1])
def test_a_run_that_integrated_no_interval_says_its_integration_did_not_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], accepted: int
) -> None:
    """One sample accepted is no interval integrated (no substep taken), yet the integration
    status read "ok", as if the twin had run the record clean; with none accepted, it said
    "not run" beside an error_norm_max of 0, a figure of no step. Where the run took no
    substep the status says it did not run, and why, at OK, with no stepper figure."""
    if accepted:
        code, doc, out = _replay(tmp_path, PUMP, _one_sample_bag(tmp_path / "one"))
    else:
        code, doc, out = _replay(tmp_path, PUMP, SHOCK, "--frame-id", "not_the_imu")
    assert code == (0 if accepted else 3)
    counts = doc["counts"]
    assert (counts.get("accepted", 0), counts.get("substeps", 0)) == (accepted, 0)
    worst = doc["diagnostics_worst"]["mount_twin: integration"]
    assert worst["level"] == "OK" and worst["message"].startswith("not run: "), worst
    why = f"({accepted} sample accepted)" if accepted else "no input sample was accepted"
    assert worst["message"].endswith(why), worst
    assert f"    OK    mount_twin: integration: {worst['message']}\n" in capsys.readouterr().out
    _, msgs = read_bag(out)
    for report in [m for _, m in msgs["/diagnostics"]]:
        (status,) = [s for s in report.status if s.name == "mount_twin: integration"]
        values = {v.key: v.value for v in status.values}
        assert status.message == worst["message"]
        assert values["error_norm_max"] == values["substeps_per_sample"] == "n/a", values


def test_a_replay_too_short_to_start_the_twin_says_so_and_does_not_pass(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Three samples accepted where a start takes five (initial_state.gravity_samples): the
    twin never started, nothing marked the period as having content, and the replay wrote no
    diagnostics report at all, while its summary read peaks and utilisations of 0, "worst over
    the run: OK", verdict OK, exit 0. The output bag ends with a report that says what
    happened, the integration at ERROR, and the summary has no figures and exits 3; a sweep of
    it is a FAILED case, and its report says it and exits 3 too."""
    gather, n = 5, 3
    data = read_scene_yaml(PUMP)
    data["initial_state"] = {**data["initial_state"], "gravity_samples": gather}
    scene = tmp_path / "gather.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    bag = _one_sample_bag(tmp_path / "three", n)
    code, doc, out = _replay(tmp_path, scene, bag)
    counts = doc["counts"]
    assert (counts["accepted"], counts.get("starts", 0), counts.get("substeps", 0)) == (n, 0, 0)
    assert code == 3 and doc["verdict"] == "ERROR" and doc["nothing_accepted"] is None
    said = doc["never_started"]
    assert said and f"{n} samples accepted" in said and f"{gather}" in said, said
    assert f"mount-twin: error: {said}\n" in capsys.readouterr().err
    assert doc["max_tilt_rad"] is None and doc["max_cg_displacement_from_start_m"] is None
    assert {m["peak_force_magnitude_N"] for m in doc["mounts"].values()} == {None}
    _, msgs = read_bag(out)
    assert "/mount_twin/pose" not in msgs  # the twin published nothing
    (report,) = [m for _, m in msgs["/diagnostics"]]
    statuses = {s.name: s for s in report.status}
    inputs = {v.key: v.value for v in statuses["mount_twin: input"].values}
    assert int(inputs["accepted"]) == n and statuses["mount_twin: input"].level == 0
    integration = statuses["mount_twin: integration"]
    assert integration.level == 2 and integration.message == said
    assert doc["diagnostics_worst"]["mount_twin: integration"]["message"] == said
    values = {v.key: v.value for v in integration.values}
    assert values["error_norm_max"] == values["substeps_per_sample"] == "n/a", values
    for name, status in statuses.items():
        if name.startswith(("mount_twin: attitude", "mount_twin: mount ")):
            figures = {v.value for v in status.values if "peak" in v.key or "max" in v.key}
            assert status.level == 0 and figures == {"n/a"}, (name, status)
            assert status.message.startswith("not computed in this period: "), status
    # a sweep of it is a case that failed, not a machine at rest (its row had read peaks of 0)
    row = _sweep_row(tmp_path, scene, data["body"]["mass"], bag)
    assert row["verdict"] == FAILED and row["error"] == said, row
    # its report says so and exits as the replay did (it had read ERROR, exit 0, peaks of 0)
    page = tmp_path / "r.html"
    capsys.readouterr()
    assert main(["report", str(out), "-o", str(page)]) == 3
    assert f"mount-twin: error: {said}\n" in capsys.readouterr().err
    assert "<p>none: the twin never started</p>" in page.read_text(encoding="utf-8")


FULL = "/dev/full"
"""A device every write to fails with ENOSPC, as on a full disk."""


@pytest.mark.skipif(not Path(FULL).exists(), reason=f"no {FULL}")
@pytest.mark.parametrize("run", ["nothing_accepted", "failed", "fail_on"])
def test_a_summary_that_cannot_be_written_hides_not_the_runs_own_failure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], run: str
) -> None:
    """A run that exits 3, 6 or 4 whose `--json` cannot be written exits 2 (a failed write, as
    documented), and its own failure was never said: stderr held the write error alone, so a
    script read a full disk where no sample had been accepted. Both are said."""
    scene, bag, extra = {
        "nothing_accepted": (PUMP, SHOCK, ["--frame-id", "not_the_imu"]),
        "failed": (_failing_scene(tmp_path), SHOCK, []),
        "fail_on": (GENSET, GENSET_BAG, ["--fail-on", "error"]),
    }[run]
    args = ["replay", str(bag), "--scene", str(scene), "-o", str(tmp_path / "out")]
    assert main([*args, "--no-progress", *extra]) in (3, 4, 6)
    own = capsys.readouterr().err.splitlines()[-1]  # the run's own line, its JSON written
    assert own.startswith("mount-twin: "), own
    assert main([*args[:-1], str(tmp_path / "out2"), "--no-progress", *extra, "--json", FULL]) == 2
    err = capsys.readouterr().err
    assert f"{own}\n" in err, err
    assert err.endswith(f"mount-twin: error: {FULL}: cannot write: No space left on device\n")


def test_the_summary_and_plot_give_the_attitude_in_radians(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Angles are in rad everywhere (the guide, the bag, the JSON's max_tilt_rad), yet the
    summary printed "max tilt 0.0987 deg" and the replay's plot drew the attitude in degrees.
    The summary gives the tilt in rad first, degrees beside it, both the output bag's own: the
    largest angle of the body's z from F's, from its pose quaternions; the plot's attitude axis
    is in rad, each curve the bag's angle."""
    pytest.importorskip("matplotlib")
    from mount_twin import figure_files

    drawn: list = []
    monkeypatch.setattr(figure_files, "save_png", lambda fig, png: drawn.append(fig) or png)
    bag, png = ROOT / "bags" / "half_sine_shock_10khz", str(tmp_path / "p.png")
    code, doc, out = _replay(tmp_path, CONFIG / "pump_8_mounts.scene.yaml", bag, "--plot", png)
    assert code == 0 and len(drawn) == 1
    tables = {t.name: t.columns for t in read_output_bag(out)}
    q = tables["pose"]
    tilt = float(np.arccos(np.clip(1.0 - 2.0 * (q["qx"] ** 2 + q["qy"] ** 2), -1.0, 1.0)).max())
    said = re.search(r"max tilt (\S+) rad \((\S+) deg\)", capsys.readouterr().out)
    assert said is not None
    assert float(said[1]) == pytest.approx(tilt, rel=1e-3)  # 4 significant figures
    assert float(said[2]) == pytest.approx(np.degrees(tilt), rel=1e-3)
    assert doc["max_tilt_rad"] == pytest.approx(tilt, rel=1e-9)
    attitude = next(ax for ax in drawn[0].axes if "angle" in ax.get_ylabel())
    assert attitude.get_ylabel().endswith("[rad]")
    for line in attitude.get_lines():
        name = str(line.get_label())
        assert np.array_equal(line.get_ydata(), tables["angles"][f"{name}_rad"]), name
