"""Spectra of the twin's response (`srs --response`): the CG's specific force from the mount
forces (Newton, no differentiation) against a closed form and against statics, and the command
on an output bag and on an input bag replayed in memory."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from io_helpers import ROOT
from physics_helpers import G, base_scene, build, mount
from scipy.linalg import expm

from mount_twin.analysis.response import response_of
from mount_twin.cli import main
from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.signals import half_sine_shock

MASS, FN, ZETA = 50.0, 40.0, 0.05  # kg, Hz, damping ratio
WN = 2 * math.pi * FN
K, C = MASS * WN**2, 2 * ZETA * WN * MASS
GENSET = ROOT / "config/genset_bolted_keyed.scene.yaml"
SHOCK = ROOT / "bags/genset_shock_10khz"


def exact_relative_motion(t: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relative displacement x and velocity v (m, m/s) of x'' + 2ζω x' + ω² x = −a, a linear
    between samples: the exact discrete solution (matrix exponential of the augmented
    system), a formulation independent of the twin's."""
    aug = np.zeros((4, 4))
    aug[:2, :2] = [[0.0, 1.0], [-(WN**2), -2 * ZETA * WN]]
    aug[1, 2] = -1.0
    aug[2, 3] = 1.0
    x, v = np.zeros(t.size), np.zeros(t.size)
    state = np.zeros(2)
    step = expm(aug * (t[1] - t[0]))
    for j in range(1, t.size):
        slope = (a[j] - a[j - 1]) / (t[j] - t[j - 1])
        state = (step @ np.array([state[0], state[1], a[j - 1], slope]))[:2]
        x[j], v[j] = state
    return x, v


def test_the_cgs_specific_force_is_the_closed_form_absolute_acceleration() -> None:
    """One mass on one mount, free along z, under a 150 m/s² half-sine: the CG reads
    g + a_abs with a_abs = −(ω² x + 2ζω x'), x the relative motion; the frozen axes are
    refused (NaN: a constraint holds them, and its force is not published)."""
    sig = half_sine_shock(150.0, 0.008, 20000.0, 0.01, 0.1, G)
    data = base_scene(
        MASS,
        [0.1, -0.2, 0.25],
        [1.0, 2.0, 2.5, 0.0, 0.0, 0.0],
        [mount("iso", [0.1, -0.2, 0.0], [1e5, 1e5, K, 10.0, 10.0, 10.0], [0, 0, C, 0, 0, 0])],
        dofs=["z"],
    )
    model = build(data)
    out = TwinEngine(model).run(SampleBatch(sig.t, sig.accel, sig.gyro, ["imu"] * sig.t.size))
    r = response_of(model.scene, out.stamps, out.wrenches, "cg")
    x, v = exact_relative_motion(sig.t, sig.accel[:, 2] - G)
    a_abs = -(WN**2 * x + 2 * ZETA * WN * v)
    assert r.unit == "m/s²" and np.isnan(r.values[:, :2]).all()
    np.testing.assert_allclose(r.values[:, 2] - G, a_abs, rtol=0, atol=1e-9 * np.abs(a_abs).max())
    assert np.abs(a_abs).max() > 100.0  # the shock went through the mount


def test_at_rest_the_mounts_carry_exactly_the_weight() -> None:
    """The pump at rest on its tilted mounts: Σ Qᵢ fᵢ / m is +g along z of F, to rounding."""
    model = build(yaml.safe_load((ROOT / "config/pump_8_mounts.scene.yaml").read_text()))
    t = np.arange(200) * 1e-3
    rest = np.tile([0.0, 0.0, G], (t.size, 1))
    out = TwinEngine(model).run(SampleBatch(t, rest, np.zeros_like(rest), ["deck_imu"] * t.size))
    r = response_of(model.scene, out.stamps, out.wrenches, "cg")
    np.testing.assert_allclose(r.values, np.tile([0.0, 0.0, G], (t.size, 1)), atol=1e-9 * G)


def _spectra(path: Path) -> dict[str, list[float]]:
    with open(path, encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def test_the_response_spectra_of_an_output_bag_and_of_its_replay_in_memory_agree(
    tmp_path: Path,
) -> None:
    """The genset's shock: from the bag `replay` wrote, and from the input bag run in memory,
    the CG's and a bolt's spectra are the same numbers."""
    out_bag = tmp_path / "out"
    assert (
        main(["replay", str(SHOCK), "--scene", str(GENSET), "-o", str(out_bag), "--no-progress"])
        == 0
    )
    for what in ("cg", "mount:foot_fl"):
        tables = []
        for src in (out_bag, SHOCK):
            table = tmp_path / f"{what.replace(':', '_')}_{src.name}.csv"
            args = ["srs", str(src), "--response", what, "--scene", str(GENSET), "--axis", "all"]
            assert main([*args, "--csv", str(table)]) == 0
            tables.append(_spectra(table))
        assert tables[0].keys() == tables[1].keys()
        for key in tables[0]:
            np.testing.assert_allclose(tables[0][key], tables[1][key], rtol=1e-12, err_msg=key)
    force = _spectra(tmp_path / "mount_foot_fl_out.csv")
    assert max(force["maximax_z"]) > 1e4  # N: the bolt's dynamic load, far above noise


def test_an_axis_the_scene_freezes_has_no_spectrum_and_is_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its CG specific force is NaN (the constraint's force is not published): `--axis all`
    failed whole with "the record must be a non-empty 1-D array of finite values"."""
    data = yaml.safe_load(GENSET.read_text(encoding="utf-8"))
    data["dofs"] = ["x", "z", "alpha", "gamma", "delta"]
    scene = tmp_path / "no_sway.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    table = tmp_path / "cg.csv"
    args = ["srs", str(SHOCK), "--response", "cg", "--scene", str(scene), "--axis"]
    assert main([*args, "all", "--csv", str(table)]) == 0
    assert "--axis all: the scene freezes y: a constraint holds" in capsys.readouterr().out
    columns = _spectra(table)
    assert "maximax_x" in columns and "maximax_z" in columns and "maximax_y" not in columns
    assert all(math.isfinite(v) for v in columns["maximax_z"])
    assert main([*args, "y"]) == 2
    assert "--axis y: the scene freezes y: a constraint" in capsys.readouterr().err


def test_the_output_bag_of_a_failed_run_is_refused_as_failed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """It was refused for "a hole of 0.0002 s", the samples the failed steps did not publish,
    as if the bag had lost them; the input bag replayed in memory said why."""
    data = yaml.safe_load(GENSET.read_text(encoding="utf-8"))
    data["integration"] = {"method": "dopri54", "rtol": 1e-13, "atol": 1e-15, "max_substeps": 1}
    scene = tmp_path / "failing.scene.yaml"
    scene.write_text(yaml.safe_dump(data), encoding="utf-8")
    out_bag = tmp_path / "out"
    replay = ["replay", str(SHOCK), "--scene", str(scene), "-o", str(out_bag), "--no-progress"]
    assert main(replay) == 6
    capsys.readouterr()
    for src in (out_bag, SHOCK):
        assert main(["srs", str(src), "--response", "cg", "--scene", str(scene)]) == 2
        err = capsys.readouterr().err
        assert f"{src}: the twin's run failed, its response is not the machine's: " in err
        assert "integration failed" in err


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--response", "mount:nope", "--scene", str(GENSET)], r"NAME one of foot_fl, foot_fr"),
        (["--response", "cg"], r"--response and --scene go together"),
        (
            ["--response", "mount:foot_fl", "--scene", str(GENSET), "--design", "DESIGN"],
            r"--design is a spectrum in g: .* is a force \(N\)",
        ),
    ],
)
def test_a_response_that_cannot_be_taken_is_refused_naming_why(
    extra: list[str], says: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    design = tmp_path / "design.csv"
    design.write_text("frequency_hz,accel_g\n10,1\n1000,50\n", encoding="utf-8")
    args = ["srs", str(SHOCK), *(str(design) if a == "DESIGN" else a for a in extra)]
    assert main(args) == 2
    assert re.search(says, capsys.readouterr().err)


def test_the_plots_title_fits_in_the_figure(tmp_path: Path, monkeypatch) -> None:
    """The title of a mount's spectra (the bag, the scene, the mount, ζ and what was taken out)
    ran past both edges of the PNG: "f genset_shock_10khz replayed on … the first 100 sam"."""
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    shown = []
    close = plt.close
    monkeypatch.setattr(plt, "close", lambda fig=None: shown.append(fig) or close(fig))
    bag = ROOT / "bags/genset_shock_10khz"
    png = tmp_path / "s.png"
    args = ["srs", str(bag), "--response", "mount:foot_fl", "--scene", str(GENSET)]
    assert main([*args, "--plot", str(png)]) == 0
    (fig,) = shown
    renderer = FigureCanvasAgg(fig).get_renderer()
    title = fig.axes[0].title
    box, page = title.get_window_extent(renderer), fig.bbox
    assert "foot_fl" in title.get_text()
    assert page.x0 <= box.x0 and box.x1 <= page.x1 and box.y1 <= page.y1


def test_the_help_gives_a_mount_forces_spectra_in_newtons() -> None:
    """`srs --help` said the --csv and --plot spectra are in g and m/s whatever --response
    takes; a mount's force has its spectra in N and its pseudo-velocity in N·s."""
    import argparse

    from mount_twin.cli import build_parser

    parser, _ = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    helps = {a.dest: a.help or "" for a in sub.choices["srs"]._actions}
    assert "with --response mount:NAME, N and N·s" in helps["csv"]
    assert "(N with --response mount:NAME)" in helps["plot"]
