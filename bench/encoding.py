"""Time the JSON encoding of step records: stdlib json vs orjson vs msgspec.

    PYTHONPATH=src python bench/encoding.py [STEPS]   (default: 20000)

The records are real: a random walk of STEPS steps in the ``three-joint`` scenario (three
links, two obstacles), one :class:`~rsstp_format.records.StepRecord` per step (about
510 bytes of JSON), built as a recorder would. Every figure is the best of five passes over
all records, in microseconds per record:

- ``a ready dict -> bytes``: the serialiser alone, on ``record.to_json()`` output;
- ``record -> bytes``: from the record, a msgspec struct (json needs ``to_json()`` first,
  itself msgspec-based; orjson a ``default`` hook that turns each struct into a dict);
- ``bytes -> record``: back to an equal record, with the field checks of ``from_json``
  (msgspec checks them while decoding into the structs);
- ``pose -> record``: ``step_record`` from a world pose and a step outcome.

On the 2-core development machine (2026-11-25, schema 2.0 records of 565 bytes, Python 3.11.7,
orjson 3.13.0, msgspec 0.22.0, the machine loaded by other work)::

    a ready dict -> bytes: json.dumps                 14.28 us/record
    a ready dict -> bytes: orjson.dumps                1.00 us/record
    a ready dict -> bytes: msgspec                     1.21 us/record
    record -> bytes: json.dumps(to_json())            18.10 us/record
    record -> bytes: orjson.dumps(record, default)     1.68 us/record
    record -> bytes: msgspec (= encode)                1.04 us/record
    bytes -> record: json.loads + from_json            9.82 us/record
    bytes -> record: orjson.loads + from_json          3.88 us/record
    bytes -> record: msgspec typed (= decode)          1.89 us/record
    pose -> record: step_record                        3.71 us/record

So ``records.encode`` and ``records.decode`` use msgspec. All three write shortest
round-trip floats; orjson and msgspec differ only in positive exponents (``1e+16`` against
``1e16``), which never occur in these records at realistic scales.
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import msgspec
import orjson

from rsstp_format.records import StepRecord, decode, encode
from rsstp_sim.arm.world import Pose
from rsstp_sim.recording.builders import step_record
from rsstp_sim.runner import Runner, StepOutcome
from rsstp_sim.scenario import load_scenario
from rsstp_sim.strategies import RandomStrategy

REPEATS = 5


def step_records(steps: int) -> list[StepRecord]:
    """The step records of a seeded random walk in ``three-joint`` (step 0 included)."""
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=1)
    pose = runner.world.current
    records = [
        step_record(
            0,
            pose,
            action=None,
            state_before=None,
            internal_state=runner.model.current,
            model_version=runner.model.version,
            no_transition=False,
            blocker=None,
        )
    ]
    for _ in range(steps):
        out = runner.step()
        records.append(build((out, runner.world.current, runner.model.version)))
    return records


def build(item: tuple[StepOutcome, Pose, int]) -> StepRecord:
    """``step_record`` of a step: its outcome, the pose it ended in, the model's version."""
    out, pose, version = item
    return step_record(
        out.step,
        pose,
        action=out.action,
        state_before=out.state_before,
        internal_state=out.state_after,
        model_version=version,
        no_transition=out.no_transition,
        blocker=out.blocker,
    )


def best_us(function: Callable[[Any], object], items: Sequence[Any]) -> float:
    """Best-of-REPEATS microseconds per item of ``function`` over ``items``."""
    best = float("inf")
    for _ in range(REPEATS):
        start = time.perf_counter()
        for item in items:
            function(item)
        best = min(best, time.perf_counter() - start)
    return best / len(items) * 1e6


def build_us(steps: int) -> float:
    """Microseconds per step for ``step_record`` on the walk's outcomes and poses."""
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=1)
    walk = []
    for _ in range(steps):
        out = runner.step()
        walk.append((out, runner.world.current, runner.model.version))
    return best_us(build, walk)


def main(argv: list[str]) -> None:
    steps = int(argv[0]) if argv else 20_000
    records = step_records(steps)
    dicts = [record.to_json() for record in records]
    payloads = [orjson.dumps(d) for d in dicts]
    size = sum(map(len, payloads)) / len(payloads)
    assert all(encode(r) == p for r, p in zip(records, payloads, strict=True))
    assert all(msgspec.json.encode(r) == p for r, p in zip(records, payloads, strict=True))
    assert all(json.loads(json.dumps(d, separators=(",", ":"))) == d for d in dicts[:1000])
    msgspec_encoder = msgspec.json.Encoder()
    typed_decoder = msgspec.json.Decoder(StepRecord)
    assert all(typed_decoder.decode(p) == r for r, p in zip(records, payloads, strict=True))

    def stdlib_dumps_dict(data: dict[str, Any]) -> bytes:
        return json.dumps(data, separators=(",", ":")).encode()

    def stdlib_dumps(record: StepRecord) -> bytes:
        return json.dumps(record.to_json(), separators=(",", ":")).encode()

    def stdlib_loads(payload: bytes) -> StepRecord:
        return StepRecord.from_json(json.loads(payload))

    def orjson_dumps(record: StepRecord) -> bytes:  # orjson does not know msgspec structs
        return orjson.dumps(record, default=msgspec.structs.asdict)

    def orjson_loads(payload: bytes) -> StepRecord:
        return StepRecord.from_json(orjson.loads(payload))

    def msgspec_decode(payload: bytes) -> object:
        return decode("rsstp.Step", payload)

    rows: list[tuple[str, float]] = [
        ("a ready dict -> bytes: json.dumps", best_us(stdlib_dumps_dict, dicts)),
        ("a ready dict -> bytes: orjson.dumps", best_us(orjson.dumps, dicts)),
        ("a ready dict -> bytes: msgspec", best_us(msgspec_encoder.encode, dicts)),
        ("record -> bytes: json.dumps(to_json())", best_us(stdlib_dumps, records)),
        ("record -> bytes: orjson.dumps(record, default)", best_us(orjson_dumps, records)),
        ("record -> bytes: msgspec (= encode)", best_us(encode, records)),
        ("bytes -> record: json.loads + from_json", best_us(stdlib_loads, payloads)),
        ("bytes -> record: orjson.loads + from_json", best_us(orjson_loads, payloads)),
        ("bytes -> record: msgspec typed (= decode)", best_us(msgspec_decode, payloads)),
        ("pose -> record: step_record", build_us(steps)),
    ]
    print(f"{len(records)} step records of three-joint, {size:.0f} bytes each on average")
    print(
        f"(orjson {orjson.__version__}, msgspec {msgspec.__version__}, "
        f"python {sys.version.split()[0]})"
    )
    for label, micros in rows:
        print(f"  {label:<48} {micros:7.2f} us/record")


if __name__ == "__main__":
    main(sys.argv[1:])
