"""The figures of a modal analysis as text: one rule for `mount-twin modes` and the modes table
of `report`, so that the two say the same of the same mode (its frequency, its effective masses).

Fixed decimals, not significant figures: an effective mass that is zero by symmetry (a fore-aft
mass in a lateral mode of a machine symmetric about its x-z plane) comes out of the
eigenvectors' round-off as 1e-25 kg, which significant figures show as a mass; to 0.1 kg it
reads 0.0. No numerics are imported here: the command line's modules import it at start.
"""

from __future__ import annotations


def fixed(value: float, decimals: int) -> str:
    """`value` with `decimals` decimals, without a sign on a rounded zero (−0.0)."""
    return f"{round(value, decimals) + 0.0:.{decimals}f}"


def effective_mass_text(kg: float) -> str:
    """An effective modal mass (kg), or a sum of them, to 0.1 kg."""
    return fixed(kg, 1)


def frequency_text(hz: float) -> str:
    """A mode's frequency (Hz; negative for an unstable mode, −√|ω²|/2π), to 1 mHz."""
    return fixed(hz, 3)
