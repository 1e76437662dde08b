"""Issue 19's last figures: one- and two-body scenes on the one engine (session 12), measured
as docs/performance.md's "The N-body engine on one- and two-body scenes" measured them at
eb8f64d, so that its two-body column compares with these.

  - the CLI (the meson build's, build/py/impact1d: release flags) on each one- and two-body
    scene of input/: instructions (valgrind --tool=callgrind; the machine's load does not move
    them) of the run with samples at t_end only and no event file, less a run of one step's
    (the CLI's start, the scene read and set up); the events of the default run;
  - impact1d's core without Python (bench/core_run, as the CVODE table runs it), dt_out =
    t_end, on case 3 at dt = 0.1 and 1e-3 and case 5 at dt = 0.1 (the rows of "The core on
    event-heavy runs"): instructions per run, whole (prepare_scene, the sink, the run) and
    the run's own share (callgrind's inclusive count of run_nbody), from the difference of
    RUNS runs and one;
  - the stepping loop against bench/bare_rk4.f90 (the rows of "The stepping loop against a
    bare RK4 loop"), in instructions per step: (a run of LOOP_STEPS steps - one of a step) /
    (LOOP_STEPS - 1), the CLI's and the bare loop's;
  - with --profile, the top self-cost procedures of that core run and of the CLI on
    impact_oscillator (t_end only).
Measured, never asserted in tests. Not part of `make bench`. Raw numbers:
bench/results/after_switch.json. Usage (after `make setup`):
  .venv/bin/python bench/after_switch.py [--profile] [scene ...]
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import cvode_peer
import impact1d
import performance

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
RESULTS = BENCH / "results"
CLI = REPO / "build" / "py" / "impact1d"
SCENES = ("case1", "case2", "case3", "case4", "case5", "case6", "impact_oscillator", "stick_slip",
          "gear_rattle", "breakaway", "mounted_stop", "inner_stop")
RUNS = 200
CORE_RUNS = (("case3", 0.1, RUNS), ("case3", 1e-3, 10), ("case5", 0.1, 40))
LOOP_STEPS = 100_001


def callgrind(command, out_file="/dev/null") -> int:
    """Instructions of a process under callgrind (its total)."""
    run = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out_file}", *map(str, command)],
                         capture_output=True, text=True)
    found = re.search(r"Collected : (\d+)", run.stderr)
    if run.returncode != 0 or not found:
        sys.exit(f"bench/after_switch.py: {command} failed:\n{run.stderr[-2000:]}")
    return int(found.group(1))


def annotate(out_file: Path, inclusive: bool) -> list:
    """(count, symbol) lines of callgrind_annotate, largest first."""
    text = subprocess.run(["callgrind_annotate", f"--inclusive={'yes' if inclusive else 'no'}",
                           "--threshold=100", str(out_file)], capture_output=True, text=True, check=True).stdout
    rows = []
    for line in text.splitlines():
        match = re.match(r"\s*([\d,]+)\s+\(.*?\)\s+(.*)", line)
        if match:
            rows.append((int(match.group(1).replace(",", "")), match.group(2).strip()))
    return rows


def symbol_count(rows, symbol) -> int:
    """A symbol's count (its clones too: gfortran's .constprop.0, .isra.0, LTO's .lto_priv.0)."""
    return sum(n for n, name in rows if re.search(rf"[:\s]{re.escape(symbol)}(\.[\w.]+)?( |$)", " " + name))


def cli_scene(name: str, folder: Path) -> dict:
    scene = REPO / "input" / f"{name}.nml"
    out = folder / "x.dat"
    whole = callgrind([CLI, scene, "-o", out, "--quiet", "--dt-out", "1e9", "--events", "none"])
    start = callgrind([CLI, scene, "-o", out, "--quiet", "--t-end", "1e-6", "--dt", "1e-6", "--events", "none"])
    subprocess.run([str(CLI), str(scene), "-o", str(out), "--quiet"], check=True, capture_output=True)
    events = [line for line in out.with_suffix(".events.dat").read_text().splitlines()
              if line.strip() and not line.startswith("#")]
    return {"instructions": whole - start, "events": len(events)}


def core(exe, name: str, dt: float, runs: int, folder: Path, profile: bool) -> dict:
    scene = REPO / "input" / f"{name}.nml"
    counts = {}
    for n in (1, 1 + runs):
        out = folder / f"core.{n}"
        callgrind([exe, scene, repr(dt), repr(impact1d.load_scene(scene).t_end), "1", n], out)
        counts[n] = annotate(out, True)

    def per_run(symbol):
        return round((symbol_count(counts[1 + runs], symbol) - symbol_count(counts[1], symbol)) / runs)
    result = {"per_run": per_run("PROGRAM TOTALS"), "run_part": per_run("__impact1d_nbody_solver_MOD_run_nbody"),
              "prepare_scene": per_run("__impact1d_io_MOD_prepare_scene"),
              "event_points": per_run("__impact1d_nbody_event_MOD_nbody_event_point"),
              "malloc_free": per_run("malloc") + per_run("free")}
    if profile:
        result["profile"] = top_self(folder / f"core.{1 + runs}")
    return result


def loop(name: str, folder: Path) -> dict:
    """Instructions per step of the CLI and of the bare RK4 loop on bench/scenes/<name>.nml."""
    path = BENCH / "scenes" / f"{name}.nml"
    scene = impact1d.load_scene(path)
    bare = performance.build_bare(folder)
    counts = {}
    for steps in (1, LOOP_STEPS):
        t_end = steps * scene.dt
        cli = callgrind([CLI, path, "--t-end", repr(t_end), "--dt-out", repr(t_end), "-o", folder / "x.dat",
                         "--quiet", "--events", "none"])
        args = [bare, steps, repr(scene.dt), repr(scene.m1), repr(scene.m2), repr(scene.f1), repr(scene.f2),
                repr(scene.x1), repr(scene.v1), repr(scene.x2), repr(scene.v2)]
        if scene.f1_amp is not None or scene.k1 is not None:
            args += [repr(scene.f1_amp or 0.0), repr(scene.f1_period or 1.0)]
        if scene.k1 is not None:
            args += [repr(scene.k1), repr(scene.x1_rest)]
        counts[steps] = (cli, callgrind(args))
    cli, bare_n = ((counts[LOOP_STEPS][i] - counts[1][i]) / (LOOP_STEPS - 1) for i in (0, 1))
    return {"cli_per_step": round(cli, 1), "bare_per_step": round(bare_n, 1), "ratio": cli / bare_n}


def top_self(out_file: Path, count: int = 12) -> list:
    rows = annotate(out_file, False)
    total = next(n for n, name in rows if name.startswith("PROGRAM TOTALS"))
    return [{"symbol": name.split(":")[-1].split(" [")[0].strip(), "self": n, "share": n / total}
            for n, name in rows if not name.startswith("PROGRAM TOTALS")][:count] + [{"symbol": "total", "self": total}]


def main(argv) -> None:
    profile = "--profile" in argv
    names = [a for a in argv if not a.startswith("--")] or list(SCENES)
    commit = subprocess.run(["git", "-C", str(REPO), "log", "-1", "--format=%h %s"], capture_output=True,
                            text=True).stdout.strip()
    result = {"commit": commit, "scenes": {}}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for name in names:
            result["scenes"][name] = cli_scene(name, folder)
            print(name, result["scenes"][name], flush=True)
        built = cvode_peer.build_core()
        if not built["available"]:
            sys.exit(f"bench/after_switch.py: core_run: {built['reason']}")
        for name, dt, runs in CORE_RUNS:
            key = f"core {name} dt={dt:g}"
            result[key] = core(built["exe"], name, dt, runs, folder, profile and dt == 0.1 and name == "case3")
            print(key, {k: v for k, v in result[key].items() if k != "profile"}, flush=True)
        for name in ("freeflight", "sineflight", "springflight"):
            result[f"loop {name}"] = loop(name, folder)
            print(name, result[f"loop {name}"], flush=True)
        if profile:
            out = folder / "osc"
            callgrind([CLI, REPO / "input" / "impact_oscillator.nml", "-o", folder / "x.dat", "--quiet",
                       "--dt-out", "1e9", "--events", "none"], out)
            result["profile_impact_oscillator"] = top_self(out)
            for key in ("profile_impact_oscillator",):
                print(key, json.dumps(result[key], indent=0), flush=True)
            print("core profile", json.dumps(result["core case3 dt=0.1"]["profile"], indent=0), flush=True)
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "after_switch.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    old[commit.split()[0]] = result
    path.write_text(json.dumps(old, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
