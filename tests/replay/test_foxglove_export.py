"""``rsstp-replay export --foxglove``: a real recording written as a Foxglove scene, read back
with the ``mcap`` reader and decoded with the schemas' own protobuf descriptors, then imported
by Rerun's MCAP importer and read back from the ``.rrd``."""

from __future__ import annotations

import importlib.metadata
import math
import os
import shutil
import subprocess
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest
from fakes import RandomRefiner
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from rerun.chunk import RrdReader

from rsstp_cli.replay import main
from rsstp_replay import open_recording
from rsstp_replay.export import _foxglove_arm
from rsstp_replay.export import foxglove as foxglove_scene
from rsstp_replay.export.foxglove import ARM_TOPIC, LOG_TOPIC, STATIC_TOPIC, TRANSFORMS_TOPIC
from rsstp_sim import __version__, palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.recording import record
from rsstp_sim.scenario import load_scenario
from waiting import HANG_S

STEPS = 400
SRC = Path(__file__).resolve().parents[2] / "src"
RERUN = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")


@dataclass
class Recorded:
    """The recording as its reader gives it: the scenario, the steps and the events."""

    path: Path
    scenario: Scenario
    steps: pd.DataFrame
    events: pd.DataFrame

    def step(self, step: int) -> pd.Series:
        """The row of ``step`` (the steps table has a ``step`` column or a ``step`` index)."""
        table = self.steps
        if "step" in table.columns:
            table = table.set_index("step")
        return table.loc[step]

    def joints(self, step: int) -> list[tuple[float, float]]:
        row = self.step(step)
        return [(row[f"joint{k}_x"], row[f"joint{k}_y"]) for k in range(self.scenario.n_joints + 1)]

    def angles_deg(self, step: int) -> list[int]:
        row = self.step(step)
        return [int(row[f"angle_deg_{j}"]) for j in range(self.scenario.n_joints)]


@dataclass
class Scene:
    """The scene file read back: ``(log_time, publish_time, decoded message)`` by topic."""

    path: Path
    header_library: str
    messages: dict[str, list[tuple[int, int, Any]]]

    @classmethod
    def read(cls, path: Path) -> Scene:
        messages: dict[str, list[tuple[int, int, Any]]] = defaultdict(list)
        with open(path, "rb") as stream:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            library = reader.get_header().library
            for schema, channel, message, decoded in reader.iter_decoded_messages():
                assert (schema.encoding, channel.message_encoding) == ("protobuf", "protobuf")
                messages[channel.topic].append((message.log_time, message.publish_time, decoded))
        return cls(path, library, dict(messages))

    def arm_at(self, step: int) -> Any:
        """The ``arm`` entity in force at ``step``: the latest update at or before it."""
        updates = [m for t, _, m in self.messages[ARM_TOPIC] if t <= step * 1_000_000]
        (entity,) = updates[-1].entities
        return entity


def export(*argv: str) -> tuple[int, str, str]:
    """``rsstp-replay export ...`` in process: exit code, stdout, stderr."""
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["export", *argv])
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    """400 steps of three-joint with a strategy that splits, merges, adds and deletes: blocked
    moves (warnings) and model operations (info) among the events."""
    path = tmp_path_factory.mktemp("foxglove") / "run.mcap"
    record(
        path,
        load_scenario("three-joint"),
        RandomRefiner(split=0.05, max_states=5),
        steps=STEPS,
        seed=7,
    )
    with open_recording(path) as recording:
        return Recorded(path, recording.scenario, recording.steps(), recording.events())


@pytest.fixture(scope="module")
def scene(recorded: Recorded) -> Scene:
    out = recorded.path.with_name("run.scene.mcap")
    code, stdout, stderr = export("--foxglove", str(recorded.path), "-o", str(out))
    assert (code, stderr) == (0, "")
    assert stdout.startswith(f"wrote {out} (")
    return Scene.read(out)


def _step_numbers(table: pd.DataFrame) -> np.ndarray:
    return table.index.to_numpy(np.int64)


# ------------------------------------------------------------------------------ the arm


def test_the_arm_is_sent_at_step_0_and_where_it_moved(recorded: Recorded, scene: Scene) -> None:
    columns = [f"joint{k}_{a}" for k in range(recorded.scenario.n_joints + 1) for a in "xy"]
    points = recorded.steps[columns].to_numpy()
    moved = np.r_[True, (points[1:] != points[:-1]).any(axis=1)]
    steps = _step_numbers(recorded.steps)
    assert 0 < (~moved).sum() < STEPS  # the run has blocked moves, which move nothing
    sent = [log_time for log_time, _, _ in scene.messages[ARM_TOPIC]]
    assert sent == (steps[moved] * 1_000_000).tolist()


@pytest.mark.parametrize("step", [0, 1, 57, 200, 333, STEPS])
def test_the_arm_line_strip_is_the_recorded_joint_positions(
    recorded: Recorded, scene: Scene, step: int
) -> None:
    entity = scene.arm_at(step)
    assert (entity.id, entity.frame_id) == ("arm", "world")
    assert not entity.HasField("lifetime")  # it stays until the next update replaces it
    (line,) = entity.lines
    assert line.type == 0  # LINE_STRIP
    joints = recorded.joints(step)
    assert [(p.x, p.y, p.z) for p in line.points] == [(x, y, 0.0) for x, y in joints]
    spheres = [(s.pose.position.x, s.pose.position.y, s.pose.position.z) for s in entity.spheres]
    assert spheres == [(x, y, 0.0) for x, y in joints]
    r, g, b = palette.ARM
    assert (line.color.r, line.color.g, line.color.b) == (r / 255, g / 255, b / 255)


def test_times_are_steps(scene: Scene) -> None:
    """``log_time``, ``publish_time`` and every message's own timestamp are step x 1e6 ns."""
    for topic, messages in scene.messages.items():
        for log_time, publish_time, message in messages:
            assert publish_time == log_time, topic
            stamps = (
                [e.timestamp for e in message.entities]
                if topic in (ARM_TOPIC, STATIC_TOPIC)
                else [t.timestamp for t in message.transforms]
                if topic == TRANSFORMS_TOPIC
                else [message.timestamp]
            )
            for stamp in stamps:
                assert stamp.seconds * 1_000_000_000 + stamp.nanos == log_time, topic
            assert log_time % 1_000_000 == 0 and 0 <= log_time <= STEPS * 1_000_000


# ------------------------------------------------------------------ static scene, frames


def test_obstacles_and_feedback_points_are_sent_once(recorded: Recorded, scene: Scene) -> None:
    ((log_time, _, update),) = scene.messages[STATIC_TOPIC]
    assert log_time == 0
    entities = {entity.id: entity for entity in update.entities}
    assert set(entities) == {"obstacles", "feedback"}
    for entity in entities.values():
        assert entity.frame_id == "world"
        assert not entity.HasField("lifetime")  # no expiry
    scenario = recorded.scenario
    cylinders = entities["obstacles"].cylinders
    assert [(c.pose.position.x, c.pose.position.y, c.pose.position.z) for c in cylinders] == [
        (o.center[0], o.center[1], 0.0) for o in scenario.obstacles
    ]
    assert [(c.size.x, c.size.y) for c in cylinders] == [
        (2 * o.radius, 2 * o.radius) for o in scenario.obstacles
    ]
    spheres = entities["feedback"].spheres
    assert [(s.pose.position.x, s.pose.position.y) for s in spheres] == list(
        scenario.feedback_points
    )
    r, g, b = palette.FEEDBACK
    assert {(s.color.r, s.color.g, s.color.b) for s in spheres} == {(r / 255, g / 255, b / 255)}


def _world_points(transforms: dict[str, Any], n_joints: int) -> list[tuple[float, float]]:
    """Where ``base``, ``link1`` ... ``link{n-1}`` and ``tip`` are in ``world``, composing the
    planar transforms parent by parent."""

    def in_world(frame: str) -> tuple[float, float, float]:  # x, y, heading
        if frame == "world":
            return 0.0, 0.0, 0.0
        t = transforms[frame]
        x, y, heading = in_world(t.parent_frame_id)
        q = t.rotation
        assert (q.x, q.y) == (0.0, 0.0) and math.isclose(q.z**2 + q.w**2, 1.0)
        dx, dy = t.translation.x, t.translation.y
        c, s = math.cos(heading), math.sin(heading)
        return x + c * dx - s * dy, y + s * dx + c * dy, heading + 2 * math.atan2(q.z, q.w)

    frames = ["base", *(f"link{k}" for k in range(1, n_joints)), "tip"]
    return [in_world(frame)[:2] for frame in frames]


@pytest.mark.parametrize("step", [0, 57, 333, STEPS])
def test_the_frames_put_the_links_where_the_joints_are(
    recorded: Recorded, scene: Scene, step: int
) -> None:
    transforms: dict[str, Any] = {}  # child frame -> the latest transform at or before step
    for log_time, _, message in scene.messages[TRANSFORMS_TOPIC]:
        if log_time <= step * 1_000_000:
            transforms |= {t.child_frame_id: t for t in message.transforms}
    n = recorded.scenario.n_joints
    assert set(transforms) == {"base", "tip", *(f"link{k}" for k in range(n))}
    assert transforms["base"].parent_frame_id == "world"
    assert [transforms[f"link{k}"].parent_frame_id for k in range(n)] == [
        "base",
        *(f"link{k}" for k in range(n - 1)),
    ]
    for k, angle in enumerate(recorded.angles_deg(step)):
        q = transforms[f"link{k}"].rotation
        assert math.isclose(math.degrees(2 * math.atan2(q.z, q.w)) % 360, angle, abs_tol=1e-9)
    found = _world_points(transforms, n)
    for (x, y), (want_x, want_y) in zip(found, recorded.joints(step), strict=True):
        assert math.isclose(x, want_x, abs_tol=1e-9) and math.isclose(y, want_y, abs_tol=1e-9)


# ----------------------------------------------------------------------------- the logs


def test_every_event_is_a_log_message(recorded: Recorded, scene: Scene) -> None:
    events = recorded.events
    assert {"blocked", "split"} <= set(events["kind"].astype(str))
    warning, info = 3, 2  # foxglove.Log.Level
    expected = [
        (step * 1_000_000, kind, text, warning if kind in ("blocked", "contradiction") else info)
        for step, kind, text in zip(
            events["step"], events["kind"].astype(str), events["text"], strict=True
        )
    ]
    found = [(t, m.name, m.message, m.level) for t, _, m in scene.messages[LOG_TOPIC]]
    assert found == expected


# ------------------------------------------------------------------- bytes and the file


def test_a_second_export_gives_the_same_bytes(recorded: Recorded, scene: Scene) -> None:
    again = scene.path.with_name("again.scene.mcap")
    code, _, stderr = export("--foxglove", str(recorded.path), "-o", str(again))
    assert (code, stderr) == (0, "")
    assert again.read_bytes() == scene.path.read_bytes()
    sdk = importlib.metadata.version("foxglove-sdk")
    assert scene.header_library == f"rsstp {__version__} (foxglove-sdk {sdk} messages)"


def test_the_scene_says_what_it_was_made_from(recorded: Recorded, scene: Scene) -> None:
    with open(scene.path, "rb") as stream:
        metadata = {m.name: m.metadata for m in make_reader(stream).iter_metadata()}
    assert metadata["rsstp.scene"] == {
        "package": "rsstp",
        "package_version": __version__,
        "scenario": "three-joint",
        "scenario_sha256": recorded.scenario.sha256,
        "strategy": "random-refiner",
        "seed": "7",
        "steps": str(STEPS),
    }


def test_an_existing_output_is_refused_without_force(recorded: Recorded, tmp_path: Path) -> None:
    out = tmp_path / "x.scene.mcap"
    out.write_bytes(b"keep me")
    code, stdout, stderr = export("--foxglove", str(recorded.path), "-o", str(out))
    assert (code, stdout) == (2, "")
    assert stderr == f"rsstp-replay: error: {out}: already exists (use --force to overwrite)\n"
    assert out.read_bytes() == b"keep me"
    code, _, stderr = export("--foxglove", str(recorded.path), "-o", str(out), "--force")
    assert (code, stderr) == (0, "")
    assert out.read_bytes().startswith(b"\x89MCAP0\r\n")
    assert not out.with_name("x.scene.mcap.partial").exists()


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("x.rrd", "a Foxglove scene is an .mcap file, not '.rrd'"),
        ("run.mcap", "is the recording being exported: give another output"),
    ],
)
def test_a_bad_output_is_one_line(recorded: Recorded, name: str, message: str) -> None:
    out = recorded.path.with_name(name)
    code, stdout, stderr = export("--foxglove", str(recorded.path), "-o", str(out), "--force")
    assert (code, stdout) == (2, "")
    assert stderr == f"rsstp-replay: error: {out}: {message}\n"


def test_a_foreign_input_is_one_line(scene: Scene, tmp_path: Path) -> None:
    """Another tool's MCAP (the scene itself) and a file that is no MCAP at all."""
    text = tmp_path / "notes.mcap"
    text.write_text("not a recording\n")
    for source in (scene.path, text):
        out = tmp_path / "out.mcap"
        code, stdout, stderr = export("--foxglove", str(source), "-o", str(out))
        assert (code, stdout) == (2, "")
        assert stderr.startswith(f"rsstp-replay: error: {source}: ")
        assert stderr.count("\n") == 1 and "Traceback" not in stderr
        assert not out.exists()


def test_a_file_size_limit_never_leaves_a_truncated_scene(
    recorded: Recorded, tmp_path: Path
) -> None:
    """EFBIG while writing (RLIMIT_FSIZE in the child): one line, exit 1, the file that was
    there untouched, no side file; the SDK's own warnings (one per message) stay quiet."""
    import resource

    out = tmp_path / "run.scene.mcap"
    out.write_bytes(b"keep me")

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "export", "--foxglove", str(recorded.path),
         "-o", str(out), "--force"],
        capture_output=True, text=True, timeout=HANG_S, preexec_fn=small_files,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": "/tmp",
             "PYTHONDONTWRITEBYTECODE": "1"},  # no .pyc cut short by the limit
    )  # fmt: skip
    assert (done.returncode, done.stdout) == (1, "")
    assert done.stderr == f"rsstp-replay: error: {out}: cannot write: File too large\n"
    assert out.read_bytes() == b"keep me"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_ctrl_c_leaves_no_part_of_a_scene(
    recorded: Recorded, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Interrupted half way: the file that was there stays as it was, no side file stays."""
    out = tmp_path / "run.scene.mcap"
    out.write_bytes(b"keep me")
    links = _foxglove_arm.ArmDrawing.links
    calls = 0

    def interrupted(self: Any, *args: Any) -> Any:
        nonlocal calls
        calls += 1
        if calls == 100:
            raise KeyboardInterrupt
        return links(self, *args)

    monkeypatch.setattr(_foxglove_arm.ArmDrawing, "links", interrupted)
    with open_recording(recorded.path) as recording, pytest.raises(KeyboardInterrupt):
        foxglove_scene.export_foxglove(recording, out)
    assert out.read_bytes() == b"keep me"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


# ---------------------------------------------------------------- Rerun's MCAP importer


def test_rerun_imports_the_logs_and_the_frames(
    recorded: Recorded, scene: Scene, tmp_path: Path
) -> None:
    """``rerun mcap convert`` (rerun-sdk's own importer): ``foxglove.Log`` becomes ``TextLog``
    and ``foxglove.FrameTransforms`` ``Transform3D`` between named frames; a SceneUpdate stays
    an undecoded message (Rerun 0.41 has no decoder for it)."""
    assert RERUN is not None, "the rerun program comes with rerun-sdk"
    rrd = tmp_path / "scene.rrd"
    done = subprocess.run(
        [RERUN, "mcap", "convert", str(scene.path), "-o", str(rrd)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        check=False,
        env={**os.environ, "RUST_LOG": "off"},
    )
    assert done.returncode == 0, done.stderr
    columns: dict[str, dict[str, list[Any]]] = defaultdict(lambda: defaultdict(list))
    for chunk in RrdReader(rrd).stream().to_chunks():
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        for name, column in zip(batch.schema.names, batch.columns, strict=True):
            if pa.types.is_timestamp(column.type):
                column = column.cast(pa.int64())  # nanoseconds
            columns[chunk.entity_path][name] += column.to_pylist()

    log = columns[LOG_TOPIC]
    events = recorded.events
    assert log["TextLog:text"] == [[text] for text in events["text"]]
    assert log["TextLog:level"] == [
        ["WARN" if kind in ("blocked", "contradiction") else "INFO"]
        for kind in events["kind"].astype(str)
    ]
    assert log["message_log_time"] == (events["step"] * 1_000_000).tolist()

    frames = columns[TRANSFORMS_TOPIC]
    children = [child for (child,) in frames["Transform3D:child_frame"]]
    parents = [parent for (parent,) in frames["Transform3D:parent_frame"]]
    assert set(zip(children, parents, strict=True)) == {
        ("base", "world"),
        ("link0", "base"),
        ("link1", "link0"),
        ("link2", "link1"),
        ("tip", "link2"),
    }
    assert len(children) == 2 + 3 * len(scene.messages[ARM_TOPIC])  # fixed once, links per move
    assert frames["Transform3D:translation"][children.index("tip")] == [[1.0, 0.0, 0.0]]

    assert set(columns[ARM_TOPIC]) >= {"foxglove.SceneUpdate:message"}
    assert not any(name.startswith(("LineStrips", "Points")) for name in columns[ARM_TOPIC])


# ------------------------------------------------------------------------------ the rover

ROVER = Path(__file__).parents[2] / "recordings" / "rover-one-way-random.mcap"


def test_the_rover_is_sent_where_it_moved_or_turned_facing_its_heading(tmp_path: Path) -> None:
    out = tmp_path / "rover.scene.mcap"
    code, stdout, stderr = export("--foxglove", str(ROVER), "-o", str(out))
    assert (code, stderr) == (0, "")
    scene = Scene.read(out)
    with open_recording(ROVER) as recording:
        table = recording.steps()
        scenario = recording.scenario
        n_events = len(recording.events())
    pose = table[["cell_x", "cell_y", "heading_deg"]].to_numpy()
    changed = np.r_[True, (pose[1:] != pose[:-1]).any(axis=1)]
    updates = scene.messages[ARM_TOPIC]
    assert [t // 1_000_000 for t, _, _ in updates] == np.flatnonzero(changed).tolist()
    for t, _, update in updates[:: max(1, len(updates) // 50)]:
        step = t // 1_000_000
        (entity,) = update.entities
        assert (
            entity.id == "robot" and entity.timestamp.seconds * 10**9 + entity.timestamp.nanos == t
        )
        (disk,) = entity.cylinders
        x, y = table.at[step, "cell_x"] + 0.5, table.at[step, "cell_y"] + 0.5
        assert (disk.pose.position.x, disk.pose.position.y) == (x, y)
        (arrow,) = entity.arrows
        turn = arrow.pose.orientation
        heading = math.degrees(2 * math.atan2(turn.z, turn.w)) % 360
        assert heading == pytest.approx(float(table.at[step, "heading_deg"]), abs=1e-9)
    [(_, _, static)] = scene.messages[STATIC_TOPIC]
    room = next(e for e in static.entities if e.id == "room")
    assert len(room.lines) == 1 + len(scenario.walls) + len(scenario.doors)  # type: ignore[union-attr]
    assert len(room.arrows) == len(scenario.doors)  # type: ignore[union-attr]
    corners = [(p.x, p.y) for p in room.lines[0].points]
    width, height = scenario.room  # type: ignore[union-attr]
    assert corners == [(0, 0), (width, 0), (width, height), (0, height), (0, 0)]
    assert len(scene.messages[LOG_TOPIC]) == n_events
