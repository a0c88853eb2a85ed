"""The health window's peaks, which the compiled loop folds in from each published row while it
is in cache (its wrench components' largest magnitude per mount, and its largest tilt from the
rotation matrix), against the same figures computed from the rows the engine published (the
tilt from their quaternions)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from io_helpers import scene_with

from mount_twin.analysis.accuracy import raw_gyro
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.tilt import tilt_from_cos, tilt_from_quaternions
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import load_scene_file

ROOT = Path(__file__).resolve().parent.parent
CASES = {
    "genset_shock": ("genset_bolted_keyed.scene.yaml", "genset_shock_10khz"),
    "pump_ship_motion": ("pump_8_mounts.scene.yaml", "ship_motion_1khz"),
}


@pytest.mark.parametrize("decimation", [1, 7])
@pytest.mark.parametrize("case", list(CASES))
def test_the_window_peaks_are_those_of_the_published_rows(case: str, decimation: int) -> None:
    scene_file, bag = CASES[case]
    scene = load_scene_file(ROOT / "config" / scene_file)
    samples = read_samples(ROOT / "bags" / bag, scene.input)
    scene = raw_gyro(scene)  # every sample answered in its push
    # one window over the whole record: no report is due before the end
    scene = scene_with(scene, outputs={"decimation": decimation, "diagnostics_period_s": 1e3})
    engine = TwinEngine(assemble(scene))
    out = engine.push(samples)
    assert not out.health and len(out) == len(samples) // decimation + (decimation > 1)
    window = engine.health
    np.testing.assert_array_equal(window.wrench_peak, np.abs(out.wrenches).max(axis=0))
    tilt = float(tilt_from_quaternions(out.quaternion).max())
    assert tilt > 1e-5  # the body tilts: a wrong element of R would not pass
    # The loop's cos θ is R₃₃, the rows' is the quaternion's 1 − 2(x² + y²): they may differ
    # by an ulp or two, which arccos near 1 turns into eps/θ of θ (3e-8 of a 6e-5 rad tilt).
    assert window.tilt_max == pytest.approx(tilt, rel=1e-9, abs=8 * np.finfo(float).eps / tilt)
    assert window.published


@pytest.mark.parametrize("as_array", [False, True], ids=["float", "array"])
def test_a_cosine_rounded_past_one_is_no_tilt_and_past_minus_one_upside_down(
    as_array: bool,
) -> None:
    """cos θ = R₃₃ may round one unit past ±1: θ is 0 and π there, not NaN; cos θ = ½ is 60°;
    a NaN stays NaN (a live push's one float and a batch's array alike)."""
    cosines = [1.0 + 2.0**-52, -1.0 - 2.0**-52, 0.5, float("nan")]
    got = (
        tilt_from_cos(np.array(cosines)).tolist()
        if as_array
        else [float(tilt_from_cos(c)) for c in cosines]
    )
    assert got[:2] == [0.0, np.pi]
    assert got[2] == pytest.approx(np.pi / 3, rel=1e-15)
    assert np.isnan(got[3])
