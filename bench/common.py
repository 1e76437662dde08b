"""Shared helpers of the bench scripts: scenes, exact references, error measures, timing,
machine description and figure style.  The studies (convergence.py, work_precision.py,
performance.py) import from here; none of them repeats this logic.

Error measures used everywhere (docs/accuracy.md states them):
  event-time error  max |t_run - t_ref| over the events both runs share, matched by kind
                    and by order within a kind (the k-th `left` impact of one run against
                    the k-th `left` impact of the other);
  final-state error max |.| over (x1, v1, x2, v2) at t_end.
"""

from __future__ import annotations

import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

import impact1d

BENCH = Path(__file__).resolve().parent
REPO = BENCH.parent
DOCS = REPO / "docs"
RESULTS = BENCH / "results"          # raw numbers (JSON) of the last `make bench`

# tests/exact_reference.py is the project's independent closed-form reference for
# frictionless constant-force scenes: reuse it, do not rewrite it.
sys.path.insert(0, str(REPO / "tests"))
import exact_reference  # noqa: E402
import exact_springs  # noqa: E402  (the springs' and static friction's closed forms)

SCENE_FILES = {
    "case3": REPO / "input" / "case3.nml",
    "case5": REPO / "input" / "case5.nml",
    "stickslip": BENCH / "scenes" / "stickslip.nml",
    "sine": BENCH / "scenes" / "sine.nml",
    "oscillator": BENCH / "scenes" / "oscillator.nml",
    "springslip": BENCH / "scenes" / "springslip.nml",
}
SCENE_LABELS = {
    "case3": "case 3 (elastic, all four contacts)",
    "case5": "case 5 (rattling into both walls, Zeno at t = 3)",
    "stickslip": "stick/slip (triangular force, friction)",
    "sine": "sine-forced (case 3 geometry, f1 = 20 sin(2 pi t/0.7 + 0.3))",
    "oscillator": "impact oscillator (spring k = 4 at a wall, r = 0.8)",
    "springslip": "stick-slip oscillator (spring k = 100, anchor 0.5 m/s, mus > mu)",
}

SCENE_SHORT = {"case3": "case 3 (elastic)", "case5": "case 5 (Zeno at t = 3)",
               "stickslip": "stick/slip (friction, triangle force)",
               "sine": "sine-forced (case 3 geometry)",
               "oscillator": "impact oscillator (spring)",
               "springslip": "stick-slip oscillator (spring)"}

IMPACT_KINDS = ("left", "right", "slot_min", "slot_max")

# Case 5: the impacts of an accumulation (Zeno) series closer to t = 3 than a step cannot
# be resolved by a fixed-step scheme (vissim) nor, past ~50 bounces, by any floating-point
# one; the error measure keeps the impacts before this time (the first five on each wall:
# t = 1, 2, 2.5, 2.75, 2.875), the same set for every method.
CASE5_EVENT_WINDOW = 2.9

# The sine scene has no closed form. Its reference is SciPy's DOP853 at the tightest
# tolerance it accepts (rtol is clipped to 100 eps), its error estimated from the runs at
# ten times the tolerance (DOP853) and with another method (RK45). Not an event-method run
# at a tiny step: those stop converging below dt ~ 2e-4 (the engine's time drift, see
# docs/accuracy.md), which the convergence study shows against this independent reference.
SINE_REFERENCE = dict(method="DOP853", rtol=1e-14, atol=1e-16)
SINE_CHECKS = (dict(method="DOP853", rtol=1e-13, atol=1e-15),
               dict(method="RK45", rtol=1e-13, atol=1e-15))


def load(name: str) -> impact1d.Scene:
    return impact1d.load_scene(SCENE_FILES[name])


def final_state(res) -> np.ndarray:
    return np.array([res.x1[-1], res.v1[-1], res.x2[-1], res.v2[-1]])


def events_of(res) -> list:
    """[(t, kind)] of an impact1d Result."""
    return [(float(t), str(k)) for t, k in zip(res.events["t"], res.events["kind"])]


# ----------------------------------------------------------------------------- references
class Reference:
    """What a run is compared with: events [(t, kind)], the final state, and how it was got."""

    def __init__(self, events, final, how, window=None, error_estimate=0.0):
        self.events = events
        self.final = np.asarray(final, dtype=float)
        self.how = how
        self.window = window               # compare only events with t_ref <= window
        self.error_estimate = error_estimate          # of its event times
        self.final_error_estimate = error_estimate    # of its final state


def _case3_reference(scene):
    events, segments = exact_reference.simulate_exact(scene)
    return Reference([(t, kind) for t, kind, *_ in events], segments[-1][1:],
                     "closed form (tests/exact_reference.py, quadratic flights and Newton's law)")


def _case5_reference(scene):
    # Each wall: a body 1 m from it, pushed at 2 m/s^2, r = 0.5. Impact n comes at
    # t_n = 3 - 2^(2-n) with speed 2^(2-n); the series accumulates at t = 3 where both
    # bodies come to rest on their walls (x1 = 0, x2 = 10) for good.
    times = [3.0 - 2.0 ** (2 - n) for n in range(1, 60)]
    events = [(t, kind) for t in times for kind in ("left", "right")]
    events += [(3.0, "rest_left"), (3.0, "rest_right")]
    return Reference(events, [0.0, 0.0, 10.0, 0.0],
                     "closed form: t_n = 3 - 2^(2-n) on each wall, rest at t = 3",
                     window=CASE5_EVENT_WINDOW)


def friction_body_exact(m, c, table, f_const, x0, v0, t_end):
    """One body on a rough floor (bound c) under f_const + a piecewise-linear table
    (held constant outside its times), from (x0, v0) at t = 0: the exact motion.
    Between table corners the acceleration is linear in t, so each stop is a root of a
    quadratic and each break-away a root of a linear function.
    Returns (events [(t, kind)] with kind in slip/stick/reverse, x(t_end), v(t_end))."""
    times = list(table[0]) if table is not None else []
    forces = list(table[1]) if table is not None else []

    def force_slope(t):                   # f and df/dt on the segment starting at t
        if not times or t < times[0] or t >= times[-1]:
            f = forces[0] if times and t < times[0] else (forces[-1] if times else 0.0)
            return f_const + f, 0.0
        k = max(i for i in range(len(times) - 1) if times[i] <= t)
        slope = (forces[k + 1] - forces[k]) / (times[k + 1] - times[k])
        return f_const + forces[k] + slope * (t - times[k]), slope

    corners = sorted(set([tc for tc in times if 0.0 < tc < t_end] + [t_end]))
    t, x, v = 0.0, float(x0), float(v0)
    events = []
    sliding = 0.0 if v == 0.0 else math.copysign(1.0, v)
    while t < t_end:
        t_next = min(tc for tc in corners if tc > t)
        f, k = force_slope(t)
        if sliding == 0.0:
            # Break-away: the earliest s in [0, t_next - t) with |f + k s| > c.
            s_break = math.inf
            if abs(f) > c:
                s_break = 0.0
            elif k != 0.0:
                target = math.copysign(c, k)
                s_break = (target - f) / k
            if s_break < t_next - t:
                t += s_break
                sliding = math.copysign(1.0, f + k * s_break if s_break > 0 else f)
                events.append((t, "slip"))
                continue
            t = t_next
            continue
        # Sliding with sign sliding: v(s) = v + A s + B s^2 / 2.
        A, B = (f - sliding * c) / m, k / m
        roots = np.roots([0.5 * B, A, v]) if B != 0.0 else ([-v / A] if A != 0.0 else [])
        s_stop = min([r.real for r in np.atleast_1d(roots)
                      if abs(np.imag(r)) == 0.0 and r.real > 1e-14], default=math.inf)
        s = min(s_stop, t_next - t)
        x += v * s + A * s * s / 2 + B * s ** 3 / 6
        v += A * s + B * s * s / 2
        t += s
        if s == s_stop:
            v = 0.0
            f_now = f + k * s
            if abs(f_now) <= c:
                sliding = 0.0
                events.append((t, "stick"))
            else:
                sliding = math.copysign(1.0, f_now)
                events.append((t, "reverse"))
    return events, x, v


def _stickslip_reference(scene):
    table_path = Path(scene.f1_table)
    table = np.loadtxt(table_path, comments="#", ndmin=2).T
    out = []
    final = []
    for i, tab in ((1, table), (2, None)):
        m = getattr(scene, f"m{i}")
        c = getattr(scene, f"mu{i}") * m * scene.g
        ev, xe, ve = friction_body_exact(m, c, tab, getattr(scene, f"f{i}") or 0.0,
                                         getattr(scene, f"x{i}"), getattr(scene, f"v{i}") or 0.0,
                                         scene.t_end)
        # The engine logs stick<i> and slip<i>; a stop-and-reverse has no kind in the log.
        out += [(t, f"{kind}{i}") for t, kind in ev if kind != "reverse"]
        final += [xe, ve]
    out.sort()
    return Reference(out, final, "closed form (piecewise-quadratic velocity, bench/common.py)")


def _sine_reference(scene):
    import warnings
    from scipy_reference import simulate_scipy
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # "rtol too small, set to 100 eps"
        best = simulate_scipy(scene, **SINE_REFERENCE)
        checks = [simulate_scipy(scene, **kw) for kw in SINE_CHECKS]
    ref = Reference(best.events, best.final,
                    "SciPy solve_ivp DOP853, rtol = 2.2e-14 (its floor), atol = 1e-16, "
                    "event-restart (bench/scipy_reference.py)")
    ref.error_estimate = max(event_time_error(c.events, ref)[0] for c in checks)
    ref.final_error_estimate = max(final_state_error(c.final, ref) for c in checks)
    return ref


def _oscillator_reference(scene):
    ref = exact_springs.impact_oscillator(scene.m1, scene.k1, scene.x1_rest, scene.x_left,
                                          scene.r_left, scene.x1, scene.v1 or 0.0, scene.t_end)
    (x, ), (v, ) = ref.state(scene.t_end)
    return Reference([(float(e.t), e.kind) for e in ref.events if e.kind == "left"],
                     [float(x), float(v), scene.x2, 0.0],
                     "closed form (harmonic arcs, 50 digits: tests/exact_springs.py)")


def _springslip_reference(scene):
    table = np.loadtxt(Path(scene.f1_table), comments="#", ndmin=2)
    pull = (table[1, 1] - table[0, 1]) / (table[1, 0] - table[0, 0])
    ref = exact_springs.stick_slip(scene.m1, scene.k1, scene.x1_rest, pull, scene.mu1,
                                   scene.mus1, scene.x1, scene.v1 or 0.0, scene.t_end,
                                   g=scene.g if scene.g is not None else exact_springs.DEFAULT_G)
    (x, ), (v, ) = ref.state(scene.t_end)
    return Reference([(float(e.t), e.kind) for e in ref.events if e.kind in ("stick1", "slip1")],
                     [float(x), float(v), scene.x2, 0.0],
                     "closed form (harmonic slip arcs, 50 digits: tests/exact_springs.py)")


_REFERENCES = {"case3": _case3_reference, "case5": _case5_reference,
               "stickslip": _stickslip_reference, "sine": _sine_reference,
               "oscillator": _oscillator_reference, "springslip": _springslip_reference}


def reference(name: str, scene=None) -> Reference:
    return _REFERENCES[name](load(name) if scene is None else scene)


# ----------------------------------------------------------------------------- errors
def match_events(run_events, ref_events, window=None):
    """Pairs (t_run, t_ref) matched by kind and by order within the kind."""
    by_kind_run, by_kind_ref = {}, {}
    for t, kind in run_events:
        by_kind_run.setdefault(kind, []).append(t)
    for t, kind in ref_events:
        if window is None or t <= window:
            by_kind_ref.setdefault(kind, []).append(t)
    pairs = []
    for kind, ref_times in by_kind_ref.items():
        run_times = by_kind_run.get(kind, [])
        pairs += list(zip(run_times, ref_times))
    return pairs


def event_time_error(run_events, ref: Reference):
    """(max |t_run - t_ref| over the shared events, number of shared events)."""
    pairs = match_events(run_events, ref.events, ref.window)
    if not pairs:
        return math.nan, 0
    return max(abs(a - b) for a, b in pairs), len(pairs)


def final_state_error(state, ref: Reference) -> float:
    return float(np.max(np.abs(np.asarray(state) - ref.final)))


def measured_order(dts, errors, floor=1e-10):
    """Least-squares slope of log(error) against log(dt), over the points above `floor`
    (rounding level: below it the error no longer depends on dt)."""
    pts = [(math.log(d), math.log(e)) for d, e in zip(dts, errors)
           if e is not None and np.isfinite(e) and e > floor]
    if len(pts) < 2:
        return math.nan
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


# ----------------------------------------------------------------------------- timing
def time_call(fn, min_repeats=3, max_repeats=50, budget=0.5):
    """Median wall time (time.perf_counter) of fn() over repeats: at least min_repeats,
    more while the total stays under `budget` seconds. Returns (median, value of the
    last call)."""
    times, value = [], None
    total_start = time.perf_counter()
    while len(times) < max_repeats:
        start = time.perf_counter()
        value = fn()
        times.append(time.perf_counter() - start)
        if len(times) >= min_repeats and time.perf_counter() - total_start > budget:
            break
    return statistics.median(times), value


# ----------------------------------------------------------------------------- machine
def _version(cmd):
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
        return out.splitlines()[0].strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def machine() -> dict:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    import scipy
    return {
        "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "nproc": os.cpu_count(),
        "cpu": cpu,
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "impact1d": impact1d.__version__,
        "gfortran": _version(["gfortran", "--version"]),
        "commit": _version(["git", "-C", str(REPO), "log", "-1", "--format=%h %s"]),
        "dirty": _dirty(),
    }


def _dirty() -> bool:
    """True when the engine's sources differ from the commit (the build is of the tree)."""
    try:
        out = subprocess.run(["git", "-C", str(REPO), "status", "--porcelain", "--", "src",
                              "app", "wrapper", "meson.build"],
                             capture_output=True, text=True, check=True).stdout
        return bool(out.strip())
    except (OSError, subprocess.CalledProcessError):
        return False


def step_sum_drift(dt: float, t_end: float) -> float:
    """How far t_end/dt additions of dt (t = t + dt, as a stepping loop does) end from the
    exact sum of those steps: the rounding drift of an uncompensated time."""
    from fractions import Fraction
    n = int(round(t_end / dt))
    t = 0.0
    for _ in range(n):
        t += dt
    return float(Fraction(t) - Fraction(dt) * n)


def machine_markdown(info: dict) -> str:
    return (f"Measured on {info['date']}: {info['nproc']} cores, {info['cpu']} "
            f"({info['platform']}); Python {info['python']}, numpy {info['numpy']}, "
            f"SciPy {info['scipy']}, {info['gfortran']}; impact1d {info['impact1d']} "
            f"at commit `{info['commit']}`"
            + (" plus uncommitted changes to the engine" if info.get("dirty") else "")
            + ". The machine is shared and noisy: ratios measured "
            "in one run are meaningful, absolute times only roughly.")


# ----------------------------------------------------------------------------- output
def save_json(name: str, data) -> Path:
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(data, indent=1, default=float))
    return path


def load_json(name: str):
    return json.loads((RESULTS / f"{name}.json").read_text())


def markdown_table(rows, header) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def fmt(x, digits=2) -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}e}" if (x != 0 and (abs(x) < 1e-2 or abs(x) >= 1e4)) else f"{x:.{digits + 1}g}"


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"figure.dpi": 110, "font.size": 9, "axes.grid": True,
                         "grid.alpha": 0.3, "legend.fontsize": 8})
    return plt
