"""`mount-twin qualify`: synthesised inputs that meet a spectrum, run through the twin, the
machine judged per mount on the worst over the inputs; the exit status says the verdict."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import CONFIG

from mount_twin import SampleBatch, TwinEngine, assemble, load_scene_file
from mount_twin.analysis.figures import mount_travel
from mount_twin.cli import main
from mount_twin.io.output_tables import read_output_bag
from mount_twin.physics.rotations import quaternion_matrices, rpy_matrix


def _table(path: Path, peak_g: float) -> Path:
    """A design of the usual shape: a ramp to 300 Hz, then a plateau of `peak_g`."""
    rows = [(10, peak_g / 30), (100, peak_g / 3), (300, peak_g), (1000, peak_g)]
    path.write_text(
        "frequency_hz,accel_g\n" + "".join(f"{f},{a}\n" for f, a in rows), encoding="utf-8"
    )
    return path


def _largest_forces(bag: Path) -> dict[str, float]:
    """max |F| (N) of each mount's wrenches, read back from an output bag."""
    out = {}
    for table in read_output_bag(bag):
        if table.name.startswith("mount_"):
            f = np.stack([table.columns[k] for k in ("fx_N", "fy_N", "fz_N")], axis=1)
            out[table.name.removeprefix("mount_")] = float(np.linalg.norm(f, axis=1).max())
    return out


@pytest.mark.parametrize(
    ("scene", "peak_g", "code", "verdict"),
    [
        ("pump_8_mounts.scene.yaml", 1.0, 0, "PASS"),  # rubber mounts well within ratings
        ("genset_bolted_keyed.scene.yaml", 60.0, 4, "FAIL"),  # bolts yield, joints open
    ],
    ids=["pump_passes_1g", "genset_fails_60g"],
)
def test_qualify_judges_the_worst_over_the_inputs(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    scene: str,
    peak_g: float,
    code: int,
    verdict: str,
) -> None:
    out, doc = tmp_path / "q", tmp_path / "q.json"
    args = ["qualify", str(CONFIG / scene), "--spectrum", str(_table(tmp_path / "d.csv", peak_g))]
    assert (
        main([*args, "-o", str(out), "--seeds", "2", "--workers", "1", "--json", str(doc)]) == code
    )
    said = capsys.readouterr().out
    assert f"qualification: {verdict} over 2 inputs" in said
    result = json.loads(doc.read_text(encoding="utf-8"))
    assert result["verdict"] == verdict
    runs = {r["input"]: r for r in result["runs"]}
    assert set(runs) == {"z/0", "z/1"}
    for r in runs.values():  # every input met the design within -1.5/+3 dB
        assert r["spectrum_margin_db"][0] >= -1.5 and r["spectrum_margin_db"][1] <= 3.0
    forces = {key: _largest_forces(Path(r["output_bag"])) for key, r in runs.items()}
    for name, m in result["mounts"].items():
        # the worst force is the larger of the two output bags' own, read back
        worst = max(f[name] for f in forces.values())
        assert m["force_max_N"] == pytest.approx(worst, rel=1e-9)
        # and the input it names is the one whose output bag holds it
        assert forces[m["force_max_N_input"]][name] == pytest.approx(worst, rel=1e-9)
        if m.get("utilisation_max") is not None:
            assert m["margin"] == pytest.approx(1.0 - m["utilisation_max"])
            assert m["utilisation_max_input"] in runs
    utilisation = [m.get("utilisation_max") for m in result["mounts"].values()]
    assert (max(u for u in utilisation if u is not None) > 1.0) == (verdict == "FAIL")
    assert 0.0 <= result["estimated_force_error_rel"] < 0.1
    if verdict == "FAIL":  # the reason names the mounts and the events that broke it
        assert re.search(r"diagnostics reached ERROR \(foot_\w+ (bolt_yielded|joint_opened)", said)


def test_at_rest_each_linear_mounts_travel_is_what_its_published_force_says() -> None:
    """Travel from the pose alone (d = r + R p − p) against the core's force: at rest a
    linear mount pushes with −Q K Qᵀ d, so Q K Qᵀ d = −F for each of the pump's mounts, its
    force published in its axes and rotated into F."""
    model = assemble(load_scene_file(CONFIG / "pump_8_mounts.scene.yaml"))
    scene = model.scene
    t = np.arange(50) * 1e-3
    rest = np.tile([0.0, 0.0, 9.80665], (t.size, 1))
    out = TwinEngine(model).run(SampleBatch(t, rest, np.zeros_like(rest), ["deck_imu"] * t.size))
    rot = quaternion_matrices(out.quaternion[-1:])
    cg = np.array(scene.body.cg)
    for i, m in enumerate(scene.mounts):
        q = rpy_matrix(*m.orientation_rpy)
        point = np.array([m.position])
        travel = mount_travel(out.position[-1:], rot, cg, point)[0]
        arm = point[0] - cg
        d = out.position[-1] - cg + rot[0] @ arm - arm
        force_f = q @ out.wrenches[-1, i, :3]
        scale = 1e-9 * np.linalg.norm(force_f)
        np.testing.assert_allclose(q @ np.diag(m.stiffness[:3]) @ q.T @ d, -force_f, atol=scale)
        assert travel == pytest.approx(np.linalg.norm(d), rel=1e-12) and travel > 1e-4


def _plan(tmp_path: Path, text: str) -> Path:
    for name, peak in (("z.csv", 1.0), ("y.csv", 0.5)):
        _table(tmp_path / name, peak)
    plan = tmp_path / "plan.yaml"
    plan.write_text(text, encoding="utf-8")
    return plan


PLAN = """spectra:
  z: z.csv
  y: y.csv
seeds: 1
rate_hz: 10000.0
criteria:
  max_utilisation: {limit}
"""


def test_a_plan_runs_every_axis_and_its_criteria_judge(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The pump on a two-axis plan, on a Dask cluster: PASS within its ratings; the same
    inputs judged against a utilisation limit below what they reach FAIL, naming the mounts
    past it. The report opens with the verdict, holds the plan, the spectra and the per-mount
    table, and is one file."""
    plan = _plan(tmp_path, PLAN.format(limit=1.0))
    page = tmp_path / "q.html"
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "--plan", str(plan)]
    assert main([*args, "-o", str(tmp_path / "a"), "--report", str(page)]) == 0
    said = capsys.readouterr().out
    assert "qualification: PASS over 2 inputs (z/0 OK, y/0 OK)" in said
    text = page.read_text(encoding="utf-8")
    assert text.index("<h2>Verdict: PASS</h2>") < text.index("inputs' spectra")
    assert "design spectrum, axis y" in text and "utilisation ≤ 1 for every rated mount" in text
    assert len(re.findall(r'src="data:image/png;base64,', text)) == 1
    assert 'src="http' not in text and "<script" not in text
    assert "<td>body.mass</td><td>1200.0</td>" in text
    scene_sum = hashlib.sha256((CONFIG / "pump_8_mounts.scene.yaml").read_bytes()).hexdigest()
    assert f"pump_8_mounts.scene.yaml (sha256 {scene_sum})" in text
    strict = _plan(tmp_path, PLAN.format(limit=0.01))
    assert main([*args[:-1], str(strict), "-o", str(tmp_path / "b"), "--workers", "1"]) == 4
    said = capsys.readouterr().out
    assert "qualification: FAIL" in said and "utilisation over 0.01: fl " in said


def test_a_fail_on_warn_verdict_names_the_status_that_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A WARN that no mount event explains (here the attitude's, past a tilt of 1e-6 rad) read
    "diagnostics reached WARN (see its diagnostics)"."""
    data = yaml.safe_load((CONFIG / "pump_8_mounts.scene.yaml").read_text(encoding="utf-8"))
    data["outputs"]["tilt_warn_rad"] = 1e-6
    scene = tmp_path / "pump.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    text = "spectra:\n  z: z.csv\nseeds: 1\ncriteria:\n  max_utilisation: 100\n  fail_on: warn\n"
    plan = _plan(tmp_path, text)
    args = ["qualify", str(scene), "--plan", str(plan), "-o", str(tmp_path / "q"), "--json"]
    assert main([*args, str(tmp_path / "q.json")]) == 4
    why = json.loads((tmp_path / "q.json").read_text(encoding="utf-8"))["why"]["broken"]
    assert list(why) == ["z/0"] and len(why["z/0"]) == 1, why
    assert why["z/0"][0].startswith("diagnostics reached WARN (mount_twin: attitude: tilt ")
    assert "past outputs.tilt_warn_rad 1e-06" in why["z/0"][0]  # it read "0.0° past 0.0°"
    assert "see its diagnostics" not in capsys.readouterr().out


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("spectra:\n  w: z.csv\n", r"plan\.yaml: spectra: give a design CSV per axis"),
        ("spectra:\n  z: none.csv\n", r"plan\.yaml: spectra\.z: no such file: .*none\.csv"),
        ("spectra:\n  z: z.csv\ncriteria:\n  fail_on: never\n", r"criteria\.fail_on"),
        ("spectra:\n  z: z.csv\nseed: 3\n", r"plan\.yaml: seed"),
        ("spectra:\n  z: z.csv\ntolerance_db: [1, 3]\n", r"tolerance_db: expected \[LOW, HIGH\]"),
        (  # a TypeError's traceback
            "spectra:\n  z: z.csv\ntolerance_db: ['-1.5', 3.0]\n",
            r"plan\.yaml: tolerance_db\[0\]: expected a number, got '-1\.5'",
        ),
        (  # named neither the file nor the key
            "spectra:\n  z: z.csv\ndamping: 5\n",
            r"plan\.yaml: damping: ζ = 5\.0: an SRS oscillator is underdamped",
        ),
        ("spectra:\n  z: z.csv\nq: 0.2\n", r"plan\.yaml: q: Q = 0\.2: an SRS oscillator"),
    ],
)
def test_a_bad_plan_fails_at_load_naming_the_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, says: str
) -> None:
    plan = _plan(tmp_path, text)
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "--plan", str(plan)]
    assert main([*args, "-o", str(tmp_path / "q")]) == 2
    assert re.search(says, capsys.readouterr().err)
    assert not (tmp_path / "q").exists()


@pytest.mark.parametrize(
    ("flags", "says"),
    [
        (["--rate", "5000"], "--rate: "),
        (["--seeds", "3", "--damping", "0.1"], "--seeds, --damping: "),
        (["--tolerance-db", "-1", "2", "--axis", "z"], "--axis, --tolerance-db: "),
    ],
)
def test_synthesis_options_beside_a_plan_are_refused_not_ignored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], flags: list[str], says: str
) -> None:
    """They were ignored without a word: the plan's synthesis ran, at its own rate and seeds."""
    plan = _plan(tmp_path, "spectra:\n  z: z.csv\n")
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "--plan", str(plan)]
    assert main([*args, *flags, "-o", str(tmp_path / "q")]) == 2
    assert f"{says}the plan sets the synthesis" in capsys.readouterr().err
    assert not (tmp_path / "q").exists()


def test_a_shock_along_a_dof_the_scene_freezes_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A pump with only z, alpha, gamma free passed a 15 g shock along x: the mounts carried
    their static load, the constraint the rest, unpublished."""
    data = yaml.safe_load((CONFIG / "pump_8_mounts.scene.yaml").read_text(encoding="utf-8"))
    data["dofs"] = ["z", "alpha", "gamma"]
    scene = tmp_path / "pump_3dof.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    spectrum = str(CONFIG / "shock_spectrum_vertical.csv")
    out = tmp_path / "q"
    args = ["qualify", str(scene), "--spectrum", spectrum, "--axis", "x", "-o", str(out)]
    assert main([*args, "--seeds", "1", "--workers", "1"]) == 2
    assert "--axis x: the scene freezes x (dofs z, alpha, gamma)" in capsys.readouterr().err
    assert not out.exists()


def test_a_synthesis_number_out_of_its_range_is_refused_naming_its_option_and_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """It said "--seeds must be ≥ 1, --head ≥ 0 s and --rate > 0 Hz", whichever was wrong."""
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "-o", str(tmp_path / "q")]
    spectrum = str(CONFIG / "shock_spectrum_vertical.csv")
    for option, value, says in (("--seeds", "-2", "≥ 1, got -2"), ("--head", "-1", "≥ 0, got -1")):
        with pytest.raises(SystemExit) as stop:
            main([*args, "--spectrum", spectrum, option, value])
        assert stop.value.code == 2
        assert f"argument {option}: must be {says}" in capsys.readouterr().err
    assert not (tmp_path / "q").exists()


def test_a_spectrum_the_synthesis_cannot_meet_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The error named the seed, not the design file (`unmeetable_design`)."""
    from io_helpers import unmeetable_design

    spectrum = unmeetable_design(tmp_path / "notch.csv")
    out = tmp_path / "q"
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "--spectrum", str(spectrum)]
    assert main([*args, "-o", str(out), "--rate", "1000", "--seeds", "1", "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert f"mount-twin: error: {spectrum}: the synthesis (seed 0) did not meet" in err, err
    assert not out.exists()


def test_a_qualification_that_fails_part_way_leaves_no_directory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The disk fills at the second input's bag, after the first input and its replay were
    written: the directory was kept, half a qualification without a verdict, and refused the
    rerun ("exists")."""
    from io_helpers import disk_full_after

    out = tmp_path / "q"
    written = disk_full_after(monkeypatch, 1)
    args = ["qualify", str(CONFIG / "pump_8_mounts.scene.yaml"), "-o", str(out)]
    spectrum = str(_table(tmp_path / "d.csv", 1.0))
    assert main([*args, "--spectrum", spectrum, "--seeds", "2", "--workers", "1"]) == 2
    assert written == [str(out / "input_z_seed_0")]
    err = capsys.readouterr().err
    assert f"mount-twin: error: {out / 'input_z_seed_1'}: No space left on device" in err
    assert f"mount-twin: warning: {out}: removed, with what qualify wrote in it" in err
    assert not out.exists() and tmp_path.is_dir()
