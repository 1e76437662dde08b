"""Work-precision study: error against run time, in one process on one machine, for the
event method (dt 1e-1 .. 1e-5), the vissim method (dt 1e-2 .. 1e-6) and SciPy's solve_ivp
(RK45 and DOP853, rtol 1e-3 .. 1e-12, atol = rtol * 1e-3) written as a SciPy user would
(bench/scipy_reference.py), on the frictionless scenes: case 3, case 5 and the sine scene.

    python bench/work_precision.py     # -> bench/results/work_precision.json, docs/work_precision.png

Time: the median wall time (time.perf_counter) of repeated calls of impact1d.simulate or
simulate_scipy, scene already loaded, output at 0 and t_end only (dt_out = t_end; SciPy:
no t_eval). Errors as in the convergence study (bench/common.py).
"""

from __future__ import annotations

import warnings

import numpy as np

import impact1d

import common
from scipy_reference import simulate_scipy

SCENES = ("case3", "case5", "sine")
EVENT_DTS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5)
VISSIM_DTS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6)
RTOLS = tuple(10.0 ** -k for k in range(3, 13))
SCIPY_METHODS = ("RK45", "DOP853")
BUDGET = 0.25          # seconds of repeats per point (at least 3 calls)


def study_scene(name):
    scene = common.load(name)
    ref = common.reference(name, scene)
    out = {"label": common.SCENE_LABELS[name], "reference": ref.how, "series": {}}

    def record(label, setting, seconds, events, final, extra=None):
        ev_err, n_shared = common.event_time_error(events, ref)
        row = {"setting": setting, "seconds": seconds, "event_error": ev_err,
               "shared_events": n_shared, "events": len(events),
               "final_error": common.final_state_error(final, ref)}
        row.update(extra or {})
        out["series"].setdefault(label, []).append(row)

    for method, dts in (("event", EVENT_DTS), ("vissim", VISSIM_DTS)):
        for dt in dts:
            seconds, res = common.time_call(
                lambda: impact1d.simulate(scene, dt=dt, dt_out=scene.t_end, method=method),
                budget=BUDGET)
            record(method, dt, seconds, common.events_of(res), common.final_state(res),
                   {"steps": res.steps})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for method in SCIPY_METHODS:
            for rtol in RTOLS:
                seconds, run = common.time_call(
                    lambda: simulate_scipy(scene, method=method, rtol=rtol), budget=BUDGET)
                record(f"SciPy {method}", rtol, seconds, run.events, run.final,
                       {"nfev": run.nfev, "stop_reason": run.stop_reason,
                        "t_stopped": run.t_stopped})
    return out


def _plot(results, path):
    plt = common.pyplot()
    fig, axes = plt.subplots(2, len(SCENES), figsize=(13, 7.5))
    styles = {"event": dict(marker="o", color="C0"), "vissim": dict(marker="s", color="C3"),
              "SciPy RK45": dict(marker="v", color="C2"),
              "SciPy DOP853": dict(marker="D", color="C4")}
    tiny = 1e-17
    for j, name in enumerate(SCENES):
        res = results[name]
        for i, key in enumerate(("event_error", "final_error")):
            ax = axes[i, j]
            for label, rows in res["series"].items():
                t = np.array([r["seconds"] for r in rows])
                e = np.array([r[key] for r in rows], dtype=float)
                ok = np.isfinite(e)
                ax.loglog(t[ok], np.maximum(e[ok], tiny), label=label, ms=4, **styles[label])
                # Label the ends of each series with its setting.
                for r in (rows[0], rows[-1]):
                    if np.isfinite(r[key]):
                        ax.annotate(f"{r['setting']:.0e}", (r["seconds"], max(r[key], tiny)),
                                    fontsize=6, color=styles[label]["color"],
                                    xytext=(3, 3), textcoords="offset points")
            ax.set_ylim(1e-17, 1e2)
            ax.set_xlabel("run time [s] (median wall time per run)")
            ax.set_ylabel("max |event-time error| [s]" if i == 0
                          else "final-state error (max over x, v)")
            if i == 0:
                ax.set_title(common.SCENE_SHORT[name], fontsize=9)
            ax.legend(loc="upper right")
    fig.suptitle("impact1d work-precision: error against run time, one process, one machine "
                 "(labels: dt for impact1d, rtol for SciPy)", fontsize=10)
    fig.text(0.005, 0.005, "an error of exactly 0 is drawn at 1e-17", fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def run():
    results = {name: study_scene(name) for name in SCENES}
    common.save_json("work_precision", results)
    _plot(results, common.DOCS / "work_precision.png")
    return results


if __name__ == "__main__":
    results = run()
    for name, res in results.items():
        print(f"== {name}")
        for label, rows in res["series"].items():
            for r in rows:
                print(f"  {label:13s} {r['setting']:8.1e}  {r['seconds']*1e3:9.3f} ms  "
                      f"event err {common.fmt(r['event_error'])}  final err "
                      f"{common.fmt(r['final_error'])}  {r.get('stop_reason', '')}")
