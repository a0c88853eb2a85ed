"""The package face: `mount_twin.__all__` resolves lazily, `import mount_twin` stays light, the
package ships py.typed, and the usage example of its docstring (the README's) runs."""

from __future__ import annotations

import re
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest
from io_helpers import run_python

import mount_twin

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("mount_twin._core", "numpy", "scipy", "rosbags", "yaml")


def usage_example() -> str:
    """The indented code block of mount_twin's docstring, dedented."""
    lines = (mount_twin.__doc__ or "").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("    "))
    block = []
    for line in lines[start:]:
        if line.strip() and not line.startswith("    "):
            break
        block.append(line)
    return textwrap.dedent("\n".join(block)).strip() + "\n"


def test_every_name_in_all_resolves() -> None:
    assert len(set(mount_twin.__all__)) == len(mount_twin.__all__)
    for name in mount_twin.__all__:
        assert getattr(mount_twin, name) is not None, name
    assert set(mount_twin.__all__) <= set(dir(mount_twin))
    namespace: dict[str, object] = {}
    exec("from mount_twin import *", namespace)
    assert set(mount_twin.__all__) <= set(namespace)


def test_exported_names_are_the_defining_modules_objects() -> None:
    from mount_twin.engine.batch import OutputBatch, SampleBatch
    from mount_twin.engine.engine import TwinEngine
    from mount_twin.errors import SceneError
    from mount_twin.replay import replay
    from mount_twin.replay_summary import ReplaySummary
    from mount_twin.scene.loader import load_scene_file

    assert mount_twin.TwinEngine is TwinEngine
    assert mount_twin.SampleBatch is SampleBatch and mount_twin.OutputBatch is OutputBatch
    assert mount_twin.load_scene_file is load_scene_file
    assert mount_twin.SceneError is SceneError
    assert mount_twin.ReplaySummary is ReplaySummary
    assert mount_twin.replay_bag is replay


def test_an_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="module 'mount_twin' has no attribute 'nope'"):
        _ = mount_twin.nope  # type: ignore[attr-defined]


def test_a_lazy_entry_naming_no_attribute_is_an_import_error_naming_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A broken entry of the lazy table is a programming error: an ImportError that names the
    entry, which neither `hasattr` nor `from mount_twin import` turns into "no such name"."""
    monkeypatch.setitem(mount_twin._LAZY, "Mistyped", "mount_twin.scene.loader:load_scene_fil")
    said = re.escape(
        "mount_twin._LAZY maps 'Mistyped' to 'mount_twin.scene.loader:load_scene_fil': "
        "mount_twin.scene.loader has no 'load_scene_fil'"
    )
    with pytest.raises(ImportError, match=said):
        hasattr(mount_twin, "Mistyped")
    with pytest.raises(ImportError, match=said):
        exec("from mount_twin import Mistyped", {})


def test_importing_the_package_imports_no_core_numpy_or_rosbags() -> None:
    done = run_python(
        "-c",
        "import sys, mount_twin\n"
        "assert mount_twin.MountTwinError.__name__ == 'MountTwinError'\n"
        f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))\n",
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_a_lazy_name_is_imported_on_first_use_and_replay_bag_is_the_function() -> None:
    done = run_python(
        "-c",
        "import sys, mount_twin\n"
        "engine = mount_twin.TwinEngine\n"
        "assert 'mount_twin._core' in sys.modules, 'TwinEngine imports the engine on first use'\n"
        "import mount_twin.replay\n"
        "assert mount_twin.replay_bag is mount_twin.replay.replay\n",
    )
    assert done.returncode == 0, done.stderr


def test_the_package_ships_py_typed_and_the_cores_stubs() -> None:
    package = Path(mount_twin.__file__).parent
    assert (package / "py.typed").is_file() and (package / "_core_ext.pyi").is_file()
    setup = (ROOT / "setup.py").read_text("utf-8")
    assert 'package_data={PACKAGE: ["py.typed", "_core_ext.pyi"]}' in setup


def test_the_usage_example_runs_and_the_mounts_carry_the_body(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from mount_twin.physics.rotations import rpy_matrix

    code = usage_example()
    assert 5 <= len(code.splitlines()) <= 10, code
    monkeypatch.chdir(ROOT)
    namespace: dict[str, object] = {}
    exec(compile(code, "mount_twin.__doc__", "exec"), namespace)
    assert capsys.readouterr().out.strip(), "the example prints the last wrenches"
    engine, out = namespace["engine"], namespace["out"]
    assert isinstance(engine, mount_twin.TwinEngine) and isinstance(out, mount_twin.OutputBatch)
    assert len(out) == 100 and engine.counts["accepted"] == 100
    scene = engine.scene
    assert out.wrenches.shape == (100, len(scene.mounts), 6)
    # at rest from the start: the static equilibrium holds, the mounts carry m·g
    np.testing.assert_allclose(out.wrenches[-1], out.wrenches[0], atol=1e-6)
    force = sum(
        rpy_matrix(*m.orientation_rpy) @ out.wrenches[-1, i, :3]
        for i, m in enumerate(scene.mounts)
    )
    np.testing.assert_allclose(
        force, [0.0, 0.0, scene.body.mass * scene.input.g], rtol=0.0, atol=1e-6
    )


@pytest.mark.parametrize(
    ("field", "bad", "says"),
    [
        ("accel", np.zeros((5, 2)), r"SampleBatch\.accel: shape \(5, 2\), expected \(5, 3\)"),
        ("gyro", np.zeros((4, 3)), r"SampleBatch\.gyro: shape \(4, 3\), expected \(5, 3\)"),
        ("stamps", np.zeros((5, 1)), r"SampleBatch\.stamps: shape \(5, 1\), expected \(n,\)"),
        ("accel", np.full((5, 3), "a"), r"SampleBatch\.accel: dtype <U1, expected real"),
        ("frame_ids", ["deck_imu"] * 4, r"SampleBatch\.frame_ids: 4 entries, expected 5"),
        # these three were an IndexError, numpy's "truth value ... ambiguous", and "5 entries,
        # expected 5 strings"
        ("stamps", np.float64(0.0), r"SampleBatch\.stamps: shape \(\), expected \(n,\)"),
        (
            "frame_ids",
            np.array([b"deck_imu"] * 5),
            r"SampleBatch\.frame_ids: expected 5 strings, \[0\] is a bytes_",
        ),
        ("frame_ids", [b"deck_imu"] * 5, r"SampleBatch\.frame_ids: .* \[0\] is a bytes"),
    ],
)
def test_a_malformed_batch_is_refused_naming_the_field_and_changes_nothing(
    field: str, bad: object, says: str
) -> None:
    """The way MuJoCo's rollout checks shapes: before the engine touches its state (a wrong
    accel surfaced as a numpy broadcasting error from deep inside)."""
    engine = mount_twin.TwinEngine(
        mount_twin.assemble(mount_twin.load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml"))
    )
    t = np.arange(5) * 1e-3
    good = {
        "stamps": t,
        "accel": np.tile([0.0, 0.0, 9.80665], (5, 1)),
        "gyro": np.zeros((5, 3)),
        "frame_ids": ["deck_imu"] * 5,
    }
    with pytest.raises(ValueError, match=says):
        engine.push(mount_twin.SampleBatch(**{**good, field: bad}))
    assert engine.counts["received"] == 0
    out = engine.run(mount_twin.SampleBatch(**good))
    assert len(out) == 5


def test_lists_and_float32_are_taken_as_the_float64_arrays_they_hold() -> None:
    """A list for accel passed the checks and was kept as the last reading: every later push
    raised a TypeError from inside the intake; float32 input warned of an overflow (the
    reading limit, 1e150, cast to float32). Each gives the float64 run's outputs, bit for bit."""
    scene = mount_twin.load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")
    t = 1.0 + np.arange(400) * 1e-3
    accel = np.tile([0.0, 0.0, 9.80665], (400, 1)) + 0.5 * np.sin(40.0 * t)[:, None]
    gyro = np.zeros((400, 3))
    ids = ["deck_imu"] * 400

    def run(a: object, g: object, stamps: object) -> mount_twin.OutputBatch:
        engine = mount_twin.TwinEngine(mount_twin.assemble(scene))
        first = engine.push(mount_twin.SampleBatch(stamps[:10], a[:10], g[:10], ids[:10]))
        rest = engine.push(mount_twin.SampleBatch(stamps[10:], a[10:], g[10:], ids[10:]))
        return first.then(rest, 10).then(engine.flush(), 400)

    want = run(accel, gyro, t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = run(accel.tolist(), gyro.tolist(), t.tolist())
        np.testing.assert_array_equal(got.wrenches, want.wrenches)
        f32 = run(accel.astype(np.float32), gyro.astype(np.float32), t)
    exact = run(accel.astype(np.float32).astype(np.float64), gyro, t)
    np.testing.assert_array_equal(f32.wrenches, exact.wrenches)


def test_the_concatenation_of_no_batch_is_an_empty_batch_an_engine_takes() -> None:
    """It was numpy's "need at least one array to concatenate"."""
    empty = mount_twin.SampleBatch.concat([])
    assert len(empty) == 0 and empty.accel.shape == (0, 3) and empty.frame_ids == []
    scene = mount_twin.load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")
    assert len(mount_twin.TwinEngine(mount_twin.assemble(scene)).push(empty)) == 0


def test_the_entry_points_refuse_a_wrong_object_naming_the_argument() -> None:
    """A scene where a model goes (or a dict where a batch goes) is refused at the door, with
    what was given and what is taken, not with an AttributeError from deep inside."""
    scene = mount_twin.load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")
    engine = mount_twin.TwinEngine(mount_twin.assemble(scene))
    cases = [
        (
            lambda: mount_twin.TwinEngine(scene),
            r"TwinEngine\(model\): got a Scene, expected a Model",
        ),
        (
            lambda: mount_twin.assemble({"body": {}}),
            r"assemble\(scene\): got a dict, expected a Scene",
        ),
        (lambda: mount_twin.TwinStream("pump.yaml"), r"TwinStream\(scene\): got a str, expected"),
        (lambda: engine.push({"stamps": []}), r"TwinEngine\.push\(batch\): got a dict, expected"),
    ]
    for call, says in cases:
        with pytest.raises(TypeError, match=says):
            call()
    assert engine.counts["received"] == 0


def test_the_events_are_in_time_order_and_the_engines_own() -> None:
    """On the genset shock, events of one substep came in mount order (foot_fl at 51.938 ms
    before foot_ml at 51.912 ms), and `events.clear()` wiped the engine's record."""
    from mount_twin.io.input_samples import read_samples

    scene = mount_twin.load_scene_file(ROOT / "config/genset_bolted_keyed.scene.yaml")
    samples = read_samples(ROOT / "bags/genset_shock_10khz", scene.input)
    engine = mount_twin.TwinEngine(mount_twin.assemble(scene))
    engine.run(samples)
    stamps = [e.stamp for e in engine.events]
    assert len(stamps) > 10 and stamps == sorted(stamps)
    engine.events.clear()
    assert len(engine.events) == len(stamps)


def test_then_changes_neither_batch() -> None:
    """`a.then(b, n)` shifted b's reports in place: b then disagreed with itself, and a second
    call shifted them twice."""
    scene = mount_twin.load_scene_file(ROOT / "config/pump_8_mounts.scene.yaml")
    t = 1.0 + np.arange(3000) * 1e-3
    accel, gyro = np.tile([0.0, 0.0, 9.80665], (3000, 1)), np.zeros((3000, 3))
    batch = mount_twin.SampleBatch(t, accel, gyro, ["deck_imu"] * 3000)
    engine = mount_twin.TwinEngine(mount_twin.assemble(scene))
    a, b = engine.push(batch.part(slice(0, 1500))), engine.push(batch.part(slice(1500, None)))
    before = [(r.sample, r.rows) for r in b.health]
    once, twice = a.then(b, 1500), a.then(b, 1500)
    assert before and [(r.sample, r.rows) for r in b.health] == before
    assert [(r.sample, r.rows) for r in once.health] == [(r.sample, r.rows) for r in twice.health]
    assert [r.sample for r in once.health][-len(before) :] == [s + 1500 for s, _ in before]
