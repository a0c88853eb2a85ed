"""The compiled core's sources and their fingerprint (standard library only: setup.py loads this
file by path to stamp the build, and `mount_twin._core` checks the stamp at import).

A source checkout (an editable install, `colcon build --symlink-install`, the tests) holds
src/core beside the package: if its sources differ from those the extension was built from, the
import fails and says how to rebuild, rather than run a core older than the code beside it.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

SOURCE_DIR = Path(__file__).resolve().parent.parent / "src" / "core"
"""src/core of a source checkout (absent in an installed copy)."""
SUFFIXES = (".hpp", ".cpp")


def source_files(root: Path = SOURCE_DIR) -> list[Path]:
    """The core's C++ sources under `root`, sorted."""
    return sorted(p for p in root.rglob("*") if p.suffix in SUFFIXES)


def fingerprint(root: Path = SOURCE_DIR) -> str:
    """SHA-256 (hex) over the relative path and bytes of every source under `root`."""
    digest = hashlib.sha256()
    for path in source_files(root):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def check_fresh(built_from: str, root: Path = SOURCE_DIR) -> None:
    """Raise ImportError if `root` holds sources other than those of the fingerprint
    `built_from` (nothing to check where there is no `root`: an installed copy)."""
    if not root.is_dir():
        return
    now = fingerprint(root)
    if now != built_from:
        msg = (
            f"mount_twin's compiled core was built from other sources than {root} holds now "
            f"(built {built_from[:12]}, sources {now[:12]}): rebuild it with "
            "`python3 -m pip install -e .` (or `python3 setup.py build_ext --inplace`)"
        )
        raise ImportError(msg)
