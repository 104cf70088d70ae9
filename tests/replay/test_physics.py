"""The physics check: a recording changed but still well-formed (each of the rewrites below
passed ``check`` before it existed) is caught, at the right step and field, by re-simulating
the world from the attached scenario and the recorded actions."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from test_corrupt import rewrite

from rsstp_cli.replay import main
from rsstp_replay import open_recording
from rsstp_replay.audits.physics import check_physics
from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.arm import world as arm_world
from rsstp_sim.recording import record

ROOT = Path(__file__).resolve().parents[2]
STEPS = 3_000


@pytest.fixture(
    autouse=True, params=["move by move", pytest.param("whole table", marks=pytest.mark.slow)]
)
def world_walk(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every check twice: the world walked move by move, and tabulated whole with the
    recorded poses followed in numpy, block by block (what a replay longer than its world's
    pose space does)."""
    if request.param == "whole table":
        monkeypatch.setattr(arm_world, "pose_space_size", lambda scenario: 0)
        monkeypatch.setattr(arm_world, "_BLOCK_STEPS", 97)  # many blocks, a step's at each edge


@pytest.fixture(scope="module")
def walk(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A random walk of the three-joint arm: blocked moves of every kind, several chunks."""
    path = tmp_path_factory.mktemp("physics") / "walk.mcap"
    record(path, load_scenario("three-joint"), make_strategy("random"), steps=STEPS, seed=1,
           chunk_size=64 * 1024)  # fmt: skip
    return path


@pytest.fixture(scope="module")
def steps(walk: Path) -> dict[int, dict[str, Any]]:
    from mcap.reader import make_reader

    with open(walk, "rb") as stream:
        found = make_reader(stream).iter_messages(topics=["/rsstp/step"])
        return {json.loads(m.data)["step"]: json.loads(m.data) for _, _, m in found}


def _first(steps: dict[int, dict[str, Any]], test: Callable[[dict[str, Any]], bool]) -> int:
    return next(t for t in sorted(steps) if t > 100 and test(steps[t]))


def _step_rewrite(
    walk: Path, target: Path, step: int, change: Callable[[dict[str, Any]], None]
) -> Path:
    def message(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/step":
            return data
        decoded = json.loads(data)
        if decoded["step"] != step:
            return data
        change(decoded)
        return json.dumps(decoded, separators=(",", ":")).encode()

    return rewrite(walk, target, message=message)


def _findings(path: Path) -> tuple[int | None, str | None]:
    with open_recording(path) as recording:
        found = check_physics(recording)
    return found.step, found.field


def test_an_unchanged_recording_holds(walk: Path) -> None:
    with open_recording(walk) as recording:
        found = check_physics(recording)
    assert found.holds and found.to_text().endswith(f"every one of the {STEPS + 1:,} steps")


@pytest.mark.parametrize("steps", [0, 1])
def test_the_reset_alone_and_one_step_hold(tmp_path: Path, steps: int) -> None:
    path = tmp_path / "short.mcap"
    record(path, load_scenario("three-joint"), make_strategy("random"), steps=steps, seed=1)
    with open_recording(path) as recording:
        found = check_physics(recording)
    assert found.holds and found.steps == steps


@pytest.mark.parametrize("name", sorted(p.name for p in (ROOT / "recordings").glob("*.mcap")))
def test_every_reference_recording_holds(name: str) -> None:
    with open_recording(ROOT / "recordings" / name) as recording:
        assert check_physics(recording).holds


def test_the_arm_jumping_into_an_obstacle(
    walk: Path, steps: dict[int, dict[str, Any]], tmp_path: Path
) -> None:
    t = _first(steps, lambda s: not s["truth"]["blocked"])

    def jump(message: dict[str, Any]) -> None:
        angles = message["truth"]["angles_deg"]
        angles[0] = (angles[0] + 90) % 360

    assert _findings(_step_rewrite(walk, tmp_path / "x.mcap", t, jump)) == (
        t,
        "truth.angles_deg[0]",
    )


def test_a_blocker_naming_an_obstacle_that_is_not_there(
    walk: Path, steps: dict[int, dict[str, Any]], tmp_path: Path
) -> None:
    t = _first(steps, lambda s: s["truth"].get("blocked_by", {}).get("kind") == "obstacle")

    def seven(message: dict[str, Any]) -> None:
        message["truth"]["blocked_by"]["indices"][1] = 7

    assert _findings(_step_rewrite(walk, tmp_path / "x.mcap", t, seven)) == (
        t,
        "truth.blocked_by.indices[1]",
    )


@pytest.mark.parametrize(
    ("field", "change"),
    [
        ("agent.sensation", lambda a: a.update(sensation=not a["sensation"])),
        ("agent.feedback", lambda a: a.update(feedback=0.5)),
    ],
)
def test_what_the_agent_sensed_changed(
    field: str,
    change: Callable[[dict[str, Any]], None],
    walk: Path,
    tmp_path: Path,
) -> None:
    bad = _step_rewrite(walk, tmp_path / "x.mcap", 1234, lambda m: change(m["agent"]))
    assert _findings(bad) == (1234, field)


def test_an_action_replaced_by_another(
    walk: Path, steps: dict[int, dict[str, Any]], tmp_path: Path
) -> None:
    t = _first(steps, lambda s: not s["truth"]["blocked"] and s["agent"]["action"] % 2 == 0)

    def reverse(message: dict[str, Any]) -> None:
        message["agent"]["action"] += 1  # the same joint, the other way

    step, field = _findings(_step_rewrite(walk, tmp_path / "x.mcap", t, reverse))
    assert step == t and field in ("agent.feedback", "truth.angles_deg[0]", "truth.angles_deg[1]",
                                   "truth.angles_deg[2]")  # fmt: skip


@pytest.mark.parametrize(
    ("field", "change"),
    [
        ("truth.joint_positions[2].x", lambda t: t["joint_positions"][2].update(x=0.25)),
        (
            "truth.distances[1].obstacles[0]",
            lambda t: t["distances"][1]["obstacles"].__setitem__(0, 9.0),
        ),
    ],
)
def test_numbers_changed_in_a_message_that_is_not_first_of_its_chunk(
    field: str, change: Callable[[dict[str, Any]], None], walk: Path, tmp_path: Path
) -> None:
    bad = _step_rewrite(walk, tmp_path / "x.mcap", 2001, lambda m: change(m["truth"]))
    assert _findings(bad) == (2001, field)


@pytest.mark.parametrize("how", ["removed", "duplicated"])
def test_blocked_events_removed_or_duplicated(
    how: str, walk: Path, steps: dict[int, dict[str, Any]], tmp_path: Path
) -> None:
    t = _first(steps, lambda s: s["truth"]["blocked"])
    done: list[bool] = []

    def message(topic: str, log_time: int, data: bytes) -> bytes | None:
        if topic == "/rsstp/event" and not done and json.loads(data)["step"] == t:
            done.append(True)
            return None if how == "removed" else data
        return data

    target = tmp_path / "x.mcap"
    if how == "removed":
        rewrite(walk, target, message=message)
    else:  # the same event twice: written once more after its own
        from mcap.reader import make_reader

        with open(walk, "rb") as stream:
            event = next(
                m.data
                for _, _, m in make_reader(stream).iter_messages(topics=["/rsstp/event"])
                if json.loads(m.data)["step"] == t
            )

        def twice(topic: str, log_time: int, data: bytes) -> bytes:
            if topic == "/rsstp/step" and log_time == t * 1_000_000:
                return data
            return data

        rewrite(walk, target, message=twice)
        _append_event(target, event, t)
    assert _findings(target) == (t, "blocked event")


def _append_event(path: Path, event: bytes, step: int) -> None:
    """Rewrite ``path`` with ``event`` once more among the events (at its own step)."""
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    with open(path, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        messages = list(reader.iter_messages(log_time_order=True))
        metadata = list(reader.iter_metadata())
        attachments = list(reader.iter_attachments())
    with open(path, "wb") as out:
        writer = Writer(out, compression=CompressionType.ZSTD)
        writer.start(profile="", library="test")
        schemas = {
            sid: writer.register_schema(s.name, s.encoding, s.data)
            for sid, s in summary.schemas.items()
        }
        channels = {
            cid: writer.register_channel(c.topic, c.message_encoding, schemas[c.schema_id])
            for cid, c in summary.channels.items()
        }
        for found in metadata:
            writer.add_metadata(found.name, found.metadata)
        for found in attachments:
            writer.add_attachment(
                found.log_time, found.create_time, found.name, found.media_type, found.data
            )
        added = False
        for _, channel, msg in messages:
            writer.add_message(channels[channel.id], msg.log_time, msg.data, msg.publish_time)
            if not added and channel.topic == "/rsstp/event" and msg.data == event:
                writer.add_message(channels[channel.id], msg.log_time, event, msg.publish_time)
                added = True
        assert added
        writer.finish()


def test_the_scenario_message_disagreeing_with_its_file(walk: Path, tmp_path: Path) -> None:
    def message(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/scenario":
            return data
        decoded = json.loads(data)
        decoded["step_deg"] = 7
        return json.dumps(decoded, separators=(",", ":")).encode()

    bad = rewrite(walk, tmp_path / "x.mcap", message=message)
    assert _findings(bad) == (None, "/rsstp/scenario step_deg")


@pytest.mark.slow
def test_check_and_audit_say_it_in_one_line_and_exit_1(
    walk: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = _step_rewrite(walk, tmp_path / "x.mcap", 1234, lambda m: m["agent"].update(feedback=0.5))
    assert main(["check", "--physics", str(bad)]) == 1
    out = capsys.readouterr().out
    assert "physics: broken at step 1,234, agent.feedback: recorded 0.5, the world gives" in out
    assert main(["audit", str(bad), "--quiet"]) == 1
    captured = capsys.readouterr()
    assert "physics: broken at step 1,234, agent.feedback" in captured.out
    assert captured.err.strip() == (
        "rsstp-replay: audit failed: the recorded world does not follow from its scenario and "
        "actions"
    )
    assert main(["audit", str(bad), "--quiet", "--allow", "contract"]) == 0
    capsys.readouterr()
    assert main(["check", "--physics", str(walk)]) == 0
    assert main(["audit", str(walk), "--quiet"]) == 0
