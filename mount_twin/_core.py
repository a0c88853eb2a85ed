"""The compiled core (src/core, C++17: the extension `mount_twin._core_ext` that setup.py
builds), checked at import against the sources beside it (`core_sources.check_fresh`).

Everything the extension defines is re-exported here; `_core_ext.pyi` types it.
"""

from __future__ import annotations

from mount_twin._core_ext import *  # noqa: F403
from mount_twin._core_ext import SOURCE_SHA256
from mount_twin.core_sources import check_fresh

check_fresh(SOURCE_SHA256)
