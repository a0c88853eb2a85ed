"""`mount-twin modes SCENE`: natural frequencies and mode shapes of the body on its mounts."""

from __future__ import annotations

import argparse
import dataclasses
from typing import TYPE_CHECKING, Any

from mount_twin.analysis.modes_text import (
    damping_text,
    effective_mass_text,
    energy_share_text,
    fixed,
    frequency_text,
)

if TYPE_CHECKING:
    from mount_twin.analysis.modes import Line, Modes
    from mount_twin.scene.description import Scene

NAME = "modes"
HELP = (
    "natural frequencies, mode shapes, modal damping, energy shares, effective masses, static "
    "mount loads and the stiffness centre of a scene, about its static equilibrium"
)
UNITS = {
    "shape": "mass-normalised (φᵀMφ = 1): m or rad per √kg of modal mass",
    "shape_in_f": "the same motion in F: CG translation x, y, z (m), rotation rot_x, rot_y, "
    "rot_z about the axes of F (rad), per √kg",
    "matrices": "SI in the generalized coordinates `dofs` (m, rad): kg, kg·m², N/m, N/rad, "
    "N·m/rad, N·s/m, N·m·s/rad",
    "positions": "m, in F at the reference pose",
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument("--json", action="store_true", help="print one JSON document instead")
    parser.add_argument(
        "--no-geometric",
        action="store_true",
        help="leave out the geometric stiffness of the weight's preload (elastic stiffness "
        "of the mounts only, still about the sagged static equilibrium: the textbook answer "
        "without gravity, about the reference pose, needs input.g: 0 in the scene)",
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.analysis.modes import modes
    from mount_twin.commands.common import json_text, load_scene

    scene = load_scene(args.scene)
    result = modes(scene, geometric=not args.no_geometric)
    print(json_text(document(scene, result), indent=2) if args.json else table(scene, result))
    return 0


def document(scene: Scene, result: Modes) -> dict[str, Any]:
    """The analysis as one JSON-ready mapping; units in the key names or under "units"."""
    centre = result.centre
    return {
        "scene": scene.name,
        "source": scene.source,
        "gravity_m_s2": scene.input.g,
        "geometric_stiffness": result.geometric,
        "dofs": list(result.dofs),
        "units": UNITS,
        "modes": [{**dataclasses.asdict(m), "dominant_dof": m.dominant_dof} for m in result.modes],
        "complex_modes": [dataclasses.asdict(m) for m in result.complex_modes],
        "mounts": [dataclasses.asdict(m) for m in result.mounts],
        "cg_m": list(result.cg_m),
        "stiffness_centre": {
            "force_lines_m": {a: list(v) for a, v in centre.force_lines_m.items()},
            "elastic_centre_m": None if centre.point_m is None else list(centre.point_m),
            "residual_m": centre.residual_m,
        },
        "stiffness_asymmetry": result.stiffness_asymmetry,
        "matrices": {
            "mass": result.mass_matrix.tolist(),
            "stiffness": result.stiffness.tolist(),
            "geometric_stiffness": result.geometric_stiffness.tolist(),
            "damping": result.damping.tolist(),
        },
    }


def table(scene: Scene, result: Modes) -> str:
    """The analysis as text tables."""
    dofs = result.dofs
    kind = "with" if result.geometric else "without"
    lines = [
        f"{scene.name} ({scene.source}): {scene.body.mass:g} kg on {len(scene.mounts)} mounts, "
        f"DOFs {' '.join(dofs)}",
        f"about the static equilibrium under g = {scene.input.g:g} m/s², stiffness {kind} the "
        "weight's geometric stiffness",
        "",
        f"{'mode':>4} {'f Hz':>9} {'ζ %':>6}  {'dominant':<13} kinetic energy % by DOF",
        " " * 35 + "".join(f"{d:>7}" for d in dofs),
    ]
    for i, m in enumerate(result.modes, 1):
        main = m.dominant_dof
        lines.append(
            f"{i:>4} {frequency_text(m.frequency_hz):>9} {damping_text(m.damping_ratio):>6}  "
            f"{main:<6}{energy_share_text(m.energy_fraction[main]):>4} %  "
            + "".join(f"{energy_share_text(m.energy_fraction[d], 1):>7}" for d in dofs)
        )
    unstable = [str(i) for i, m in enumerate(result.modes, 1) if m.frequency_hz < 0.0]
    if unstable:
        lines.append(
            f"modes {', '.join(unstable)}: negative ω² (−√|ω²|/2π shown): the static "
            "equilibrium is unstable (the weight's geometric stiffness exceeds the mounts')"
        )
    exact = ", ".join(
        f"{frequency_text(c.frequency_hz)} ({damping_text(c.damping_ratio)})"
        for c in result.complex_modes
    )
    lines += [
        "ζ: proportional-damping approximation φᵀCφ/2ω; the damped linearisation's eigenvalues",
        f"give f Hz (ζ %): {exact}",
        *_masses(result),
        *_mounts(result),
        *_centre(result),
    ]
    return "\n".join(lines)


def _masses(result: Modes) -> list[str]:
    head = "".join(f"{a:>10}" for a in "xyz")
    lines = [
        "",
        f"{'mode':>4} {'f Hz':>9}  effective mass kg along, inertia kg·m² about the axes of F "
        "through the CG",
        f"{'':>4} {'':>9}  {head}  {head}",
    ]
    for i, m in enumerate(result.modes, 1):
        masses = "".join(f"{effective_mass_text(m.effective_mass_kg[a]):>10}" for a in "xyz")
        inertias = "".join(f"{fixed(m.effective_inertia_kg_m2[a], 2):>10}" for a in "xyz")
        lines.append(f"{i:>4} {frequency_text(m.frequency_hz):>9}  {masses}  {inertias}")
    sums = "".join(
        f"{effective_mass_text(sum(m.effective_mass_kg[a] for m in result.modes)):>10}"
        for a in "xyz"
    )
    sums_i = "".join(
        f"{fixed(sum(m.effective_inertia_kg_m2[a] for m in result.modes), 2):>10}" for a in "xyz"
    )
    lines.append(f"{'sum':>4} {'':>9}  {sums}  {sums_i}")
    return lines


def _mounts(result: Modes) -> list[str]:
    width = max(len("mount"), *(len(ml.name) for ml in result.mounts))
    lines = [
        "",
        "static mount loads at the equilibrium, in each mount's axes: force on the body N, "
        "deflection mm",
        f"{'mount':<{width}}  {'kind':<13}"
        + "".join(f"{h:>10}" for h in ("Fx", "Fy", "Fz"))
        + "".join(f"{h:>9}" for h in ("dx", "dy", "dz")),
    ]
    for ml in result.mounts:
        forces = "".join(f"{fixed(v, 1):>10}" for v in ml.force_n)
        travel = "".join(f"{fixed(1e3 * v, 4):>9}" for v in ml.deflection_m)
        lines.append(f"{ml.name:<{width}}  {ml.kind:<13}{forces}{travel}")
    total = [sum(ml.force_in_f_n[k] for ml in result.mounts) for k in range(3)]
    carried = (
        "the weight, up"
        if "z" in result.dofs
        else "z is frozen: its constraint holds the weight, less what the mounts carry"
    )
    lines.append(f"sum of the forces in F: {', '.join(fixed(v, 1) for v in total)} N ({carried})")
    return lines


def _centre(result: Modes) -> list[str]:
    centre = result.centre
    names = {
        "x": "fore-aft force line (a force along x there: no pitch, no yaw)",
        "y": "lateral force line (a force along y there: no roll, no yaw)",
        "z": "vertical stiffness centre (a vertical load there: no tilt)",
    }
    rows: list[tuple[str, Line]] = [("CG", result.cg_m)]
    rows += [(names[a], line) for a, line in centre.force_lines_m.items()]
    if centre.point_m is not None:
        rows.append(
            (f"elastic centre (least squares, residual {centre.residual_m:.3g} m)", centre.point_m)
        )
    if len(rows) == 1:
        return []
    lines = [
        "",
        "stiffness centre of the elastic stiffness, m in F at the reference pose"
        + "".join(f"{a:>9}" for a in "xyz"),
    ]
    lines += [
        f"  {label:<69}" + "".join(f"{'-' if v is None else fixed(v, 3):>9}" for v in at)
        for label, at in rows
    ]
    return lines
