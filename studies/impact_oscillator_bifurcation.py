"""A bifurcation diagram of the impact oscillator (input/impact_oscillator.nml) over its
forcing amplitude: for each amplitude, the speeds at which the block hits the wall once the
start has died away. A few impact speeds per amplitude are a periodic orbit (one per impact
of the period); a smear is chaos; none, a block that no longer reaches the wall.

    python studies/impact_oscillator_bifurcation.py [OUT.png] [--runs N]

A sweep with keep="results" (each run's event log is needed, not only its summary), on all
cores; samples only at 0 and t_end (the events carry what the diagram needs).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import impact1d

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "input" / "impact_oscillator.nml"
T_END = 120.0          # s: long enough for a settled orbit to repeat many times
SETTLED = 60.0         # s: impacts before this are the transient, left out


def impact_speeds(results, amplitudes):
    """(amplitude, speed) pairs of every settled impact on the wall."""
    xs, ys = [], []
    for amplitude, result in zip(amplitudes, results):
        if result is None:
            continue
        events = result.events
        hits = events[(events["kind"] == "left") & (events["t"] > SETTLED)]
        xs.append(np.full(len(hits), amplitude))
        ys.append(np.abs(hits["v1_before"]))
    return np.concatenate(xs), np.concatenate(ys)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(ROOT / "docs" / "study_impact_oscillator.png"))
    parser.add_argument("--runs", type=int, default=400)
    args = parser.parse_args(argv)

    scene = impact1d.load_scene(SCENE)
    amplitudes = np.linspace(0.5, 20.0, args.runs)
    table, results = impact1d.sweep(scene, {"f1_amp": amplitudes, "t_end": [T_END],
                                            "dt_out": [T_END]}, keep="results")
    failed = table[table["error"] != ""]
    if len(failed):
        print(f"{len(failed)} runs failed, e.g.: {failed['error'].iloc[0]}")
    x, y = impact_speeds(results, amplitudes)

    import matplotlib
    if not os.environ.get("MPLBACKEND"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(9, 5))
    ax.plot(x, y, ",", color="tab:blue", alpha=0.6)
    ax.set_xlabel("forcing amplitude f1_amp (N)")
    ax.set_ylabel("impact speed |v1| at the wall (m/s)")
    ax.set_title(f"Impact oscillator: settled impact speeds (t > {SETTLED:g} s) over the forcing "
                 f"amplitude\n{args.runs} runs of {SCENE.relative_to(ROOT)}, dt = {scene.dt:g} s")
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out} ({len(x)} impacts from {args.runs - len(failed)} runs)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
