"""The figures of a modal analysis as text: one rule for `mount-twin modes` and the modes table
of `report`, so that the two say the same of the same mode (its frequency, its damping ratio, its
dominant DOF's energy share, its effective masses).

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


def damping_text(ratio: float) -> str:
    """A modal damping ratio ζ (a fraction; NaN for a mode without a frequency) as a percentage,
    to 0.01 %. An undamped mode's φᵀCφ comes out of round-off of either sign: −1e-19 reads 0.00."""
    return fixed(100.0 * ratio, 2)


def energy_share_text(fraction: float, decimals: int = 0) -> str:
    """A DOF's share of a mode's kinetic energy (a fraction) as a percentage: to 1 % for the
    dominant DOF, to 0.1 % (`decimals` 1) in `modes`' table of every DOF's share."""
    return fixed(100.0 * fraction, decimals)
