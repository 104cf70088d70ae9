"""Reading a recording: the steps table, the memory, the model at any step, the events.

>>> with open_recording("run.mcap") as recording:  # doctest: +SKIP
...     table = recording.steps()          # one row per step, typed columns
...     memory = recording.memory()        # the agent's memory, entry by entry
...     model = recording.model_at(500)    # the model at the end of step 500

The file is checked at the boundary: :func:`open_recording` reads its structure, the
scenario, the metadata and the schemas (an unknown major version is refused); each table is
checked while it is decoded (CRCs, types, ranges, the step sequence, the model chain). Every
problem raises a :class:`~rsstp_replay.errors.ReplayError` whose one-line message names the
file and where. A file whose writer was killed is read up to its last complete chunk, with an
:class:`~rsstp_replay.errors.UnfinishedRecordingWarning`.
"""

from __future__ import annotations

import bisect
import operator
import os
import warnings
from collections.abc import Callable, Generator, Sequence
from contextlib import closing
from functools import partial
from pathlib import Path
from types import TracebackType
from typing import Any, NamedTuple, TypeVar, get_args

import msgspec
import numpy as np
import numpy.typing as npt
import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_format.records import EventKind, EventRecord, ModelRecord, json_array
from rsstp_format.schemas import STEP_NS
from rsstp_replay.errors import (
    BadStep,
    CorruptRecording,
    ReplayError,
    StepOutOfRange,
    TableError,
    UnfinishedRecordingWarning,
)
from rsstp_replay.reader._chunks import Messages, gc_paused
from rsstp_replay.reader._container import ChunkRef, open_container
from rsstp_replay.reader._contract import CheckedFile, check_file
from rsstp_replay.reader._decode import LogTimes, StepColumns, body_reader
from rsstp_replay.reader._models import (
    HEADS,
    ChainCheck,
    ModelHead,
    ModelHistory,
    version_heads,
)
from rsstp_sim.errors import MemoryRangeError
from rsstp_sim.memory import Memory
from rsstp_sim.recording.builders import model_record
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth
from rsstp_sim.truth.cache import load_truth
from rsstp_sim.words import counted

__all__ = ["EVENT_KINDS", "Recording", "open_recording"]

_Stepped = TypeVar("_Stepped", EventRecord, ModelRecord, ModelHead)

EVENT_KINDS: tuple[EventKind, ...] = get_args(EventKind)
"""The categories of :meth:`Recording.events`' ``kind`` column: the event kinds of the record
(:data:`rsstp_format.records.EventKind`), in its order."""

_CACHED_CHUNKS = 4


_Ints = npt.NDArray[np.int64]


def open_recording(path: str | os.PathLike[str]) -> Recording:
    """Open the recording at ``path`` (also a context manager).

    Raises :class:`~rsstp_replay.errors.NotARecording`, :class:`~rsstp_replay.errors.
    ForeignRecording`, :class:`~rsstp_replay.errors.UnsupportedVersion` or
    :class:`~rsstp_replay.errors.CorruptRecording`; warns with
    :class:`~rsstp_replay.errors.UnfinishedRecordingWarning` when the file was not finished.
    """
    recording = Recording(check_file(open_container(path)))
    if recording.recovered_steps is not None:
        warnings.warn(
            UnfinishedRecordingWarning(
                f"{recording.path}: the file was not finished; recovered "
                f"{counted(recording.recovered_steps, 'step')} from its complete chunks "
                f"(read {recording._file.container.recovered_bytes} of "
                f"{recording._file.container.size} bytes)"
            ),
            stacklevel=2,
        )
    return recording


class Recording:
    """One recorded run. Use :func:`open_recording`; the file is opened only during a call.

    Properties: ``path``, ``finished`` (the file has its footer), ``n_steps`` (the last step
    index; steps ``0 .. n_steps``, 0 being the reset), ``topic_counts`` (messages per topic),
    ``seed``, ``strategy`` (its name), ``strategy_params``, ``recovered_steps`` (``None`` for a
    finished file, else ``n_steps``: the steps read from the complete chunks), ``scenario``
    (rebuilt from the ``scenario.toml`` attachment), ``scenario_record`` (the
    ``/rsstp/scenario`` message), ``metadata`` (the ``rsstp`` metadata record),
    ``metadata_verified`` (its checksum matched; False for a file of schema 2.1 or older,
    written before the checksum) and
    ``schema_versions`` (schema name -> ``"major.minor"`` found in the file).

    An unfinished file is cut before its last recovered step: that step's model and event
    messages may have been in the chunk that was lost, so ``n_steps`` is the step before it
    (unless the scan reached the end of the data section).
    """

    def __init__(self, file: CheckedFile) -> None:
        self._file = file
        self._closed = False
        self._ground_truth: GroundTruth | None = None
        self.schema_versions = file.schema_versions
        self.metadata = file.metadata
        self.metadata_verified = file.metadata_verified
        self.topic_counts = file.topic_counts
        self.n_steps = file.n_steps
        self.recovered_steps: int | None = None if file.container.finished else self.n_steps
        self.scenario_record = file.scenario_record
        self.scenario = file.scenario
        self._step_chunks: dict[int, tuple[ChunkRef, bytes, Messages]] = {}
        self._agent: StepColumns | None = None
        self._log_times: LogTimes | None = None
        self._models: Sequence[ModelRecord] | None = None
        self._version_steps: list[int] | None = None
        self._events: pd.DataFrame | None = None

    # -- properties ------------------------------------------------------------------------

    @property
    def path(self) -> Path:
        return self._file.container.path

    @property
    def finished(self) -> bool:
        return self._file.container.finished

    @property
    def seed(self) -> int:
        return self.scenario_record.seed

    @property
    def strategy(self) -> str:
        return self.scenario_record.strategy.name

    @property
    def strategy_params(self) -> dict[str, Any]:
        return self.scenario_record.strategy.param_values()

    def __repr__(self) -> str:
        state = "finished" if self.finished else "unfinished"
        return f"Recording({str(self.path)!r}, steps=0..{self.n_steps}, {state})"

    def close(self) -> None:
        """Drop the cached tables; later calls raise :class:`ReplayError`."""
        self._closed = True
        self._agent = None
        self._log_times = None
        self._step_chunks.clear()
        self._models = None
        self._version_steps = None
        self._events = None

    def __enter__(self) -> Recording:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    # -- tables ----------------------------------------------------------------------------

    def steps(self, *, truth: bool = False, geometry: bool = True) -> pd.DataFrame:
        """One row per step, indexed by ``step`` (a ``RangeIndex`` ``0 .. n_steps`` named
        ``step``; there is no ``step`` column, so ``groupby("step")`` and ``loc[a:b]`` read
        the index), flat typed columns:

        - ``action`` and ``state_before`` (nullable Int64, ``<NA>`` at step 0);
          ``internal_state`` (int64); ``sensation`` (bool); ``feedback`` (float64, closeness in
          ``[0, 1]``); ``model_version`` (int64); ``no_transition`` (bool): the agent's view;
        - ``blocked`` (bool) and what blocked the move: ``blocked_kind`` (categorical, always
          every body's kinds as categories; missing when not blocked) and
          nullable Int64 indices, each present exactly at the steps of its kind:
          ``blocked_joint`` (``fold``: the joint whose relative angle would reach 180),
          ``blocked_link`` and ``blocked_obstacle`` (``obstacle``: the link that meets the
          obstacle), ``blocked_link_i`` and ``blocked_link_j`` (``links``: two links that
          meet, ``blocked_link_i < blocked_link_j - 1``);
        - ``angle_deg_{j}`` (int64, joint ``j``'s relative angle in degrees);
        - ``joint{k}_x``, ``joint{k}_y`` (float64, length units, world frame): point ``k`` of
          the arm, ``k = 0`` the base, ``k = n`` the tip of the last link;
        - ``dist_{k}_{j}`` (float64, length units): from the tip of link ``k`` (point ``k + 1``)
          to obstacle ``j``'s surface (a pose's numbers are its first message's, as the file
          holds them; ``check --physics`` compares every message with the geometry);
        - a rover's ``cell_x``, ``cell_y``, ``heading_deg`` (int64) and ``x``, ``y`` (float64,
          its position) instead of an arm's pose columns, and its own blocked index columns
          (``docs/tables.md``);
        - with ``truth=True``, also ``true_class`` (int64): the state of the minimal correct
          model (the ground truth of :mod:`rsstp_sim.truth`) that the step's pose belongs to.

        ``geometry=False`` leaves out the joint positions and the distances (what the audits
        do not read: a tenth of the memory per step).

        Every name is the same in every scenario (joints, points and obstacles are numbered
        from 0), so the tables of several recordings concatenate by name:
        ``pd.concat([a, b], keys=["a", "b"], names=["recording"])`` has the union of their
        columns (a joint or obstacle that one scenario lacks is missing in its rows, and
        such an int64 column becomes float64 there); the other columns keep their dtypes.
        """
        self._check_open()
        columns = self._step_columns(truth=True, numbers=geometry)
        self._log_times = columns.log_times()  # kept: the contract check needs no second pass
        frame = columns.frame(geometry=geometry)
        if truth:
            frame["true_class"] = self.ground_truth().classes_of_table(frame)
        return frame

    def step_log_times(self) -> _Ints:
        """The log time of each step message, in step order (the contract wants step x
        1,000,000 ns: :func:`~rsstp_replay.audits.contract.check_contract`)."""
        if self._log_times is None:
            self._log_times = self._agent_columns().log_times()
        return self._log_times.values()

    def ground_truth(self, *, cache: bool = True) -> GroundTruth:
        """The scenario's ground truth, once per recording: read from the truth cache on disk
        (:func:`~rsstp_sim.truth.cache.load_truth`), or computed (seconds for a large world)
        and kept there; ``cache=False`` computes it without the disk cache."""
        if self._ground_truth is None:
            self._ground_truth = load_truth(self.scenario, cache=cache)
        return self._ground_truth

    def memory(self) -> Memory:
        """The agent's memory, entry by entry as the live run had it."""
        columns = self._agent_columns()
        try:
            return Memory.from_arrays(
                columns.action.values,
                columns.internal_state.values,
                columns.sensation,
                columns.feedback,
            )
        except MemoryRangeError as exc:
            raise CorruptRecording(f"{self.path}: the steps do not make a memory: {exc}") from None

    def events(self) -> pd.DataFrame:
        """One row per event: ``step`` (int64), ``kind`` (categorical, :data:`EVENT_KINDS`),
        ``text`` (one line), ``data`` (its details as JSON text). The messages are decoded
        once per recording; each call gets its own copy of the table."""
        self._check_open()
        if self._events is None:
            self._events = self._event_table()
        return _event_texts(self._events)

    def steps_and_events(
        self,
        *,
        geometry: bool = True,
        blockers: bool = True,
        narrow: bool = False,
        models: bool = False,
    ) -> tuple[pd.DataFrame, pd.DataFrame]:
        """:meth:`steps` and :meth:`events` in one read of the chunks (each alone reads
        every chunk, the events being among the steps): what an audit reads.
        ``blockers=False`` leaves out of the steps table what blocked a move
        (``blocked_kind`` and its indices; ``blocked`` stays): no audit reads them, and
        they are a third of the table's memory without the geometry; ``narrow=True``: the
        integer columns in the narrowest dtype that holds their values (the agent's ids and
        versions, an arm's angles), not int64, and the events' ``text`` and ``data``
        categorical (each distinct one once: a long run's blocked events repeat a few), in
        the table the recording keeps (not a copy); ``models=True``: the model messages are
        read and checked in the same pass too (what :meth:`model_versions` then gives; most
        chunks hold some), a corrupt one named after every step is checked, as when they are
        read on their own."""
        self._check_open()
        events = _EventParts() if self._events is None else None
        chain = None
        if models and self._models is None and self.has_model:
            chain = _ModelPass(ChainCheck(self.path, last_step=self.n_steps))
        columns = self._step_columns(truth=True, events=events, numbers=geometry, models=chain)
        if chain is not None:
            self._models = self._models_checked(chain.finish())
        self._log_times = columns.log_times()
        if events is not None:
            self._events = events.table()
        steps = columns.frame(geometry=geometry, blockers=blockers, narrow=narrow)
        if narrow and self._events is not None:
            return steps, self._events
        return steps, self.events()

    def _event_table(self) -> pd.DataFrame:
        events = _EventParts()
        for ref, _, views, times in self._chunks("/rsstp/event"):
            events.add(self._chunk_records("/rsstp/event", ref, views, times))
        self._counted("/rsstp/event", events.count)
        return events.table()

    def verify_chunks(self) -> int:
        """Read, decompress and CRC-check every chunk; the number of chunks. Raises
        :class:`~rsstp_replay.errors.CorruptRecording` naming the first that fails."""
        self._check_open()
        container = self._file.container
        with container.open() as stream:
            for ref in container.chunks:
                container.chunk_data(stream, ref)
        return len(container.chunks)

    # -- the model ---------------------------------------------------------------------------

    @property
    def has_model(self) -> bool:
        """Whether the run recorded its agent's model. An agent that keeps none (a
        Gymnasium-driven run) leaves no ``/rsstp/model`` channel; its steps are all in state
        0, and the recording is read as having the one-state model (a self-loop per action)."""
        return "/rsstp/model" in self._file.channels

    def model_versions(self) -> Sequence[ModelRecord]:
        """The ``/rsstp/model`` messages in order, the chain between them checked (without a
        model channel, the one-state model at step 0: :attr:`has_model`)."""
        self._check_open()
        if self._models is None:
            if not self.has_model:
                one_state = TransitionSystem.universal(self.scenario_record.actions)
                self._models = (model_record(one_state, step=0, operations=()),)
                return self._models
            self._models = self._checked_models()
        return self._models

    def _checked_models(self) -> ModelHistory:
        """The model messages, each checked against the chain as it is read: a message that
        is byte for byte what its operations make is read without parsing its transitions
        (:meth:`~rsstp_replay.reader._models.ChainCheck.head`)."""
        chain = ChainCheck(self.path, last_step=self.n_steps)
        for ref, _, parts, times in self._chunks("/rsstp/model"):
            self._check_models(chain, ref, parts, times)
        return self._models_checked(chain)

    def _check_models(
        self, chain: ChainCheck, ref: ChunkRef, parts: list[memoryview], times: _Ints
    ) -> None:
        """A chunk's model messages, checked against the chain in order."""
        topic = "/rsstp/model"
        try:
            heads = HEADS.decode(json_array(parts))
        except (msgspec.DecodeError, RecursionError):  # decoded whole below: named there
            heads = None
        if heads is None or len(heads) != len(parts):
            records = self._file.decode_many(topic, parts, times, ref)
            for record, log_time in zip(records, times.tolist(), strict=True):
                chain(self._timed(topic, record, log_time, ref))
            return
        for head, part, log_time in zip(heads, parts, times.tolist(), strict=True):
            self._timed(topic, head, log_time, ref)
            decode = partial(self._file.decode_one, topic, part, log_time, ref)
            chain.head(head, part.tobytes(), decode)

    def _models_checked(self, chain: ChainCheck) -> ModelHistory:
        """The versions of a chain given every model message, counted."""
        found = chain.finish()
        self._counted("/rsstp/model", len(found))
        return found

    def _timed(self, topic: str, record: _Stepped, log_time: int, ref: ChunkRef) -> _Stepped:
        """``record``, a ``topic`` message, checked to be logged at its step's time."""
        if record.step * STEP_NS != log_time:
            raise CorruptRecording(
                f"{self.path}: a {topic} message logged at step "
                f"{log_time / STEP_NS:g} says step {record.step} (chunk at byte "
                f"{ref.offset})"
            )
        return record

    def model_at(self, step: int) -> TransitionSystem:
        """The model at the end of step ``step``, after the strategy's refinement.

        Its structure is the last model message at or before ``step``; its current state is
        the step's internal state (which the contract makes the state of that version the
        next step starts from: docs/contract.md).
        """
        step = self._check_step(step)
        models = self.model_versions()
        heads = version_heads(models)
        if self._version_steps is None or len(self._version_steps) != len(heads):
            self._version_steps = [m.step for m in heads]
        index = bisect.bisect_right(self._version_steps, step) - 1
        record = heads[index]
        if isinstance(models, ModelHistory):
            model = models.model(index)
        else:
            transitions = models[index].transitions
            model = TransitionSystem.from_columns(
                models[index].states,
                record.actions,
                (transitions.source, transitions.action, transitions.target),
                next_id=record.next_id,
                current=record.current,
                version=record.version,
            )
        here = self._agent_row(step)
        if here.model_version != record.version:
            raise CorruptRecording(
                f"{self.path}: step {step} says model version {here.model_version}, but the "
                f"last model message at or before it (step {record.step}) is version "
                f"{record.version}"
            )
        current = here.internal_state
        if current not in model:
            raise CorruptRecording(
                f"{self.path}: step {step}: the internal state {current} is not a state of "
                f"model version {record.version}"
            )
        model.current = current
        return model

    # -- reading -----------------------------------------------------------------------------

    def _check_open(self) -> None:
        if self._closed:
            raise ReplayError(f"{self.path}: the recording is closed")

    def _check_step(self, step: int) -> int:
        self._check_open()
        if isinstance(step, bool):
            raise StepOutOfRange(f"{self.path}: a step must be an integer, got {step!r}")
        try:
            index = operator.index(step)
        except TypeError:
            raise StepOutOfRange(f"{self.path}: a step must be an integer, got {step!r}") from None
        if not 0 <= index <= self.n_steps:
            raise StepOutOfRange(
                f"{self.path}: step {index} is out of range: the recording has steps 0 to "
                f"{self.n_steps}"
            )
        return index

    def _chunks(
        self, topic: str, *, step: int | None = None
    ) -> Generator[tuple[ChunkRef, bytes, list[memoryview], _Ints], None, None]:
        self._check_open()
        return self._file.chunks(topic, step=step)

    def _chunks_of(
        self, topics: Sequence[str], *, step: int | None = None
    ) -> Generator[tuple[ChunkRef, bytes, list[Messages]], None, None]:
        self._check_open()
        return self._file.chunks_of(topics, step=step)

    def step_message_bytes(self) -> Generator[tuple[bytes, list[int], list[int]], None, None]:
        """The step messages' own bytes, a chunk at a time: the chunk's decompressed data and
        where each of its step messages starts and ends in it, in step order; the garbage
        collector paused meanwhile. For a check that compares bytes (the physics check), with
        no decoding."""
        with gc_paused():
            for _, data, [found] in self._chunks_of(("/rsstp/step",)):
                yield data, found.starts, found.ends

    def _records(self, topic: str) -> list[Any]:
        """Every message of ``topic`` as its record, checked against its log time."""
        found: list[Any] = []
        for ref, _, parts, times in self._chunks(topic):
            found += self._chunk_records(topic, ref, parts, times)
        self._counted(topic, len(found))
        return found

    def _chunk_records(
        self, topic: str, ref: ChunkRef, parts: list[memoryview], times: _Ints
    ) -> list[Any]:
        """A chunk's messages of ``topic`` as their records, checked against their log times."""
        records = self._file.decode_many(topic, parts, times, ref)
        return [
            self._timed(topic, record, log_time, ref)
            for record, log_time in zip(records, times.tolist(), strict=True)
        ]

    def _counted(self, topic: str, found: int) -> None:
        """``found`` messages of ``topic`` must be the summary's count."""
        expected = self.topic_counts.get(topic, 0)
        if found != expected:
            raise CorruptRecording(
                f"{self.path}: expected {expected} {topic} messages (the summary's count), "
                f"found {found}"
            )

    def _decode_steps(
        self,
        columns: StepColumns,
        ref: ChunkRef,
        data: bytes,
        parts: list[memoryview],
        log_times: _Ints,
    ) -> None:
        try:
            columns.add(parts, log_times)
        except BadStep as exc:
            at = f"at step {log_times[exc.index] // STEP_NS} " if exc.index is not None else ""
            raise CorruptRecording(
                f"{self.path}: the step message {at}(chunk at byte {ref.offset}) is invalid: "
                f"{exc.text}"
            ) from None

    def _step_columns(
        self,
        *,
        truth: bool,
        events: _EventParts | None = None,
        numbers: bool = True,
        models: _ModelPass | None = None,
    ) -> StepColumns:
        """Decode and check every step message; with ``events``, add each chunk's events to
        it, and with ``models`` check each chunk's model messages, read in the same pass over
        the chunks; ``numbers``: an arm's joint positions and distances too (the table's
        geometry)."""
        columns = self._new_step_columns(truth=truth, numbers=numbers)
        for _ in self._decoding(columns, events, models):
            pass
        self._check_steps(columns)
        return columns

    def step_parts(self, rows: int = 262_144) -> Generator[pd.DataFrame, None, None]:
        """The steps table (:meth:`steps`) in parts of ``rows`` rows, in order (their
        ``pd.concat`` is :meth:`steps`), each given as soon as its steps are decoded, the
        last once every step is checked: to write a long table while the rest is decoded
        (``rsstp-replay table`` does, :func:`~rsstp_replay.export.table_files.write_table_parts`).
        An error raised on the way (a corrupt step) voids the parts given before it. Until
        the last part is taken, the garbage collector is paused (the decoding makes and
        drops millions of acyclic objects): what runs between parts frees by reference
        counting alone."""
        if rows < 1:
            raise TableError(f"a part of the steps table has at least one row, not {rows}")
        self._check_open()
        columns = self._new_step_columns(truth=True)
        done = 0
        for _ in self._decoding(columns, None):
            while columns.rows - done >= rows:
                yield columns.frame(rows=slice(done, done + rows))
                done += rows
        self._check_steps(columns)
        self._log_times = columns.log_times()
        if done < columns.n_rows:
            yield columns.frame(rows=slice(done, columns.n_rows))

    def _new_step_columns(self, *, truth: bool, numbers: bool = True) -> StepColumns:
        n_rows = self.n_steps + 1
        if not truth:
            return StepColumns(n_rows)
        reader = body_reader(self.scenario.body)
        pose = reader.truth_columns(n_rows, self.scenario, numbers=numbers)
        return StepColumns(n_rows, truth=pose, kinds=reader.kinds)

    def _decoding(
        self, columns: StepColumns, events: _EventParts | None, models: _ModelPass | None = None
    ) -> Generator[None, None, None]:
        """Decode the step messages into ``columns`` chunk by chunk (pausing after each);
        with ``events``, add to it each chunk's events as a part of the events table; with
        ``models``, check each chunk's model messages."""
        topics = ["/rsstp/step"]
        topics += [] if events is None else ["/rsstp/event"]
        topics += [] if models is None else ["/rsstp/model"]
        with gc_paused():
            for ref, data, found in self._chunks_of(topics):
                self._decode_steps(columns, ref, data, found[0].views(data), found[0].times)
                if events is not None:
                    event_parts = found[1].views(data)
                    events.add(
                        self._chunk_records("/rsstp/event", ref, event_parts, found[1].times)
                    )
                if models is not None:
                    model_parts = found[-1]
                    models.check(
                        partial(self._check_models, models.chain, ref, model_parts.views(data)),
                        model_parts.times,
                    )
                yield
        if events is not None:
            self._counted("/rsstp/event", events.count)

    def _check_steps(self, columns: StepColumns) -> None:
        try:
            columns.check(actions=self.scenario_record.actions)
        except BadStep as exc:
            raise CorruptRecording(f"{self.path}: step {exc.step}: {exc.text}") from None

    def _agent_columns(self) -> StepColumns:
        self._check_open()
        if self._agent is None:
            self._agent = self._step_columns(truth=False)
        return self._agent

    def _agent_row(self, step: int) -> _AgentRow:
        """The agent's fields of ``step``: from the whole memory when it was read, else from
        the one message of the step, in the chunk holding it (the last few such chunks are
        kept, decompressed, with where their messages lie: no other message is decoded)."""
        if self._agent is not None:
            found = _row(self._agent, step)
            if found is None:  # pragma: no cover - the columns were checked
                raise CorruptRecording(f"{self.path}: the message of step {step} is missing")
            return found
        for ref, data, messages in self._step_chunks.values():
            row = self._step_row(ref, data, messages, step)
            if row is not None:
                return row
        with closing(self._chunks_of(("/rsstp/step",), step=step)) as chunks:
            for ref, data, [messages] in chunks:
                if len(self._step_chunks) >= _CACHED_CHUNKS:
                    self._step_chunks.pop(next(iter(self._step_chunks)))
                self._step_chunks[ref.offset] = (ref, data, messages)
                row = self._step_row(ref, data, messages, step)
                if row is not None:
                    return row
        raise CorruptRecording(f"{self.path}: the message of step {step} is missing")

    def _step_row(
        self, ref: ChunkRef, data: bytes, messages: Messages, step: int
    ) -> _AgentRow | None:
        """The agent's fields of ``step`` from its message among a chunk's ``messages``
        (None when the chunk does not hold it)."""
        index = int(np.searchsorted(messages.times, step * STEP_NS))
        if index >= len(messages.times) or messages.times[index] != step * STEP_NS:
            return None
        part = memoryview(data)[messages.starts[index] : messages.ends[index]]
        columns = StepColumns(1, keep_steps=True)
        self._decode_steps(columns, ref, data, [part], messages.times[index : index + 1])
        return _row(columns, step)


class _ModelPass:
    """The model messages checked in the pass that decodes the steps (:meth:`Recording.
    steps_and_events`): the first corrupt one is kept, not raised, and no later one checked,
    until :meth:`finish`, once every step is decoded and checked, so that a recording with a
    bad step and a bad model message names the step first, as when the model messages are
    read after the steps."""

    def __init__(self, chain: ChainCheck) -> None:
        self.chain = chain
        self._error: CorruptRecording | None = None

    def check(self, chunk: Callable[[_Ints], None], times: _Ints) -> None:
        """Check a chunk's model messages (``chunk`` with their log times)."""
        if self._error is None:
            try:
                chunk(times)
            except CorruptRecording as exc:
                self._error = exc

    def finish(self) -> ChainCheck:
        """The chain, every model message given to it; the corrupt one raised."""
        if self._error is not None:
            raise self._error
        return self.chain


class _AgentRow(NamedTuple):
    state_before: int
    internal_state: int
    model_version: int


def _row(columns: StepColumns, step: int) -> _AgentRow | None:
    steps = columns.step
    index = int(np.searchsorted(steps, step))
    if index >= columns.rows or steps[index] != step:
        return None
    return _AgentRow(
        int(columns.state_before.values[index]),
        int(columns.internal_state.values[index]),
        int(columns.model_version.values[index]),
    )


_EVENT_KIND_DTYPE = pd.CategoricalDtype(list(EVENT_KINDS))


class _EventParts:
    """The events table built as its records are read, a part of at least :attr:`ROWS` rows
    at a time: a long run has millions of events (a blocked move is one), and kept as records
    until the end they took most of the memory of reading it. Their texts and data repeat (a
    blocked event's are its action's and blocker's), so each distinct one is kept once, and
    each event holds its index among them."""

    ROWS = 1 << 16

    def __init__(self) -> None:
        self.count = 0
        self._steps: list[npt.NDArray[np.int64]] = []
        self._kinds: list[npt.NDArray[np.int8]] = []
        self._texts: list[npt.NDArray[np.int32]] = []
        self._datas: list[npt.NDArray[np.int32]] = []
        self._text_codes: dict[str, int] = {}
        self._data_codes: dict[str, int] = {}
        self._pending: list[Any] = []

    def add(self, records: list[Any]) -> None:
        self.count += len(records)
        self._pending += records
        if len(self._pending) >= self.ROWS:
            self._flush()

    def _flush(self) -> None:
        events, self._pending = self._pending, []
        k = len(events)
        texts, datas = self._text_codes, self._data_codes
        encode = msgspec.json.encode
        self._steps.append(np.fromiter((e.step for e in events), np.int64, k))
        self._kinds.append(np.fromiter((_EVENT_KIND_CODES[e.kind] for e in events), np.int8, k))
        self._texts.append(
            np.fromiter((texts.setdefault(e.text, len(texts)) for e in events), np.int32, k)
        )
        self._datas.append(
            np.fromiter(
                (datas.setdefault(encode(e.data).decode(), len(datas)) for e in events),
                np.int32,
                k,
            )
        )

    def table(self) -> pd.DataFrame:
        """One row per event, in order, indexed ``0 .. n - 1``; ``text`` and ``data`` are
        categorical (their distinct values, once: :func:`_event_texts` makes them text)."""
        if self._pending:
            self._flush()

        def joined(parts: list[npt.NDArray[Any]], dtype: type) -> npt.NDArray[Any]:
            return np.concatenate(parts) if parts else np.empty(0, dtype)

        def categorical(codes: npt.NDArray[np.int32], values: dict[str, int]) -> Any:
            categories = pd.Index(list(values), dtype="str")
            return pd.Categorical.from_codes(codes, dtype=pd.CategoricalDtype(categories))

        return pd.DataFrame(
            {
                "step": joined(self._steps, np.int64),
                "kind": pd.Categorical.from_codes(
                    joined(self._kinds, np.int8), dtype=_EVENT_KIND_DTYPE
                ),
                "text": categorical(joined(self._texts, np.int32), self._text_codes),
                "data": categorical(joined(self._datas, np.int32), self._data_codes),
            }
        )


_EVENT_KIND_CODES = {kind: code for code, kind in enumerate(EVENT_KINDS)}


def _event_texts(events: pd.DataFrame) -> pd.DataFrame:
    """The events table of :meth:`Recording.events`: its categorical ``text`` and ``data``
    as text columns (a new table)."""
    return pd.DataFrame(
        {
            "step": events["step"].to_numpy(copy=True),
            "kind": events["kind"].array.copy(),
            "text": pd.array(events["text"].to_numpy(object), dtype="str"),
            "data": pd.array(events["data"].to_numpy(object), dtype="str"),
        }
    )
