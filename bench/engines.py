"""The N-body engine on one- and two-body scenes, against the two-body engine that runs them
today (issue 19's last criterion: one engine, no special path for two bodies).

Builds the CLI twice from this tree's sources in a temporary folder (meson, the release
flags): as it is, and with `run`'s dispatch (src/impact1d_solver.f90) sending every
event-method scene to the N-body engine. Runs each one- and two-body scene of input/ through
both and compares
  - what they compute: the event logs (same kinds in the same order; the largest difference
    of an event time) and the samples (largest difference relative to max(1, |value|));
  - what it costs: instructions (valgrind --tool=callgrind; the machine's load does not move
    them) of the run with samples at t_end only, less those of a run of one step (the CLI's
    start, the scene read and set up).
Measured, never asserted in tests. Raw numbers: bench/results/engines.json. Usage:
  .venv/bin/python bench/engines.py [scene ...]
"""

from __future__ import annotations

import json
from collections import Counter
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
RESULTS = BENCH / "results"
DISPATCH = "if (runs_nbody(scene)) then"
# The scenes of input/ the two-body engine runs (N <= 2, no moving ground, the event method).
SCENES = ("case1", "case2", "case3", "case4", "case5", "case6", "impact_oscillator", "stick_slip",
          "gear_rattle", "breakaway", "mounted_stop", "inner_stop")


def build(tree: Path, patch: bool) -> Path:
    """The CLI built from a copy of the sources in `tree`, its dispatch forced when `patch`."""
    shutil.copytree(REPO, tree, ignore=shutil.ignore_patterns(".venv", "build", "output", ".git", "*.pyc"))
    if patch:
        solver = tree / "src" / "impact1d_solver.f90"
        text = solver.read_text()
        if DISPATCH not in text:
            sys.exit(f"bench/engines.py: the dispatch line is no longer in {solver.name}: update DISPATCH")
        solver.write_text(text.replace(DISPATCH, "if (.true.) then"))
    bin_dir = Path(sys.executable).parent
    env = {"PATH": f"{bin_dir}:/usr/bin:/bin"}
    subprocess.run(["meson", "setup", "build"], cwd=tree, env=env, check=True, capture_output=True)
    subprocess.run(["ninja", "-C", "build", "impact1d"], cwd=tree, env=env, check=True, capture_output=True)
    return tree / "build" / "impact1d"


def instructions(cli: Path, scene: Path, out: Path, *options: str) -> int:
    run = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", str(cli), str(scene),
                          "-o", str(out), "--quiet", *options], capture_output=True, text=True)
    found = re.search(r"Collected : (\d+)", run.stderr)
    if run.returncode != 0 or not found:
        sys.exit(f"bench/engines.py: {cli} {scene.name} failed:\n{run.stderr[-2000:]}")
    return int(found.group(1))


def table(path: Path):
    rows = [line.split() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]
    return rows


def compare(a: Path, b: Path) -> dict:
    """What two runs' outputs (samples a, b and their .events.dat) differ by."""
    sa, sb = np.array(table(a), dtype=float), np.array(table(b), dtype=float)
    ea, eb = table(a.with_suffix(".events.dat")), table(b.with_suffix(".events.dat"))
    same_kinds = [row[1] for row in ea] == [row[1] for row in eb]
    result = {"events": [len(ea), len(eb)], "same_kinds": same_kinds,
              "kinds": [dict(Counter(row[1] for row in e)) for e in (ea, eb)]}
    if same_kinds and ea:
        result["event_time_difference"] = float(max(abs(float(p[0]) - float(q[0])) for p, q in zip(ea, eb)))
    if sa.shape == sb.shape:
        result["sample_difference"] = float(np.max(np.abs(sa - sb) / np.maximum(1.0, np.abs(sa))))
    return result


def main(names) -> None:
    rows = {}
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        two_body = build(folder / "two_body", patch=False)
        n_body = build(folder / "n_body", patch=True)
        for name in names:
            scene = REPO / "input" / f"{name}.nml"
            outs = {engine: folder / f"{name}.{engine}.dat" for engine in ("two_body", "n_body")}
            row = {}
            for engine, cli in (("two_body", two_body), ("n_body", n_body)):
                whole = instructions(cli, scene, folder / "x.dat", "--dt-out", "1e9", "--events", "none")
                start = instructions(cli, scene, folder / "x.dat", "--t-end", "1e-6", "--dt", "1e-6",
                                     "--events", "none")
                row[engine] = whole - start
                subprocess.run([str(cli), str(scene), "-o", str(outs[engine]), "--quiet"], check=True,
                               capture_output=True)
            row["ratio"] = row["n_body"] / row["two_body"]
            row.update(compare(outs["two_body"], outs["n_body"]))
            rows[name] = row
            print(f"{name}: {row}", flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "engines.json").write_text(json.dumps(rows, indent=1) + "\n")
    print("\n| scene | two-body engine, instructions | N-body engine | ratio | events (two-body / N-body) "
          "| event times, largest difference | samples, largest relative difference |")
    print("|---|---|---|---|---|---|---|")
    for name, row in rows.items():
        times = f"{row['event_time_difference']:.1e} s" if "event_time_difference" in row else \
            ("(no events)" if row["events"] == [0, 0] else "other kinds")
        samples = f"{row['sample_difference']:.1e}" if "sample_difference" in row else "other shape"
        print(f"| {name} | {row['two_body']:,} | {row['n_body']:,} | {row['ratio']:.1f}x | "
              f"{row['events'][0]} / {row['events'][1]} | {times} | {samples} |")


if __name__ == "__main__":
    main(sys.argv[1:] or SCENES)
