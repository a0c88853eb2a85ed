"""A bag's input record for analyses: every sample of the scene's input topic, decoded."""

from __future__ import annotations

from pathlib import Path

from mount_twin.engine.batch import SampleBatch
from mount_twin.errors import BagError, DamagedBagError
from mount_twin.io.bag import InputBag
from mount_twin.io.messages import Decoded, TimeBase, decode_inputs
from mount_twin.scene.description import InputSpec


def read_input(bag: str | Path, spec: InputSpec, keys: tuple[str, str] | None = None) -> Decoded:
    """The decodable samples of the input topic `spec.topic` in `bag` with a positive stamp
    (sensor frame, as recorded); an error names the bag if there is none. `keys`: what sets
    the topic and the type, for errors (`InputBag`'s; default: the scene's input). A bag
    damaged part-way is a BagError (exit 2), not the DamagedBagError of a replay that ran up
    to the damage (exit 5): what reads the record whole analyses none of it."""
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


def read_samples(bag: str | Path, spec: InputSpec) -> SampleBatch:
    """`read_input` as engine samples, stamps (s) counted from the first one's whole second."""
    decoded = read_input(bag, spec)
    return decoded.batch(TimeBase.at(int(decoded.stamps_ns[0])))
