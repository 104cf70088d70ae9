"""The recorder: writes a run to MCAP as it happens (docs/contract.md, schemas/README.md).

A layer around :class:`~rsstp_sim.runner.Runner`, the way a monitor wraps an
environment: the world and the model do not know a file exists. The recorder
observes each step's outcome, the model operations and the events through the
runner's callbacks and writes:

- ``/rsstp/scenario`` once, then ``/rsstp/step`` for step 0 (the reset) and
  every step after, ``/rsstp/model`` at step 0 and whenever the model changes,
  ``/rsstp/event`` for blocked moves, model operations, steps with no
  transition and strategy notes;
- a metadata record ``rsstp`` and the attachment ``scenario.toml``.

``log_time`` of step ``t`` is ``t * 1_000_000`` ns; no wall-clock time is
written, so the same scenario, strategy and seed give the same bytes.

Speed: a step's message comes from per-pose templates
(:mod:`~rsstp_sim.recording.step_messages`), in blocks of steps that the chunk writer
consumes, with little Python per message (:mod:`~rsstp_sim.recording.chunks`: the mcap
``Writer``'s bytes); each chunk's CRC, compression and write run on a second thread
(:mod:`~rsstp_sim.recording.output`). A long run whose steps are light has its chunks built
by a helper process (:mod:`~rsstp_sim.recording.chunk_process`), and writes them.

Crash safety: the recording goes to a locked side file, renamed onto the output only when
finished (:mod:`rsstp_sim.recording.output`). :meth:`Recorder.request_stop` (what the CLI's
SIGINT/SIGTERM handlers call) ends the run after the current step and the file is finished
properly.
"""

from __future__ import annotations

import io
import json
import os
import platform
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping, Sequence
from contextlib import closing, contextmanager, suppress
from dataclasses import dataclass, replace
from importlib import metadata
from itertools import islice
from pathlib import Path

from rsstp_format import records
from rsstp_format.schemas import (
    ATTACHMENT_MEDIA_TYPE,
    ATTACHMENT_NAME,
    BODY_TOPICS,
    METADATA_CHECKSUM_KEY,
    METADATA_KEYS,
    METADATA_NAME,
    SCHEMA_NAMES,
    STEP_NS,
    metadata_checksum,
    schema_bytes,
)
from rsstp_sim.errors import (
    ChunkProcessFailed,
    RecordingError,
    RecordingWriteError,
    RsstpError,
)
from rsstp_sim.files import side_file
from rsstp_sim.interface import Blocker, World
from rsstp_sim.recording import builders
from rsstp_sim.recording.chunk_process import ChunkProcess
from rsstp_sim.recording.chunks import ChunkedWriter, Message
from rsstp_sim.recording.output import SideFileWriter, open_side_file
from rsstp_sim.recording.step_messages import Block, BlockMessages, StepMessages
from rsstp_sim.runner import Event, Runner, StepOutcome
from rsstp_sim.scenario import AnyScenario
from rsstp_sim.strategies import Strategy, strategy_origin
from rsstp_sim.transition_system import Operation

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "HELPER_STEPS",
    "KEYFRAME_CHANGES",
    "TRIAL_STEPS",
    "RecordResult",
    "Recorder",
    "environment_versions",
    "record",
]

DEFAULT_CHUNK_SIZE = 1024 * 1024
"""Bytes of uncompressed messages per chunk (see the README for steps per chunk)."""

KEYFRAME_CHANGES = 256
"""At most this many model messages from one keyframe (the whole model) to the next; the
ones between are changes (their operations alone)."""

HELPER_STEPS = 131_072
"""A run of more steps than this may build its chunks in a helper process, left to choose
(:meth:`Recorder.run`), after recording the first :data:`TRIAL_STEPS` itself: the helper
then has at least as many steps to save time on, and its start (about 0.2 s of the other
core) is paid for (at 100,000 steps a recording is no faster with it)."""

TRIAL_STEPS = 65_536
"""The steps a run left to choose records itself before it chooses (see
:data:`HELPER_BYTES_PER_STEP`)."""

HELPER_BYTES_PER_STEP = 180
"""The most bytes of new tails and whole messages a step may cost, over the last
:data:`_WINDOW_STEPS` of the first :data:`TRIAL_STEPS`, for the helper to be kept. Measured
with seeds 1 and 2 (``bench/record_vs_run.py``): the random walk of ``three-joint`` 93-140
(its poses met again: the helper makes its recording about 20 % faster, 3.5 s against
4.35 s for 1,000,000 steps in one process), the learner on ``thesis-algo`` 140 (3 % faster),
an arm roaming free of obstacles 225-234 (no faster, no slower), the same among two far
obstacles 287-298 (5 % slower with the helper: bigger tails, half its steps at a new pose),
the splitter on ``two-joint-30`` 16,000-26,000 (a whole model message every few steps: 28 %
slower)."""

_WINDOW_STEPS = 16_384

# The steps whose messages are built before they go into the chunk, or while their tails and
# whole messages take at most so many bytes (a world of many obstacles: the chunks' zstd on
# the second thread goes on beside the steps, not after a burst of them)...
_BLOCK_STEPS, _BLOCK_BYTES = 64, 128 * 1024
# ... before they go to the helper.
_HELPER_BLOCK_STEPS, _HELPER_BLOCK_BYTES = 4096, 4 * 1024 * 1024

_VERSION_KEYS = ("package_version", "python", "numpy", "shapely", "mcap")


def environment_versions() -> dict[str, str]:
    """The versions a recording's metadata names: this package, Python and key libraries."""

    def version(dist: str) -> str:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return "unknown"

    from rsstp_sim import __version__

    return {
        "package_version": __version__,
        "python": platform.python_version(),
        "numpy": version("numpy"),
        "shapely": version("shapely"),
        "mcap": version("mcap"),
    }


@dataclass(frozen=True, slots=True)
class RecordResult:
    """What a recording run wrote."""

    path: Path
    steps: int
    messages: dict[str, int]
    interrupted: bool
    stopped: str | None = None
    budget: int | None = None


class Recorder:
    """Runs a strategy in a scenario and records every step to an MCAP file.

    The steps come from its runner (:meth:`run`, :meth:`step`), or from a loop that moves the
    world itself (``world=``, the loop's world, and :meth:`taken` after each move): the file
    is the same either way.

    ``versions`` overrides the library versions written in the metadata (used
    to reproduce a reference recording byte for byte on newer libraries). ``compact``: write
    no message indexes and compress the chunks harder (:mod:`~rsstp_sim.recording.chunks`):
    the same messages in less than half the bytes, for readers that read chunks through.
    """

    def __init__(
        self,
        path: str | Path,
        scenario: AnyScenario,
        strategy: Strategy,
        *,
        seed: int,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        force: bool = False,
        versions: Mapping[str, str] | None = None,
        model: bool = True,
        world: World | None = None,
        compact: bool = False,
    ) -> None:
        if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1024:
            raise RecordingError(f"chunk size must be an integer >= 1024 bytes, got {chunk_size!r}")
        self.path = Path(path)
        # What waits for the next step's message to be written, in order: (step, event
        # message) and (step, operations) of a model change, whose message is built when the
        # step is written, since the runner also reports changes made during its own reset,
        # before ``self.runner`` exists.
        self._waiting: list[tuple[int, bytes | tuple[Operation, ...]]] = []
        topics = BODY_TOPICS[scenario.body]
        self._topics = {t: name for t, name in topics.items() if model or t != "/rsstp/model"}
        self.runner = Runner(
            scenario,
            strategy,
            seed=seed,
            on_event=self._on_event,
            on_model_change=self._on_model_change,
            world=world,
        )
        self._versions = dict(environment_versions())
        if versions is not None:
            self._versions.update({k: v for k, v in versions.items() if k in _VERSION_KEYS})
        self._stop = False
        self._budget: int | None = None
        # Since the last keyframe: model messages, operations; its states and transitions.
        self._changes_since = self._operations_since = self._keyframe_size = 0
        self._messages = StepMessages()
        self._counts = dict.fromkeys(self._topics, 0)
        self.side_file = side_file(self.path)
        self._raw = open_side_file(self.path, force=force)
        self._file = SideFileWriter(self._raw)
        self._writer = ChunkedWriter(self._file, chunk_size=chunk_size, compact=compact)
        self._closed = False
        try:
            self._write_header(strategy, seed)
        except OSError as exc:
            self._abort()
            raise RecordingError(
                f"{self.side_file}: cannot write: {exc.strerror or exc}; nothing recorded"
            ) from None
        except BaseException:
            self._abort()
            raise

    # -- callbacks from the runner -------------------------------------------

    def _on_event(self, event: Event) -> None:
        # Steps with no transition are recorded from the step outcome (it has the
        # state and the action); the runner's events add the strategy notes.
        if event.kind == "note":
            note = builders.note_event(event.step, event.text, event.data)
            self._waiting.append((event.step, records.encode(note)))

    def _on_model_change(self, step: int, operations: Sequence[Operation]) -> None:
        if "/rsstp/model" not in self._topics:
            raise RecordingError(
                f"step {step}: the model changed in a run recorded without a model channel"
            )
        self._waiting.append((step, tuple(operations)))
        self._waiting.extend(
            (step, records.encode(event)) for event in builders.operation_events(step, operations)
        )

    # -- writing ----------------------------------------------------------------

    def _write_header(self, strategy: Strategy, seed: int) -> None:
        """The header, from the world the runner built (its scenario is the run's)."""
        world = self.runner.world
        scenario = world.scenario
        writer = self._writer
        writer.start(profile="", library=f"rsstp {self._versions['package_version']}")
        self._channels: dict[str, int] = {}
        schema_ids = {
            name: writer.register_schema(name, "jsonschema", schema_bytes(name))
            for name in SCHEMA_NAMES
            if name in self._topics.values()
        }
        for topic, name in self._topics.items():
            self._channels[topic] = writer.register_channel(topic, "json", schema_ids[name])
        self._step_channel = self._channels["/rsstp/step"]
        # The channels of the steps and of their blocked events that StepMessages.blocks
        # leaves in columns.
        self._column_channels = (self._step_channel, self._channels["/rsstp/event"])
        self._block_messages = BlockMessages(*self._column_channels)
        params = dict(strategy.params())
        origin = strategy_origin(strategy)
        if origin.distribution == "rsstp":  # ours: the version the metadata names
            origin = replace(origin, version=self._versions["package_version"])
        meta = {
            "package": "rsstp",
            **self._versions,
            "seed": str(seed),
            "strategy": strategy.name,
            "strategy_params": json.dumps(params, sort_keys=True),
            "strategy_import_path": origin.import_path,
            "strategy_distribution": origin.distribution or "",
            "strategy_version": origin.version or "",
            "scenario_sha256": scenario.sha256,
        }
        values = {key: meta[key] for key in METADATA_KEYS}
        values[METADATA_CHECKSUM_KEY] = metadata_checksum(values)
        writer.add_metadata(METADATA_NAME, values)
        writer.add_attachment(
            0, 0, ATTACHMENT_NAME, ATTACHMENT_MEDIA_TYPE, scenario.source.encode("utf-8")
        )
        record = builders.scenario_record(
            world,
            seed=seed,
            strategy_name=strategy.name,
            strategy_params=params,
            strategy_origin=origin,
        )
        self._add("/rsstp/scenario", 0, records.encode(record))
        if "/rsstp/model" in self._topics and not any(
            isinstance(change, tuple) for _, change in self._waiting
        ):
            self._waiting.append((0, ()))  # step 0 always has the initial model
        self._write_step_zero()

    def _add(self, topic: str, step: int, data: bytes, tail: bytes = b"") -> None:
        self._writer.add_message(*self._message(topic, step, data, tail))

    def _message(self, topic: str, step: int, data: bytes, tail: bytes = b"") -> Message:
        self._counts[topic] += 1
        return self._channels[topic], step * STEP_NS, data, tail

    def _step_blocks(
        self, outcomes: Iterable[StepOutcome], *, steps: int, max_bytes: int
    ) -> Generator[Block, None, None]:
        """The messages of each step of ``outcomes``, in file order, in blocks of ``steps``
        steps or ``max_bytes`` (see :meth:`StepMessages.blocks`)."""
        return self._messages.blocks(
            outcomes,
            self.runner.world,
            self.runner.model,
            channel=self._step_channel,
            waiting=self._waiting,
            then=self._after_step,
            steps=steps,
            max_bytes=max_bytes,
        )

    def _after_step(self, outcome: StepOutcome) -> Iterator[Message]:
        """The messages after a step's own: the model's, then the events. Of the events, the
        world's (blocked) and the internal transition's (no transition) lead: they came
        first."""
        t = outcome.step
        lead = []
        if outcome.blocker is not None:
            lead.append((t, self._messages.blocked_event(t, outcome.action, outcome.blocker)))
        if outcome.no_transition:
            event = builders.no_transition_event(
                t, state=outcome.state_before, action=outcome.action
            )
            lead.append((t, records.encode(event)))
        self._waiting[:0] = lead
        return self._pending(t)

    def _pending(self, step: int) -> Iterator[Message]:
        """The model messages (built now), then the events, that wait for ``step``."""
        model = self.runner.model
        for model_step, change in self._waiting:
            if isinstance(change, tuple):
                record = builders.model_record(
                    model, step=model_step, operations=change, keyframe=self._keyframe_due(change)
                )
                yield self._message("/rsstp/model", step, records.encode(record))
        for event_step, change in self._waiting:
            if isinstance(change, bytes):
                yield self._message("/rsstp/event", event_step, change)
        self._waiting.clear()

    def _keyframe_due(self, operations: tuple[Operation, ...]) -> bool:
        """Whether the next model message is a keyframe (the whole model): the first, then
        once :data:`KEYFRAME_CHANGES` changes or more operations than the last keyframe's
        states and transitions have passed since the last one (a reader rebuilds a version
        from the nearest keyframe before it, and the file grows with the changes)."""
        self._changes_since += 1
        self._operations_since += len(operations)
        due = (
            self._keyframe_size == 0
            or self._changes_since >= KEYFRAME_CHANGES
            or self._operations_since > self._keyframe_size
        )
        if due:
            model = self.runner.model
            self._keyframe_size = len(model) + len(model.transitions())
            self._changes_since = self._operations_since = 0
        return due

    def _write_step_zero(self) -> None:
        runner = self.runner
        message = self._messages.first(
            runner.world.current,
            internal_state=runner.model.current,
            model_version=runner.model.version,
        )
        self._add("/rsstp/step", 0, *message)
        self._writer.add_messages(self._pending(0))

    # -- running ------------------------------------------------------------------

    def request_stop(self) -> None:
        """Ask the run to end after the current step (safe from a signal handler)."""
        self._stop = True

    def run(
        self,
        steps: int,
        *,
        progress: Callable[[int], None] | None = None,
        helper: bool | None = None,
    ) -> RecordResult:
        """Take and record ``steps`` steps, then finish the file.

        ``progress`` is called with the number of steps done every 4,096 steps and at the end.
        ``helper``: build the chunks in a helper process beside the run
        (:mod:`~rsstp_sim.recording.chunk_process`; the same bytes): ``True`` from the
        first step, ``False`` never; by default for a run of more than :data:`HELPER_STEPS`
        steps, from then on, when its steps were light (see :meth:`_write_run`).
        Stops early (file finished, ``interrupted=True``) after :meth:`request_stop`. When
        the strategy ends the run (:attr:`Runner.stopped <rsstp_sim.runner.Runner.stopped>`),
        the file ends with an event saying so, at that step, of a budget of ``steps``.
        """
        _check_steps(steps)
        self._budget = self.runner.step_index + steps
        # Closed as soon as the writing ends, so that the steps taken are counted then.
        outcomes = self._outcomes(steps, progress)
        with self._closed_on_failure(), closing(outcomes):
            self._write_run(outcomes, steps, helper)
        self.close()
        return self.result()

    def _outcomes(
        self, steps: int, progress: Callable[[int], None] | None
    ) -> Generator[StepOutcome, None, None]:
        """Take up to ``steps`` steps (fewer after a stop request, or when the strategy ends
        the run), counted as they are taken."""
        step, agent = self.runner.step, self.runner.agent
        done = 0
        try:
            while done < steps and not self._stop and agent.stopped is None:
                for _ in range(min(4096, steps - done)):
                    yield step()
                    done += 1
                    if self._stop or agent.stopped is not None:
                        break
                if progress is not None:
                    progress(done)
        finally:
            self._counts["/rsstp/step"] += done

    def _write(self, outcomes: Iterable[StepOutcome]) -> None:
        """Write the messages of the steps ``outcomes`` takes."""
        with closing(
            self._step_blocks(outcomes, steps=_BLOCK_STEPS, max_bytes=_BLOCK_BYTES)
        ) as blocks:
            self._writer.add_messages(self._block_messages.of(blocks))

    def _write_run(self, outcomes: Iterator[StepOutcome], steps: int, helper: bool | None) -> None:
        """Write the run's steps, in this process or helped (see :meth:`run`). Left to choose,
        a run of more than :data:`HELPER_STEPS` steps starts a helper at once and writes its
        first :data:`TRIAL_STEPS` steps here, then keeps the helper if the last
        :data:`_WINDOW_STEPS` of them were light (:data:`HELPER_BYTES_PER_STEP`), else ends
        it: a run that keeps meeting new poses or changing its model sends the helper more
        bytes than the helper saves it."""
        if helper is False or (helper is None and steps <= HELPER_STEPS):
            self._write(outcomes)
            return
        process = self._start_helper()
        if process is None:  # no process could be started: this one does the work
            self._write(outcomes)
            return
        try:
            if helper is None:
                first = self.runner.step_index
                self._write(islice(outcomes, TRIAL_STEPS - _WINDOW_STEPS))
                before = self._messages.heavy_bytes
                self._write(islice(outcomes, _WINDOW_STEPS))
                if self.runner.step_index - first < TRIAL_STEPS:  # the run ended there
                    return
                if self._messages.heavy_bytes - before > HELPER_BYTES_PER_STEP * _WINDOW_STEPS:
                    process.close()  # (at once: its core is the run's from here)
                    self._write(outcomes)
                    return
            self._write_helped(outcomes, process)
        finally:
            process.close()

    def _start_helper(self) -> ChunkProcess | None:
        try:
            return ChunkProcess(
                chunk_size=self._writer.chunk_size,
                channels=self._column_channels,
                compact=self._writer.compact,
            )
        except OSError:
            return None

    def _write_helped(self, outcomes: Iterable[StepOutcome], helper: ChunkProcess) -> None:
        """:meth:`_write`, the chunks built by ``helper`` (by this process alone if the helper
        ended before it was given the chunk). A failure of the run keeps the steps before it,
        as :meth:`_write` does; a failure of the helper or of the disk loses those it held."""
        writer = self._writer
        self._messages.restart_tails()  # the helper's BlockMessages starts without any
        chunk = writer.hand_over()
        try:
            helper.take_over(chunk)
        except ChunkProcessFailed:  # it ended before it was used: this process goes on alone
            writer.take_back(chunk)
            self._write(outcomes)
            return
        try:
            with closing(
                self._step_blocks(
                    outcomes, steps=_HELPER_BLOCK_STEPS, max_bytes=_HELPER_BLOCK_BYTES
                )
            ) as blocks:
                for block in blocks:
                    for packed in helper.send(block):
                        writer.add_packed(packed)
        except BaseException as exc:
            if not (exc is self._file.error or isinstance(exc, ChunkProcessFailed)):
                with suppress(Exception):  # the run's own error is the one to tell
                    self._end_helper(helper)
            raise
        else:
            self._end_helper(helper)

    def _end_helper(self, helper: ChunkProcess) -> None:
        """Write the helper's last chunks and go on with the chunk it leaves open."""
        packed, chunk = helper.finish()
        for one in packed:
            self._writer.add_packed(one)
        self._writer.take_back(chunk)
        self._messages.restart_tails()  # ours has not seen those the helper's got

    def _write_stop(self) -> None:
        """The event that ends a run the strategy stopped: its last message."""
        reason = self.runner.agent.stopped
        if reason is not None:
            t = self.runner.step_index
            event = builders.stop_event(t, reason=reason, budget=self._budget)
            self._add("/rsstp/event", t, records.encode(event))

    def step(self) -> StepOutcome:
        """Take and record one step; the file stays open until :meth:`close`."""
        with self._closed_on_failure():
            outcome = self.runner.step()
            self._write((outcome,))
        self._counts["/rsstp/step"] += 1
        return outcome

    def taken(self, action: int, blocker: Blocker | None) -> StepOutcome:
        """Record a step whose move the world (the one given as ``world=``) has made, with
        ``blocker`` its answer: the agent's part of it (:meth:`Runner.taken
        <rsstp_sim.runner.Runner.taken>`) and its messages. A loop that moves the world
        itself (a Gymnasium env, a user's own) hands each step over this way."""
        with self._closed_on_failure():
            outcome = self.runner.taken(action, blocker)
            self._write((outcome,))
        self._counts["/rsstp/step"] += 1
        return outcome

    def result(self) -> RecordResult:
        """What has been recorded so far (``stopped``: the strategy's reason for ending the
        run, or None)."""
        return RecordResult(
            self.path,
            self.runner.step_index,
            dict(self.counts),
            self._stop,
            self.runner.agent.stopped,
            self._budget,
        )

    @contextmanager
    def _closed_on_failure(self) -> Iterator[None]:
        """A write error of the disk leaves the side file with its chunks and says what is
        safe; any other failure (a strategy's, a MemoryError, Ctrl-C in Python) finishes the
        side file but leaves it beside the output, never onto it, and the error says where."""
        try:
            yield
        except BaseException as exc:
            if isinstance(exc, OSError) and exc is self._file.error:
                raise self._write_failed(exc) from None
            kept = self._finish_aside()
            if isinstance(exc, MemoryError):
                raise RecordingError(
                    f"out of memory at step {self.runner.step_index:,}; {kept}"
                ) from None
            if isinstance(exc, RsstpError):
                exc.args = (f"{exc}; {kept}",)
            raise

    def _finish_aside(self) -> str:
        """Finish the side file of a run stopped by an error, not renamed; say where it is."""
        if self._closed:
            return f"{self.path} was not touched"
        try:
            self._writer.finish()
        except BaseException:  # a full disk, or still no memory: the chunks written stay
            finished = "unfinished; rsstp-replay reads its complete chunks"
        else:
            finished = "finished"
        finally:
            self._closed = True
            try:
                self._file.close()
            except OSError:
                pass
        return (
            f"the steps before it are in {self.side_file} ({finished}); {self.path} was not touched"
        )

    def close(self) -> None:
        """Finish the file (summary and indexes) and rename it onto the output; idempotent.
        A write error leaves the side file (its complete chunks readable) and raises
        :class:`~rsstp_sim.errors.RecordingWriteError`."""
        if self._closed:
            return
        try:
            self._write_stop()
            self._writer.finish()
        except OSError as exc:
            if exc is not self._file.error:
                self._closed = True
                self._file.close()
                raise
            raise self._write_failed(exc) from None
        except BaseException:
            self._closed = True
            self._file.close()
            raise
        self._closed = True
        try:
            _check_finished(self._raw, self._file.tell(), self.side_file)
            os.replace(self.side_file, self.path)  # still locked: nobody can take the file
        finally:
            self._file.close()

    def _write_failed(self, exc: OSError) -> RecordingWriteError:
        """Close the side file as it is (no summary can be written) and say what is safe."""
        self._closed = True
        try:
            self._file.close()
        except OSError:
            pass
        safe = self._file.safe_steps
        return RecordingWriteError(
            f"{self.side_file}: cannot write: {exc.strerror or exc}; steps 1 to {safe:,} "
            f"are safe in it (rsstp-replay reads them); {self.path} was not touched",
            safe_steps=safe,
            side_file=str(self.side_file),
        )

    def _abort(self) -> None:
        self._closed = True
        self._file.close()
        self.side_file.unlink(missing_ok=True)  # ours: the lock was held from its creation

    @property
    def counts(self) -> Mapping[str, int]:
        counts = dict(self._counts)
        counts["/rsstp/event"] += self._messages.column_events  # (not through _message)
        return counts


_MCAP_MAGIC = b"\x89MCAP0\r\n"


def _check_finished(raw: io.FileIO, size: int, side: Path) -> None:
    """Before the output is replaced: the side file holds every byte written and ends as an
    MCAP file ends (its closing magic)."""
    found = os.fstat(raw.fileno()).st_size
    end = os.pread(raw.fileno(), len(_MCAP_MAGIC), max(0, size - len(_MCAP_MAGIC)))
    if found != size or end != _MCAP_MAGIC:
        raise RecordingError(
            f"{side}: the finished recording does not check ({found:,} bytes on disk of "
            f"{size:,} written, ending {end!r}); it stays there, the output was not touched"
        )


def _check_steps(steps: object) -> None:
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
        raise RecordingError(f"steps must be an integer >= 0, got {steps!r}")


def record(
    path: str | Path,
    scenario: AnyScenario,
    strategy: Strategy,
    *,
    steps: int,
    seed: int,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    force: bool = False,
    versions: Mapping[str, str] | None = None,
    compact: bool = False,
) -> RecordResult:
    """Record ``steps`` steps of ``strategy`` in ``scenario`` to ``path`` (one call);
    ``compact``: see :class:`Recorder`."""
    _check_steps(steps)  # before the file exists: bad input must not leave a file behind
    recorder = Recorder(
        path,
        scenario,
        strategy,
        seed=seed,
        chunk_size=chunk_size,
        force=force,
        versions=versions,
        compact=compact,
    )
    return recorder.run(steps)
