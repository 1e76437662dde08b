"""Long chains (issue 20 item 3): how the N-body engine's cost grows with the number of bodies.

Two scenes for N = 10, 100, 1000, 10000 bodies, run by the command line (`impact1d`, the
installed executable, its summary read for steps and events; output at t_end only, of body 1:
`bodies_out`), each under `/usr/bin/time -v` (wall time, peak memory):

  train   N - 1 wagons (40 t) and a locomotive (80 t, body N) standing buffer to buffer,
          couplers with 62.5 mm of slack, rolling friction 0.002, breakaway 0.004, the
          locomotive pulling with 20 kN per body (input/train.nml at N = 10);
  chain   N elastic balls (1 kg) on a line with 10 mm gaps between their surfaces, no
          friction, velocities 0.5 sin(1.7 i) m/s: impacts everywhere, a few bodies each;
  quiet   the chain at rest (no events): the cost of a step alone.

Times are CPU times (user + system: the machine is shared, and wall time there measures the
neighbours). Per step: the quiet run's time over its steps. Per event: (run - set-up - steps x per step)
over the events, the set-up a run of one step. One run per point, a time limit per run (a
point past it is reported as such, and larger N of that scene are not tried). Results are
figures from one run on a shared machine, never asserted anywhere.

    .venv/bin/python bench/chains.py [--max-n 10000] [--limit 300] [--out bench/results/chains.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import signal
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent


def nml_array(values: list[float]) -> str:
    """A namelist list, ten values a line (a 10,000-body scene stays readable)."""
    text = [", ".join(repr(v) for v in values[j:j + 10]) for j in range(0, len(values), 10)]
    return ",\n    ".join(text)


def train(n: int, t_end: float) -> str:
    x = [16.0 * i for i in range(n)]
    return f"""&scene title = 'bench: train of {n} bodies' /
&bodies m = {n - 1}*40.0, 80.0, mu = {n}*0.002, mus = {n}*0.004, g = 9.81 /
&initial x = {nml_array(x)} /
&forces f = {n - 1}*0.0, {20.0 * n!r} /
&link d_min = {n - 1}*16.0, r_min = {n - 1}*0.0, d_max = {n - 1}*16.0625, r_max = {n - 1}*0.0 /
&run t_end = {t_end!r}, dt = 1.0e-3, dt_out = {t_end!r}, bodies_out = 1 /
"""


def chain(n: int, t_end: float, moving: bool = True) -> str:
    x = [0.0725 * i for i in range(n)]
    v = [0.5 * math.sin(1.7 * i) if moving else 0.0 for i in range(n)]
    return f"""&scene title = 'bench: elastic chain of {n} bodies' /
&bodies m = {n}*1.0 /
&initial x = {nml_array(x)},
  v = {nml_array(v)} /
&link d_min = {n - 1}*0.0625, r_min = {n - 1}*1.0 /
&run t_end = {t_end!r}, dt = 1.0e-3, dt_out = {t_end!r}, bodies_out = 1 /
"""


EXE = shutil.which("impact1d") or str(REPO / ".venv" / "bin" / "impact1d")


def run_cli(text: str, work: Path, name: str, limit: float) -> dict:
    """One CLI run under /usr/bin/time -v: wall time, peak RSS, steps, events (or why not)."""
    scene = work / f"{name}.nml"
    scene.write_text(text)
    exe = EXE
    cmd = ["/usr/bin/time", "-v", exe, str(scene), "-o", str(work / f"{name}.dat"), "--events", "none"]
    start = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    # Its own process group: a run past the limit is ended with time's child, not left behind.
    child = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
    try:
        stdout, stderr = child.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        os.killpg(child.pid, signal.SIGKILL)
        child.communicate()
        return {"status": f"over the {limit:.0f} s limit (wall clock)"}
    done = subprocess.CompletedProcess(cmd, child.returncode, stdout, stderr)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # (the children's rusage to the microsecond: time -v's has 10 ms steps)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
    result = {"wall_s": wall, "cpu_s": cpu, "peak_rss_kb": int(rss.group(1)) if rss else None,
              "exit": done.returncode}
    if done.returncode != 0:
        tail = [line for line in done.stderr.splitlines() if "impact1d" in line or "error" in line.lower()]
        result["status"] = "exit %d: %s" % (done.returncode, " / ".join(tail[-2:])[:300])
        return result
    steps = re.search(r"steps\s+(\d+)", done.stdout)
    events = re.search(r"(\d+) events counted", done.stdout)
    result["steps"] = int(steps.group(1)) if steps else None
    result["events"] = int(events.group(1)) if events else 0
    result["status"] = "ok"
    return result


def measure(n: int, t_end: float, work: Path, limit: float, train_too: bool) -> dict:
    """One N: the quiet chain over 10 t_end, the moving chain over t_end 1000 / N (its events
    grow with N: about 20,000 at every N), the train over t_end, each with its one-step set-up."""
    row = {"n": n, "chain_t_end": t_end * 1000.0 / n}
    row["quiet"] = run_cli(chain(n, 10.0 * t_end, moving=False), work, f"quiet{n}", limit)
    row["chain_setup"] = run_cli(chain(n, 1.0e-3), work, f"chainsetup{n}", limit)
    row["chain"] = run_cli(chain(n, row["chain_t_end"]), work, f"chain{n}", limit)
    row["train_setup"] = run_cli(train(n, 1.0e-3), work, f"trainsetup{n}", limit) if train_too \
        else {"status": "not tried (a smaller N was over the limit)"}
    row["train"] = run_cli(train(n, t_end), work, f"train{n}", limit) \
        if row["train_setup"].get("status") == "ok" else {"status": "not tried (its set-up was not ok)"}
    return row


def per_event(row: dict, scene: str) -> float | None:
    """Seconds per event: the run less its set-up and its steps at the quiet run's rate."""
    run, setup, quiet = row[scene], row[f"{scene}_setup"], row["quiet"]
    if run.get("status") != "ok" or quiet.get("status") != "ok" or not run.get("events"):
        return None
    step = row["per_step_s"]
    base = setup["cpu_s"] if setup.get("status") == "ok" else 0.0
    return (run["cpu_s"] - base - run["steps"] * step) / run["events"]


def figure(data: dict, path: Path) -> None:
    """docs/chains.png: per step per body, per event, peak memory against N (log-log)."""
    sys.path.insert(0, str(BENCH))
    from common import pyplot  # noqa: E402  (matplotlib and the benches' style)
    plt = pyplot()
    rows = data["rows"]
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
    ns = [r["n"] for r in rows if r.get("per_step_s")]
    axes[0].semilogx(ns, [1e9 * r["per_step_s"] / r["n"] for r in rows if r.get("per_step_s")], "o-",
                     label="quiet chain (no events)")
    axes[0].set_ylim(0, 80)
    axes[0].set(xlabel="bodies N", ylabel="CPU ns per step per body", title="a step: per body")
    for scene, mark in (("chain", "o-"), ("train", "s-")):
        pts = [(r["n"], r[f"{scene}_per_event_s"]) for r in rows if (r.get(f"{scene}_per_event_s") or 0) > 0]
        if pts:
            axes[1].loglog(*zip(*pts), mark, label={"chain": "elastic chain with gaps",
                                                    "train": "train (slack couplers, friction)"}[scene])
    starts = [(s["n"], s["train_setup"]["cpu_s"]) for s in data.get("train_starts", [])
              if s["train_setup"].get("status") == "ok"]
    starts += [(r["n"], r["train_setup"]["cpu_s"]) for r in rows if r["train_setup"].get("status") == "ok"]
    if starts:
        axes[1].loglog(*zip(*sorted(starts)), "^--", label="train: its start alone (one step)")
    axes[1].set(xlabel="bodies N", ylabel="CPU seconds", title="an event (and the train's start)")
    axes[1].set_ylim(top=1e7)
    for scene, mark in (("quiet", "o-"), ("train", "s-")):
        pts = [(r["n"], r[scene]["peak_rss_kb"] / 1024) for r in rows if r[scene].get("peak_rss_kb")]
        axes[2].loglog(*zip(*pts), mark, label={"quiet": "chain", "train": "train"}[scene])
    pts = [(s["n"], s["train_setup"]["peak_rss_kb"] / 1024) for s in data.get("train_starts", [])
           if s["train_setup"].get("peak_rss_kb")]
    if pts:
        axes[2].loglog(*zip(*pts), "^", label="train: its start alone")
    axes[2].set(xlabel="bodies N", ylabel="peak RSS [MiB]", title="memory of the CLI run")
    for ax, where in zip(axes, ("best", "upper left", "best")):
        ax.legend(loc=where)
    fig.tight_layout()
    fig.savefig(path)


def table(data: dict) -> str:
    """The markdown table of docs/performance.md's long-chains section."""
    def ms(x):
        if x is None:
            return "-"
        return f"{1e3 * x:.3g}" if x > 0 else "below the steps' noise"
    out = ["| N | step (quiet chain), CPU us | per body, ns | chain: events, steps | chain: per event, CPU ms "
           "| train: events, steps | train: start (one step), CPU s | train: per event, CPU ms "
           "| peak RSS chain / train [MB] |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in data["rows"]:
        step = r.get("per_step_s")
        ch, tr, ts = r["chain"], r["train"], r["train_setup"]
        out.append("| {} | {} | {} | {} | {} | {} | {} | {} | {} / {} |".format(
            f"{r['n']:,}", "-" if step is None else f"{1e6 * step:.3g}",
            "-" if step is None else f"{1e9 * step / r['n']:.3g}",
            f"{ch['events']:,}, {ch['steps']:,} (t_end {r['chain_t_end']:g} s)" if ch.get("status") == "ok"
            else ch["status"], ms(r.get("chain_per_event_s")),
            f"{tr['events']:,}, {tr['steps']:,}" if tr.get("status") == "ok" else tr["status"],
            f"{ts['cpu_s']:.3g}" if ts.get("status") == "ok" else ts["status"], ms(r.get("train_per_event_s")),
            f"{r['chain'].get('peak_rss_kb', 0) / 1024:.1f}" if r["chain"].get("peak_rss_kb") else "-",
            f"{tr['peak_rss_kb'] / 1024:.1f}" if tr.get("peak_rss_kb") else "-"))
    return "\n".join(out)


def main() -> None:
    global EXE
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10,100,1000,10000")
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--limit", type=float, default=300.0, help="seconds a run may take")
    parser.add_argument("--out", type=Path, default=BENCH / "results" / "chains.json")
    parser.add_argument("--exe", default=EXE, help="the impact1d executable (a copy: a build may replace it)")
    parser.add_argument("--train-setup-sizes", default="30,300",
                        help="train sizes whose start alone (one step) is measured: how its set-up grows")
    parser.add_argument("--report", action="store_true",
                        help="no runs: the table and docs/chains.png from --out's results")
    args = parser.parse_args()
    if args.report:
        data = json.loads(args.out.read_text())
        figure(data, REPO / "docs" / "chains.png")
        print(table(data))
        return
    EXE = args.exe
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        train_too = True
        for n in [int(s) for s in args.sizes.split(",")]:
            row = measure(n, args.t_end, Path(tmp), args.limit, train_too)
            train_too = row["train"].get("status") == "ok"
            q = row["quiet"]
            if q.get("status") == "ok":
                row["per_step_s"] = (q["cpu_s"] - row["chain_setup"].get("cpu_s", 0.0)) / q["steps"]
            for scene in ("chain", "train"):
                row[f"{scene}_per_event_s"] = per_event(row, scene)
            rows.append(row)
            print(json.dumps(row), flush=True)
        starts = []
        for n in [int(s) for s in args.train_setup_sizes.split(",") if s]:
            starts.append({"n": n, "train_setup": run_cli(train(n, 1.0e-3), Path(tmp), f"trainstart{n}", args.limit)})
            print(json.dumps(starts[-1]), flush=True)
    args.out.write_text(json.dumps({"t_end": args.t_end, "rows": rows, "train_starts": starts}, indent=1) + "\n")


if __name__ == "__main__":
    main()
