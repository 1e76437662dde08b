"""The frictionless scenes written as a SciPy user would: scipy.integrate.solve_ivp on
y = (x1, v1, x2, v2) with one terminal event per constraint (direction -1: the gap
closing), restarted after each impact with Newton's restitution law.

This is the comparison point of the work-precision and speed studies, not a second
solver of the project: no Zeno handling, no friction, no force tables. A user's loop needs
a guard against impacts that accumulate (case 5): it stops after MAX_IMPACTS impacts,
or when the event time stops advancing, and reports which.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

# A contact whose gap is this close to zero at an event takes part in the impact (a user's
# choice: far above the event location's rounding, far below any real gap).
TOUCH_TOL = 1e-9

# Guards of the restart loop (see the module docstring).
MAX_IMPACTS = 2000
STALL_EVENTS = 50          # this many impacts in a row without t advancing: give up

_CONTACTS = (  # name, normal on (x1, x2), limit field, restitution field
    ("left", (1.0, 0.0), "x_left", "r_left"),
    ("right", (0.0, -1.0), "x_right", "r_right"),
    ("slot_min", (-1.0, 1.0), "d_min", "r_min"),
    ("slot_max", (1.0, -1.0), "d_max", "r_max"),
)


def _gap_function(name, limit):
    if name == "left":
        return lambda t, y: y[0] - limit
    if name == "right":
        return lambda t, y: limit - y[2]
    if name == "slot_min":
        return lambda t, y: (y[2] - y[0]) - limit
    return lambda t, y: limit - (y[2] - y[0])


class ScipyRun:
    """Result of simulate_scipy: events [(t, kind)], samples, final state, diagnostics."""

    def __init__(self):
        self.events = []
        self.t = []
        self.y = []
        self.final = None
        self.nfev = 0
        self.stop_reason = "t_end reached"
        self.t_stopped = math.nan


def simulate_scipy(scene, method="DOP853", rtol=1e-9, atol=None, t_eval=None, t_end=None):
    """Run a frictionless impact1d.Scene (constant and sine forces) with solve_ivp.

    atol defaults to rtol * 1e-3 (positions and velocities are of order 1-10).
    t_eval: sample times (as solve_ivp's t_eval), or None for the final state only."""
    if (scene.mu1 or 0.0) != 0.0 or (scene.mu2 or 0.0) != 0.0:
        raise ValueError("the SciPy version handles frictionless scenes only")
    if scene.f1_table or scene.f2_table:
        raise ValueError("the SciPy version handles constant and sine forces only")
    atol = rtol * 1e-3 if atol is None else atol
    t_end = float(scene.t_end if t_end is None else t_end)
    m = np.array([scene.m1, scene.m2], dtype=float)

    def sine_term(i):
        amp = getattr(scene, f"f{i}_amp")
        if not amp:
            return 0.0, 1.0, 0.0
        return (float(amp), 2.0 * math.pi / float(getattr(scene, f"f{i}_period")),
                float(getattr(scene, f"f{i}_phase") or 0.0))

    f_const = [float(scene.f1 or 0.0), float(scene.f2 or 0.0)]
    (a1, w1, p1), (a2, w2, p2) = sine_term(1), sine_term(2)

    def rhs(t, y):
        f1 = f_const[0] + a1 * math.sin(w1 * t + p1)
        f2 = f_const[1] + a2 * math.sin(w2 * t + p2)
        return [y[1], f1 / m[0], y[3], f2 / m[1]]

    contacts, events = [], []
    for name, normal, limit_name, r_name in _CONTACTS:
        limit = getattr(scene, limit_name)
        if limit is None:
            continue
        r = getattr(scene, r_name)
        contacts.append((name, np.array(normal), float(limit), 1.0 if r is None else float(r)))
        g = _gap_function(name, float(limit))
        g.terminal = True
        g.direction = -1
        events.append(g)

    run = ScipyRun()
    t = 0.0
    y = np.array([scene.x1, scene.v1 or 0.0, scene.x2, scene.v2 or 0.0], dtype=float)
    t_eval = None if t_eval is None else np.asarray(t_eval, dtype=float)
    stalls, last_t = 0, -math.inf
    while True:
        seg_eval = None
        if t_eval is not None:
            seg_eval = t_eval[(t_eval >= t) & (t_eval <= t_end)]
        sol = solve_ivp(rhs, (t, t_end), y, method=method, rtol=rtol, atol=atol,
                        events=events, t_eval=seg_eval)
        run.nfev += sol.nfev
        if sol.t.size and t_eval is not None:
            run.t.extend(sol.t.tolist())
            run.y.extend(sol.y.T.tolist())
        if sol.status != 1:
            if sol.status < 0:
                run.stop_reason = f"solve_ivp failed: {sol.message}"
            run.final = sol.y[:, -1].copy()
            run.t_stopped = float(sol.t[-1])
            break
        k = next(i for i, te in enumerate(sol.t_events) if te.size)
        t = float(sol.t_events[k][0])
        y = sol.y_events[k][0].copy()
        # Restitution on every touching, approaching contact (simultaneous impacts),
        # most approaching first, until none approaches.
        for _ in range(100):
            worst, pick = 0.0, None
            for name, n, limit, r in contacts:
                gap = events[[c[0] for c in contacts].index(name)](t, y)
                vn = n[0] * y[1] + n[1] * y[3]
                if abs(gap) <= TOUCH_TOL and vn < worst:
                    worst, pick = vn, (name, n, r)
            if pick is None:
                break
            name, n, r = pick
            p = -(1.0 + r) * worst / (n[0] ** 2 / m[0] + n[1] ** 2 / m[1])
            y[1] += n[0] * p / m[0]
            y[3] += n[1] * p / m[1]
            run.events.append((t, name))
        stalls = stalls + 1 if t <= last_t else 0
        last_t = t
        if len(run.events) >= MAX_IMPACTS:
            run.stop_reason = f"stopped by the user's guard after {MAX_IMPACTS} impacts"
            run.final, run.t_stopped = y, t
            break
        if stalls >= STALL_EVENTS:
            run.stop_reason = (f"stopped by the user's guard: {STALL_EVENTS} events in a row "
                               f"at t = {t!r} (time no longer advances)")
            run.final, run.t_stopped = y, t
            break
    run.t = np.array(run.t)
    run.y = np.array(run.y)
    return run
