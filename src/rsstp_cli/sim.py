"""``rsstp-sim``: list scenarios, run strategies, draw models.

Bad input gets one line on stderr naming the problem and exit code 2; never a
traceback.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rsstp_cli._commandline import (
    Parser,
    UsageError,
    add_no_cache,
    progress,
    run_command,
    warning_line,
)
from rsstp_cli._json import indented
from rsstp_sim import graph
from rsstp_sim.bodies import body_of
from rsstp_sim.errors import RecordingWriteError
from rsstp_sim.files import check_output
from rsstp_sim.nesting import too_deep
from rsstp_sim.runner import Runner, stop_text
from rsstp_sim.scenario import AnyScenario, builtin_scenarios, load_scenario
from rsstp_sim.strategies import builtin_strategies, make_strategy
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.words import counted

__all__ = ["main"]

PROG = "rsstp-sim"


_JSON_STARTS = frozenset('[{"-0123456789')
"""A value starting with one of these is JSON or an error; any other text is a string."""


def _parse_params(items: Sequence[str]) -> dict[str, Any]:
    """``key=value`` pairs; values are JSON when they parse as JSON, else strings."""
    params: dict[str, Any] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        if not sep or not key:
            raise UsageError(f"--param expects key=value, got {item!r}")
        deep = too_deep(raw)
        if deep is not None:
            raise UsageError(f"--param {key}: {deep}")
        try:
            params[key] = json.loads(raw)
        except json.JSONDecodeError as exc:
            if raw.lstrip()[:1] in _JSON_STARTS:  # meant as JSON: say where it breaks
                raise UsageError(f"--param {key}: not valid JSON ({exc}): {raw!r}") from None
            params[key] = raw
    return params


def _add_run_arguments(parser: argparse.ArgumentParser, *, steps_default: int) -> None:
    parser.add_argument("scenario", help="a built-in scenario name or a scenario .toml file")
    parser.add_argument(
        "--quiet", action="store_true", help="no progress bar (none is shown when piped either)"
    )
    parser.add_argument(
        "--strategy",
        default="random",
        help=f"a built-in strategy ({', '.join(builtin_strategies())}), an installed plugin "
        "(see: rsstp-sim strategies) or package.module:Class; default random",
    )
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="strategy parameter (JSON value), repeatable; e.g. actions=[0,1]",
    )
    parser.add_argument(
        "--steps",
        type=_non_negative,
        default=steps_default,
        help=f"the budget of steps (default {steps_default}; a strategy may stop earlier)",
    )
    parser.add_argument("--seed", type=_non_negative, default=0, help="seed (default 0)")


def _non_negative(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def _chunk_size(text: str) -> int:
    value = _non_negative(text)
    if value < 1024:
        raise argparse.ArgumentTypeError(f"expected at least 1024 bytes, got {text!r}")
    return value


_MEMORY_BYTES_PER_STEP = 32
"""What a run's memory holds per step (action, state, sensation, feedback: 21 bytes) with
the slack of its doubling arrays."""
_DISK_BYTES_PER_STEP = 16
"""Fewer bytes than any recording takes per step (the smallest scenarios take about 20)."""


def _check_steps_fit(steps: int, output: Path | None = None) -> None:
    """Refuse at once a run this machine cannot hold: its memory in RAM, its recording on
    the output's disk."""
    import shutil

    ram = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    need = steps * _MEMORY_BYTES_PER_STEP
    if need > ram:
        raise UsageError(
            f"--steps {steps:,}: the run's memory needs about {_size(need)}, more than this "
            f"machine's {_size(ram)} of RAM"
        )
    if output is not None:
        parent = output.parent if str(output.parent) else Path(".")
        if parent.is_dir() and os.access(parent, os.W_OK):  # else the recorder says why
            free = shutil.disk_usage(parent).free
            if steps * _DISK_BYTES_PER_STEP > free:
                raise UsageError(
                    f"--steps {steps:,}: the recording needs at least "
                    f"{_size(steps * _DISK_BYTES_PER_STEP)}; {parent} has {_size(free)} free"
                )


def _size(n_bytes: int) -> str:
    if n_bytes < 1024:
        return f"{n_bytes:,} bytes"
    power = min(4, (n_bytes.bit_length() - 1) // 10)
    return f"{n_bytes / 1024**power:,.1f} {('KiB', 'MiB', 'GiB', 'TiB')[power - 1]}"


def _warn_about(scenario: AnyScenario) -> None:
    """Warnings a scenario earns before it runs (its body's, :meth:`Body.warnings`)."""
    for text in body_of(scenario).warnings(scenario):
        print(warning_line(PROG, text), file=sys.stderr)


def _runner(args: argparse.Namespace) -> Runner:
    scenario = load_scenario(args.scenario)
    _warn_about(scenario)
    strategy = make_strategy(args.strategy, _parse_params(args.param))
    return Runner(scenario, strategy, seed=args.seed)


def _cmd_scenarios(args: argparse.Namespace) -> int:
    scenarios = builtin_scenarios()
    width = max(map(len, scenarios))
    for name, description in scenarios.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _cmd_strategies(args: argparse.Namespace) -> int:
    from rsstp_sim.strategies import ENTRY_POINT_GROUP, plugin_strategies

    for name in builtin_strategies():
        print(f"{name:<12} built-in")
    for name, origin in plugin_strategies().items():
        print(f"{name:<12} {origin}")
    print(
        f"(a plugin declares [project.entry-points.{ENTRY_POINT_GROUP!r}] name = "
        f'"package.module:Class"; any class is also --strategy package.module:Class)'
    )
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    _check_steps_fit(args.steps)
    runner = _runner(args)
    started = time.perf_counter()
    with progress(args.steps, "running", quiet=args.quiet) as bar:
        summary = runner.run(args.steps, progress=bar.to)
    seconds = time.perf_counter() - started
    print(f"scenario: {runner.scenario.name}  strategy: {args.strategy}  seed: {args.seed}")
    print(summary.to_text())
    rate = f" ({summary.steps / seconds:,.0f} steps/s)" if seconds > 0 and summary.steps else ""
    print(f"time: {seconds:.2f} s{rate}")
    return 0


def _cmd_graph(args: argparse.Namespace) -> int:
    check_output(Path(args.output), force=args.force)
    if args.matrix is not None:
        deep = too_deep(args.matrix)
        if deep is not None:
            raise UsageError(f"--matrix: {deep}")
        try:
            matrix = json.loads(args.matrix)
        except json.JSONDecodeError as exc:
            raise UsageError(f"--matrix is not JSON: {exc}") from None
        if not isinstance(matrix, list):
            raise UsageError("--matrix must be a JSON list of lists of action lists")
        model = TransitionSystem.from_matrix(matrix)
    else:
        if args.scenario is None:
            raise UsageError("graph needs a SCENARIO or --matrix")
        runner = _runner(args)
        runner.run(args.steps)
        model = runner.model
    out = Path(args.output)
    written = graph.render(model, out)
    print(f"wrote {written} ({counted(len(model), 'state')})")
    return 0


def _cmd_record(args: argparse.Namespace) -> int:
    from rsstp_sim.recording.recorder import Recorder

    _check_steps_fit(args.steps, Path(args.output))
    scenario = load_scenario(args.scenario)
    _warn_about(scenario)
    strategy = make_strategy(args.strategy, _parse_params(args.param))
    recorder = Recorder(
        args.output,
        scenario,
        strategy,
        seed=args.seed,
        chunk_size=args.chunk_size,
        force=args.force,
        compact=args.compact,
    )
    received: list[int] = []

    def stop(signum: int, _frame: object) -> None:
        received.append(signum)
        recorder.request_stop()

    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        with progress(args.steps, "recording", quiet=args.quiet) as bar:
            result = recorder.run(args.steps, progress=bar.to)
    except RecordingWriteError as exc:  # the disk failed, not the input: exit 1
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    counts = ", ".join(f"{topic} {count:,}" for topic, count in result.messages.items())
    if result.interrupted:
        name = signal.Signals(received[0]).name if received else "a stop request"
        print(
            f"{PROG}: interrupted by {name}: kept {counted(result.steps, 'step')} in {result.path} "
            f"(file finished)",
            file=sys.stderr,
        )
        return 128 + received[0] if received else 1
    if result.stopped is not None:
        print(f"{stop_text(result.steps, result.budget)}: {result.stopped}")
    print(f"recorded {counted(result.steps, 'step')} to {result.path} ({counts})")
    return 0


def _cmd_truth(args: argparse.Namespace) -> int:
    from rsstp_sim.truth import format_truth
    from rsstp_sim.truth.cache import cache_info, load_truth

    if args.cache_info:
        info = cache_info()
        print(indented(info.to_json()) if args.json else info.to_text())
        return 0
    if args.scenario is None:
        raise UsageError("truth: name a scenario (or ask for --cache-info)")
    scenario = load_scenario(args.scenario)
    _warn_about(scenario)
    truth = load_truth(scenario, cache=not args.no_cache, max_poses=args.max_poses)
    if args.json:
        print(indented(truth.to_json()))
    else:
        print(format_truth(truth))
    return 0


def _build_parser() -> Parser:
    parser = Parser(prog=PROG, description="RSSTP simulator: scenarios, strategies, models.")
    from rsstp_sim import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    p = sub.add_parser("scenarios", help="list the built-in scenarios")
    p.set_defaults(func=_cmd_scenarios)

    p = sub.add_parser("strategies", help="list the built-in and installed strategies")
    p.set_defaults(func=_cmd_strategies)

    p = sub.add_parser("run", help="run a strategy and print a summary")
    _add_run_arguments(p, steps_default=1000)
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("graph", help="draw a model (the one a run ends with, or a thesis matrix)")
    p.add_argument("scenario", nargs="?", help="scenario to run first (omit with --matrix)")
    p.add_argument("--matrix", help="a thesis-format matrix as JSON, e.g. '[[[0],[1]],[[1],[0]]]'")
    p.add_argument("--strategy", default="random")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--steps", type=_non_negative, default=1000)
    p.add_argument("--seed", type=_non_negative, default=0)
    p.add_argument("-o", "--output", required=True, help="output file: .svg, .png, .pdf or .dot")
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(func=_cmd_graph)

    p = sub.add_parser("record", help="run a strategy and record every step to an MCAP file")
    _add_run_arguments(p, steps_default=1000)
    p.add_argument("-o", "--output", required=True, help="the .mcap file to write")
    p.add_argument(
        "--chunk-size",
        type=_chunk_size,
        default=1024 * 1024,
        metavar="BYTES",
        help="uncompressed bytes per MCAP chunk (default 1 MiB)",
    )
    p.add_argument(
        "--compact",
        action="store_true",
        help="no message indexes, chunks compressed harder: under half the size, for readers "
        "that read chunks through (rsstp-replay, Python mcap >= 1.4; not Foxglove: see "
        "docs/recording.md)",
    )
    p.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p.set_defaults(func=_cmd_record)

    p = sub.add_parser("truth", help="the ground truth: reachable poses and the minimal model")
    p.add_argument("scenario", nargs="?", help="a built-in scenario name or a scenario .toml file")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument(
        "--max-poses",
        type=_non_negative,
        default=2_000_000,
        help="refuse larger pose spaces (default 2,000,000)",
    )
    add_no_cache(p)
    p.add_argument(
        "--cache-info",
        action="store_true",
        help="say where the truth cache is, whether it can be written, and how big it is",
    )
    p.set_defaults(func=_cmd_truth)

    # The sweep records and audits: it sits above the simulator and the replay side, and is
    # imported only when the command runs.
    from rsstp_cli.sweep import add_sweep_parser

    add_sweep_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (0 ok, 2 bad input, 130 interrupted)."""
    return run_command(PROG, _build_parser(), argv)


if __name__ == "__main__":
    sys.exit(main())
