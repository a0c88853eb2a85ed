"""Optional dependencies: a command that needs one says which extra installs it."""

from __future__ import annotations

from importlib.util import find_spec

from mount_twin.errors import MountTwinError

EXTRAS = {"matplotlib": "plot", "dask": "sweep", "pyarrow": "parquet"}
"""Top-level module → the pip extra of mount_twin that installs it (pyarrow: `pip install
pyarrow`, no extra)."""


def require(module: str, what: str) -> None:
    """Raise a one-line error naming `what` needs `module` and how to install it."""
    top = module.partition(".")[0]
    if find_spec(top) is None:
        extra = EXTRAS.get(top, top)
        how = "pip install pyarrow" if top == "pyarrow" else f"pip install 'mount_twin[{extra}]'"
        msg = f"{what} needs {top}, which is not installed: {how}"
        raise MountTwinError(msg)
