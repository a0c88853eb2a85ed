"""Calls that compile to nothing when a scene lacks what they work on.

numba types None as its own type, so an overload can pick a no-op for it at compile time: the
kernels of a scene without, say, non-linear mounts then carry no trace of their code. (Merely
present and never run, that code slowed the linear right-hand side by ~40 % while the kernels
still used numba's runtime.)
"""

from __future__ import annotations

from collections.abc import Callable

from numba import types
from numba.extending import overload


def skip_if_none(impl: Callable[..., None]) -> Callable[..., None]:
    """A function for compiled code: impl(*args), or nothing when args[1] is None."""

    def gate(*args: object) -> None:
        msg = f"{impl.__name__}: callable from compiled code only"
        raise TypeError(msg)

    @overload(gate, jit_options={"cache": True})  # type: ignore[typeddict-unknown-key]
    def _typed(*args):
        if isinstance(args[1], types.NoneType):
            return lambda *args: None
        return lambda *args: impl(*args)  # noqa: PLW0108 (numba compiles this lambda)

    return gate
