"""The fixed cost of `impact1d.simulate` in instructions (issue 20 item 1): callgrind counts
what a short run of case 3 (t_end = dt = 1e-3) executes, whatever else the machine runs
(wall-clock times on a loaded machine mean little). A process runs 200 calls and then N more;
(count(N = 2000) - count(N = 0)) / 2000 is one call, and the same difference of a function's
inclusive count is that stage's share. `--before SITE` measures a package installed apart
(pip install --target SITE) as the stored 'before' (--before-label: which commit it is);
without it the stored one is kept.
Measured, never asserted in tests."""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import common

CALLS = 2000
SCRIPT = """
import impact1d, sys
scene = impact1d.load_scene(sys.argv[2])
for _ in range(200): impact1d.simulate(scene, t_end=1e-3, dt=1e-3)
for _ in range(int(sys.argv[1])): impact1d.simulate(scene, t_end=1e-3, dt=1e-3)
"""
# Stages: (name, symbols whose inclusive counts add up to it); the first is the call whole.
STAGES = (
    ("simulate() whole", ("PROGRAM TOTALS",)),
    ("the f2py call (arguments, set-up, sink, run)", ("f2py_rout__core_impact1d_api_simulate",
                                                       "f2py_rout__core_impact1d_api_run_prepared")),
    ("the Fortran entry (simulate, or run_prepared)", ("__impact1d_api_MOD_simulate",
                                                       "__impact1d_api_MOD_run_prepared")),
    ("prepare_scene (validate, validate_chain, build_scene)", ("__impact1d_io_MOD_prepare_scene",)),
    ("run (one step, two samples)", ("__impact1d_solver_MOD_run",)),
    ("interrupt_epoch_now (f2py call)", ("f2py_rout__core_impact1d_api_interrupt_epoch_now",)),
    ("the core form's key (marshal.dumps)", ("marshal_dumps",)),
)


def _inclusive(out_file: Path) -> dict:
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out_file)],
                          capture_output=True, text=True, check=True).stdout
    counts = {}
    for line in text.splitlines():
        match = re.match(r"\s*([\d,]+)\s+\(.*?\)\s+(.*)", line)
        if match:
            counts[match.group(2).strip()] = int(match.group(1).replace(",", ""))
    return counts


def _stage(counts: dict, symbols) -> int:
    # (a symbol's line names its file too: the first line that names it, exactly once)
    total = 0
    for symbol in symbols:
        lines = [name for name in counts if name == symbol or re.search(rf"[:\s]{re.escape(symbol)}( |$)", name)]
        total += counts[lines[0]] if lines else 0
    return total


def measure(pythonpath: str | None = None) -> dict:
    """Instructions per short call, whole and per stage."""
    env = dict(os.environ, PYTHONHASHSEED="0")
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    scene = str(common.SCENE_FILES["case3"])
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "short.py"
        script.write_text(SCRIPT)
        subprocess.run([sys.executable, str(script), "0", scene], env=env, check=True)   # (.pyc written)
        counts = []
        for n in (0, CALLS):
            out = Path(folder) / f"cg.{n}"
            subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable,
                            str(script), str(n), scene], env=env, check=True, capture_output=True)
            counts.append(_inclusive(out))
    return {name: round((_stage(counts[1], symbols) - _stage(counts[0], symbols)) / CALLS)
            for name, symbols in STAGES}


def run(before: str | None = None, before_label: str = "before") -> dict:
    path = common.RESULTS / "call_instructions.json"
    res = common.load_json("call_instructions") if path.exists() else {}
    if before:
        res["before"] = {"label": before_label, "stages": measure(before)}
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=common.REPO, capture_output=True, text=True)
    res["after"] = {"label": head.stdout.strip() or "this tree", "stages": measure()}
    common.save_json("call_instructions", res)
    return res


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--before", help="a site folder with the package as it was (pip install --target)")
    parser.add_argument("--before-label", default="before", help="what the before is (a commit)")
    args = parser.parse_args()
    print(run(args.before, args.before_label))
