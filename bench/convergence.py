"""Convergence study: error against dt for the event and vissim methods on case 3, case 5,
the stick/slip scene and the sine-forced scene, with the measured orders.

    python bench/convergence.py        # -> bench/results/convergence.json, docs/convergence.png

Every run uses dt_out = t_end (samples at 0 and t_end only), so dt is the step the
integrator takes. Errors: see bench/common.py (event-time and final-state errors).
"""

from __future__ import annotations

import math

import numpy as np

import impact1d

import common

SCENES = ("case3", "case5", "stickslip", "sine", "oscillator", "springslip")
# Scenes whose motion between events is not polynomial: the event method has an order there.
ORDERED = ("sine", "oscillator", "springslip")
EVENT_DTS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5)
VISSIM_DTS = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6)


def study_scene(name):
    scene = common.load(name)
    ref = common.reference(name, scene)
    out = {"label": common.SCENE_LABELS[name], "reference": ref.how,
           "reference_event_error": ref.error_estimate,
           "reference_final_error": ref.final_error_estimate,
           "methods": {}}
    variants = [("event", EVENT_DTS, {}), ("vissim", VISSIM_DTS, {})]
    if name == "stickslip":
        # vissim's zero-velocity threshold (0.005 m/s by default) is an error of its own
        # that no step removes: also run it with a threshold that shrinks with the step.
        variants.append(("vissim, zero_vel = dt m/s", VISSIM_DTS, {"zero_vel": "dt"}))
    for label, dts, extra in variants:
        rows = []
        for dt in dts:
            kwargs = {k: (dt if v == "dt" else v) for k, v in extra.items()}
            res = impact1d.simulate(scene, dt=dt, dt_out=scene.t_end,
                                    method=label.split(",")[0], **kwargs)
            ev_err, n_shared = common.event_time_error(common.events_of(res), ref)
            rows.append({"dt": dt, "steps": res.steps, "events": len(res.events),
                         "event_error": ev_err, "shared_events": n_shared,
                         "final_error": common.final_state_error(common.final_state(res), ref),
                         "energy_residual": res.energy_residual})
        # Orders are fitted on the asymptotic range only: vissim's coarse steps change the
        # event sequence itself (dt > 1e-3), and the sine scene's event runs reach the
        # rounding-drift floor below dt = 3e-4. The event method on polynomial scenes has no
        # order: its error is rounding whatever dt is.
        if label == "event" and name not in ORDERED:
            keep = []
        elif label == "event":
            keep = [r for r in rows if r["dt"] >= 3e-4]
        else:
            keep = [r for r in rows if r["dt"] <= 1e-3]
        orders = {k: common.measured_order([r["dt"] for r in keep],
                                           [r[f"{k}_error"] for r in keep], 0.0)
                  for k in ("event", "final")}
        out["methods"][label] = {"rows": rows, "order_event": orders["event"],
                                 "order_final": orders["final"]}
    return out


def _plot(results, path):
    plt = common.pyplot()
    fig, axes = plt.subplots(2, len(SCENES), figsize=(15, 7.2), sharex=False)
    styles = {"event": dict(marker="o", color="C0"), "vissim": dict(marker="s", color="C3"),
              "vissim, zero_vel = dt m/s": dict(marker="^", color="C1", ls="--")}
    tiny = 1e-17   # an exact zero is drawn here
    for j, name in enumerate(SCENES):
        res = results[name]
        for i, key in enumerate(("event_error", "final_error")):
            ax = axes[i, j]
            for label, data in res["methods"].items():
                dts = np.array([r["dt"] for r in data["rows"]])
                err = np.array([r[key] for r in data["rows"]], dtype=float)
                ok = np.isfinite(err)
                if not ok.any():
                    continue
                order = data["order_event" if i == 0 else "order_final"]
                tag = f"{label} (order {order:.2f})" if np.isfinite(order) else f"{label} (no order fitted)"
                ax.loglog(dts[ok], np.maximum(err[ok], tiny), label=tag, **styles[label])
            # Slope guides through a corner of the panel.
            x = np.array([1e-6, 1e-1])
            for p, ls in ((1, ":"), (4, "-.")):
                y0 = 1e-1 if p == 1 else 1e-4
                ax.loglog(x, y0 * (x / 1e-1) ** p, color="gray", ls=ls, lw=0.8,
                          label=f"slope {p}" if j == 0 and i == 0 else None)
            ax.axhline(2.2e-16, color="k", lw=0.5, ls="--")
            ax.set_ylim(1e-17, 1e2)
            ax.set_xlim(5e-7, 2e-1)
            ax.set_xlabel("dt [s]")
            if i == 0:
                ax.set_title(common.SCENE_SHORT[name], fontsize=9)
                ax.set_ylabel("max |event-time error| [s]")
            else:
                ax.set_ylabel("final-state error (max over x, v)")
            ax.legend(loc="lower right")
    axes[0, 0].text(3e-6, 5e-16, "eps", fontsize=7)
    fig.suptitle("impact1d convergence: error against step, event method (located events) "
                 "and vissim (the tutorial's fixed-step scheme)", fontsize=10)
    fig.text(0.005, 0.005, "an error of exactly 0 is drawn at 1e-17", fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def tutorial_check(dt=1e-3):
    """vissim at the tutorial's step against what the tutorial reports for cases 3 and 5."""
    out = {}
    s3 = common.load("case3")
    r3 = impact1d.simulate(s3, dt=dt, dt_out=dt, method="vissim")
    ev3 = r3.events
    out["case3"] = {
        "ke_min": float(r3.ke.min()), "ke_max": float(r3.ke.max()),
        "right_wall_times": [float(t) for t in ev3["t"][ev3["kind"] == "right"]],
        "left_wall_times": [float(t) for t in ev3["t"][ev3["kind"] == "left"]],
        "slot_impacts": int(np.isin(ev3["kind"], ["slot_min", "slot_max"]).sum()),
    }
    s5 = common.load("case5")
    r5 = impact1d.simulate(s5, dt=dt, dt_out=dt, method="vissim")
    ev5 = r5.events

    def ke_before(t):            # KE just before an impact at t (the sample one step earlier)
        return float(r5.ke[np.searchsorted(r5.t, t - 0.5 * dt) - 1])

    left = ev5["t"][ev5["kind"] == "left"]
    out["case5"] = {
        "first_left_impacts": [float(t) for t in left[:5]],
        "first_right_impacts": [float(t) for t in ev5["t"][ev5["kind"] == "right"][:5]],
        "ke_before_t1": ke_before(1.0 + dt), "ke_before_t2": ke_before(2.0 + dt),
        "ke_max_after_3": float(r5.ke[r5.t >= 3.0 + 10 * dt].max()),
        "impacts_after_3": int((ev5["t"] > 3.0).sum()),
        "slot_impacts": int(np.isin(ev5["kind"], ["slot_min", "slot_max"]).sum()),
        "final": [float(r5.x1[-1]), float(r5.v1[-1]), float(r5.x2[-1]), float(r5.v2[-1])],
    }
    return out


def run():
    results = {name: study_scene(name) for name in SCENES}
    results["tutorial_check"] = tutorial_check()
    common.save_json("convergence", results)
    _plot(results, common.DOCS / "convergence.png")
    return results


if __name__ == "__main__":
    results = run()
    print(results.pop("tutorial_check"))
    for name, res in results.items():
        print(f"== {name}: reference {res['reference']}")
        for label, data in res["methods"].items():
            print(f"  {label}: order (events) {data['order_event']:.2f}, "
                  f"order (final) {data['order_final']:.2f}")
            for r in data["rows"]:
                print(f"    dt {r['dt']:8.1e}  event err {common.fmt(r['event_error'])} "
                      f"({r['shared_events']} shared)  final err {common.fmt(r['final_error'])}")
