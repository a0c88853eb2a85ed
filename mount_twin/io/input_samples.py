"""A bag's input record for analyses: every sample of the scene's input topic, decoded."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from mount_twin.engine.batch import SampleBatch
from mount_twin.engine.reading_screen import disregarded, provided
from mount_twin.errors import BagError, DamagedBagError
from mount_twin.io.input_bag import InputBag
from mount_twin.io.input_decoding import Decoded, TimeBase, decode_inputs
from mount_twin.scene.description import InputSpec


def read_input(bag: str | Path, spec: InputSpec, keys: tuple[str, str] | None = None) -> Decoded:
    """The decodable samples of the input topic `spec.topic` in `bag` with a positive stamp
    (sensor frame, as recorded); an error names the bag if there is none. `keys`: what sets
    the topic and the type, for errors (`InputBag`'s; default: the scene's input). A bag
    damaged part-way is a BagError (exit 2), not the DamagedBagError of a replay that ran up
    to the damage (exit 5): what reads the record whole analyses none of it. A reading its
    message marks not provided stays marked (`Decoded.unprovided`): an analysis refuses such a
    record (`refuse_unprovided`) or leaves those samples out as the twin does
    (`provided_input`)."""
    damaged = ""
    try:
        with InputBag(bag, spec.topic, spec.msg_type, *([keys] if keys else [])) as reader:
            raws = [raw for chunk in reader.chunks(10_000) for raw in chunk]
    except DamagedBagError as err:  # raised below, not within: no damage behind another error
        damaged = str(err)
    if damaged:
        msg = (
            f"{damaged}; {bag} is damaged part-way, and this analysis reads its record whole: "
            "none of it was analysed (`mount-twin replay` runs what comes before the damage)"
        )
        raise BagError(msg)
    decoded = decode_inputs(raws, spec.msg_type)
    decoded = decoded.select(decoded.stamps_ns > 0)
    if not len(decoded.stamps_ns):
        msg = f"{bag}: no decodable sample on {spec.topic}"
        raise ValueError(msg)
    return decoded


def _unprovided_text(decoded: Decoded, marked: np.ndarray) -> str:
    """'K of N samples mark a reading not provided (…)' of the samples `marked`, the first
    named by its place and stamp."""
    first = int(np.flatnonzero(marked)[0])
    assert decoded.unprovided is not None
    which = [
        f"{name} {int((marked & decoded.unprovided[:, i]).sum())}"
        for i, name in enumerate(("acceleration", "angular velocity"))
    ]
    return (
        f"{int(marked.sum())} of {marked.shape[0]} samples mark a reading not provided "
        f"(covariance[0] = -1, REP-145: {', '.join(which)}), the first its message {first} "
        f"(stamp {int(decoded.stamps_ns[first])} ns)"
    )


def refuse_unprovided(decoded: Decoded, where: str, reads_rate: bool, why: str) -> None:
    """Refuse a record in which a sample's message marks a reading the analysis reads (the
    acceleration; the angular velocity too if `reads_rate`) not provided (REP-145: to be
    disregarded, as the twin's intake disregards it): ValueError '<where> K of N samples mark
    a reading not provided (…), the first …: <why>'. An analysis that takes the samples as
    evenly spaced would join those around a skipped one, and one that takes them as values
    would read a placeholder."""
    marked = disregarded(decoded.unprovided, len(decoded.stamps_ns), reads_rate)
    if marked.any():
        raise ValueError(f"{where} {_unprovided_text(decoded, marked)}: {why}")


def provided_input(bag: str | Path, spec: InputSpec) -> tuple[Decoded, str]:
    """`read_input` without the samples the scene's twin disregards for a reading marked not
    provided (`reading_screen.disregarded`: the acceleration, or the rate unless input.gyro_filter:
    ignore; a rate it does not read is zeroed), and a note naming the bag and how many were
    dropped ('' if none): for an analysis that runs the twin on input it derives from the
    record (accuracy's reference holds each sample's value to the next), so that it runs on
    what the twin's replay takes. The twin's outputs are those of the whole record: it skips
    such a sample without leaving a hole."""
    decoded = read_input(bag, spec)
    marked = disregarded(decoded.unprovided, len(decoded.stamps_ns), spec.reads_rate)
    note = ""
    if marked.any():
        note = (
            f"{bag}: {spec.topic}: {_unprovided_text(decoded, marked)}: disregarded, as the "
            f"twin's replay disregards them; analysed: the other {int((~marked).sum())}"
        )
        decoded = decoded.select(~marked)
    if decoded.unprovided is not None:  # rates the twin does not read
        _, gyro = provided(decoded.accel, decoded.gyro, decoded.unprovided)
        decoded = dataclasses.replace(decoded, gyro=gyro, unprovided=None)
    if not len(decoded.stamps_ns):
        raise ValueError(note)
    return decoded, note


def read_samples(bag: str | Path, spec: InputSpec) -> SampleBatch:
    """`read_input` as engine samples, stamps (s) counted from the first one's whole second."""
    decoded = read_input(bag, spec)
    return decoded.batch(TimeBase.at(int(decoded.stamps_ns[0])))
