"""Output never depends on how the input is batched, on the scenes where that is hardest.

The bundled genset switches (bolted joints slip and open, keys close) and runs `auto`, which
ends a compiled run at a stiffening event to look at the scene again; with the deck rotating,
the gyro conditioning carries state across those stops. One batch, one sample per push and
ragged pieces must give the same numbers bit for bit, and the same events, counts and method
choices (a live node's batches are whatever its executor delivers).
"""

from __future__ import annotations

import numpy as np
import pytest
from io_helpers import ROOT, split

from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.io.input_samples import read_samples
from mount_twin.model.assemble import assemble
from mount_twin.scene import load_scene_file

GENSET = ROOT / "config" / "genset_bolted_keyed.scene.yaml"


def _rolling_shock() -> SampleBatch:
    """The bundled genset shock record with the deck rolling and pitching (rad/s)."""
    scene = load_scene_file(GENSET)
    b = read_samples(ROOT / "bags" / "genset_shock_10khz", scene.input)
    t = b.stamps - b.stamps[0]
    b.gyro[:, 0] += 0.4 * np.sin(2.0 * np.pi * 30.0 * t)
    b.gyro[:, 1] += 0.2 * np.sin(2.0 * np.pi * 12.0 * t + 0.3)
    return b


def _run(pieces: list[int] | None) -> tuple[OutputBatch, TwinEngine]:
    scene = load_scene_file(GENSET)
    assert scene.integration.method == "auto" and scene.input.gyro_filter != "none"
    engine = TwinEngine(assemble(scene))
    full = _rolling_shock()
    parts = [full] if pieces is None else split(full, pieces)
    outs = [engine.push(p) for p in parts]
    joined = OutputBatch(
        np.concatenate([o.stamps for o in outs]),
        np.concatenate([o.sample for o in outs]),
        np.concatenate([o.pose for o in outs]),
        np.concatenate([o.wrenches for o in outs]),
    )
    return joined, engine


@pytest.fixture(scope="module")
def reference() -> tuple[OutputBatch, TwinEngine]:
    return _run(None)


@pytest.mark.parametrize(
    "pieces",
    [[1] * 2500, [7] * 400, [3, 1, 50, 7, 200, 1, 1, 99, 238, 1000, 13]],
    ids=["one_sample_each", "sevens", "ragged"],
)
def test_a_switching_rotating_scene_gives_the_same_bits_in_any_batching(
    reference: tuple[OutputBatch, TwinEngine], pieces: list[int]
) -> None:
    want, ref_engine = reference
    stiffening = [e for e in ref_engine.events if ref_engine._stiffens(e)]
    assert len(stiffening) >= 2, "the record must make auto look again mid-run"
    got, engine = _run(pieces)
    np.testing.assert_array_equal(got.stamps, want.stamps)
    np.testing.assert_array_equal(got.pose, want.pose)
    np.testing.assert_array_equal(got.wrenches, want.wrenches)
    assert engine.events == ref_engine.events
    assert engine.counts == ref_engine.counts
    assert engine.health.method == ref_engine.health.method
    np.testing.assert_array_equal(engine.state, ref_engine.state)
