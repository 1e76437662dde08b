"""Performance study (measured here, reported in docs/performance.md, never asserted in tests):

 1. case 3 (dt = 1e-3, output every 0.01 s) through impact1d.simulate against the SciPy
    DOP853 event-restart version (bench/scipy_reference.py, same output times) at equal or
    better event-time accuracy: median of the ratios of paired, alternating runs, a run
    being one call (each starts with the caches the other left) or 10 calls in a row
    (the steady state of a sweep);
 2. the stepping loop: RK4 steps per second of the `impact1d` CLI on a long free-flight run
    (bench/scenes/freeflight.nml, output at 0 and t_end only) against bench/bare_rk4.f90,
    a plain RK4 loop on the same force law compiled here with the release build's -O3;
    both timed the same way (wall and CPU time of the process), alternating; and the same
    under a sine force (bench/scenes/sineflight.nml), where the engine's general step runs;
 3. cost against t_end (free flight) and against the number of events (slot rattle at a
    fixed step count), with linear fits;
 4. the CLI's peak memory (/usr/bin/time -f %M) at 10^6 and 10^7 steps, output streamed.

    python bench/performance.py        # -> bench/results/performance.json, docs/performance.png
"""

from __future__ import annotations

import os
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

import impact1d

import common
from scipy_reference import simulate_scipy

FREEFLIGHT = common.BENCH / "scenes" / "freeflight.nml"
SINEFLIGHT = common.BENCH / "scenes" / "sineflight.nml"
SPRINGFLIGHT = common.BENCH / "scenes" / "springflight.nml"
SLOTRATTLE = common.BENCH / "scenes" / "slotrattle.nml"
BARE_SOURCE = common.BENCH / "bare_rk4.f90"
# The meson release build compiles the core with these (buildtype=release: -O3, -DNDEBUG).
RELEASE_FLAGS = ["-O3"]

PAIRS_CASE3 = 21           # paired alternating runs for the case-3 ratio
BATCH_CASE3 = 10           # calls in a row per run, for the steady-state ratio
PAIRS_LOOP = 5             # paired alternating runs, CLI against the bare loop
LOOP_STEPS = 100_000_000   # free-flight steps per run (t_end = 1e5 s at dt = 1e-3 s)
SINE_STEPS = 10_000_000    # the same under a sine force (t_end = 1e4 s)


def cli_path() -> str:
    path = shutil.which("impact1d")
    if path is None:
        raise SystemExit("the impact1d CLI is not on PATH: run `make setup` (or `make bench`)")
    return path


def timed_process(cmd) -> dict:
    """Wall time (perf_counter) and CPU time (user + sys of the child) of one process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {proc.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall": wall, "cpu": cpu, "stdout": proc.stdout}


# ----------------------------------------------------------------------------- 1. case 3
def case3_against_scipy():
    scene = common.load("case3")
    ref = common.reference("case3", scene)
    dt, dt_out = 1e-3, 0.01
    ours = impact1d.simulate(scene, dt=dt, dt_out=dt_out)
    our_error, _ = common.event_time_error(common.events_of(ours), ref)
    t_eval = ours.t.copy()                       # the same output times
    # The loosest DOP853 tolerance whose event-time error is at least as good as ours.
    chosen = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tried = []
        for k in range(3, 15):
            rtol = 10.0 ** -k
            run = simulate_scipy(scene, "DOP853", rtol, t_eval=t_eval)
            err, _ = common.event_time_error(run.events, ref)
            tried.append({"rtol": rtol, "event_error": err})
            if err <= our_error:
                chosen = rtol
                break
        if chosen is None:        # SciPy never matches: compare with its best
            chosen = min(tried, key=lambda r: r["event_error"])["rtol"]
        scipy_run = simulate_scipy(scene, "DOP853", chosen, t_eval=t_eval)
        scipy_error, _ = common.event_time_error(scipy_run.events, ref)

        def ours_call():
            return impact1d.simulate(scene, dt=dt, dt_out=dt_out)

        def scipy_call():
            return simulate_scipy(scene, "DOP853", chosen, t_eval=t_eval)

        ours_call(), scipy_call()          # warm-up (imports, caches)
        pairs = _paired(ours_call, scipy_call, 1)
        batches = _paired(ours_call, scipy_call, BATCH_CASE3)
    ratios = [s / o for o, s in pairs]
    batch_ratios = [s / o for o, s in batches]
    return {
        "dt": dt, "dt_out": dt_out, "samples": len(ours.t), "steps": ours.steps,
        "impact1d_event_error": our_error, "scipy_rtol": chosen,
        "scipy_atol": chosen * 1e-3, "scipy_event_error": scipy_error,
        "scipy_tolerances_tried": tried, "scipy_nfev": scipy_run.nfev,
        "scipy_restarts": len(scipy_run.events) + 1,
        "impact1d_median_s": statistics.median(o for o, _ in pairs),
        "scipy_median_s": statistics.median(s for _, s in pairs),
        "ratio_median": statistics.median(ratios),
        "ratio_min": min(ratios), "ratio_max": max(ratios), "pairs": len(pairs),
        "batch": {"calls": BATCH_CASE3,
                  "impact1d_median_s": statistics.median(o for o, _ in batches),
                  "scipy_median_s": statistics.median(s for _, s in batches),
                  "ratio_median": statistics.median(batch_ratios),
                  "ratio_min": min(batch_ratios), "ratio_max": max(batch_ratios)},
    }


def _paired(ours_call, scipy_call, calls):
    """PAIRS_CASE3 pairs of runs, alternating which goes first; a run is `calls` calls in a
    row, timed together (wall time per call). One call a run: each starts with the caches
    the other left; several: the steady state of calls in a loop, as in a sweep."""
    pairs = []
    for i in range(PAIRS_CASE3):
        order = (ours_call, scipy_call) if i % 2 == 0 else (scipy_call, ours_call)
        times = {}
        for fn in order:
            start = time.perf_counter()
            for _ in range(calls):
                fn()
            times[fn.__name__] = (time.perf_counter() - start) / calls
        pairs.append((times["ours_call"], times["scipy_call"]))
    return pairs


# ----------------------------------------------------------------------------- 2. steps/s
def build_bare(workdir: Path) -> Path:
    exe = workdir / "bare_rk4"
    subprocess.run(["gfortran", *RELEASE_FLAGS, "-o", str(exe), str(BARE_SOURCE)], check=True)
    return exe


def stepping_loop(workdir: Path, scene_path: Path, n_steps: int):
    scene = impact1d.load_scene(scene_path)
    dt = scene.dt
    t_end = n_steps * dt
    bare = build_bare(workdir)
    cli = [cli_path(), str(scene_path), "--t-end", repr(t_end), "--dt", repr(dt),
           "--dt-out", repr(t_end), "-o", str(workdir / "freeflight.dat")]
    bare_cmd = [str(bare), str(n_steps), repr(dt), repr(scene.m1), repr(scene.m2),
                repr(scene.f1), repr(scene.f2), repr(scene.x1), repr(scene.v1),
                repr(scene.x2), repr(scene.v2)]
    if scene.f1_amp is not None or scene.k1 is not None:
        bare_cmd += [repr(scene.f1_amp or 0.0), repr(scene.f1_period or 1.0)]
    if scene.k1 is not None:
        bare_cmd += [repr(scene.k1), repr(scene.x1_rest)]
    timed_process(bare_cmd), timed_process(cli)          # warm-up (page cache)
    rows = []
    for i in range(PAIRS_LOOP):
        order = ((cli, "cli"), (bare_cmd, "bare")) if i % 2 == 0 else ((bare_cmd, "bare"), (cli, "cli"))
        row = {}
        for cmd, name in order:
            row[name] = timed_process(cmd)
        rows.append(row)
    steps_reported = int(re.search(r"steps\s+(\d+)", rows[0]["cli"]["stdout"]).group(1))
    # How far each lands from the exact final time (the bare loop's clock is a plain sum).
    bare_t = float(rows[0]["bare"]["stdout"].split()[0])
    out = {"scene": scene_path.name, "steps": n_steps, "cli_steps_reported": steps_reported,
           "dt": dt, "pairs": PAIRS_LOOP, "bare_clock_error": abs(bare_t - t_end)}
    for clock in ("wall", "cpu"):
        cli_t = statistics.median(r["cli"][clock] for r in rows)
        bare_t = statistics.median(r["bare"][clock] for r in rows)
        out[clock] = {"cli_s": cli_t, "bare_s": bare_t,
                      "cli_steps_per_s": n_steps / cli_t,
                      "bare_steps_per_s": n_steps / bare_t,
                      "ratio_median": statistics.median(r["cli"][clock] / r["bare"][clock]
                                                        for r in rows)}
    # The same loop through the Python API (output at 0 and t_end only).
    seconds, res = common.time_call(
        lambda: impact1d.simulate(scene, t_end=t_end, dt_out=t_end), min_repeats=3, budget=0)
    out["simulate_s"] = seconds
    out["simulate_steps_per_s"] = res.steps / seconds
    return out


# ----------------------------------------------------------------------------- 3. scaling
def scaling():
    free = impact1d.load_scene(FREEFLIGHT)
    t_ends = (10.0, 100.0, 1000.0, 10000.0)
    by_t_end = []
    for t_end in t_ends:
        seconds, res = common.time_call(
            lambda: impact1d.simulate(free, t_end=t_end, dt_out=t_end), budget=0.3)
        by_t_end.append({"t_end": t_end, "steps": res.steps, "seconds": seconds,
                         "ns_per_step": 1e9 * seconds / res.steps})
    rattle = impact1d.load_scene(SLOTRATTLE)
    by_events = []
    for v2 in (0.1, 1.0, 10.0, 100.0, 1000.0, 3000.0):
        seconds, res = common.time_call(
            lambda: impact1d.simulate(rattle, v1=-2.0 * v2, v2=v2), budget=0.3)
        by_events.append({"v2": v2, "events": len(res.events), "steps": res.steps,
                          "seconds": seconds})
    # Linear fits: time = a + b * steps (t_end); time = a + b * events (fixed t_end and dt).
    fit_t = np.polyfit([r["steps"] for r in by_t_end], [r["seconds"] for r in by_t_end], 1)
    fit_e = np.polyfit([r["events"] for r in by_events], [r["seconds"] for r in by_events], 1)
    return {"by_t_end": by_t_end, "by_events": by_events,
            "seconds_per_step_fit": float(fit_t[0]), "seconds_per_event_fit": float(fit_e[0]),
            "rattle_base_steps": by_events[0]["steps"]}


# ----------------------------------------------------------------------------- 4. memory
def memory(workdir: Path):
    time_exe = "/usr/bin/time"
    if not os.path.exists(time_exe):
        return {"skipped": "/usr/bin/time is missing (apt-get install time)"}
    free = impact1d.load_scene(FREEFLIGHT)
    rows = []
    for steps in (10**6, 10**7):
        t_end = steps * free.dt
        dt_out = 100 * free.dt          # a row every 100 steps: the output grows with the run
        out = workdir / f"memory_{steps}.dat"
        proc = subprocess.run([time_exe, "-f", "%M", cli_path(), str(FREEFLIGHT),
                               "--t-end", repr(t_end), "--dt-out", repr(dt_out), "-o", str(out)],
                              capture_output=True, text=True, check=True)
        rss_kb = int(proc.stderr.strip().splitlines()[-1])
        rows.append({"steps": steps, "rows_written": int(round(t_end / dt_out)) + 1,
                     "output_mb": out.stat().st_size / 1e6, "max_rss_kb": rss_kb})
        out.unlink()
        Path(str(out)[:-4] + ".events.dat").unlink(missing_ok=True)
    return {"rows": rows}


def _plot(results, path):
    plt = common.pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    sc = results["scaling"]
    ax = axes[0]
    steps = np.array([r["steps"] for r in sc["by_t_end"]])
    secs = np.array([r["seconds"] for r in sc["by_t_end"]])
    ax.loglog(steps, secs, "o-", label="impact1d.simulate, free flight")
    ax.loglog(steps, steps * sc["seconds_per_step_fit"], ":", color="gray",
              label=f"linear fit: {1e9 * sc['seconds_per_step_fit']:.0f} ns/step")
    bare = results["loop"]["wall"]["bare_s"] / results["loop"]["steps"]
    ax.loglog(steps, steps * bare, "--", color="C3", label=f"bare RK4 loop: {1e9 * bare:.0f} ns/step")
    ax.set_xlabel("RK4 steps (t_end / dt, dt = 1e-3 s)")
    ax.set_ylabel("run time [s]")
    ax.set_title("cost against t_end", fontsize=9)
    ax.legend()
    ax = axes[1]
    ev = np.array([r["events"] for r in sc["by_events"]])
    secs = np.array([r["seconds"] for r in sc["by_events"]])
    ax.loglog(np.maximum(ev, 1), secs, "s-", color="C2",
              label=f"slot rattle, {sc['rattle_base_steps']} steps")
    grid = np.logspace(0, np.log10(max(ev.max(), 10)), 50)
    base = sc["by_events"][0]["seconds"]
    ax.loglog(grid, base + grid * sc["seconds_per_event_fit"], ":", color="gray",
              label=f"fit: {base * 1e3:.2f} ms + {1e6 * sc['seconds_per_event_fit']:.2f} us/event")
    ax.set_xlabel("events in the run")
    ax.set_ylabel("run time [s]")
    ax.set_title("cost against the number of events (fixed t_end and dt)", fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def run():
    with tempfile.TemporaryDirectory(prefix="impact1d-bench-") as tmp:
        work = Path(tmp)
        results = {"case3": case3_against_scipy(),
                   "loop": stepping_loop(work, FREEFLIGHT, LOOP_STEPS),
                   "loop_sine": stepping_loop(work, SINEFLIGHT, SINE_STEPS),
                   "loop_spring": stepping_loop(work, SPRINGFLIGHT, SINE_STEPS),
                   "scaling": scaling(), "memory": memory(work)}
    common.save_json("performance", results)
    _plot(results, common.DOCS / "performance.png")
    return results


if __name__ == "__main__":
    import json
    print(json.dumps(run(), indent=1, default=float))
