"""`mount-twin qualify`: synthesised inputs that meet a spectrum, run through the twin, the
machine judged per mount on the worst over the inputs; the exit status says the verdict."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from io_helpers import CONFIG

from mount_twin.cli import main
from mount_twin.io.output_tables import read_output_bag


def _table(path: Path, peak_g: float) -> Path:
    """A design of the usual shape: a ramp to 300 Hz, then a plateau of `peak_g`."""
    rows = [(10, peak_g / 30), (100, peak_g / 3), (300, peak_g), (1000, peak_g)]
    path.write_text(
        "frequency_hz,accel_g\n" + "".join(f"{f},{a}\n" for f, a in rows), encoding="utf-8"
    )
    return path


def _largest_force(bag: Path, mount: str) -> float:
    """max |F| (N) of one mount's wrenches, read back from an output bag."""
    (table,) = (t for t in read_output_bag(bag) if t.name == f"mount_{mount}")
    f = np.stack([table.columns[k] for k in ("fx_N", "fy_N", "fz_N")], axis=1)
    return float(np.linalg.norm(f, axis=1).max())


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
    assert main([*args, "-o", str(out), "--seeds", "2", "--json", str(doc)]) == code
    said = capsys.readouterr().out
    assert said.count("40 of 40 frequencies within -1.5/+3 dB: PASS") == 2
    assert f"qualification: {verdict} over 2 inputs" in said
    result = json.loads(doc.read_text(encoding="utf-8"))
    assert result["verdict"] == verdict
    runs = {r["seed"]: r for r in result["runs"]}
    for name, m in result["mounts"].items():
        # the worst force is the larger of the two output bags' own, read back
        worst = max(_largest_force(out / f"output_seed_{s}", name) for s in runs)
        assert m["force_max_N"] == pytest.approx(worst, rel=1e-9)
        # and the seed it names is the input whose output bag holds it
        own = _largest_force(out / f"output_seed_{m['force_max_seed']}", name)
        assert own == pytest.approx(worst, rel=1e-9)
        if m["utilisation_max"] is not None:
            assert m["margin"] == pytest.approx(1.0 - m["utilisation_max"])
            assert m["utilisation_max_seed"] in runs
    utilisation = [m["utilisation_max"] for m in result["mounts"].values()]
    assert (max(u for u in utilisation if u is not None) > 1.0) == (verdict == "FAIL")
    assert 0.0 <= result["estimated_force_error_rel"] < 0.1
