"""Impact and rest events read from a Siconos run's rows (bench/siconos_worker.py), in
impact1d's event-log terms [(t, kind)], so that bench/common.py's error measures apply.

Pure functions on plain arrays (numpy only): no Siconos and no impact1d needed, which is
what lets tests/test_siconos_events.py check them in `make test`.

Rows: [t, x1, v1, x2, v2, p_left, p_right, p_slot_min, p_slot_max, flag], one per step
(flag 1) and, for the event-driven scheme, one per nonsmooth event (flag 2), p being the
contact's impulse lambda(1) over the step or at the event.
"""

from __future__ import annotations

import numpy as np

CONTACTS = ("left", "right", "slot_min", "slot_max")
IMPULSE_COLUMNS = slice(5, 9)
FLAG_COLUMN = 9
STEP, NONSMOOTH = 1.0, 2.0

# An impulse above this (N s) is a contact at work. A contact outside the LCP has exactly
# zero; the smallest real impulses of the studied scenes are ~1e-3 N s (a body pressed
# on its wall with 2 N over a 1e-3 s step), far above rounding of impulses of order 10.
IMPULSE_FLOOR = 1e-12


def _active(rows):
    """Boolean (rows, 4): the contact's impulse is above the floor."""
    return np.asarray(rows, dtype=float)[:, IMPULSE_COLUMNS] > IMPULSE_FLOOR


def impacts_event_driven(rows):
    """[(t, kind)] of an event-driven run: every contact with an impulse at a nonsmooth
    event, at the event's time (located by the integrator's root finding)."""
    rows = np.asarray(rows, dtype=float)
    active = _active(rows)
    events = []
    for i in np.flatnonzero(rows[:, FLAG_COLUMN] == NONSMOOTH):
        events += [(float(rows[i, 0]), kind) for k, kind in enumerate(CONTACTS) if active[i, k]]
    return events


def impacts_time_stepping(rows):
    """[(t, kind)] of a time-stepping run: a contact's impact is the first step of each
    run of steps in which it carries an impulse, at that step's end time (the first
    time the post-impact velocity is seen; the impact itself lies within the step)."""
    rows = np.asarray(rows, dtype=float)
    active = _active(rows)
    events = []
    for k, kind in enumerate(CONTACTS):
        starts = active[:, k] & ~np.concatenate([[False], active[:-1, k]])
        events += [(float(t), kind) for t in rows[starts, 0]]
    return sorted(events, key=lambda e: e[0])          # contact order at one instant


def rest_times(rows):
    """{kind: t} of a time-stepping run: for each contact that still carries an impulse
    at the last step, the end time of the first step of that final unbroken run (from
    there on the contact stays closed: the body rests on it)."""
    rows = np.asarray(rows, dtype=float)
    active = _active(rows)
    out = {}
    for k, kind in enumerate(CONTACTS):
        if rows.size == 0 or not active[-1, k]:
            continue
        open_steps = np.flatnonzero(~active[:, k])
        first = open_steps[-1] + 1 if open_steps.size else 0
        out[kind] = float(rows[first, 0])
    return out


def time_stepping_log(rows):
    """Impacts and `rest_<contact>` entries of a time-stepping run, in time order, a rest
    after the impact of the same instant (as impact1d logs them)."""
    events = impacts_time_stepping(rows)
    events += [(t, f"rest_{kind}") for kind, t in rest_times(rows).items()]
    return sorted(events, key=lambda e: (e[0], e[1].startswith("rest_")))
