"""Sweeps at scale (issue 11): runs per second of a 10^4-run sweep of case-3 variants
(v1 varied) as a Python loop of simulate(), as impact1d.sweep on 1 and 2 threads and on a
Dask LocalCluster of 2 worker processes, and the peak memory of sweeps of 10^4 and 10^5
runs (each in a fresh process). Ratios from one run on this machine; never asserted.

    python bench/sweep_study.py [--quick]
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time

import numpy as np

import common

N_RUNS = 10_000
MEMORY_RUNS = (10_000, 100_000)
QUICK_RUNS = 200


def _scene():
    import impact1d
    return impact1d.load_scene(common.REPO / "input" / "case3.nml")


def _runs(n):
    return [{"v1": float(v)} for v in np.linspace(-9.0, -1.0, n)]


def _rate(work, n) -> float:
    start = time.perf_counter()
    work()
    return n / (time.perf_counter() - start)


def _memory_child(n: int) -> None:
    """In a fresh process: sweep n runs, print the peak RSS in MiB."""
    import impact1d
    impact1d.sweep(_scene(), _runs(n), workers=2)
    print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)


def run(quick: bool = False) -> dict:
    import impact1d
    n = QUICK_RUNS if quick else N_RUNS
    scene, runs = _scene(), _runs(n)
    impact1d.sweep(scene, runs[:50])       # warm up: imports, caches

    def loop():
        for overrides in runs:
            impact1d.simulate(scene, **overrides)

    rates = {"loop": _rate(loop, n),
             "workers1": _rate(lambda: impact1d.sweep(scene, runs, workers=1), n),
             "workers2": _rate(lambda: impact1d.sweep(scene, runs, workers=2), n)}
    try:
        from distributed import Client, LocalCluster
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            impact1d.sweep(scene, runs[:200], client=client)     # workers warm
            rates["dask2"] = _rate(lambda: impact1d.sweep(scene, runs, client=client), n)
    except ImportError:
        rates["dask2"] = None
    memory = {}
    for size in (MEMORY_RUNS if not quick else (QUICK_RUNS, 2 * QUICK_RUNS)):
        done = subprocess.run([sys.executable, __file__, "--memory-child", str(size)],
                              capture_output=True, text=True, check=True, cwd=common.BENCH)
        memory[str(size)] = float(done.stdout.split()[-1])
    data = {"runs": n, "rates": rates, "peak_rss_mib": memory, "quick": quick}
    if not quick:
        common.save_json("sweep", data)
    return data


def performance_section(data) -> str:
    if data is None:
        return "## Sweeps\n\nNot measured in this run (`python bench/sweep_study.py`).\n"
    r = data["rates"]
    mem = data["peak_rss_mib"]
    sizes = sorted(mem, key=int)
    out = ["## Sweeps", "",
           f"A sweep of {data['runs']} case-3 variants (v1 from -9 to -1 m/s, 6 s at dt = 1e-3 "
           "each), as runs per second, measured in one run of `make bench`:", "",
           "| how | runs/s | ratio |", "|---|---|---|",
           f"| Python loop of `simulate()` | {r['loop']:.0f} | 1 |",
           f"| `sweep(workers=1)` | {r['workers1']:.0f} | {r['workers1'] / r['loop']:.2f}x the loop |",
           f"| `sweep(workers=2)` (threads) | {r['workers2']:.0f} | "
           f"{r['workers2'] / r['workers1']:.2f}x workers=1 |"]
    if r.get("dask2"):
        out.append(f"| Dask LocalCluster, 2 worker processes | {r['dask2']:.0f} | "
                   f"{r['dask2'] / r['workers2']:.2f}x workers=2 |")
    out += ["", f"Peak memory of a whole sweep process: {mem[sizes[0]]:.0f} MiB for {sizes[0]} "
            f"runs, {mem[sizes[-1]]:.0f} MiB for {sizes[-1]} runs: the table's rows are what "
            "grows (no run's samples are kept).", "",
            "Targets of issue 11: `workers=1` at 3x the loop, `workers=2` at 1.8x `workers=1`, "
            "Dask within 25% of `workers=2`. A sweep runs its chunks of 64 runs through the "
            "core's batch entry (one call, a summary sink that keeps no samples, the GIL "
            "released); the Python glue a loop pays per run is about 0.05 ms of a case-3 "
            "run's ~0.8 ms here, so most of a run is the engine itself and 3x over the loop "
            "cannot come from removing glue."]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--memory-child":
        _memory_child(int(sys.argv[2]))
    else:
        print(json.dumps(run(quick="--quick" in sys.argv), indent=1))
