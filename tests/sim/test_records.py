"""The recording contract: the JSON Schemas, and the records that mirror them.

Round trips run over a corpus of real messages (every built-in scenario, a random walk,
a model changed by hand, events of every kind): object -> JSON -> schema-valid -> object
again (equal) -> the same bytes.
"""

from __future__ import annotations

import copy
import dataclasses
import doctest
import functools
import hashlib
import json
import re
import struct
import typing
from collections.abc import Iterator, Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import msgspec
import orjson
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from jsonschema import Draft202012Validator
from steps import step_record_after

import rsstp_sim
from rsstp_format import records, schemas
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.bodies import make_world
from rsstp_sim.recording import builders
from rsstp_sim.rover import RoverScenario
from rsstp_sim.runner import Event, Runner, StepOutcome
from rsstp_sim.scenario import builtin_scenarios, load_scenario
from rsstp_sim.strategies import RandomStrategy, strategy_origin
from rsstp_sim.transition_system import TransitionSystem

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "schemas"
STEPS = 300
HAND_EDIT_AT = 150


# ------------------------------------------------------------------ the schemas


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_schema_is_a_valid_draft_2020_12_schema(name: str) -> None:
    schema = schemas.schema_json(name)
    Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["title"] == name
    assert schema["version"] == schemas.SCHEMA_VERSION
    assert schema["additionalProperties"] is True
    # A change (schema 3.0) leaves the model's states and transitions out; a 2.x keyframe has
    # no keyframe field.
    optional = {"rsstp.Model": ["states", "transitions", "keyframe"]}.get(name, [])
    assert schema["required"] == [key for key in schema["properties"] if key not in optional]


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_packaged_schema_bytes_are_the_repository_files(name: str) -> None:
    on_disk = (SCHEMA_DIR / f"{name}.json").read_bytes()
    assert schemas.schema_bytes(name) == on_disk
    packaged = resources.files("rsstp_format").joinpath(f"schemas/{name}.json").read_bytes()
    assert packaged == on_disk


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_schema_files_are_formatted_deterministically(name: str) -> None:
    text = schemas.schema_bytes(name).decode("utf-8")
    assert text == json.dumps(json.loads(text), indent=2, ensure_ascii=False) + "\n"


def _object_schemas(schema: Mapping[str, Any], where: str) -> Iterator[tuple[str, Any]]:
    """Every (path, object schema with properties) inside ``schema``, itself included."""
    if "properties" in schema:
        yield where, schema
        for key, sub in schema["properties"].items():
            yield from _object_schemas(sub, f"{where}.{key}")
    if isinstance(schema.get("items"), Mapping):
        yield from _object_schemas(schema["items"], f"{where}[]")
    for i, branch in enumerate(schema.get("allOf", ())):
        yield from _object_schemas(branch["then"], f"{where}.allOf[{i}]")


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_every_property_has_a_description_and_objects_are_open(name: str) -> None:
    for where, schema in _object_schemas(schemas.schema_json(name), name):
        for key, sub in schema["properties"].items():
            assert sub.get("description"), f"{where}.{key} has no description"
        if "type" in schema:  # the allOf branches only add requirements
            assert schema.get("additionalProperties") is True, where
            required = schema.get("required", [])
            assert required == [k for k in schema["properties"] if k in required], where


def test_topics_schemas_and_record_types_agree() -> None:
    assert schemas.TOPICS == schemas.BODY_TOPICS["arm"]
    named = {name for topics in schemas.BODY_TOPICS.values() for name in topics.values()}
    assert named == set(schemas.SCHEMA_NAMES) == set(records.RECORD_TYPES)
    for body, topics in schemas.BODY_TOPICS.items():
        assert list(topics) == ["/rsstp/scenario", "/rsstp/step", "/rsstp/model", "/rsstp/event"]
        for topic, name in topics.items():  # the body's own name before its message's
            prefix = "" if body == "arm" or topic in ("/rsstp/model", "/rsstp/event") else body
            assert name.lower() == "rsstp." + prefix + topic.removeprefix("/rsstp/")
    assert schemas.log_time_ns(7) == 7_000_000


def _is_record(hint: object) -> bool:
    return isinstance(hint, type) and issubclass(hint, msgspec.Struct)


def _mirror(cls: type, schema: Mapping[str, Any], where: str) -> None:
    """The record class's fields are the schema's properties, in order, recursively; the
    fields with a default (None: left out of the JSON) are the ones the schema does not
    require."""
    fields = msgspec.structs.fields(cls)
    names = [field.name for field in fields]
    assert names == list(schema["properties"]), where
    assert [f.name for f in fields if f.required] == schema["required"], where
    hints = typing.get_type_hints(cls)
    for name in names:
        hint, sub = hints[name], schema["properties"][name]
        inner = [a for a in typing.get_args(hint) if a is not type(None) and a is not Ellipsis]
        if _is_record(hint):
            _mirror(typing.cast(type, hint), sub, f"{where}.{name}")
        elif inner and _is_record(inner[0]):
            target = sub["items"] if typing.get_origin(hint) is tuple else sub
            _mirror(typing.cast(type, inner[0]), target, f"{where}.{name}")


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_record_classes_mirror_their_schema(name: str) -> None:
    _mirror(records.RECORD_TYPES[name], schemas.schema_json(name), name)


# ------------------------------------------------------------------ versions


@pytest.mark.parametrize(
    ("text", "expected"), [("1.0", (1, 0)), ("1.12", (1, 12)), ("2.3", (2, 3)), ("0.1", (0, 1))]
)
def test_parse_version(text: str, expected: tuple[int, int]) -> None:
    assert schemas.parse_version(text) == expected


@pytest.mark.parametrize("text", ["1", "1.0.0", "v1.0", "01.0", "1.x", "", " 1.0", 1.0, None])
def test_parse_version_refuses_anything_else(text: object) -> None:
    with pytest.raises(records.RecordFormatError, match=r'schema version: expected "major.minor"'):
        schemas.parse_version(text)


def _with_version(name: str, version: str) -> bytes:
    schema = schemas.schema_json(name)
    schema["version"] = version
    return json.dumps(schema).encode()


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_a_reader_accepts_any_2_x_and_3_x(name: str) -> None:
    now = schemas.parse_version(schemas.SCHEMA_VERSION)
    assert now[0] == 3
    assert schemas.check_schema_version(name, schemas.schema_bytes(name)) == now
    assert schemas.check_schema_version(name, _with_version(name, "3.7")) == (3, 7)
    assert schemas.check_schema_version(name, _with_version(name, "2.3")) == (2, 3)


def test_a_reader_refuses_another_major_version_or_a_foreign_schema() -> None:
    for other in ("1.0", "4.0"):
        with pytest.raises(
            records.RecordFormatError,
            match=rf"rsstp.Step: schema version {other} is not supported .*re-record",
        ):
            schemas.check_schema_version("rsstp.Step", _with_version("rsstp.Step", other))
    with pytest.raises(
        records.RecordFormatError, match=r"title: expected 'rsstp.Step', found 'rsstp.Model'"
    ):
        schemas.check_schema_version("rsstp.Step", schemas.schema_bytes("rsstp.Model"))
    with pytest.raises(records.RecordFormatError, match=r"rsstp.Step: the schema is not JSON"):
        schemas.check_schema_version("rsstp.Step", b"{")
    no_version = schemas.schema_json("rsstp.Step")
    del no_version["version"]
    with pytest.raises(
        records.RecordFormatError, match=r"rsstp.Step: schema version: .* found None"
    ):
        schemas.check_schema_version("rsstp.Step", json.dumps(no_version).encode())


def test_unknown_schema_names_are_refused() -> None:
    with pytest.raises(records.RecordFormatError, match=r"unknown schema 'rsstp.Pose'"):
        schemas.schema_bytes("rsstp.Pose")
    with pytest.raises(records.RecordFormatError, match=r"unknown schema 'rsstp.Pose'"):
        records.decode("rsstp.Pose", b"{}")


# ------------------------------------------------------------- a corpus of real messages


@dataclasses.dataclass
class Corpus:
    scenario: str
    messages: list[records.MessageRecord]
    models: list[tuple[records.ModelRecord, TransitionSystem]]  # with the model as it was

    def of(self, cls: type[records.MessageRecord]) -> list[Any]:
        return [m for m in self.messages if isinstance(m, cls)]

    def steps(self) -> list[Any]:
        """The step messages, of any body."""
        return self.of(records.StepRecord) + self.of(records.RoverStepRecord)


def _edit_by_hand(model: TransitionSystem, actions: Sequence[int]) -> None:
    """Split, merge, add and delete: leaves a nondeterministic model with a missing action."""
    s, a0, a1 = model.current, actions[0], actions[-1]
    model.merge(s, model.split(s))
    new = model.split(s)
    model.delete(s, new, a1)
    model.add(s, new, a1)
    model.delete(s, s, a0)
    model.delete(s, new, a0)


def record_run(name: str) -> Corpus:
    """Run RandomStrategy for STEPS steps, recording as a recorder would (in memory)."""
    pending: list[Event] = []
    messages: list[records.MessageRecord] = []
    models: list[tuple[records.ModelRecord, TransitionSystem]] = []
    runner: Runner | None = None

    def on_model_change(step: int, operations: Sequence[Any]) -> None:
        assert runner is not None
        record = builders.model_record(runner.model, step=step, operations=operations)
        report = runner.model.determinism_report()
        assert record.nondeterministic_pairs == len(report.nondeterministic)
        assert record.deterministic == runner.model.is_deterministic()
        models.append((record, runner.model.copy()))
        messages.append(record)
        messages.extend(builders.operation_events(step, operations))

    scenario = load_scenario(name)
    runner = Runner(
        scenario, RandomStrategy(), seed=1, on_event=pending.append, on_model_change=on_model_change
    )
    messages.insert(
        0,
        builders.scenario_record(
            runner.world,
            seed=1,
            strategy_name="random",
            strategy_params={"block": 4096, "tags": ("a", "b")},
            strategy_origin=strategy_origin(RandomStrategy()),
        ),
    )
    first = builders.model_record(runner.model, step=0, operations=())
    models.insert(0, (first, runner.model.copy()))
    messages.append(first)
    world, model = runner.world, runner.model

    def step_message(out: StepOutcome | None) -> records.StepRecord:
        return step_record_after(world.current, model, out)

    messages.append(step_message(None))
    for _ in range(STEPS):
        if runner.step_index == HAND_EDIT_AT:
            _edit_by_hand(model, scenario.actions)
            runner.agent.note("the model was edited by hand\nbefore this step")
        out = runner.step()
        messages.append(step_message(out))
        if out.blocker is not None:
            messages.append(
                builders.blocked_event(out.step, action=out.action, blocker=out.blocker)
            )
        for event in pending:
            messages.append(builders.event_record(event, state=out.state_before, action=out.action))
        pending.clear()
    messages.append(builders.contradiction_event(STEPS, state=0, i=3, j=17, actions=[1, 0]))
    return Corpus(name, messages, models)


@pytest.fixture(scope="module", params=sorted(builtin_scenarios()))
def corpus(request: pytest.FixtureRequest) -> Corpus:
    return record_run(request.param)


def _round_trip(record: records.MessageRecord) -> None:
    name = record.schema_name
    data = record.to_json()
    schema = schemas.schema_json(name)
    assert list(data) == [key for key in schema["properties"] if key in data]
    assert set(schema["required"]) <= set(data)
    schemas.validate(name, data)
    again = type(record).from_json(data)
    assert again == record
    payload = records.encode(record)
    assert records.encode(again) == payload
    assert json.loads(payload) == data == orjson.loads(payload)
    assert msgspec.json.encode(data) == payload
    decoded = records.decode(name, payload)
    assert decoded == record
    assert records.encode(decoded) == payload


def test_every_message_round_trips(corpus: Corpus) -> None:
    for record in corpus.messages:
        _round_trip(record)


def test_the_corpus_has_every_kind_of_message(corpus: Corpus) -> None:
    kinds = {event.kind for event in corpus.of(records.EventRecord)}
    expected = {"split", "merge", "add", "delete", "note", "no_transition", "contradiction"}
    assert expected <= kinds
    steps = corpus.steps()
    assert [s.step for s in steps] == list(range(STEPS + 1))
    assert any(s.agent.no_transition for s in steps)
    assert not corpus.models[-1][0].deterministic
    if load_scenario(corpus.scenario).obstacles or corpus.scenario == "three-joint":
        assert "blocked" in kinds
        assert any(s.truth.blocked_by is not None for s in steps)


def test_step_records_carry_the_pose_and_the_outcome(corpus: Corpus) -> None:
    scenario = load_scenario(corpus.scenario)
    for step in corpus.steps():
        truth, agent = step.truth, step.agent
        if isinstance(truth, records.RoverTruthRecord):
            assert isinstance(scenario, RoverScenario)
            x, y = truth.cell
            assert 0 <= x < scenario.room[0] and 0 <= y < scenario.room[1]
            assert truth.position == records.PointRecord(x=x + 0.5, y=y + 0.5)
            assert truth.heading_deg % scenario.turn_deg == 0
        else:
            assert isinstance(scenario, Scenario)
            n, m = scenario.n_joints, len(scenario.obstacles)
            assert len(truth.angles_deg) == n
            assert len(truth.joint_positions) == n + 1
            assert truth.joint_positions[0] == records.PointRecord(x=0.0, y=0.0)
            assert len(truth.distances) == n
            assert all(len(tip.obstacles) == m for tip in truth.distances)
        assert truth.blocked == (truth.blocked_by is not None)
        assert (agent.action is None) == (agent.state_before is None) == (step.step == 0)
        assert agent.sensation == (agent.feedback == 1.0) or not agent.sensation
    scenario_message = corpus.messages[0]
    assert isinstance(scenario_message, records.ScenarioRecord | records.RoverScenarioRecord)
    if isinstance(scenario_message, records.ScenarioRecord):
        assert isinstance(scenario, Scenario) and scenario_message.n_joints == scenario.n_joints
    else:
        assert list(scenario_message.rover.room) == list(scenario.room)  # type: ignore[union-attr]
    assert scenario_message.origin == corpus.scenario
    assert scenario_message.sha256 == scenario.sha256
    strategy = scenario_message.strategy
    assert strategy.param_values() == {"block": 4096, "tags": ["a", "b"]}
    assert [p.value for p in strategy.params] == ["4096", '["a","b"]']
    assert strategy.import_path == "rsstp_sim.strategies.random_walk:RandomStrategy"
    assert (strategy.distribution, strategy.version) == ("rsstp", rsstp_sim.__version__)


def test_the_model_is_rebuilt_from_the_model_messages(corpus: Corpus) -> None:
    (first, _), *later = corpus.models
    model = TransitionSystem.from_snapshot(first.snapshot(), version=first.version)
    for record, truth in later:
        for operation in record.operations:
            model.apply(operation.to_operation())
        assert model.version == record.version == truth.version
        assert model.transitions() == truth.transitions()
        assert list(model.states) == list(record.states)
        rebuilt = TransitionSystem.from_snapshot(record.snapshot(), version=record.version)
        assert rebuilt == truth


def test_ground_truth_floats_survive_json_exactly(corpus: Corpus) -> None:
    floats = [
        value
        for step in corpus.of(records.StepRecord)
        for value in (
            step.agent.feedback,
            *(c for point in step.truth.joint_positions for c in (point.x, point.y)),
            *(d for tip in step.truth.distances for d in tip.obstacles),
        )
    ]
    bits = [struct.pack("<d", v) for v in floats]
    for text in (records.encode, orjson.dumps, lambda v: json.dumps(v).encode()):
        for load in (json.loads, orjson.loads):
            assert [struct.pack("<d", load(text(v))) for v in floats] == bits


def test_the_same_run_gives_the_same_bytes() -> None:
    one, two = record_run("three-joint"), record_run("three-joint")
    assert [records.encode(m) for m in one.messages] == [records.encode(m) for m in two.messages]


def test_origin_is_the_file_base_name_never_a_directory(tmp_path: Path, corpus: Corpus) -> None:
    builtin = resources.files("rsstp_sim.scenarios").joinpath(f"{corpus.scenario}.toml")
    text = builtin.read_text(encoding="utf-8")
    path = tmp_path / "deep" / "my arm.toml"
    path.parent.mkdir()
    path.write_text(text, encoding="utf-8")
    record = builders.scenario_record(
        make_world(load_scenario(path)),
        seed=3,
        strategy_name="random",
        strategy_params={},
        strategy_origin=strategy_origin(RandomStrategy()),
    )
    assert record.origin == "my arm.toml"
    assert str(tmp_path) not in records.encode(record).decode()
    assert record.sha256 == hashlib.sha256(text.encode()).hexdigest()


# ----------------------------------------------------------------- bad messages


@functools.cache
def _three_joint() -> Corpus:
    return record_run("three-joint")


@functools.cache
def _rover() -> Corpus:
    return record_run("rover-two-rooms")


def _sample(name: str) -> dict[str, Any]:
    """A message with every optional object present (a blocked step, a blocked event)."""
    for record in [*_three_joint().messages, *_rover().messages]:
        if record.schema_name != name:
            continue
        if isinstance(record, records.StepRecord | records.RoverStepRecord) and (
            record.truth.blocked_by is None
        ):
            continue
        if isinstance(record, records.EventRecord) and record.kind != "blocked":
            continue
        if isinstance(record, records.ModelRecord) and not record.operations:
            continue
        return record.to_json()
    raise AssertionError(f"no sample of {name}")


SAMPLES = {name: _sample(name) for name in schemas.SCHEMA_NAMES}


def _required_paths(
    value: Any, schema: Mapping[str, Any], path: tuple[Any, ...]
) -> Iterator[tuple[Any, ...]]:
    """Paths (keys and indices) of every required field of ``value`` under ``schema``."""
    if "properties" in schema and isinstance(value, dict):
        for key in schema.get("required", ()):
            yield (*path, key)
            yield from _required_paths(value[key], schema["properties"][key], (*path, key))
    elif isinstance(schema.get("items"), Mapping) and isinstance(value, list) and value:
        yield from _required_paths(value[0], schema["items"], (*path, 0))


def _dotted(path: Sequence[Any]) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


MISSING_CASES = [
    (name, path)
    for name in schemas.SCHEMA_NAMES
    for path in _required_paths(SAMPLES[name], schemas.schema_json(name), ())
]


@pytest.mark.parametrize(
    ("name", "path"), MISSING_CASES, ids=lambda v: _dotted(v) if isinstance(v, tuple) else v
)
def test_a_missing_field_fails_validation_and_from_json(name: str, path: tuple[Any, ...]) -> None:
    data = copy.deepcopy(SAMPLES[name])
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    del parent[path[-1]]
    with pytest.raises(records.RecordFormatError, match=f"^{name}: .*'{path[-1]}' is a required"):
        schemas.validate(name, data)
    expected = f"{name}: {_dotted(path)}: missing"
    with pytest.raises(records.RecordFormatError) as raised:
        records.RECORD_TYPES[name].from_json(data)
    assert str(raised.value).startswith(expected)
    with pytest.raises(records.RecordFormatError, match=f"^{re.escape(expected)}"):
        records.decode(name, orjson.dumps(data))


@pytest.mark.parametrize(
    ("name", "path", "value", "message"),
    [
        ("rsstp.Step", ("agent", "sensation"), 1, r"agent.sensation: expected `bool`, got `int`"),
        ("rsstp.Step", ("agent", "action"), 1.5, r"agent.action: expected `int \| null`"),
        (
            "rsstp.Step",
            ("truth", "joint_positions", 1, "x"),
            "x",
            r"truth.joint_positions\[1\].x: expected `float`, got `str`",
        ),
        (
            "rsstp.Step",
            ("truth", "joint_positions", 1),
            [1.0, 2.0],
            r"truth.joint_positions\[1\]: expected `object`, got `array`",
        ),
        (
            "rsstp.Step",
            ("truth", "blocked_by", "kind"),
            "tree",
            r"truth.blocked_by.kind: invalid enum value 'tree'",
        ),
        (
            "rsstp.Model",
            ("transitions", "target", 0),
            "x",
            r"transitions.target\[0\]: expected `int`, got `str`",
        ),
        ("rsstp.Model", ("operations", 0, "kind"), "swap", r"operations\[0\].kind: invalid enum"),
        ("rsstp.Scenario", ("feedback", "mode"), "int", r"feedback.mode: invalid enum value"),
        ("rsstp.Scenario", ("seed",), True, r"seed: expected `int`, got `bool`"),
        ("rsstp.Event", ("kind",), "crash", r"kind: invalid enum value 'crash'"),
        (
            "rsstp.Event",
            ("data", "blocked_by", "indices", 0),
            "a",
            r"data.blocked_by.indices\[0\]: expected `int`, got `str` \(kind 'blocked'\)",
        ),
    ],
)
def test_a_mistyped_field_is_refused_with_its_path(
    name: str, path: tuple[Any, ...], value: object, message: str
) -> None:
    data = copy.deepcopy(SAMPLES[name])
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    with pytest.raises(records.RecordFormatError, match=f"^{name}: {message}"):
        records.RECORD_TYPES[name].from_json(data)
    with pytest.raises(records.RecordFormatError, match=f"^{name}: {message}"):
        records.decode(name, orjson.dumps(data))
    with pytest.raises(records.RecordFormatError, match=f"^{name}: "):
        schemas.validate(name, data)


def test_transitions_of_unequal_lengths_are_refused() -> None:
    data = copy.deepcopy(SAMPLES["rsstp.Model"])
    data["transitions"]["target"] = data["transitions"]["target"][:-1]
    message = r"^rsstp.Model: transitions: source, action and target differ in length"
    with pytest.raises(records.RecordFormatError, match=message):
        records.ModelRecord.from_json(data)
    with pytest.raises(records.RecordFormatError, match=message):
        records.decode("rsstp.Model", orjson.dumps(data))


@pytest.mark.parametrize(
    ("kind", "data", "message"),
    [
        ("blocked", {"action": 1}, r"data.blocked_by: missing \(kind 'blocked'\)"),
        ("no_transition", {"state": 0}, r"data.action: missing"),
        ("split", {"result": 1}, r"data.args: missing"),
        (
            "contradiction",
            {"state": 0, "i": 1, "j": 2, "actions": ["x"]},
            r"data.actions\[0\]: expected `int`",
        ),
    ],
)
def test_event_data_is_checked_by_kind(kind: str, data: dict[str, Any], message: str) -> None:
    event = {"step": 4, "kind": kind, "text": "t", "data": data}
    with pytest.raises(records.RecordFormatError, match=f"^rsstp.Event: {message}"):
        records.EventRecord.from_json(event)
    with pytest.raises(records.RecordFormatError, match=r"^rsstp.Event: data[.:\[]"):
        schemas.validate("rsstp.Event", event)


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_unknown_fields_are_ignored(name: str) -> None:
    data = copy.deepcopy(SAMPLES[name])
    expected = records.RECORD_TYPES[name].from_json(data)
    data["added_in_2_1"] = {"anything": [1, 2]}
    for key, value in data.items():
        if isinstance(value, dict) and key != "data":  # an event's data keeps every key
            value["also_new"] = None
    schemas.validate(name, data)
    assert records.RECORD_TYPES[name].from_json(data) == expected
    assert records.decode(name, orjson.dumps(data)) == expected


def test_bad_bytes_and_bad_shapes_are_refused() -> None:
    with pytest.raises(records.RecordFormatError, match=r"^rsstp.Step: invalid JSON: "):
        records.decode(
            "rsstp.Step", records.encode(records.StepRecord.from_json(SAMPLES["rsstp.Step"]))[:-3]
        )
    with pytest.raises(
        records.RecordFormatError, match=r"^rsstp.Step: expected `object`, got `array`"
    ):
        records.decode("rsstp.Step", b"[1, 2]")
    with pytest.raises(
        records.RecordFormatError, match=r"^rsstp.Model: expected `object`, got `str`"
    ):
        records.ModelRecord.from_json("model")  # type: ignore[arg-type]
    with pytest.raises(
        records.RecordFormatError, match=r"^AgentRecord: feedback: expected `float`"
    ):
        records.AgentRecord.from_json({**SAMPLES["rsstp.Step"]["agent"], "feedback": "high"})
    with pytest.raises(
        records.RecordFormatError, match=r"^rsstp.Step: agent.feedback: .* less than"
    ):
        schemas.validate(
            "rsstp.Step",
            {
                **SAMPLES["rsstp.Step"],
                "agent": {**SAMPLES["rsstp.Step"]["agent"], "feedback": -0.5},
            },
        )


def test_builders_refuse_what_cannot_be_recorded() -> None:
    scenario = load_scenario("three-joint")
    with pytest.raises(
        records.RecordFormatError, match=r"^rsstp.Scenario: strategy.params: expected"
    ):
        builders.scenario_record(
            make_world(scenario),
            seed=0,
            strategy_name="x",
            strategy_params={"f": object()},
            strategy_origin=strategy_origin(RandomStrategy()),
        )
    with pytest.raises(
        records.RecordFormatError, match=r"no_transition event needs state and action"
    ):
        builders.event_record(Event(3, "no_transition", "no transition"))
    assert builders.note_event(2, "two\nlines").text == "two lines"
    assert (
        builders.contradiction_event(5, state=1, i=0, j=2, actions=[3], text="a\r\nb").text == "a b"
    )


def test_docstring_examples_run() -> None:
    for module in (records, builders, schemas):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0


# ------------------------------------------------------------ random step records

finite = st.floats(allow_nan=False, allow_infinity=False)
ids = st.integers(min_value=0, max_value=2**40)


@st.composite
def step_records(draw: st.DrawFn) -> records.StepRecord:
    n = draw(st.integers(min_value=1, max_value=4))
    m = draw(st.integers(min_value=0, max_value=3))
    step = draw(st.integers(min_value=0, max_value=10**9))
    first = step == 0
    blocker = (
        None
        if first
        else draw(
            st.none()
            | st.builds(
                records.BlockedByRecord,
                kind=st.sampled_from(["fold", "obstacle", "links"]),
                indices=st.lists(st.integers(0, 50), min_size=1, max_size=2).map(tuple),
            )
        )
    )
    agent = records.AgentRecord(
        action=None if first else draw(st.integers(min_value=0, max_value=7)),
        state_before=None if first else draw(ids),
        internal_state=draw(ids),
        sensation=draw(st.booleans()),
        feedback=draw(st.floats(min_value=0.0, max_value=1.0)),
        model_version=draw(ids),
        no_transition=False if first else draw(st.booleans()),
    )
    points = draw(st.lists(st.tuples(finite, finite), min_size=n + 1, max_size=n + 1))
    truth = records.TruthRecord(
        angles_deg=tuple(draw(st.lists(st.integers(0, 359), min_size=n, max_size=n))),
        joint_positions=tuple(records.PointRecord(x=x, y=y) for x, y in points),
        blocked=blocker is not None,
        blocked_by=blocker,
        distances=tuple(
            records.DistancesRecord(obstacles=tuple(draw(st.lists(finite, min_size=m, max_size=m))))
            for _ in range(n)
        ),
    )
    return records.StepRecord(step=step, agent=agent, truth=truth)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(step_records())
def test_random_step_records_round_trip(record: records.StepRecord) -> None:
    _round_trip(record)
    payload = records.encode(record)
    assert records.StepRecord.from_json(json.loads(payload)) == record
    floats = [c for p in record.truth.joint_positions for c in (p.x, p.y)]
    decoded = records.decode("rsstp.Step", payload)
    assert isinstance(decoded, records.StepRecord)
    back = [c for p in decoded.truth.joint_positions for c in (p.x, p.y)]
    assert [struct.pack("<d", v) for v in back] == [struct.pack("<d", v) for v in floats]
