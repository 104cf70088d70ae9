"""``rsstp-replay``: look into a recording: ``info``, ``check``, ``table``, ``events``,
``audit``, ``compare``, ``view``, ``graph``, ``export``.

Bad input (a missing or damaged file, a file from another tool, a schema version this reader
does not know, a step out of range) gets one line on stderr naming the file and the problem,
and exit code 2; never a traceback. A file whose writer was killed is read up to its last
complete chunk, with a one-line warning on stderr. ``audit --fail-on`` exits with 1 when such
a finding exists.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rsstp_cli._commandline import (
    Parser,
    UsageError,
    add_no_cache,
    progress,
    run_command,
    warning_line,
)
from rsstp_cli._json import indented
from rsstp_replay.errors import StepOutOfRange, UnfinishedRecordingWarning
from rsstp_replay.export.table_files import (
    TABLE_FORMATS,
    sidecar_path,
    write_table,
    write_table_parts,
)
from rsstp_replay.export.tables import TABLES, recording_table
from rsstp_replay.reader.recording import Recording, open_recording
from rsstp_sim.bodies import body_of
from rsstp_sim.files import check_output
from rsstp_sim.words import counted

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["main"]

PROG = "rsstp-replay"
_FAIL_ON = (
    "contract",
    "contradiction",
    "nondeterministic",
    "not-learned",
    "aliasing",
    "redundancy",
    "not-equivalent",
)
_TRUTH_GATES = ("not-learned", "aliasing", "redundancy", "not-equivalent")


def _open(path: str) -> Recording:
    """Open a recording; an unfinished file's warning is shown, as one line (``run_command``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("always", UnfinishedRecordingWarning)
        return open_recording(path)


def _cmd_info(args: argparse.Namespace) -> int:
    from rsstp_replay.audits.summary import strategy_stop

    with _open(args.file) as recording:
        record = recording.scenario_record
        scenario = recording.scenario
        size = os.path.getsize(recording.path)
        chunks = recording.verify_chunks()  # a chunk that fails its CRC is an error, not "finished"
        state = (
            f"finished, {counted(chunks, 'chunk')} checked"
            if recording.finished
            else f"NOT finished (recovered from its {counted(chunks, 'complete chunk')})"
        )
        print(f"file: {recording.path} ({size:,} bytes, {state})")
        print(f"scenario: {record.name} ({record.description})")
        for line in body_of(scenario).describe(scenario):
            print(line)
        params = json.dumps(recording.strategy_params, sort_keys=True)
        strategy = record.strategy
        origin = " ".join(filter(None, (strategy.distribution, strategy.version)))
        print(
            f"strategy: {recording.strategy} {params}; seed: {recording.seed}\n"
            f"  class: {strategy.import_path}" + (f" (from {origin})" if origin else "")
        )
        print(
            f"steps: 0 to {recording.n_steps:,} (the reset, then "
            f"{counted(recording.n_steps, 'step')})"
        )
        stop = strategy_stop(recording.events())
        if stop is not None:
            print(f"  {stop.to_text()}")
        print("topics:")
        width = max(map(len, recording.topic_counts))
        for topic, count in recording.topic_counts.items():
            print(f"  {topic:<{width}}  {count:>12,}")
        model = recording.model_at(recording.n_steps)
        kind = "deterministic" if model.is_deterministic() else "nondeterministic"
        if not recording.has_model:
            print(f"model: {_NO_MODEL}")
        else:
            print(
                f"model at the end: version {model.version:,}, {counted(len(model), 'state')}, "
                f"{counted(len(model.transitions()), 'transition')}, {kind}"
            )
        schemas = ", ".join(f"{name} {v}" for name, v in recording.schema_versions.items())
        print(f"schemas: {schemas}")
        meta = recording.metadata
        print(
            f"written by: rsstp {meta['package_version']} (Python {meta['python']}, "
            f"numpy {meta['numpy']}, mcap {meta['mcap']})"
        )
        print(_metadata_text(recording))
    return 0


def _check_table_output(out: Path, *, force: bool) -> None:
    """One line for a table path we cannot or must not write (before reading anything): a
    CSV's dtype sidecar too."""
    if out.suffix.lower() not in TABLE_FORMATS:
        raise UsageError(
            f"{out}: unknown table format {out.suffix or '(no suffix)'!r}: expected "
            f"{' or '.join(TABLE_FORMATS)}"
        )
    check_output(out, force=force)
    if out.suffix.lower() == ".csv":
        check_output(sidecar_path(out), force=force)


def _write_table(table: pd.DataFrame, out: Path) -> None:
    """Write ``table`` whole (:func:`rsstp_replay.export.table_files.write_table`): a failed
    write leaves no partial table and the old one untouched."""
    _wrote(len(table), table, out, write_table(table, out))


def _wrote(rows: int, table: pd.DataFrame, out: Path, written: list[Path]) -> None:
    index = f" (index {table.index.name})" if table.index.name is not None else ""
    sidecar = f"; dtypes in {written[1]}" if len(written) > 1 else ""
    print(f"wrote {rows:,} rows and {len(table.columns)} columns{index} to {out}{sidecar}")


def _cmd_table(args: argparse.Namespace) -> int:
    out = Path(args.output)
    if args.truth and args.what != "steps":
        raise UsageError(f"table: --truth adds to the steps table, not to --what {args.what}")
    _check_table_output(out, force=args.force)
    with _open(args.file) as recording:
        if args.what == "steps" and not args.truth and out.suffix.lower() == ".parquet":
            # Written a part at a time while the next is decoded.
            head = write_table_parts(recording.step_parts(), out)
            _wrote(recording.n_steps + 1, head, out, [out])
            return 0
        table = recording_table(
            recording, args.what, truth=args.truth, truth_cache=not args.no_cache
        )
    _write_table(table, out)
    return 0


def _cmd_events(args: argparse.Namespace) -> int:
    from rsstp_replay.reader.recording import EVENT_KINDS

    out = Path(args.output)
    _check_table_output(out, force=args.force)
    unknown = sorted(set(args.kind or ()) - set(EVENT_KINDS))
    if unknown:
        raise UsageError(
            f"events: unknown kind {unknown[0]!r}: expected one of {', '.join(EVENT_KINDS)}"
        )
    with _open(args.file) as recording:
        table = recording.events()
    if args.kind:
        table = table.loc[table["kind"].isin(args.kind)].reset_index(drop=True)
    _write_table(table, out)
    return 0


_NO_MODEL = "none recorded (the agent kept no model; read as the one-state model)"


def _cmd_audit(args: argparse.Namespace) -> int:
    from rsstp_replay.audits import audit_truth, run_audits
    from rsstp_replay.audits.explanation import explain
    from rsstp_replay.audits.loaded import load
    from rsstp_replay.audits.physics import check_physics

    fail_on = set(args.fail_on or [])
    if "contract" not in (args.allow or []):  # a broken rule fails the audit unless allowed
        fail_on.add("contract")
    needs_truth = fail_on & set(_TRUTH_GATES)
    if needs_truth and not args.truth:
        raise UsageError(f"--fail-on {sorted(needs_truth)[0]} needs --truth")
    stages = 3 if args.truth else 2
    with (
        _open(args.file) as recording,
        progress(stages, "reading", unit="stage", quiet=args.quiet) as bar,
    ):
        loaded = load(recording)  # the steps decoded once for every audit
        bar.to(1)
        bar.stage("auditing")
        report = run_audits(loaded, consistency_steps=args.consistency_steps or None)
        physics = check_physics(recording, loaded.steps(), events=loaded.events())
        bar.to(2)
        truth = explanation = None
        if args.truth:
            bar.stage("comparing with the truth")
            ground_truth = recording.ground_truth(cache=not args.no_cache)
            truth = audit_truth(loaded, truth=ground_truth, within_versions=report.within_versions)
            explanation = explain(
                loaded.memory(),
                loaded.model_versions(),
                phases=report.summary.phases,
                feedback_mode=recording.scenario.feedback_mode,
                truth=ground_truth,
                true_class=truth.true_class,
                learned=truth.verdict.learned,
            )
            bar.to(3)
    if args.json:
        document = {
            "model_recorded": recording.has_model,
            **report.to_json(),
            "physics": physics.to_json(),
        }
        if truth is not None and explanation is not None:
            document = {
                "verdict": truth.verdict.to_json(),
                "explanation": explanation.to_json(),
                **document,
                "truth": truth.to_json(),
            }
        print(indented(document))
    else:
        if truth is not None and explanation is not None:
            print(f"{truth.verdict.to_text()}\n")
            print(f"== where the steps went ==\n{explanation.to_text()}\n")
        if not recording.has_model:
            print(f"model: {_NO_MODEL}\n")
        text = report.to_text()
        print(text, end="" if text.endswith("\n") else "\n")
        print(physics.to_text())
        if truth is not None:
            print("\n== truth ==")
            print(truth.to_text(verdict=False), end="")
    findings = {
        "contract": (
            not report.contract.holds or not physics.holds,
            "the steps break the recording contract"
            if not report.contract.holds
            else "the recorded world does not follow from its scenario and actions",
        ),
        "contradiction": (
            report.has_contradiction,
            "the memory contradicts a state of the final model version",
        ),
        "nondeterministic": (report.has_nondeterminism, "the final model is nondeterministic"),
    }
    if truth is not None:
        # Over the whole history, as the README's accumulated figures (the per-version ones
        # are in the JSON and the verdict).
        findings |= {
            "not-learned": (not truth.verdict.learned, truth.verdict.line()),
            "aliasing": (bool(truth.aliased), "an internal state stood for several true classes"),
            "redundancy": (bool(truth.redundant), "a true class was split over several states"),
            "not-equivalent": (
                not truth.verdict.learned,
                "the final model is not equivalent to the truth",
            ),
        }
    failed = [text for reason, (found, text) in findings.items() if reason in fail_on and found]
    if failed:
        print(f"{PROG}: audit failed: {'; '.join(failed)}", file=sys.stderr)
        return 1
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from rsstp_replay.audits import check_contract
    from rsstp_replay.audits.physics import check_physics

    with _open(args.file) as recording:
        findings = check_contract(recording)  # reads and checks every step and model message
        events = len(recording.events())
        versions = len(recording.model_versions())
        physics = check_physics(recording) if args.physics else None
    if args.json:
        document = findings.to_json()
        document = {**document, "metadata_verified": recording.metadata_verified}
        if physics is not None:
            document = {**document, "physics": physics.to_json()}
        print(indented(document))
    else:
        print(
            f"{recording.path}: {counted(recording.n_steps + 1, 'step')}, "
            f"{counted(versions, 'model version')}, {counted(events, 'event')}: every chunk read "
            "and checked"
        )
        print(_metadata_text(recording))
        print(findings.to_text())
        if physics is not None:
            print(physics.to_text())
    return 0 if findings.holds and (physics is None or physics.holds) else 1


def _metadata_text(recording: Recording) -> str:
    if recording.metadata_verified:
        return "metadata: verified by its checksum"
    from rsstp_format.schemas import parse_version

    version = max(recording.schema_versions.values(), key=parse_version)
    return (
        f"metadata: unverified (a schema {version} recording, written before the metadata "
        "carried a checksum)"
    )


def _cmd_compare(args: argparse.Namespace) -> int:
    from rsstp_replay.audits import compare

    with _open(args.file) as recording:
        for name, step in (("N", args.n), ("M", args.m)):
            if not 0 <= step <= recording.n_steps:
                raise StepOutOfRange(
                    f"{recording.path}: compare {name} = {step} is out of range: the recording "
                    f"has steps 0 to {recording.n_steps}"
                )
        if args.n == args.m:
            raise UsageError(f"compare: N and M must differ (both are {args.n})")
        findings = compare(recording, args.n, args.m)
    if args.json:
        print(indented(findings.to_json()))
    else:
        print(findings.to_text())
    return 0


def _cmd_view(args: argparse.Namespace) -> int:
    from rsstp_replay.viewer import (
        ViewerWarning,
        ViewResult,
        check_port,
        ctrl_c_remembered,
        has_display,
        rerun_command,
        view,
    )

    save = Path(args.save) if args.save is not None else None
    spawn = args.spawn or (save is None and not args.serve_web)
    if spawn and not has_display():
        raise UsageError(
            "view: no display for a native viewer (neither DISPLAY nor WAYLAND_DISPLAY is set): "
            "write a file with --save OUT.rrd, or serve the web viewer with --serve-web"
        )
    if save is not None:
        check_output(save, force=args.force)
    if args.serve_web:  # before anything is read: a port in use is one line
        check_port(args.bind, args.web_port, option="--web-port")
        check_port(args.bind, args.grpc_port, option="--grpc-port")
    with ctrl_c_remembered() as pressed:  # a Ctrl-C lost in a finaliser still stops serving
        result: ViewResult | None = None
        try:  # once the server runs, Ctrl-C at any moment stops it and removes its file
            with (
                _open(args.file) as recording,
                warnings.catch_warnings(record=True) as caught,
                progress(
                    1, "reading, auditing, logging to Rerun", unit="view", quiet=args.quiet
                ) as bar,
            ):
                warnings.simplefilter("always", ViewerWarning)
                result = view(
                    recording,
                    save=save,
                    spawn=spawn,
                    serve_web=args.serve_web,
                    start=args.start,
                    end=args.end,
                    bind=args.bind,
                    web_port=args.web_port,
                    grpc_port=args.grpc_port,
                )
                bar.to(1)
            for warning in caught:  # after the progress bar, not through it
                print(warning_line(PROG, warning.message), file=sys.stderr)
            print(result.to_text())
            if save is not None:
                print(f"open it with: {shlex.quote(rerun_command())} {shlex.quote(str(save))}")
            if args.serve_web:
                print(f"serving on {args.bind} until Ctrl-C", flush=True)
                result.serve_forever(pressed)
        except KeyboardInterrupt:
            if result is None or not args.serve_web:  # still reading: "interrupted"
                raise
        finally:
            if result is not None:
                result.close()
    if args.serve_web:
        print("stopped serving")
    return 0


def _cmd_graph(args: argparse.Namespace) -> int:
    from rsstp_replay.viewer import render_graph

    out = Path(args.output)
    check_output(out, force=args.force)
    with _open(args.file) as recording:
        written = render_graph(recording, args.step, out, on_world=args.on_world)
    where = "on the world" if args.on_world else "laid out as in every version"
    print(f"wrote {written} (the model at step {args.step}, {where})")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from rsstp_replay.export.foxglove import export_foxglove

    out = Path(args.output)
    if out.suffix.lower() != ".mcap":
        raise UsageError(
            f"{out}: a Foxglove scene is an .mcap file, not {out.suffix or '(no suffix)'!r}"
        )
    if out.resolve() == Path(args.foxglove).resolve():
        raise UsageError(f"{out}: is the recording being exported: give another output")
    check_output(out, force=args.force)
    with _open(args.foxglove) as recording:
        print(export_foxglove(recording, out).to_text())
    return 0


_CONSISTENCY_STEPS = 1 << 21
"""``rsstp_replay.audits.consistency.MAX_STEPS``, without importing the audits at start-up (a
test checks they agree)."""


def _count(text: str) -> int:
    value = _integer(text)
    if value < 0 or value == 1:
        raise argparse.ArgumentTypeError(f"expected 0 (every step) or at least 2, got {value}")
    return value


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None


def _table_parser(sub: Any, name: str, description: str) -> Parser:
    """A subcommand that writes a table: the recording, ``-o`` and ``--force``."""
    p: Parser = sub.add_parser(name, help=description)
    p.add_argument("file", help="the .mcap recording")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="the table: .parquet, or .csv (with its dtypes in OUT.csv.dtypes.json)",
    )
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    return p


def _build_parser() -> Parser:
    parser = Parser(prog=PROG, description="Read, export and audit RSSTP recordings (MCAP).")
    from rsstp_sim import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    p = sub.add_parser("info", help="what a recording holds: scenario, strategy, steps, topics")
    p.add_argument("file", help="the .mcap recording")
    p.set_defaults(func=_cmd_info)

    p = _table_parser(
        sub, "table", "write a table: the steps (one row per step), model, events or scenario"
    )
    p.add_argument(
        "--what",
        choices=TABLES,
        default="steps",
        help="which table: steps (one row per step, indexed by step; the default), model (one "
        "row per transition of every model version), events (one row per event) or scenario "
        "(one row)",
    )
    p.add_argument(
        "--truth",
        action="store_true",
        help="add the ground truth of every step: true_class, pose (index among the reachable "
        "poses) and aliased (its internal state stood for several true classes under its "
        "model version)",
    )
    add_no_cache(p)
    p.set_defaults(func=_cmd_table)

    p = _table_parser(sub, "events", "write the events table (one row per event)")
    p.add_argument(
        "--kind",
        action="append",
        metavar="KIND",
        help="only events of this kind (repeatable): blocked, no_transition, split, merge, add, "
        "delete, note, contradiction",
    )
    p.set_defaults(func=_cmd_events)

    p = sub.add_parser("audit", help="consistency, determinism and summary audits")
    p.add_argument("file", help="the .mcap recording")
    p.add_argument("--quiet", action="store_true", help="no progress bar (none when piped)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument(
        "--truth",
        action="store_true",
        help="open with the verdict (learned, from which step, or why not) and compare every "
        "model version with the ground truth (aliasing, redundancy, equivalence)",
    )
    p.add_argument(
        "--fail-on",
        action="append",
        choices=_FAIL_ON,
        help="exit with 1 when such a finding exists (repeatable; a broken contract or "
        "physics always does, unless allowed)",
    )
    p.add_argument(
        "--allow",
        action="append",
        choices=("contract",),
        help="exit with 0 even when the recording breaks the contract or its physics",
    )
    p.add_argument(
        "--consistency-steps",
        type=_count,
        default=_CONSISTENCY_STEPS,
        metavar="N",
        help=f"judge contradictions in the last N steps of a longer run, and say so (default "
        f"{_CONSISTENCY_STEPS:,}; 0: every step, minutes and gigabytes past ten million)",
    )
    add_no_cache(p)
    p.set_defaults(func=_cmd_audit)

    p = sub.add_parser("view", help="stream a recording to the Rerun viewer or an .rrd file")
    p.add_argument("file", help="the .mcap recording")
    p.add_argument("--quiet", action="store_true", help="no progress bar (none when piped)")
    p.add_argument(
        "--save", metavar="OUT.rrd", help="write an .rrd file (open it with: rerun OUT.rrd)"
    )
    p.add_argument("--spawn", action="store_true", help="open the native viewer")
    p.add_argument(
        "--serve-web", action="store_true", help="serve the web viewer (on 127.0.0.1 by default)"
    )
    p.add_argument(
        "--bind",
        default="127.0.0.1",
        metavar="ADDR",
        help="the address --serve-web listens on (default 127.0.0.1; 0.0.0.0 for every interface)",
    )
    p.add_argument("--web-port", type=_integer, default=9090, help="the web page's port")
    p.add_argument("--grpc-port", type=_integer, default=9877, help="the data's port")
    p.add_argument("--from", dest="start", type=_integer, metavar="STEP", help="first step")
    p.add_argument("--to", dest="end", type=_integer, metavar="STEP", help="last step (inclusive)")
    p.add_argument("--force", action="store_true", help="overwrite an existing .rrd file")
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser("graph", help="draw the model at a step (same node positions as the viewer)")
    p.add_argument("file", help="the .mcap recording")
    p.add_argument("--step", type=_integer, required=True, help="the step")
    p.add_argument("-o", "--output", required=True, help="output: .svg, .png, .pdf or .dot")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.add_argument(
        "--on-world",
        action="store_true",
        help="put every state where the arm's tip was while the agent was in it (as the viewer "
        "does) instead of the thesis-style layout",
    )
    p.set_defaults(func=_cmd_graph)

    p = sub.add_parser(
        "check", help="check a recording's meaning: every step against its model version"
    )
    p.add_argument("file", help="the .mcap recording")
    p.add_argument("--json", action="store_true", help="print the findings as JSON")
    p.add_argument(
        "--physics",
        action="store_true",
        help="also re-simulate the world from the attached scenario and the recorded actions "
        "and compare every ground-truth field at every step (no strategy code runs)",
    )
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("compare", help="the thesis's compare of the sub-memories at N and M")
    p.add_argument("file", help="the .mcap recording")
    p.add_argument("n", type=_integer, metavar="N", help="first start step")
    p.add_argument("m", type=_integer, metavar="M", help="second start step")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_compare)

    p = sub.add_parser("export", help="write a recording for another viewer: a Foxglove scene")
    p.add_argument(
        "--foxglove",
        required=True,
        metavar="FILE",
        help="the .mcap recording to write as a Foxglove scene (SceneUpdate, FrameTransforms, Log)",
    )
    p.add_argument("-o", "--output", required=True, help="the scene file (.mcap)")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(func=_cmd_export)

    from rsstp_cli.sweep import add_report_parser  # the sweep's report (no Dask needed)

    add_report_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (0 ok, 1 an audit failed, 2 bad input)."""
    # Rerun's native logs (gRPC retries, its file writer's errors) would add lines of their
    # own to ours; they stay off unless the user sets RUST_LOG.
    os.environ.setdefault("RUST_LOG", "off")
    return run_command(PROG, _build_parser(), argv)


if __name__ == "__main__":
    sys.exit(main())
