"""A sweep on 1 and on 2 local workers: the speed-up, and what the engine costs per run.

    python bench/sweep.py [--seeds 12] [--steps 20000]

The sweep: 2 scenarios (two-joint-30, one-joint-10) x 2 strategies (learner, random) x
``--seeds`` seeds x ``--steps`` steps, each run recorded and audited against the truth.
Each sweep is ``rsstp-sim sweep`` end to end in a fresh process (cold: imports, the cluster's
start and stop, every run), into a fresh folder. Targets: speed-up of 2 workers over 1 >= 1.7x
on a 2-core machine; the engine's overhead per run <= 50 ms.

The overhead per run is the 1-worker sweep's wall time, less the time the runs spent inside
their task (``seconds`` of runs.parquet) and less the cluster's start and stop (measured apart,
in a fresh process), divided by the runs: scheduling, shipping the run and its row, the
progress and the table.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

BIN = Path(sys.executable).parent

CLUSTER = """
import logging, time
began = time.perf_counter()
from distributed import Client, LocalCluster
cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                       dashboard_address=None, silence_logs=logging.ERROR)
with Client(cluster) as client:
    client.submit(sum, [1, 2]).result()
cluster.close()
print(time.perf_counter() - began)
"""


BURN = """
import time
t = time.perf_counter()
s = 0
for i in range(30_000_000):
    s += i * i
print(time.perf_counter() - t)
"""


def ceiling() -> float:
    """The machine's own parallel ceiling for pure-Python work: one loop alone against two
    copies at once, each in its own process (the speed-up no sweep engine can beat)."""
    alone = float(
        subprocess.run(
            [sys.executable, "-c", BURN], check=True, capture_output=True, text=True
        ).stdout
    )
    began = time.perf_counter()
    pair = [
        subprocess.Popen([sys.executable, "-c", BURN], stdout=subprocess.DEVNULL) for _ in range(2)
    ]
    for process in pair:
        process.wait()
    return 2 * alone / (time.perf_counter() - began)


def sweep_file(folder: Path, seeds: int, steps: int) -> Path:
    path = folder / "bench.toml"
    path.write_text(
        f"steps = {steps}\nseeds = {seeds}\n"
        'scenarios = ["two-joint-30", "one-joint-10"]\n'
        '[[strategy]]\nname = "learner"\n[[strategy]]\nname = "random"\n'
    )
    return path


def run(sweep: Path, out: Path, workers: int) -> tuple[float, pd.DataFrame]:
    began = time.perf_counter()
    subprocess.run(
        [str(BIN / "rsstp-sim"), "sweep", str(sweep), "-o", str(out), "--workers", str(workers),
         "--quiet"],
        check=True, capture_output=True,
    )  # fmt: skip
    return time.perf_counter() - began, pd.read_parquet(out / "runs.parquet")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("--steps", type=int, default=20_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        sweep = sweep_file(folder, args.seeds, args.steps)
        start_stop = [
            float(subprocess.run([sys.executable, "-c", CLUSTER], check=True,
                                 capture_output=True, text=True).stdout)
            for _ in range(3)
        ]  # fmt: skip
        cluster_s = sorted(start_stop)[1]
        one_s, one = run(sweep, folder / "one", 1)
        two_s, two = run(sweep, folder / "two", 2)
    machine = ceiling()
    runs = len(one)
    assert (one["status"] == "done").all() and (two["status"] == "done").all()
    inside = float(one["seconds"].sum())
    overhead_ms = (one_s - inside - cluster_s) / runs * 1000
    print(
        f"sweep of {runs} runs x {args.steps:,} steps (2 scenarios x 2 strategies x "
        f"{args.seeds} seeds), end to end in a fresh process:"
    )
    print(f"  1 worker : {one_s:6.1f} s   (runs inside their task: {inside:.1f} s)")
    print(f"  2 workers: {two_s:6.1f} s   (runs inside their task: {two['seconds'].sum():.1f} s)")
    print(f"  speed-up : {one_s / two_s:.2f}x (target >= 1.7x)")
    print(f"  this machine's ceiling (two pure-Python loops at once vs one): {machine:.2f}x")
    print(f"  local cluster start and stop (1 worker, fresh process): {cluster_s:.2f} s")
    print(f"  engine overhead per run: {overhead_ms:.0f} ms (target <= 50 ms)")
    learned = one.groupby(["scenario", "strategy"])["equivalent"].mean()
    print("  learned fraction:", ", ".join(f"{s}/{t} {v:.0%}" for (s, t), v in learned.items()))


if __name__ == "__main__":
    main()
