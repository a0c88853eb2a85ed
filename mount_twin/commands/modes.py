"""`mount-twin modes SCENE`: natural frequencies and mode shapes of the body on its mounts."""

from __future__ import annotations

import argparse

NAME = "modes"
HELP = "natural frequencies, mode shapes, damping, energy and effective masses of a scene"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML")
    parser.add_argument("--json", action="store_true", help="print one JSON document instead")
    parser.add_argument(
        "--no-geometric",
        action="store_true",
        help="linearise about the unstressed reference pose without gravity (no geometric "
        "stiffness of the weight's preload)",
    )


def run(args: argparse.Namespace) -> int:
    import dataclasses
    import json

    from mount_twin.analysis.modes import modes
    from mount_twin.scene.loader import load_scene_file

    scene = load_scene_file(args.scene)
    result = modes(scene, geometric=not args.no_geometric)
    if args.json:
        doc = {
            "scene": scene.name,
            "geometric_stiffness": not args.no_geometric,
            "dofs": list(result.dofs),
            "modes": [dataclasses.asdict(m) for m in result.modes],
            "mounts": [dataclasses.asdict(m) for m in result.mounts],
            "cg_m": list(result.cg_m),
            "elastic_centre_m": None
            if result.elastic_centre_m is None
            else list(result.elastic_centre_m),
        }
        print(json.dumps(doc, indent=2))
        return 0
    kind = "with" if not args.no_geometric else "without"
    print(
        f"{scene.name}: {scene.body.mass:g} kg, DOFs {', '.join(result.dofs)}; stiffness {kind} "
        "the weight's geometric stiffness"
    )
    dofs = list(result.dofs)
    print(
        f"{'mode':>4} {'f Hz':>8} {'ζ %':>6}  kinetic energy % by DOF"
        + " " * 12
        + "effective mass kg (x y z)"
    )
    for i, m in enumerate(result.modes, 1):
        energy = " ".join(f"{d}:{100 * m.energy_fraction[d]:5.1f}" for d in dofs)
        masses = " ".join(f"{m.effective_mass_kg.get(a, 0.0):8.1f}" for a in "xyz")
        print(f"{i:>4} {m.frequency_hz:>8.3f} {100 * m.damping_ratio:>6.2f}  {energy}  {masses}")
    print("static mount loads (mount axes): force N, deflection mm")
    for ml in result.mounts:
        f = " ".join(f"{v:9.1f}" for v in ml.force_n)
        d = " ".join(f"{1e3 * v:7.3f}" for v in ml.deflection_m)
        print(f"  {ml.name:>10}: {f}   {d}")
    if result.elastic_centre_m is not None:
        e = result.elastic_centre_m
        off = [a - b for a, b in zip(e, result.cg_m, strict=True)]
        print(
            f"elastic centre {[round(v, 4) for v in e]} m in F; CG {list(result.cg_m)} m; "
            f"offset {[round(v, 4) for v in off]} m"
        )
    return 0
