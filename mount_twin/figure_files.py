"""Figures drawn headless and written as PNG files: one way for every command that draws.

matplotlib is imported on first use only (a command that draws nothing never pays its import),
on the Agg backend (no display needed); a figure's file is written whole or not at all
(`textfiles.replacing`: a full disk fails naming the file and leaves no part of it)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mount_twin.textfiles import replacing


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig: Any, png: str | Path, dpi: int = 110) -> Path:
    """Lay `fig` out, write it as the PNG `png` (dots per inch `dpi`) whole or not at all, and
    close it; the path written."""
    fig.tight_layout()
    out = Path(png)
    try:
        with replacing(out) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        pyplot().close(fig)
    return out
