"""The recorder: real MCAP files, written by its chunked writer and read back with ``mcap``.

A recording is checked against the contract of docs/contract.md and ``schemas/README.md``
(topics and counts, metadata, attachment, schemas byte for byte, step times, no wall-clock),
against a live run with the same seed (the hand-assembled step bytes equal the record types'
bytes; agent view = memory, truth = the world's poses), for determinism, for a strategy that
refines its model (also in its reset), for write-through (every completed chunk is on disk
during the run), and for bad input.
"""

from __future__ import annotations

import collections
import io
import json
import re
import struct
from collections.abc import Generator, Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Channel, Chunk
from mcap.records import Message as McapMessage
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.summary import Summary

from builtin_worlds import builtins_of
from rsstp_format import records, schemas
from rsstp_format.records import EventRecord, ModelRecord, StepRecord
from rsstp_sim import (
    AgentView,
    Pose,
    RandomStrategy,
    RecordingError,
    Runner,
    StepOutcome,
    StrategyBase,
    StrategyError,
    load_scenario,
    make_strategy,
)
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.bodies import make_world
from rsstp_sim.recording import builders
from rsstp_sim.recording import recorder as recorder_module
from rsstp_sim.recording.recorder import Recorder, record
from rsstp_sim.recording.step_messages import Block
from rsstp_sim.strategies import Strategy
from rsstp_sim.transition_system import TransitionSystem

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "schemas"
STEPS = 2000
SEED = 1
STEP_NS = 1_000_000


# ------------------------------------------------------------------------- helpers


@dataclass(frozen=True)
class Message:
    topic: str
    schema_name: str
    log_time: int
    publish_time: int
    data: bytes


def read_summary(path: Path) -> Summary:
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None, f"{path}: no summary (the file was not finished)"
    return summary


def read_messages(path: Path) -> list[Message]:
    """Every message, in file order."""
    with path.open("rb") as stream:
        return [
            Message(
                channel.topic, schema.name if schema else "", m.log_time, m.publish_time, m.data
            )
            for schema, channel, m in make_reader(stream).iter_messages(log_time_order=False)
        ]


def topic_counts(summary: Summary) -> dict[str, int]:
    assert summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    return {channel.topic: counts.get(channel.id, 0) for channel in summary.channels.values()}


def decoded(messages: list[Message], topic: str) -> Iterator[Any]:
    for message in messages:
        if message.topic == topic:
            yield records.decode(message.schema_name, message.data)


@dataclass
class LiveRun:
    """A live run without a recorder: what the recording must reproduce."""

    runner: Runner
    steps: list[StepRecord]
    models: list[tuple[int, dict[str, object]]]
    outcomes: list[StepOutcome]
    poses: list[Pose]


def live_run(scenario: Scenario, strategy: Strategy, *, steps: int, seed: int) -> LiveRun:
    runner = Runner(scenario, strategy, seed=seed)
    model = runner.model
    step_records = [
        builders.step_record(
            0,
            runner.world.current,
            action=None,
            state_before=None,
            internal_state=model.current,
            model_version=model.version,
            no_transition=False,
            blocker=None,
        )
    ]
    models = [(0, model.copy().snapshot())]
    outcomes = []
    poses = [runner.world.current]
    version = model.version
    for _ in range(steps):
        outcome = runner.step()
        outcomes.append(outcome)
        poses.append(runner.world.current)
        step_records.append(
            builders.step_record(
                outcome.step,
                runner.world.current,
                action=outcome.action,
                state_before=outcome.state_before,
                internal_state=outcome.state_after,
                model_version=runner.model.version,
                no_transition=outcome.no_transition,
                blocker=outcome.blocker,
            )
        )
        if runner.model.version != version:
            version = runner.model.version
            models.append((outcome.step, runner.model.copy().snapshot()))
    return LiveRun(runner, step_records, models, outcomes, poses)


@pytest.fixture(scope="module")
def three_joint() -> Scenario:
    return load_scenario("three-joint")


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory, three_joint: Scenario) -> Path:
    """three-joint, random, 2,000 steps, seed 1."""
    path = tmp_path_factory.mktemp("recording") / "run.mcap"
    result = record(path, three_joint, RandomStrategy(), steps=STEPS, seed=SEED)
    assert result.path == path
    assert result.steps == STEPS
    assert not result.interrupted
    return path


@pytest.fixture(scope="module")
def messages(recording: Path) -> list[Message]:
    return read_messages(recording)


@pytest.fixture(scope="module")
def live(three_joint: Scenario) -> LiveRun:
    return live_run(three_joint, RandomStrategy(), steps=STEPS, seed=SEED)


# ---------------------------------------------------------- 1. structure and counts


def test_message_counts_per_topic(recording: Path, live: LiveRun) -> None:
    counts = topic_counts(read_summary(recording))
    blocked = sum(outcome.blocker is not None for outcome in live.outcomes)
    assert blocked == live.runner.blocked > 0
    assert live.runner.no_transition == 0  # the universal model always has a transition
    assert counts["/rsstp/scenario"] == 1
    assert counts["/rsstp/step"] == STEPS + 1
    assert counts["/rsstp/model"] >= 1
    assert counts["/rsstp/event"] == blocked  # random never refines the model


def test_record_result_counts_equal_the_files(tmp_path: Path, three_joint: Scenario) -> None:
    path = tmp_path / "run.mcap"
    result = record(path, three_joint, RandomStrategy(), steps=300, seed=4)
    assert result.messages == topic_counts(read_summary(path))
    assert list(result.messages) == list(schemas.TOPICS)


def test_metadata_record_rsstp(recording: Path, three_joint: Scenario) -> None:
    with recording.open("rb") as stream:
        metadata = list(make_reader(stream).iter_metadata())
    assert [m.name for m in metadata] == [schemas.METADATA_NAME] == ["rsstp"]
    values = metadata[0].metadata
    assert tuple(values) == (*schemas.METADATA_KEYS, schemas.METADATA_CHECKSUM_KEY)
    assert all(isinstance(v, str) for v in values.values())
    assert values["package"] == "rsstp"
    assert values["seed"] == str(SEED)
    assert values["strategy"] == "random"
    assert json.loads(values["strategy_params"]) == {}
    assert values["strategy_import_path"] == "rsstp_sim.strategies.random_walk:RandomStrategy"
    assert values["strategy_distribution"] == "rsstp"
    assert values["strategy_version"] == values["package_version"]
    assert values["scenario_sha256"] == three_joint.sha256
    for key, version in recorder_module.environment_versions().items():
        assert values[key] == version


def test_versions_override_only_library_versions(tmp_path: Path, three_joint: Scenario) -> None:
    path = tmp_path / "run.mcap"
    versions = {"numpy": "1.26.0", "python": "3.11.0", "seed": "999"}
    record(path, three_joint, RandomStrategy(), steps=5, seed=2, versions=versions)
    with path.open("rb") as stream:
        (metadata,) = make_reader(stream).iter_metadata()
    assert metadata.metadata["numpy"] == "1.26.0"
    assert metadata.metadata["python"] == "3.11.0"
    assert metadata.metadata["seed"] == "2"  # not a version: not overridable


def test_attachment_is_the_scenario_text(recording: Path, three_joint: Scenario) -> None:
    with recording.open("rb") as stream:
        attachments = list(make_reader(stream).iter_attachments())
    assert len(attachments) == 1
    (attachment,) = attachments
    assert attachment.name == schemas.ATTACHMENT_NAME == "scenario.toml"
    assert attachment.media_type == "application/toml"
    assert attachment.data == three_joint.source.encode("utf-8")
    assert (attachment.create_time, attachment.log_time) == (0, 0)


def test_schemas_are_the_files_byte_for_byte(recording: Path) -> None:
    summary = read_summary(recording)
    registered = {schema.name: schema for schema in summary.schemas.values()}
    assert sorted(registered) == ["rsstp.Event", "rsstp.Model", "rsstp.Scenario", "rsstp.Step"]
    for name, schema in registered.items():
        assert schema.encoding == "jsonschema"
        assert schema.data == (SCHEMA_DIR / f"{name}.json").read_bytes()
    channels = {channel.topic: channel for channel in summary.channels.values()}
    assert list(channels) == list(schemas.TOPICS)
    for topic, channel in channels.items():
        assert channel.message_encoding == "json"
        assert summary.schemas[channel.schema_id].name == schemas.TOPICS[topic]


def test_log_times_are_step_times(messages: list[Message]) -> None:
    assert messages[0].topic == "/rsstp/scenario"
    assert (messages[0].log_time, messages[0].publish_time) == (0, 0)
    steps = [m for m in messages if m.topic == "/rsstp/step"]
    assert [json.loads(m.data)["step"] for m in steps] == list(range(STEPS + 1))
    for message in messages:
        if message.topic == "/rsstp/scenario":
            continue
        step = json.loads(message.data)["step"]
        assert message.log_time == message.publish_time == step * STEP_NS


def test_no_wall_clock_time_anywhere(recording: Path) -> None:
    summary = read_summary(recording)
    end = STEPS * STEP_NS
    assert summary.statistics is not None
    assert summary.statistics.message_start_time == 0
    assert summary.statistics.message_end_time == end
    assert summary.chunk_indexes
    for chunk in summary.chunk_indexes:
        assert 0 <= chunk.message_start_time <= chunk.message_end_time <= end
    for index in summary.attachment_indexes:
        assert (index.create_time, index.log_time) == (0, 0)
    with recording.open("rb") as stream:
        header = make_reader(stream).get_header()
    assert header.profile == ""
    assert header.library == f"rsstp {recorder_module.environment_versions()['package_version']}"


# ------------------------------------------------- 2. every message, against a live run


def test_every_message_is_schema_valid_and_decodes(messages: list[Message]) -> None:
    for message in messages:
        assert schemas.TOPICS[message.topic] == message.schema_name
        schemas.validate(message.schema_name, json.loads(message.data))
        record_ = records.decode(message.schema_name, message.data)
        assert records.encode(record_) == message.data


def test_step_bytes_equal_the_record_types_bytes(messages: list[Message], live: LiveRun) -> None:
    recorded = [m.data for m in messages if m.topic == "/rsstp/step"]
    expected = [records.encode(step) for step in live.steps]
    assert len(recorded) == len(expected) == STEPS + 1
    for step, (got, want) in enumerate(zip(recorded, expected, strict=True)):
        assert got == want, f"step {step}"


def test_agent_part_is_the_live_memory(messages: list[Message], live: LiveRun) -> None:
    memory = live.runner.memory
    steps = list(decoded(messages, "/rsstp/step"))
    assert len(steps) == len(memory) == STEPS + 1
    for step, entry in zip(steps, memory, strict=True):
        agent = step.agent
        assert agent.action == entry.action
        assert agent.internal_state == entry.internal_state
        assert agent.sensation == entry.sensation
        assert agent.feedback == entry.feedback
    assert steps[0].agent.action is None and steps[0].agent.state_before is None


def test_truth_part_is_the_worlds_poses(messages: list[Message], live: LiveRun) -> None:
    blockers = [None, *(outcome.blocker for outcome in live.outcomes)]
    steps = decoded(messages, "/rsstp/step")
    for step, pose, blocker in zip(steps, live.poses, blockers, strict=True):
        truth = step.truth
        assert truth.angles_deg == pose.angles_deg
        assert [[p.x, p.y] for p in truth.joint_positions] == pose.joint_positions.tolist()
        assert [list(tip.obstacles) for tip in truth.distances] == pose.distances.tolist()
        assert truth.blocked == (blocker is not None)
        assert truth.blocked_by == records.BlockedByRecord.of(blocker)


def test_blocked_events_are_the_blocked_moves(messages: list[Message], live: LiveRun) -> None:
    events = list(decoded(messages, "/rsstp/event"))
    expected = [
        builders.blocked_event(o.step, action=o.action, blocker=o.blocker)
        for o in live.outcomes
        if o.blocker is not None
    ]
    assert events == expected


# ----------------------------------------------------------------- 3. determinism


@pytest.mark.parametrize("strategy", ["random", "script"])
@pytest.mark.parametrize("name", builtins_of("arm"))
def test_same_scenario_strategy_and_seed_give_the_same_bytes(
    tmp_path: Path, name: str, strategy: str
) -> None:
    scenario = load_scenario(name)
    first, second = tmp_path / "first.mcap", tmp_path / "second.mcap"
    record(first, scenario, make_strategy(strategy), steps=500, seed=7)
    record(second, load_scenario(name), make_strategy(strategy), steps=500, seed=7)
    assert first.read_bytes() == second.read_bytes()


@pytest.mark.parametrize(
    ("name", "strategy"),
    [("two-joint-30", "learner"), ("thesis-algo", "random"), ("rover-one-way", "random")],
)
def test_a_loop_that_moves_its_own_world_records_the_same_bytes(
    tmp_path: Path, name: str, strategy: str
) -> None:
    """The recorder as a sink: a user's loop moves its own world and hands each step over
    (``world=``, :meth:`Recorder.taken`); the file is the one ``record`` writes, byte for
    byte, whatever the body, with the model's changes (the learner) and blocked moves."""
    scenario = load_scenario(name)
    ran, handed = tmp_path / "ran.mcap", tmp_path / "handed.mcap"
    record(ran, scenario, make_strategy(strategy), steps=1_500, seed=3)
    world = make_world(scenario)
    chooser = make_strategy(strategy)
    recorder = Recorder(handed, scenario, chooser, seed=3, world=world)
    agent = recorder.runner.agent
    while recorder.runner.step_index < 1_500 and agent.stopped is None:
        action = chooser.choose_action(agent)
        blocker = world.move(action)  # the loop's own move
        recorder.taken(action, blocker)
    recorder.close()
    assert recorder.runner.world is world
    assert handed.read_bytes() == ran.read_bytes()


def test_a_different_seed_gives_different_steps(tmp_path: Path, three_joint: Scenario) -> None:
    first, second = tmp_path / "seed1.mcap", tmp_path / "seed2.mcap"
    record(first, three_joint, RandomStrategy(), steps=500, seed=1)
    record(second, three_joint, RandomStrategy(), steps=500, seed=2)
    assert first.read_bytes() != second.read_bytes()
    steps = [
        [m.data for m in read_messages(p) if m.topic == "/rsstp/step"] for p in (first, second)
    ]
    assert steps[0][0] == steps[1][0]  # the same reset
    assert steps[0] != steps[1]


class SplitOnce(StrategyBase):
    """Random actions; splits the current state at step 3 and edits its transitions.

    Step 3: split, two deletes and a note; step 5: an add and a note. With
    ``at_reset``, ``reset`` splits too (the model changes before the first step).
    """

    name: ClassVar[str] = "split-once"

    def __init__(self, *, at_reset: bool = False) -> None:
        self.at_reset = at_reset
        self.new: int | None = None

    def params(self) -> Mapping[str, Any]:
        return {"at_reset": self.at_reset}

    def reset(self, agent: AgentView) -> None:
        self.new = None
        if self.at_reset:
            agent.model.split(agent.model.current)
            agent.note("split at the reset")

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]

    def refine(self, agent: AgentView) -> None:
        model, a0, a1 = agent.model, agent.actions[0], agent.actions[1]
        if agent.step == 3:
            s = model.current
            self.new = model.split(s)
            model.delete(s, self.new, a0)
            model.delete(self.new, self.new, a1)
            agent.note(f"split state {s} after a sensation\nat step 3")
        elif agent.step == 5 and self.new is not None:
            model.add(self.new, self.new, a1)
            agent.note("restored one transition")


@pytest.mark.parametrize("at_reset", [False, True], ids=["refine", "refine-at-reset"])
def test_model_messages_are_live_copies_of_the_model(
    tmp_path: Path, three_joint: Scenario, at_reset: bool
) -> None:
    path = tmp_path / "split.mcap"
    result = record(path, three_joint, SplitOnce(at_reset=at_reset), steps=40, seed=3)
    live = live_run(three_joint, SplitOnce(at_reset=at_reset), steps=40, seed=3)
    messages = read_messages(path)

    models: list[ModelRecord] = list(decoded(messages, "/rsstp/model"))
    # The first message is a keyframe, the whole model; the others are changes (schema 3.0).
    assert [m.keyframe for m in models] == [True, False, False]
    assert (models[0].step, models[0].snapshot()) == live.models[0]
    assert all(m.states == () and m.transitions is records.NO_TRANSITIONS for m in models[1:])
    assert [m.step for m in models] == [0, 3, 5]
    assert result.messages["/rsstp/model"] == 3
    assert [m.version for m in models] == [
        int(at_reset),
        int(at_reset) + 3,
        int(at_reset) + 4,
    ]
    assert [[op.kind for op in m.operations] for m in models] == [
        ["split"] if at_reset else [],
        ["split", "delete", "delete"],
        ["add"],
    ]
    model_times = [m.log_time for m in messages if m.topic == "/rsstp/model"]
    assert model_times == [0, 3 * STEP_NS, 5 * STEP_NS]

    # The model at any step: the keyframe's model with the later operations applied is the
    # live run's.
    rebuilt = TransitionSystem.from_snapshot(models[0].snapshot(), version=models[0].version)
    for model, (step, snapshot) in zip(models[1:], live.models[1:], strict=True):
        for op in model.operations:
            rebuilt.apply(op.to_operation())
        rebuilt.current = model.current
        assert (model.step, rebuilt.snapshot()) == (step, snapshot)
        assert rebuilt.version == model.version
        assert (model.next_id, model.actions) == (rebuilt.next_id, rebuilt.actions)

    # The step messages follow the model versions and still equal the live run's.
    steps = [m.data for m in messages if m.topic == "/rsstp/step"]
    assert steps == [records.encode(s) for s in live.steps]

    events: list[EventRecord] = list(decoded(messages, "/rsstp/event"))
    kinds = collections.Counter((e.step, e.kind) for e in events if e.kind != "blocked")
    expected = {(3, "split"): 1, (3, "delete"): 2, (3, "note"): 1, (5, "add"): 1, (5, "note"): 1}
    if at_reset:
        expected.update({(0, "split"): 1, (0, "note"): 1})
    assert kinds == expected
    blocked = [(e.step, e.data["action"]) for e in events if e.kind == "blocked"]
    assert blocked == [(o.step, o.action) for o in live.outcomes if o.blocker is not None]
    notes = [e.text for e in events if e.kind == "note"]
    assert any(re.fullmatch(r"split state \d+ after a sensation at step 3", n) for n in notes)
    for event in events:
        if event.kind in ("split", "add", "delete"):
            (op,) = (
                op
                for m in models
                if m.step == event.step
                for op in m.operations
                if op.kind == event.kind and list(op.args) == event.data["args"]
            )
            assert event.data.get("result") == op.result


# -------------------------------------------------------------------- 4. bad input


def make_recorder(path: Path, scenario: str = "three-joint", **kwargs: Any) -> Recorder:
    return Recorder(path, load_scenario(scenario), RandomStrategy(), seed=1, **kwargs)


def test_existing_output_is_refused_and_left_untouched(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    path.write_bytes(b"an earlier recording")
    with pytest.raises(RecordingError, match=re.escape(f"{path}: already exists") + r".*--force"):
        make_recorder(path)
    assert path.read_bytes() == b"an earlier recording"


def test_existing_output_is_overwritten_with_force(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    path.write_bytes(b"an earlier recording" * 10_000)
    result = make_recorder(path, force=True).run(10)
    assert result.steps == 10
    assert topic_counts(read_summary(path))["/rsstp/step"] == 11
    assert not path.read_bytes().startswith(b"an earlier")


def test_missing_output_directory(tmp_path: Path) -> None:
    path = tmp_path / "missing" / "out.mcap"
    with pytest.raises(RecordingError, match=r"output directory .*missing does not exist"):
        make_recorder(path)
    assert not path.parent.exists()


def test_output_directory_that_is_a_file(tmp_path: Path) -> None:
    parent = tmp_path / "not-a-dir"
    parent.write_text("a file")
    with pytest.raises(RecordingError, match=r"output directory .*not-a-dir is not a directory"):
        make_recorder(parent / "out.mcap")
    assert parent.read_text() == "a file"


def test_unwritable_output_directory(unwritable_directory: Path) -> None:
    before = sorted(unwritable_directory.iterdir())
    with pytest.raises(RecordingError, match=rf"{re.escape(str(unwritable_directory))} is not"):
        make_recorder(unwritable_directory / "out.mcap")
    assert sorted(unwritable_directory.iterdir()) == before


def test_output_path_that_is_a_directory(tmp_path: Path) -> None:
    for force in (False, True):
        with pytest.raises(RecordingError, match=re.escape(f"{tmp_path}: is a directory")):
            make_recorder(tmp_path, force=force)


@pytest.mark.parametrize("chunk_size", [0, -1, 1023, 1024.0, True, "4096", None])
def test_bad_chunk_size(tmp_path: Path, chunk_size: object) -> None:
    path = tmp_path / "out.mcap"
    with pytest.raises(RecordingError, match=r"chunk size must be an integer >= 1024 bytes"):
        make_recorder(path, chunk_size=chunk_size)
    assert not path.exists()


def test_smallest_chunk_size_makes_many_chunks(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    make_recorder(path, chunk_size=1024).run(200)
    summary = read_summary(path)
    assert len(summary.chunk_indexes) > 10
    assert topic_counts(summary)["/rsstp/step"] == 201
    assert recorder_module.DEFAULT_CHUNK_SIZE == 1024 * 1024


@pytest.mark.parametrize("steps", [-1, 1.5, True, "10"])
def test_bad_steps_leave_no_file(tmp_path: Path, steps: object) -> None:
    path = tmp_path / "out.mcap"
    with pytest.raises(RecordingError, match=r"steps must be an integer >= 0"):
        record(path, load_scenario("three-joint"), RandomStrategy(), steps=steps, seed=1)  # type: ignore[arg-type]
    assert not path.exists()


class BadAfter(StrategyBase):
    """Plays action 0, then an action the scenario does not have at step 5."""

    name: ClassVar[str] = "bad-after"

    def choose_action(self, agent: AgentView) -> int:
        return 99 if agent.step == 4 else agent.actions[0]


@pytest.mark.parametrize("old", [None, b"a good recording"])
def test_a_failing_strategy_finishes_its_file_beside_the_output(
    tmp_path: Path, old: bytes | None
) -> None:
    """The steps before the failure are finished in the side file; the output (an old
    recording under ``force``) is never replaced by them, and the error says where they are."""
    path = tmp_path / "out.mcap"
    if old is not None:
        path.write_bytes(old)
    side = tmp_path / "out.mcap.partial"
    said = f"the steps before it are in {side} (finished); {path} was not touched"
    with pytest.raises(StrategyError, match=r"bad-after.*" + re.escape(said)):
        record(path, load_scenario("three-joint"), BadAfter(), steps=100, seed=1, force=True)
    steps = [m for m in read_messages(side) if m.topic == "/rsstp/step"]
    assert [json.loads(m.data)["step"] for m in steps] == [0, 1, 2, 3, 4]
    assert topic_counts(read_summary(side))["/rsstp/step"] == 5
    assert (path.read_bytes() if path.exists() else None) == old


class RunsOutOfMemory(Recorder):
    """A recorder whose step 6 meets a MemoryError (what a run under a memory limit meets,
    outside the strategy, which the runner names instead)."""

    def _step_blocks(
        self, outcomes: Iterable[StepOutcome], *, steps: int, max_bytes: int
    ) -> Generator[Block, None, None]:
        def until_six() -> Iterator[StepOutcome]:
            for outcome in outcomes:
                if outcome.step == 6:
                    raise MemoryError
                yield outcome

        return super()._step_blocks(until_six(), steps=steps, max_bytes=max_bytes)


def test_a_memory_error_under_force_leaves_the_old_recording(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    scenario = load_scenario("three-joint")
    record(path, scenario, make_strategy("random"), steps=50, seed=1)
    good = path.read_bytes()
    side = tmp_path / "out.mcap.partial"
    said = (
        f"out of memory at step 6; the steps before it are in {side} (finished); {path} was "
        "not touched"
    )
    with pytest.raises(RecordingError, match=re.escape(said)):
        RunsOutOfMemory(path, scenario, make_strategy("random"), seed=1, force=True).run(2_000)
    assert path.read_bytes() == good
    assert topic_counts(read_summary(side))["/rsstp/step"] == 6


def test_request_stop_finishes_the_file_after_the_current_step(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    recorder = make_recorder(path)
    stop_at = 4096

    def progress(done: int) -> None:
        if done == stop_at:
            recorder.request_stop()

    result = recorder.run(100_000, progress=progress)
    assert result.interrupted
    assert result.steps == stop_at
    assert topic_counts(read_summary(path))["/rsstp/step"] == stop_at + 1
    assert result.messages == topic_counts(read_summary(path))


def recovered_steps(data: bytes) -> tuple[list[int], int]:
    """Step numbers of the complete chunks of a file being written, read sequentially, and
    the number of those chunks (the tail, a chunk not yet written or cut short, stops it)."""
    reader = StreamReader(io.BytesIO(data), skip_magic=False, emit_chunks=True)
    topics: dict[int, str] = {}
    steps: list[int] = []
    chunks = 0
    try:
        for rec in reader.records:
            if isinstance(rec, Chunk):
                chunks += 1
                for item in breakup_chunk(rec, validate_crc=True):
                    if isinstance(item, Channel):
                        topics[item.id] = item.topic
                    elif isinstance(item, McapMessage) and topics[item.channel_id] == "/rsstp/step":
                        steps.append(json.loads(item.data)["step"])
    except (McapError, struct.error):
        pass
    return steps, chunks


def test_completed_chunks_are_on_disk_during_the_run(tmp_path: Path) -> None:
    """Write-through: at any time, every chunk the writer completed can be read from disk.

    With a user-space buffer in between, several small chunks (here about 1 kB compressed
    each) would wait in memory, and a SIGKILL would lose them.
    """
    path = tmp_path / "out.mcap"
    recorder = make_recorder(path, "two-joint-30", chunk_size=4096)
    seen: list[tuple[int, list[int], int]] = []

    def progress(done: int) -> None:  # the side file, where it is written until finished
        seen.append((done, *recovered_steps(recorder.side_file.read_bytes())))

    recorder.run(4 * 4096, progress=progress)
    assert [done for done, _, _ in seen] == [4096, 8192, 12288, 16384]
    for done, steps, chunks in seen:
        assert chunks > 0, f"after {done} steps, no complete chunk on disk"
        assert steps == list(range(len(steps)))
        steps_per_chunk = (done + 1) / chunks
        missing = done + 1 - len(steps)  # the steps of the chunk being built
        assert 0 <= missing < 2 * steps_per_chunk, (done, missing, steps_per_chunk)


def test_zero_steps_record_the_reset_only(tmp_path: Path) -> None:
    path = tmp_path / "out.mcap"
    result = record(path, load_scenario("one-joint-10"), RandomStrategy(), steps=0, seed=1)
    assert result.messages == {
        "/rsstp/scenario": 1,
        "/rsstp/step": 1,
        "/rsstp/model": 1,
        "/rsstp/event": 0,
    }
    summary = read_summary(path)
    assert summary.statistics is not None
    assert summary.statistics.message_end_time == 0
