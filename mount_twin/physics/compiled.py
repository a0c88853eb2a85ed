"""How the hot-path functions are compiled, and how their on-disk cache is kept fresh.

`kernel`: numba nopython, cached on disk, and without numba's runtime (NRT). These functions never
allocate: they work on arrays the engine owns and keeps alive. Without NRT numba emits no
reference counting, which otherwise costs an atomic increment and decrement for every array
taken out of the model's and the scratch's tuples: the right-hand side ran 3.5× faster without
it (1.2 → 0.35 µs for the default scene). A kernel that tried to allocate would fail to compile.
Small helpers stay `njit(inline="always")`: inlined, they are compiled with their caller's flags.

**Cache freshness.** numba stamps a cached function with its own source file only, yet a kernel
carries the code of every function it inlines or calls and the values of the module constants
it reads, from other files (`rhs` inlines every kind's force law): after an edit to such a file
numba would keep loading the old machine code. Importing this module therefore installs
`PackageStampedLocator` in front of numba's cache locators (`CacheImpl._locator_classes`,
consulted when a `cache=True` function is decorated). For a function defined in a file of this
package it keeps numba's cache directory (NUMBA_CACHE_DIR, else `__pycache__`, else the user-wide
one) but stamps the cache with `source_stamp()`, one SHA-256 over the path and content of every
file that holds or feeds compiled code (`COMPILED_SOURCES`): any edit to any of them makes every
cached kernel of the package stale, and the next process recompiles them (about a minute on a
cold machine). Functions defined elsewhere keep numba's behaviour.

The locator must be in place before the package's first cached function is decorated:
`mount_twin.kinds` imports this module before its kind modules, and `physics.dynamics` imports
`mount_twin.kinds` first. `install` also re-keys any package function decorated before it ran,
so the import order cannot leave one on numba's own stamp. numba's NUMBA_CACHE_LOCATOR_CLASSES
override bypasses the locator list: do not set it for this package.
"""

from __future__ import annotations

import hashlib
import os
import sys
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

from numba import njit
from numba.core import caching
from numba.core.dispatcher import Dispatcher

F = TypeVar("F", bound=Callable[..., object])

PACKAGE_DIR = Path(__file__).resolve().parent.parent
"""The mount_twin package directory."""
COMPILED_SOURCES = (
    "physics",
    "kinds",
    "integrate",
    "model",
    "engine/kernel.py",
    "engine/companion.py",
    "engine/estimate.py",
    "engine/gyro_filter.py",
)
"""Package-relative directories (their *.py files) and files that define compiled functions or
constants that compiled code reads: their content is the cache stamp. A new file of compiled
code outside these must be added here (test/test_compiled_cache.py checks it)."""


def kernel(fn: F) -> F:
    """Compile `fn` as a cached, NRT-free nopython kernel."""
    return njit(cache=True, _nrt=False)(fn)  # type: ignore[call-overload, no-any-return]


def compiled_source_files(root: Path = PACKAGE_DIR) -> list[Path]:
    """The files of `COMPILED_SOURCES` under the package directory `root`, sorted."""
    files: set[Path] = set()
    for entry in COMPILED_SOURCES:
        path = root / entry
        files.update(path.glob("*.py") if path.is_dir() else [path])
    return sorted(files)


@cache
def source_stamp(root: Path = PACKAGE_DIR) -> str:
    """SHA-256 (hex) over the relative path and bytes of every compiled source file: the stamp
    of every cached function of the package (hashed once per process, ~1 ms)."""
    digest = hashlib.sha256()
    for path in compiled_source_files(root):
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
        digest.update(b"\0")
    return digest.hexdigest()


def _in_package(py_file: str) -> bool:
    try:
        return Path(py_file).resolve().is_relative_to(PACKAGE_DIR)
    except (OSError, ValueError):
        return False


def _numba_class(*names: str) -> Any:
    """A class of numba.core.caching by its current name or an older one (numba < 0.59 used
    leading underscores)."""
    for name in names:
        cls = getattr(caching, name, None)
        if cls is not None:
            return cls
    msg = f"numba.core.caching has none of {names}: update mount_twin.physics.compiled"
    raise ImportError(msg)


_CACHE_IMPL = _numba_class("CacheImpl", "_CacheImpl")
_NUMBA_LOCATORS = tuple(
    _numba_class(name, f"_{name}")
    for name in ("UserProvidedCacheLocator", "InTreeCacheLocator", "UserWideCacheLocator")
)
"""numba's file-backed locators, in its order of preference; the package locators extend each."""


class PackageStampedLocator:
    """Mixin for numba's file-backed locators: for a function defined in this package, numba's
    own choice of cache directory, stamped with `source_stamp()` instead of the function's file
    alone; for any other function, None (numba's own locators then decide)."""

    @classmethod
    def from_function(cls, py_func: Callable[..., object], py_file: str) -> Any:
        """numba's hook: a locator for `py_func` defined in `py_file`, or None."""
        if not _in_package(py_file):
            return None
        return super().from_function(py_func, py_file)  # type: ignore[misc]

    def get_source_stamp(self) -> str:
        """numba's hook: the stamp written into, and required of, the cache index."""
        return source_stamp()


_USER_PROVIDED, _IN_TREE, _USER_WIDE = _NUMBA_LOCATORS


class PackageUserProvidedLocator(PackageStampedLocator, _USER_PROVIDED):  # type: ignore[misc, valid-type]
    """In NUMBA_CACHE_DIR, when set."""


class PackageInTreeLocator(PackageStampedLocator, _IN_TREE):  # type: ignore[misc, valid-type]
    """In the `__pycache__` next to the source file."""


class PackageUserWideLocator(PackageStampedLocator, _USER_WIDE):  # type: ignore[misc, valid-type]
    """In the user-wide cache directory, when `__pycache__` is not writable."""


_LOCATORS = (PackageUserProvidedLocator, PackageInTreeLocator, PackageUserWideLocator)


def _uses_package_stamp(dispatcher: Dispatcher) -> bool:
    impl = getattr(getattr(dispatcher, "_cache", None), "_impl", None)
    return impl is None or isinstance(impl.locator, PackageStampedLocator)


def install() -> None:
    """Put the package locators first in numba's list (idempotent), and re-key the cache of any
    package function decorated before (none, in the package's own import order)."""
    classes = _CACHE_IMPL._locator_classes
    classes[:] = [*_LOCATORS, *(c for c in classes if c not in _LOCATORS)]
    for name, module in list(sys.modules.items()):
        if name != "mount_twin" and not name.startswith("mount_twin."):
            continue
        for value in list(vars(module).values()):
            if isinstance(value, Dispatcher) and not _uses_package_stamp(value):
                value.enable_caching()


def package_dispatchers() -> list[tuple[str, Dispatcher]]:
    """(module.name, dispatcher) of every compiled function in the imported package modules."""
    found: list[tuple[str, Dispatcher]] = []
    for name, module in sorted(sys.modules.items()):
        if name == "mount_twin" or name.startswith("mount_twin."):
            found.extend(
                (f"{name}.{attr}", value)
                for attr, value in vars(module).items()
                if isinstance(value, Dispatcher) and value.py_func.__module__ == name
            )
    return found


def kernel_cache_is_cold() -> bool:
    """True if numba has no compiled kernel of mount_twin cached for this Python: building a
    TwinEngine will then compile them (20–60 s) rather than load them (< 1 s).

    Cheap (a few directory listings): looks for numba's index files,
    `<module>.<function>-<line>.py<XY>.nbi`, where the locators above keep them for each
    subpackage: under $NUMBA_CACHE_DIR if set, else in its __pycache__, or in numba's
    user-wide cache where that is not writable. An index of stale sources counts as warm here:
    `replay.kernels_loading` then notices the slow load instead.
    """
    pattern = f"*.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    package = str(PACKAGE_DIR)
    user_dir = os.environ.get("NUMBA_CACHE_DIR")
    user_wide = os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "numba"
    )
    for entry in os.scandir(package):
        if not entry.is_dir() or entry.name == "__pycache__":
            continue
        # numba's get_suitable_cache_subpath: <dir name>_<sha1 of the directory's path>
        keyed = f"{entry.name}_{hashlib.sha1(entry.path.encode()).hexdigest()}"
        dirs = (
            [Path(user_dir, keyed)]
            if user_dir
            else [Path(entry.path, "__pycache__"), Path(user_wide, keyed)]
        )
        if any(next(d.glob(pattern), None) is not None for d in dirs):
            return False
    return True


install()
