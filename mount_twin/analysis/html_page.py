"""The pieces of a self-contained HTML page (`report`, `qualify --report`): inline PNGs,
tables, provenance (software, date, file digests) and the scene as loaded."""

from __future__ import annotations

import base64
import hashlib
import html
import io
from collections.abc import Callable
from datetime import datetime, timezone
from importlib.metadata import version as package_version
from pathlib import Path
from typing import Any

from mount_twin.model.scene_file import INPUT_OPTIONS
from mount_twin.scene.description import Scene
from mount_twin.scene.params import effective_parameters, parameter_description


def png(draw: Callable[[Any], None], size: tuple[float, float]) -> str:
    """A figure drawn by `draw(fig)`, as an <img> with the PNG inline."""
    from mount_twin.figure_files import pyplot

    plt = pyplot()
    fig = plt.figure(figsize=size)
    draw(fig)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return (
        f'<img alt="plot" src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">'
    )


def table(head: list[str], rows: list[list[str]]) -> str:
    """An HTML table of text cells (escaped) under a header row."""
    cells = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(v)}</td>" for v in r) + "</tr>" for r in rows
    )
    return f"<table><tr>{cells}</tr>{body}</table>"


def fingerprint(path: Path) -> str:
    """`sha256 <hex>` of a file as `sha256sum` prints it, or of each file of a directory (a
    bag's), by its path inside, in name order."""
    files = sorted(f for f in path.rglob("*") if f.is_file()) if path.is_dir() else [path]
    sums = []
    for f in files:
        with f.open("rb") as fh:  # in blocks: a bag may be larger than memory
            hexdigest = hashlib.file_digest(fh, "sha256").hexdigest()
        sums.append(hexdigest if f is path else f"{f.relative_to(path)} {hexdigest}")
    return "sha256 " + ", ".join(sums)


def page(title: str, sections: list[str]) -> str:
    """The HTML document of `sections`, styled inline."""
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>"
        "body{font-family:sans-serif;margin:2em;max-width:1100px}"
        "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:3px 8px;"
        "text-align:right}img{max-width:100%}</style></head><body>"
        + "\n".join(sections)
        + "</body></html>"
    )


def produced_by() -> str:
    """The software and the time (UTC) that produced a page."""
    now = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return f"mount_twin {package_version('mount_twin')}, {now}"


def _file_parameters(scene: Scene) -> dict[str, Any]:
    """Every parameter of the file `scene` was read from, with its value there (none for a
    scene not read from a file)."""
    if not Path(scene.source).is_file():
        return {}
    return dict(effective_parameters({"scene_file": scene.source}, "report").values)


def _replaced(scene: Scene, in_file: dict[str, Any]) -> dict[str, tuple[str, str]]:
    """Of `scene`'s input settings, those whose value differs from the file's (`in_file`), each
    with the option that replaced it (`replay --topic`, `--frame-id`) and the run's value
    (`report` gives the scene those its run read and expected, as its output bag recorded)."""
    ran = {"input.topic": scene.input.topic, "input.frame_id": scene.input.frame_id}
    return {
        key: (option, ran[key])
        for key, option in INPUT_OPTIONS.items()
        if in_file.get(key, ran[key]) != ran[key]
    }


def frame_id_setting(scene: Scene | None, expected: str | None = None) -> str:
    """What set the header.frame_id the run of `scene` expected, for a message to point at:
    `replay --frame-id` where it replaced the file's, else the scene's input.frame_id. Without
    the scene no one can tell which: the output bag's input status records the frame the run
    expected (`expected`; None in a bag written before it was recorded), not what set it. Then
    both, and the frame expected where the bag has it."""
    key = "input.frame_id"
    if scene is None:
        from mount_twin.scene.reader import shown  # a 1 MB frame id, shortened

        frame = "the one" if expected is None else f"the {shown(expected)}"
        return f"the scene's {key} or {INPUT_OPTIONS[key]}, whichever set {frame} the run expected"
    replaced = _replaced(scene, _file_parameters(scene))
    return replaced[key][0] if key in replaced else key


def scene_section(scene: Scene) -> list[str]:
    """The scene as loaded: every parameter with its value, meaning and unit (none for a scene
    not read from a file)."""
    effective = _file_parameters(scene)
    if not effective:
        return []
    for key, (option, ran) in _replaced(scene, effective).items():
        effective[key] = (
            f"{ran or 'any'} (the run's, from `{option}`; the file's: {effective[key] or 'any'})"
        )
    return [
        "<h2>Scene as loaded</h2>",
        table(
            ["parameter", "value", "meaning, unit"],
            [
                [name, str(value), parameter_description(name, effective)]
                for name, value in effective.items()
                if name != "scene_file"
            ],
        ),
    ]
