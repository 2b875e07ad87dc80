"""The Python package's overhead: `simulate` of the paper's attractor (ω = 20.465 rad/s,
1000 forcing periods from the static equilibrium, rtol = 1e-8, 64 samples per period,
every impact recorded) against the same run in Rust (`rust_tests/attractor_time.rs`), in
one session, several runs each, medians compared; and the wall time of a 256-point sweep
on all cores against one thread.

    python python/examples/overhead.py [RUNS]
"""

from __future__ import annotations

import os
import pathlib
import re
import statistics
import subprocess
import sys
import time

import numpy as np

import nonsmooth as ns

ROOT = pathlib.Path(__file__).resolve().parents[2]


def python_runs(runs: int) -> list[float]:
    cart = ns.paper(20.465)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        run = ns.simulate(cart, (0.0, 1000 * cart.period), dt=cart.period / 64)
        times.append(time.perf_counter() - start)
        print(f"python: {times[-1]:.4f} s ({len(run.t)} samples, {len(run.event_t)} impacts, "
              f"{run.stats.accepted} steps)")
    return times


def rust_runs(runs: int) -> list[float]:
    out = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "-p", "nonsmooth-python", "--example",
         "attractor_time", "--", str(runs)],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    print(out, end="")
    return [float(m) for m in re.findall(r"rust: ([0-9.]+) s", out)]


SWEEP = """
import os, time, numpy as np, nonsmooth as ns
s = ns.paper(20.0)
v = np.linspace(17.5, 25.0, 256)
t, c = time.perf_counter(), time.process_time()
ns.sweep(s, "omega", v, continuation=False, direction="up", transient=(100, 50), record=50)
print(time.perf_counter() - t, time.process_time() - c)
# The CPU seconds of the busiest thread (Linux): the sweep's work split over the threads
# shows on a machine whose other jobs leave no core free.
try:
    tick = os.sysconf("SC_CLK_TCK")
    per = []
    for tid in os.listdir("/proc/self/task"):
        f = open(f"/proc/self/task/{tid}/stat").read().rsplit(")", 1)[1].split()
        per.append((int(f[11]) + int(f[12])) / tick)
    print(max(per))
except OSError:
    print("nan")
"""


def sweep_time(threads: int | None) -> tuple[float, float, float]:
    """Wall and CPU seconds (all threads, the busiest thread) of a 256-point sweep without
    continuation."""
    env = dict(os.environ)
    if threads is not None:
        env["RAYON_NUM_THREADS"] = str(threads)
    out = subprocess.run([sys.executable, "-c", SWEEP], env=env, check=True,
                         capture_output=True, text=True).stdout
    wall, cpu, busiest = out.split()
    return float(wall), float(cpu), float(busiest)


def main() -> None:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 7
    # Interleaved, so that both see the same load of a shared machine.
    py, rs = [], []
    for _ in range(2):
        rs += rust_runs(runs)
        py += python_runs(runs)
    p, r = statistics.median(py), statistics.median(rs)
    print(f"simulate, 1000 periods: python median {p:.4f} s, rust median {r:.4f} s, "
          f"overhead {100 * (p / r - 1):+.1f} %")
    # Interleaved runs; the best of each (a shared machine only ever adds time).
    ones, boths = [], []
    for _ in range(3):
        ones.append(sweep_time(1))
        boths.append(sweep_time(None))
    one = min(w for w, _, _ in ones)
    both, cpu, busiest = min(boths)
    print(f"256-point sweep: one thread {one:.2f} s, all cores ({os.cpu_count()}) "
          f"{both:.2f} s wall ({cpu:.2f} s CPU: {cpu / both:.2f} cores busy), "
          f"ratio {both / one:.2f}")
    # Below 1 core busy the machine had no core to spare: the wall ratio then says
    # nothing; the busiest thread's share of the CPU time is what the sweep would take
    # with every core free.
    print(f"  the busiest thread ran {busiest:.2f} s of the {cpu:.2f} s CPU "
          f"(share {busiest / cpu:.2f}; 1/{os.cpu_count()} = {1 / (os.cpu_count() or 1):.2f})")


if __name__ == "__main__":
    main()
