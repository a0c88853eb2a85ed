"""Replays of one bag in chunks of different sizes write the same output bag.

    python3 bench/chunk_invariance.py SCENE BAG [--chunks 1 7 1000 100000]

Each chunk size is a different batching of the input into the engine (a live node's batches
are whatever its executor delivers). Every message of every topic must be byte-equal to the
largest chunk's; diagnostics are compared decoded, less the real-time factor (wall time), as
test/test_batching_invariance.py compares the bundled bags. Prints one line per chunk size
with the replay's verdict; exits 1 if any bag differs.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))
from io_helpers import comparable_messages

from mount_twin.replay import replay
from mount_twin.scene import load_scene_file


def main() -> int:
    """Replay per chunk size, compare with the largest; 1 if any differs."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("bag")
    parser.add_argument("--chunks", type=int, nargs="+", default=[1, 7, 1000, 100_000])
    args = parser.parse_args()
    scene = load_scene_file(args.scene)
    chunks = sorted(set(args.chunks), reverse=True)
    differ = 0
    with tempfile.TemporaryDirectory() as tmp:
        reference: dict[str, list[tuple[int, object]]] = {}
        for chunk in chunks:
            out = Path(tmp) / f"chunk_{chunk}"
            summary = replay(scene, args.bag, out, chunk=chunk, progress=False)
            got = comparable_messages(out)
            reference = reference or got
            bad = sorted(
                t for t in reference.keys() | got.keys() if reference.get(t) != got.get(t)
            )
            differ += bool(bad)
            said = f"DIFFERS on {len(bad)} topics, e.g. {bad[:3]}" if bad else "equal"
            print(
                f"chunk {chunk:>7}: {sum(map(len, got.values())):8d} messages, verdict "
                f"{summary.verdict:<6} {'(the reference)' if got is reference else said}",
                flush=True,
            )
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
