"""Compiled code is never stale: numba's on-disk cache of the package is keyed on the content of
every compiled source file (`physics.compiled`), not only on the file of the cached function.

The proof runs a copy of the package in fresh processes: a dispatcher in kinds/__init__.py
inlines the shear key's law from kinds/shear_key.py; doubling that law in the copy must change
the next process's answer (numba's own locator, run as a control, keeps the old one), and an
unedited re-run must load from the cache.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numba
import pytest
from io_helpers import run_python

from mount_twin.physics import compiled
from mount_twin.physics.compiled import (
    COMPILED_SOURCES,
    PACKAGE_DIR,
    PackageStampedLocator,
    compiled_source_files,
    source_stamp,
)

LAW_LINE = "f[j] = -side * max(k * pen + p[C0 + j] * side * v[j], 0.0)"
"""The shear key's contact force in kinds/shear_key.py."""

PROBE = """
import json
import numpy as np
import mount_twin
from mount_twin import kinds
from mount_twin.kinds import shear_key

p = np.zeros(kinds.N_PAR)
p[shear_key.K0 : shear_key.K0 + 3] = 1.0e6
d, z, y = np.array([1.0e-3, 0.0, 0.0]), np.zeros(3), np.zeros(1)
f, c = np.zeros(3), np.zeros(3)
kinds.kind_load(kinds.CODES["shear_key"], p, y, -1, d, z, z, z, y.copy(), f, c)
stats = kinds.kind_load.stats
print(json.dumps({
    "file": mount_twin.__file__,
    "force": f[0],
    "hits": sum(stats.cache_hits.values()),
    "misses": sum(stats.cache_misses.values()),
}))
"""


def copy_package(dest: Path) -> Path:
    """A copy of the mount_twin package (sources only, no cache) under dest; returns dest."""
    shutil.copytree(PACKAGE_DIR, dest / "mount_twin", ignore=shutil.ignore_patterns("__pycache__"))
    return dest


def run_probe(root: Path, **env: str) -> dict:
    """Run PROBE in a new interpreter that imports the package copy under root."""
    environ = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    environ.update(PYTHONPATH=str(root), PYTHONDONTWRITEBYTECODE="1", **env)
    out = run_python("-c", PROBE, cwd=root, env=environ, timeout=600.0)
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert Path(result["file"]).resolve().is_relative_to(root.resolve()), result["file"]
    return result


def double_the_shear_key_law(root: Path) -> None:
    """Edit the copy's shear key: twice the contact force."""
    path = root / "mount_twin" / "kinds" / "shear_key.py"
    text = path.read_text(encoding="utf-8")
    assert text.count(LAW_LINE) == 1
    path.write_text(text.replace(LAW_LINE, LAW_LINE.replace("-side", "-2.0 * side")), "utf-8")


def test_an_edited_inlined_law_is_picked_up_and_an_unedited_rerun_is_cached(
    tmp_path: Path,
) -> None:
    """First run compiles (1 kN for 1 mm on 1e6 N/m), a re-run loads the cache; after the law is
    doubled in its own file, the next run recompiles and gives 2 kN, and then caches that."""
    root = copy_package(tmp_path)
    first = run_probe(root)
    assert first["force"] == pytest.approx(-1.0e3) and first["misses"] == 1
    again = run_probe(root)
    assert again["force"] == first["force"] and (again["hits"], again["misses"]) == (1, 0)
    double_the_shear_key_law(root)
    edited = run_probe(root)
    assert edited["force"] == pytest.approx(-2.0e3) and edited["misses"] == 1
    edited_again = run_probe(root)
    assert edited_again["force"] == pytest.approx(-2.0e3)
    assert (edited_again["hits"], edited_again["misses"]) == (1, 0)


@pytest.mark.skipif(
    not hasattr(numba.config, "CACHE_LOCATOR_CLASSES"), reason="numba < 0.60 has no override"
)
def test_control_numbas_own_locator_keeps_the_old_law(tmp_path: Path) -> None:
    """The same edit under numba's own in-tree locator (forced by its override variable) runs
    the old law from the cache: what the package locator prevents."""
    root = copy_package(tmp_path)
    numba_own = {"NUMBA_CACHE_LOCATOR_CLASSES": "InTreeCacheLocator"}
    assert run_probe(root, **numba_own)["force"] == pytest.approx(-1.0e3)
    double_the_shear_key_law(root)
    stale = run_probe(root, **numba_own)
    assert stale["force"] == pytest.approx(-1.0e3) and stale["hits"] == 1


def test_the_stamp_follows_compiled_sources_only(tmp_path: Path) -> None:
    """Any byte of a compiled source changes the stamp (and so every cached kernel's); other
    files of the package (io, ros, adapters) do not, so editing them costs no recompilation."""
    root = copy_package(tmp_path) / "mount_twin"
    stamp = source_stamp.__wrapped__(root)
    assert stamp == source_stamp.__wrapped__(PACKAGE_DIR)  # content, not place
    (root / "io" / "bag.py").write_text("# edited\n", encoding="utf-8")
    assert source_stamp.__wrapped__(root) == stamp
    for rel in ("engine/kernel.py", "integrate/dopri54.py", "physics/dynamics.py"):
        path = root / rel
        original = path.read_bytes()
        path.write_bytes(original + b"\n")
        assert source_stamp.__wrapped__(root) != stamp, rel
        path.write_bytes(original)
    assert source_stamp.__wrapped__(root) == stamp
    (root / "kinds" / "new_kind.py").write_text('"""A new kind."""\n', encoding="utf-8")
    assert source_stamp.__wrapped__(root) != stamp


def test_every_file_with_compiled_code_is_stamped() -> None:
    """A file that compiles anything (njit, kernel, an overload) lies in COMPILED_SOURCES."""
    stamped = set(compiled_source_files())
    compiles = re.compile(
        r"^(from numba|import numba|@kernel|@njit|@overload)|skip_if_none\(", re.MULTILINE
    )
    unstamped = [
        str(path.relative_to(PACKAGE_DIR))
        for path in PACKAGE_DIR.rglob("*.py")
        if "__pycache__" not in path.parts
        and path not in stamped
        and compiles.search(path.read_text(encoding="utf-8"))
    ]
    assert not unstamped, f"add to COMPILED_SOURCES: {unstamped} ({COMPILED_SOURCES})"


def test_every_package_function_uses_the_package_stamp_whatever_the_import_order() -> None:
    """In a fresh process that imports a leaf physics module before the locator, then the rest,
    every cached function of the package is stamped by the package locator."""
    script = """
import mount_twin.physics.chart  # decorated before mount_twin.physics.compiled is imported
import mount_twin.engine.kernel, mount_twin.model.assemble
from mount_twin.physics.compiled import PackageStampedLocator, package_dispatchers
bad = [n for n, d in package_dispatchers()
       if not isinstance(d._cache._impl.locator, PackageStampedLocator)]
print(len(package_dispatchers()), bad)
"""
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300, check=True
    ).stdout.split(maxsplit=1)
    assert int(out[0]) > 40 and out[1].strip() == "[]", out


def test_the_locator_is_first_and_installed_once() -> None:
    """install() is idempotent and puts the package locators before numba's."""
    compiled.install()
    compiled.install()
    classes = compiled._CACHE_IMPL._locator_classes
    ours = [c for c in classes if issubclass(c, PackageStampedLocator)]
    assert classes[: len(ours)] == ours and len(ours) == 3
