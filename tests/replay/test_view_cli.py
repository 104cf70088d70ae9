"""``rsstp-replay view`` and ``graph`` on a real recording (no viewer: .rrd files only)."""

from __future__ import annotations

import os
import select
import shlex
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "recordings" / "thesis-roulette-script.mcap"
LEARNER = ROOT / "recordings" / "two-joint-30-learner.mcap"


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", *args],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "HOME": "/tmp"},
        timeout=HANG_S,
    )


def test_view_saves_an_rrd_and_says_how_to_open_it(tmp_path: Path) -> None:
    out = tmp_path / "run.rrd"
    done = run_cli("view", str(REFERENCE), "--save", str(out))
    assert done.returncode == 0, done.stderr
    assert out.stat().st_size > 0
    assert out.read_bytes()[:4] == b"RRF2"  # Rerun's file magic
    # PATH without the venv's bin (not activated): the printed command runs as printed
    rerun = str(Path(sys.executable).parent / "rerun")
    assert f"open it with: {rerun} {out}" in done.stdout
    shown = next(line for line in done.stdout.splitlines() if line.startswith("open it with"))
    verified = subprocess.run(
        [*shlex.split(shown.removeprefix("open it with: "))[:1], "rrd", "verify", str(out)],
        capture_output=True, text=True, timeout=HANG_S, env={"PATH": "/usr/bin:/bin"},
    )  # fmt: skip
    assert verified.returncode == 0, verified.stderr
    again = run_cli("view", str(REFERENCE), "--save", str(out))
    assert again.returncode == 2
    assert (
        again.stderr.strip()
        == f"rsstp-replay: error: {out}: already exists (use --force to overwrite)"
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--from", "5", "--to", "500"], "the end step 500 is out of range"),
        (
            ["--save", "/nonexistent/dir/x.rrd"],
            "the output directory /nonexistent/dir does not exist",
        ),
    ],
)
def test_view_bad_arguments_are_one_line(args: list[str], message: str, tmp_path: Path) -> None:
    save = [] if "--save" in args else ["--save", str(tmp_path / "x.rrd")]
    done = run_cli("view", str(REFERENCE), *save, *args)
    assert done.returncode == 2
    assert message in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


def test_graph_draws_the_model_at_a_step(tmp_path: Path) -> None:
    """Graphviz in process (no ``dot`` on this PATH is needed), and nothing of what it prints
    on the way reaches stderr."""
    out = tmp_path / "model.svg"
    done = run_cli("graph", str(REFERENCE), "--step", "10", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert out.read_text().lstrip().startswith(("<?xml", "<svg", "<!DOCTYPE"))
    bad = run_cli("graph", str(REFERENCE), "--step", "1000", "-o", str(tmp_path / "m.svg"))
    assert bad.returncode == 2 and "out of range" in bad.stderr


_FAILING_GRAPHVIZ = """
import os, runpy, sys
from pygraphviz import graphviz as gv

def fail(context, handle, engine):
    os.write(2, b"Error: " + engine + b" gave up\\n")
    return -1

gv.gvLayout = fail
sys.argv = ["rsstp-replay", *sys.argv[1:]]
runpy.run_module("rsstp_cli.replay", run_name="__main__")
"""


@pytest.mark.parametrize(
    ("extra", "engine", "what"),
    [((), "sfdp", "the layout of every model version"), (("--on-world",), "nop2", "a model of")],
)
def test_a_graphviz_failure_is_one_line(
    tmp_path: Path, extra: tuple[str, ...], engine: str, what: str
) -> None:
    """Graphviz's layout failing inside the library, as it does (its error on file descriptor
    2, status -1; the learner's union of versions has over 400 state pairs, so sfdp lays it
    out): one line naming the engine and Graphviz's error, exit 2, nothing written."""
    out = tmp_path / "model.svg"
    done = subprocess.run(
        [sys.executable, "-c", _FAILING_GRAPHVIZ, "graph", str(LEARNER), "--step", "8000",
         "-o", str(out), *extra],
        capture_output=True, text=True, timeout=HANG_S,
        env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
    )  # fmt: skip
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert lines[0].startswith(f"rsstp-replay: error: Graphviz ({engine}) failed drawing {what}")
    assert lines[0].endswith(f": Error: {engine} gave up; write .dot instead to keep the graph")
    assert not out.exists()


# ------------------------------------------------------------------- headless and the web


def test_view_without_a_display_says_what_to_do_at_once() -> None:
    """No DISPLAY (as in CI): no wait for a viewer that cannot start, one line, exit 2."""
    for extra in ((), ("--spawn",)):
        done = run_cli("view", str(REFERENCE), *extra)  # run_cli's environment has no display
        assert done.returncode == 2
        assert done.stderr.strip() == (
            "rsstp-replay: error: view: no display for a native viewer (neither DISPLAY nor "
            "WAYLAND_DISPLAY is set): write a file with --save OUT.rrd, or serve the web viewer "
            "with --serve-web"
        )


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def test_serve_web_refuses_a_port_in_use_in_one_line() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        for option, other in (("--web-port", "--grpc-port"), ("--grpc-port", "--web-port")):
            done = run_cli(
                "view", str(REFERENCE), "--serve-web", option, str(port), other, str(_free_port())
            )
            assert done.returncode == 2
            assert done.stderr.strip() == (
                f"rsstp-replay: error: port {port} on 127.0.0.1 is in use: choose another with "
                f"{option} N"
            )


def _listening(port: int) -> set[str]:
    """The local addresses (hex, as in /proc/net/tcp) listening on ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not Path(table).exists():
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, hex_port = fields[1].rsplit(":", 1)
            if fields[3] == "0A" and int(hex_port, 16) == port:
                found.add(address)
    return found


def _serve(web: int, grpc: int, tmp_path: Path) -> subprocess.Popen[str]:
    """``rsstp-replay view REFERENCE --serve-web`` on these ports, its temporary files in
    ``tmp_path``."""
    return subprocess.Popen(
        [sys.executable, "-m", "rsstp_cli.replay", "view", str(REFERENCE), "--serve-web"]
        + ["--web-port", str(web), "--grpc-port", str(grpc)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(tmp_path)},
    )


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="needs Linux's /proc/net/tcp")
def test_ctrl_c_as_the_server_starts_leaves_no_server(tmp_path: Path) -> None:
    """SIGINT the moment the port listens, before the command has said so: whether it ends
    as "interrupted" (130) or as a stopped server (0), no server and no file stay behind."""
    web, grpc = _free_port(), _free_port()
    server = _serve(web, grpc, tmp_path)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not _listening(web) and server.poll() is None:
        time.sleep(0.01)
    server.send_signal(signal.SIGINT)
    try:
        _, err = server.communicate(timeout=HANG_S)
    except subprocess.TimeoutExpired:
        server.kill()
        _, err = server.communicate()
        pytest.fail(f"still running 60 s after Ctrl-C: {err[-500:]}")
    assert server.returncode in (0, 130), err
    assert "Traceback" not in err
    time.sleep(0.5)  # the server's child has had its SIGTERM; give the kernel a moment
    assert not _listening(web) and not _listening(grpc)
    assert not list(tmp_path.glob("rsstp-view-*"))


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="needs Linux's /proc/net/tcp")
@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP], ids=str)
def test_serve_web_listens_on_loopback_and_stops_on_ctrl_c(
    stop: signal.Signals, tmp_path: Path
) -> None:
    """A real server: once it says it serves, the page answers on 127.0.0.1, nothing listens
    on another address, and SIGINT (or SIGTERM, SIGHUP) stops both servers with exit 0 and
    removes the temporary file it served. (A Ctrl-C before that line, while the file is read,
    is "interrupted", exit 130.)"""
    web, grpc = _free_port(), _free_port()
    server = _serve(web, grpc, tmp_path)
    said = b""  # read from the pipe itself: a text reader's buffer would hide what it holds
    try:
        assert server.stdout is not None
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and b"until Ctrl-C" not in said:
            assert server.poll() is None, server.communicate()[1]
            if select.select([server.stdout], [], [], 0.2)[0]:
                said += os.read(server.stdout.fileno(), 4096)
        assert b"until Ctrl-C" in said, said  # the server is up
        assert _listening(web) == {"0100007F"}  # 127.0.0.1 only
        assert _listening(grpc) == {"0100007F"}
        page = urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=HANG_S).read()
        assert b"<html" in page.lower()
        assert list(tmp_path.glob("rsstp-view-*/view.rrd"))
    finally:
        server.send_signal(stop)
        try:
            out, err = server.communicate(timeout=HANG_S)
        except subprocess.TimeoutExpired:  # fail this test alone: leave nothing running
            server.kill()
            out, err = server.communicate()
            pytest.fail(f"still serving 60 s after Ctrl-C: {err[-500:]}")
    out = said.decode() + out
    assert server.returncode == 0, err
    assert "serving the web viewer at http://127.0.0.1:" in out and "stopped serving" in out
    assert "Traceback" not in err
    assert not list(tmp_path.glob("rsstp-view-*"))
    time.sleep(0.5)  # the server's child has had its SIGTERM; give the kernel a moment
    assert not _listening(web) and not _listening(grpc)


def test_a_file_size_limit_never_leaves_a_truncated_rrd(tmp_path: Path) -> None:
    """EFBIG while saving (RLIMIT_FSIZE in the child): one line, exit 1, and the .rrd that
    was there is untouched; no side file stays."""
    import resource

    out = tmp_path / "run.rrd"
    first = run_cli("view", str(REFERENCE), "--save", str(out))
    assert first.returncode == 0, first.stderr
    before = out.read_bytes()

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "view", str(LEARNER), "--save", str(out),
         "--force", "--quiet"],
        capture_output=True, text=True, timeout=HANG_S, preexec_fn=small_files,
        env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "HOME": "/tmp"},
    )  # fmt: skip
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert lines == [f"rsstp-replay: error: {out}: cannot write: File too large"], done.stderr
    assert out.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]
