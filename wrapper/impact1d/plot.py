"""Plots of one impact1d run: positions, velocities, applied forces, kinetic and potential
energy, impacts, energy ledger; and of a sweep's table.

The panels follow the VisSim tutorial's result figures (positions: Figures 19
and 21; kinetic energy: Figures 20 and 22; impact indicator: Figure 23) and add
the energy ledger that every run reports.

A *result* is anything with the attributes of :class:`impact1d.Result`:
``t x1 v1 x2 v2 ke work friction_loss impact_loss residual`` (1-D arrays; ``pe``
and ``damping_loss`` too when present), ``events`` (structured array with fields
``t kind v1_before v2_before v1_after v2_after``, or None) and ``scene`` (an
object with the scene's fields, absent ones None or missing; may itself be
None).  Both ``impact1d.simulate`` and ``impact1d.read_output`` return such
objects; one read back without its scene has ``forces_known = False`` (the file
does not record its force tables), and then no force panel is drawn.

Only the object API of matplotlib is used (``matplotlib.figure.Figure``), so
this module never touches pyplot's global state or picks a backend:
``save`` renders PNGs through Agg on any machine.

Artists carry a ``gid`` so tests and scripts can find them: lines ``x1 x2 v1 v2
f1 f2 ke pe work friction_loss impact_loss damping_loss ke_change residual``, walls ``wall:left``,
``wall:right``, the slot band ``slot_band`` (or ``slot:min``/``slot:max`` when
only one limit exists), the limits of the scene's &contact records ``wall:<name>``
(with the ground: a wall, or a dashed stop of one body) and ``limit:<name>`` (between
the bodies: a line at x_a + d, as the slot's), impact markers on the position panel
``impact:<contact>``, impact ticks ``tick:<contact>`` and persistent-contact
bars ``rest:<contact>`` on the impact panel, friction events ``stick1`` etc. on
the velocity panel.  Axes are labelled (``Axes.get_label()``) ``positions
velocities forces kinetic_energy potential_energy impacts ledger residual``.

Mechanisms of any number of bodies: :func:`spacetime` (every body's position against
time, impacts where they happen, what holds; a colour map over body index and time for
many bodies), the default picture of :func:`figure` for three bodies or more, and
:func:`animate` (the mechanism moving, as a GIF or MP4). They read a small interface that
today's Result and the N-body Result of DESIGN.md ("Mechanisms as data") both have:
``t``; ``x``, ``v`` as (samples, N) arrays, or ``x1 v1 [x2 v2]``; ``ke``; events with
``t`` and ``kind`` (and, for N > 2, ``a``, ``b``: the contact's ends, 0 the ground); the
scene's contact records (``scene.contacts``: ``a b d_min d_max name [name_min name_max]``,
as mappings or objects) or today's walls and slot, and its springs (``scene.springs``:
``a b d_rest``, or today's ``k1 x1_rest k2 x2_rest k12 d_rest``).
"""

from __future__ import annotations

import math
import os
import warnings
from typing import NamedTuple, Optional

import numpy as np
from matplotlib.figure import Figure
from matplotlib import colormaps
from matplotlib.ticker import MaxNLocator, ScalarFormatter

from ._files import check_input, write_whole
from ._simulate import is_impact_kind

__all__ = ["figure", "save", "sweep", "applied_forces", "spacetime", "animate", "PANELS",
           "NBODY_PANELS", "CONTACTS"]

#: Panel names, in drawing order; ``save(..., separate=True)`` appends them to the file stem.
#: A run has those of its content: ``forces`` when drawn (see :func:`figure`),
#: ``potential_energy`` with springs (a ``pe`` column), the others always.
PANELS = ("positions", "velocities", "forces", "kinetic_energy", "potential_energy", "impacts",
          "energy")

#: The panels of a run of three bodies or more (figure's default picture for N >= 3): the
#: space-time plot (:func:`spacetime`), kinetic and potential energy, the ledger.
NBODY_PANELS = ("spacetime", "kinetic_energy", "potential_energy", "energy")

#: The four unilateral constraints, in the order of the impact panel's rows (top to bottom).
CONTACTS = ("left", "right", "slot_min", "slot_max")

_CONTACT_LABEL = {
    "left": "left wall",
    "right": "right wall",
    "slot_min": "slot min",
    "slot_max": "slot max",
}
# Colours: bodies take the first two of the default cycle, contacts four others,
# so a marker's colour says which constraint was hit, not which body.
_BODY_COLOR = {1: "tab:blue", 2: "tab:orange"}
_CONTACT_COLOR = {
    "left": "tab:green",
    "right": "tab:red",
    "slot_min": "tab:purple",
    "slot_max": "tab:brown",
}
# Which bodies a contact involves (the body whose position marks the impact).
_CONTACT_BODIES = {"left": (1,), "right": (2,), "slot_min": (1, 2), "slot_max": (1, 2)}

_HEIGHT = {  # relative panel heights in the combined figure
    "positions": 3.0,
    "velocities": 2.0,
    "forces": 1.6,
    "kinetic_energy": 1.8,
    "potential_energy": 1.6,
    "impacts": 0.45,  # per row of the impact indicator, plus a base below
    "ledger": 2.0,
    "residual": 1.1,
    "spacetime": 4.5,
}
_WIDTH = 11.0  # inches; with dpi 100 the PNG is 1100 px wide


# ----------------------------------------------------------------------------
# access to the result (only the documented attributes)


def _scene_value(result, name):
    """A scene field, or None when the scene or the field is absent."""
    scene = getattr(result, "scene", None)
    if scene is None:
        return None
    value = getattr(scene, name, None)
    if value is None:
        return None
    if isinstance(value, (bytes, bytearray)):
        value = value.decode(errors="replace")
    if isinstance(value, str):
        value = value.strip()
        return value or None
    return value


def _float_or_none(value):
    if value is None:
        return None
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return out if np.isfinite(out) else None


def _kind_str(kind):
    if isinstance(kind, (bytes, bytearray, np.bytes_)):
        kind = bytes(kind).decode(errors="replace")
    return str(kind).strip()


def _events(result):
    """List of (t, kind) pairs, in time order."""
    ev = getattr(result, "events", None)
    if ev is None or len(ev) == 0:
        return []
    times = np.asarray(ev["t"], dtype=float)
    kinds = [_kind_str(k) for k in ev["kind"]]
    order = np.argsort(times, kind="stable")
    return [(float(times[i]), kinds[i]) for i in order]


def _event_times(events, kind):
    return np.array([t for t, k in events if k == kind], dtype=float)


def _contacts_present(result, events):
    """Contacts drawn in the impact panel: the tutorial's the scene has, plus any that had
    events, then the rows of its &contact records."""
    limits = {
        "left": "x_left",
        "right": "x_right",
        "slot_min": "d_min",
        "slot_max": "d_max",
    }
    seen = set()
    for _, kind in events:
        for c in CONTACTS:
            if kind in (c, "rest_" + c, "release_" + c):
                seen.add(c)
    tutorial = [c for c in CONTACTS if c in seen or _float_or_none(_scene_value(result, limits[c])) is not None]
    # The rows of the scene's &contact records (one or two bodies), after the tutorial's.
    extra = [row.name for row in _scene_record_rows(result)]
    return tutorial + [name for name in dict.fromkeys(extra) if name not in tutorial]


# Colours of the records' rows (impact panel), after the tutorial's four, in turn.
_RECORD_COLORS = ("tab:pink", "tab:olive", "tab:cyan", "tab:gray", "gold", "navy", "teal", "maroon")


def _contact_color(contact, contacts):
    """A tutorial contact's own colour; a record's row one of _RECORD_COLORS by its place."""
    if contact in _CONTACT_COLOR:
        return _CONTACT_COLOR[contact]
    extra = [c for c in contacts if c not in _CONTACT_COLOR]
    return _RECORD_COLORS[extra.index(contact) % len(_RECORD_COLORS)]


def _rest_intervals(events, contact, t_start, t_end):
    """(start, end) of each persistent contact: rest_<c> to release_<c> or the end of the run.

    A release with no rest before it means the run started in that contact.
    """
    return _intervals(events, "rest_" + contact, "release_" + contact, t_start, t_end)


def _intervals(events, begin, end, t_start, t_end):
    """(start, end) of each stretch from a `begin` event to an `end` one or the end of the
    run; an `end` with no `begin` before it: from the run's start."""
    out = []
    start = None
    for t, kind in events:
        if kind == begin and start is None:
            start = t
        elif kind == end:
            out.append((t_start if start is None else start, t))
            start = None
    if start is not None:
        out.append((start, t_end))
    return out


def _title(result):
    title = _scene_value(result, "title")
    if title:
        return str(title)
    source = _scene_value(result, "source")
    if source:
        return os.path.basename(str(source))
    return "impact1d run"


def _subtitle(window, events):
    parts = []
    method = _scene_value(window, "method")
    if method:
        parts.append(f"method {method}")
    dt = _float_or_none(_scene_value(window, "dt"))
    if dt is not None:
        parts.append(f"dt = {dt:g} s")
    n_impacts = sum(1 for _, k in events if is_impact_kind(k))
    where = f" in t = {window.span[0]:g} to {window.span[1]:g} s" if window.span != window.run else ""
    parts.append(f"{n_impacts} impact{'s' if n_impacts != 1 else ''}{where}")
    residual = np.asarray(window.result.residual, dtype=float)
    if residual.size:
        parts.append(f"max |energy residual| = {np.max(np.abs(residual)):.1e} J")
    return "  \u00b7  ".join(parts)


# ----------------------------------------------------------------------------
# what the panels draw: a time window of the run, its applied forces

# Every sample column a result may have (impact1d.COLUMNS, without importing the core).
_SAMPLES = ("t", "x1", "v1", "x2", "v2", "ke", "pe", "work", "friction_loss", "impact_loss",
            "damping_loss", "drive_work", "residual")


class _Window:
    """The result as the panels see it: its samples from t_from to t_to (with the sample on
    each side, so that lines reach the window's edges; all of them by default), its events
    (`events`: all, in time order) and what counts from the run's start (`run`: its first
    and last times; `energy0`: KE + PE at the first sample, which the ledger counts from)."""

    def __init__(self, result, t_from=None, t_to=None):
        t = np.asarray(result.t, dtype=float)
        self.result, self.scene = result, getattr(result, "scene", None)
        self.run = (float(t[0]), float(t[-1])) if t.size else (0.0, 0.0)
        self.span = _span(self.run, t_from, t_to)
        inside = _samples_around(t, self.span)
        for name in _SAMPLES:
            column = getattr(result, name, None)
            setattr(self, name, None if column is None else np.asarray(column, dtype=float)[inside])
        self.energy0 = 0.0
        for name in ("ke", "pe"):
            column = getattr(result, name, None)
            if column is not None and len(column):
                self.energy0 += float(column[0])
        self.events = _events(result)
        self.forces = None      # (times, {"f1": ..., "f2": ...}) when the panel is drawn

    def within(self, events):
        """The (t, kind) pairs inside the window."""
        lo, hi = self.span
        return [(t, kind) for t, kind in events if lo <= t <= hi]


def _span(run, t_from, t_to):
    """The window (t_from, t_to) within the run's times; ValueError if it is empty."""
    lo = run[0] if t_from is None else float(t_from)
    hi = run[1] if t_to is None else float(t_to)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise ValueError(f"the time window must be finite, got t_from = {lo:g}, t_to = {hi:g}")
    if t_from is not None and t_to is not None and lo >= hi:
        raise ValueError(f"the time window is empty: t_from = {lo:g} s is not below t_to = {hi:g} s")
    if (t_from is not None or t_to is not None) and (hi <= run[0] or lo >= run[1]):
        raise ValueError(f"the time window t = {lo:g} to {hi:g} s misses the run "
                         f"(t = {run[0]:g} to {run[1]:g} s)")
    return max(lo, run[0]), min(hi, run[1])


def _force_terms(result):
    """Each body's force terms from the result's scene: {"f1": (constant, table or None,
    [(amp, period, phase), ...]), ...} (table: its corner times and values; the sines: the
    body's own, then its &sine records'), "f2" only with a second body. ValueError saying
    why when the result does not know its forces."""
    scene = getattr(result, "scene", None)
    if scene is None:
        raise ValueError("the result has no scene to take its forces from")
    if not getattr(result, "forces_known", True):
        raise ValueError("the output file does not record its force tables (read it with "
                         "read_output(path, scene=...), or impact1d-plot --scene SCENE)")
    bodies = (1, 2) if getattr(result, "x2", None) is not None else (1,)
    terms = {}
    for body in bodies:
        constant = _float_or_none(_scene_value(result, f"f{body}")) or 0.0
        table = _scene_value(result, f"f{body}_table")
        if table is not None:
            table = _force_table(os.fspath(table))
        amp = _float_or_none(_scene_value(result, f"f{body}_amp"))
        period = _float_or_none(_scene_value(result, f"f{body}_period"))
        phase = _float_or_none(_scene_value(result, f"f{body}_phase")) or 0.0
        sines = [(amp, period, phase)] if amp and period else []
        sines += [(float(r["amp"]), float(r["period"]), float(r.get("phase") or 0.0))
                  for r in (_scene_value(result, "sines") or []) if int(r["body"]) == body]
        terms[f"f{body}"] = (constant, table, sines)
    return terms


def _force_table(path):
    """A force table's (times, values): two columns, '#' comments (the core has checked it
    when it ran the scene)."""
    try:
        check_input(path, "force table")
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as error:
        raise ValueError(f"the force table cannot be read: {error}") from None
    if data.shape[1] != 2 or data.shape[0] == 0:
        raise ValueError(f"the force table {path} is not two columns t f")
    return data[:, 0], data[:, 1]


def _force_values(terms, t):
    """f_i(t) = f_i + table_i(t) + sum of amp sin(2 pi t / period + phase), each term when
    named (a table held at its end values outside its times, as the core does)."""
    out = {}
    for name, (constant, table, sines) in terms.items():
        f = np.full(t.shape, constant)
        if table is not None:
            f = f + np.interp(t, *table)
        for amp, period, phase in sines:
            f = f + amp * np.sin(2.0 * np.pi * t / period + phase)
        out[name] = f
    return out


# A sine drawn with at least this many points per period (samples may be coarser), and
# never more than this many points in all.
_SINE_POINTS, _MAX_FORCE_POINTS = 48, 200_000


def _force_times(terms, window):
    """Where to draw the forces: the window's samples, its edges, the tables' corners in it
    (a triangle stays sharp whatever dt_out is), and a fine grid under a sine."""
    lo, hi = window.span
    t = window.t[(window.t >= lo) & (window.t <= hi)]
    parts = [t, np.array([lo, hi])]
    for _, table, sines in terms.values():
        if table is not None:
            parts.append(table[0][(table[0] > lo) & (table[0] < hi)])
        if sines:
            fastest = min(abs(period) for _, period, _ in sines)
            count = min(int(_SINE_POINTS * (hi - lo) / fastest) + 2, _MAX_FORCE_POINTS)
            parts.append(np.linspace(lo, hi, count))
    return np.unique(np.concatenate(parts))


def applied_forces(result, t=None) -> dict:
    """The applied forces of the result's scene, f_i(t) = f_i + table_i(t) + f_i_amp
    sin(2 pi t / f_i_period + f_i_phase) + body i's &sine terms (Scene.sines), at the times
    `t` (default: the result's samples):
    {"f1": array, "f2": array} ("f2" only with a second body). Springs, dampers, friction
    and contacts are not applied forces. ValueError saying why when the result does not
    know its forces: no scene, a file read back without its scene (the header does not
    record force tables), a force table that cannot be read."""
    times = np.asarray(result.t if t is None else t, dtype=float)
    return _force_values(_force_terms(result), times)


def _forces_vary(terms) -> bool:
    """Whether some force changes in time (a table or a sine): a constant one is flat."""
    return any(table is not None or sines for _, table, sines in terms.values())


# ----------------------------------------------------------------------------
# panels


def _finish_time_axis(ax, window):
    if window.span[1] > window.span[0]:
        ax.set_xlim(*window.span)
    ax.grid(True, alpha=0.3)


def _legend(ax, **kw):
    # Outside the plotting area, right: legends never hide the curves.
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
              fontsize="small", frameon=False, **kw)


def _draw_positions(ax, result, events):
    t = np.asarray(result.t, dtype=float)
    x1 = np.asarray(result.x1, dtype=float)
    # A one-body scene has no x2: drawn as an empty series.
    x2 = np.asarray(result.x2 if result.x2 is not None else x1[:0], dtype=float)
    n = 2 if x2.size else 1
    d_min = _float_or_none(_scene_value(result, "d_min"))
    d_max = _float_or_none(_scene_value(result, "d_max"))
    # Walls: the tutorial's, then the records' limits that bound every body (body 1's
    # lower, body N's upper); the records' other limits are drawn as stops and slots. Each
    # as (name, line over t, side, label, still): a moving wall where it is at each time.
    walls = [(row.name, _ground_line(row, t), row.side,
              f"{row.name} wall x = {row.limit:g} m" + (" + w(t)" if row.motion else ""), not row.motion)
             for record in _tutorial_records(result, n) if record["name"] in ("left", "right")
             for row in _record_rows(0, record)]
    records = _scene_record_rows(result)
    walls += [(row.name, _ground_line(row, t), row.side, _row_label(row), not row.motion)
              for row in records if _is_wall(row, n)]

    # Limits from the bodies and the walls only: a wide slot (case 5 has
    # d_max = 50 m) must not squash the motion.
    lo = [np.min(x1)] + ([np.min(x2)] if x2.size else []) if t.size else [0.0]
    hi = [np.max(x1)] + ([np.max(x2)] if x2.size else []) if t.size else [1.0]
    lo = float(min(lo + [np.min(w[1]) for w in walls if w[1].size]))
    hi = float(max(hi + [np.max(w[1]) for w in walls if w[1].size]))
    pad = 0.06 * (hi - lo) if hi > lo else 0.5
    ylim = (lo - pad, hi + pad)

    wall_lo = np.max([w for _, w, side, _, _ in walls if side == "min"] or [np.full(t.shape, -np.inf)], axis=0)
    wall_hi = np.min([w for _, w, side, _, _ in walls if side == "max"] or [np.full(t.shape, np.inf)], axis=0)

    def inside_walls(y):
        # x2 cannot pass a wall, so neither does the band that says where it may be.
        return np.clip(y, wall_lo, wall_hi)

    # A slot limit that stays beyond the walls (or out of view) all run never binds before
    # a wall does: drawn, it would only shade the panel (case 5: d_max = 50 m, walls 10 m
    # apart). Such a limit is left out.
    view = (max(float(np.min(wall_lo, initial=np.inf)), ylim[0]), min(float(np.max(wall_hi, initial=-np.inf)),
                                                                    ylim[1]))
    if d_min is not None and not _in_view(x1 + d_min, "min", view):
        d_min = None
    if d_max is not None and not _in_view(x1 + d_max, "max", view):
        d_max = None

    if d_min is not None and d_max is not None:
        ax.fill_between(t, inside_walls(x1 + d_min), inside_walls(x1 + d_max), color=_BODY_COLOR[2], alpha=0.10,
                        linewidth=0, gid="slot_band",
                        label=f"slot: x1 + [{d_min:g}, {d_max:g}] m")
    else:
        for name, d in (("min", d_min), ("max", d_max)):
            if d is not None:
                _draw_slot_line(ax, t, inside_walls(x1 + d), f"slot:{name}", f"slot {name}: x1 + {d:g} m")
    _draw_record_limits(ax, t, (x1, x2), [row for row in records if not _is_wall(row, n)], view,
                        inside_walls)

    for name, w, side, label, still in walls:
        beyond = ylim[0] - 1e3 * (pad + 1) if side == "min" else ylim[1] + 1e3 * (pad + 1)
        if still:
            w = float(w[0]) if w.size else 0.0
            ax.axhspan(min(w, beyond), max(w, beyond), color="0.85", zorder=0)
            ax.axhline(w, color="0.25", linewidth=1.5, gid=f"wall:{name}", label=label)
        else:
            ax.fill_between(t, w, beyond, color="0.85", linewidth=0, zorder=0)
            ax.plot(t, w, color="0.25", linewidth=1.5, gid=f"wall:{name}", label=label)

    ax.plot(t, x1, color=_BODY_COLOR[1], linewidth=1.4, gid="x1", label="x1 (body 1)")
    if x2.size:
        ax.plot(t, x2, color=_BODY_COLOR[2], linewidth=1.4, gid="x2", label="x2 (body 2)")

    # Smaller markers when impacts crowd (long runs), so the paths stay visible.
    contacts = _contacts_present(result, result.events)
    n_impacts = sum(1 for _, k in events if k in contacts)
    size = 5 if n_impacts <= 150 else 3
    # The bodies a record's row involves (its ends but the ground).
    bodies = {row.name: tuple(e for e in (row.a, row.b) if e > 0) for row in _rows(result, 2 if x2.size else 1)}
    bodies.update(_CONTACT_BODIES)
    for contact in CONTACTS + tuple(c for c in contacts if c not in CONTACTS):
        times = _event_times(events, contact)
        if times.size == 0:
            continue
        xs, ys = [], []
        # One body: both walls hold body 1.
        for body in (bodies[contact] if x2.size else (1,)):
            pos = x1 if body == 1 else x2
            xs.append(times)
            ys.append(np.interp(times, t, pos))
        ax.plot(np.concatenate(xs), np.concatenate(ys), linestyle="none", marker="o",
                markersize=size, markerfacecolor="none", markeredgewidth=1.2,
                color=_contact_color(contact, contacts), gid=f"impact:{contact}", zorder=5,
                label=f"impact, {_CONTACT_LABEL.get(contact, contact)}")

    ax.set_ylim(*ylim)
    ax.set_ylabel("position (m)")
    _finish_time_axis(ax, result)
    _legend(ax)


def _in_view(line, side, view):
    """Whether a lower ("min") or upper ("max") limit at `line` comes into view (lo, hi)
    some time in the run: one that never does never binds before a wall does."""
    return bool(np.any(line > view[0])) if side == "min" else bool(np.any(line < view[1]))


def _draw_slot_line(ax, t, line, gid, label, color=_BODY_COLOR[2], linestyle=":"):
    """A limit between two bodies: where it holds body b, x_a + d, in b's colour."""
    ax.plot(t, line, color=color, linestyle=linestyle, linewidth=1.0, gid=gid, label=label)


def _draw_record_limits(ax, t, positions, rows, view, inside_walls):
    """The records' limits that are not walls, labelled by name: a stop (a limit of body b
    with the ground) dashed at its position, a limit between two bodies as the slot's lines;
    each in the colour of the body it holds (dash-dotted: the slot's lines are dotted),
    left out as a slot limit is when it stays out of view all run."""
    for row in rows:
        line = _ground_line(row, t) if row.a == 0 else positions[row.a - 1] + row.limit
        if not _in_view(line, row.side, view):
            continue
        if row.a == 0:
            _draw_stop(ax, row, _BODY_COLOR[row.b], t)
        else:
            _draw_slot_line(ax, t, inside_walls(line), f"limit:{row.name}", _row_label(row),
                            _BODY_COLOR[row.b], "-.")


def _draw_velocities(ax, result, events):
    t = np.asarray(result.t, dtype=float)
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    ax.plot(t, np.asarray(result.v1, dtype=float), color=_BODY_COLOR[1], linewidth=1.2,
            gid="v1", label="v1 (body 1)")
    if result.v2 is not None:
        ax.plot(t, np.asarray(result.v2, dtype=float), color=_BODY_COLOR[2], linewidth=1.2,
                gid="v2", label="v2 (body 2)")
    # Friction mode switches: the body's velocity is zero there.
    styles = {"stick": ("s", "stuck (friction holds)"), "slip": ("D", "slips (breaks away)")}
    for what, (marker, text) in styles.items():
        for body in (1, 2):
            times = _event_times(events, f"{what}{body}")
            if times.size == 0:
                continue
            v = np.asarray(result.v1 if body == 1 else result.v2, dtype=float)
            ax.plot(times, np.interp(times, t, v), linestyle="none", marker=marker,
                    markersize=4, color=_BODY_COLOR[body], gid=f"{what}{body}",
                    label=f"body {body} {text}")
    ax.set_ylabel("velocity (m/s)")
    _finish_time_axis(ax, result)
    _legend(ax)


def _draw_energy(ax, result, name, label, color, ylabel):
    """An energy from zero up: a constant one (case 3's KE) then reads as a flat line, not
    as rounding noise blown up by autoscaling. KE and PE each have their own axes: one
    can be a thousand times the other (stick-slip: 5,000 J of spring energy, KE ~ 0.5 J)."""
    t = np.asarray(result.t, dtype=float)
    energy = np.asarray(getattr(result, name), dtype=float)
    ax.plot(t, energy, color=color, linewidth=1.3, gid=name, label=label)
    top = float(np.max(energy)) if energy.size else 1.0
    ax.set_ylim(0.0, 1.1 * top if top > 0 else 1.0)
    ax.set_ylabel(ylabel)
    _finish_time_axis(ax, result)
    _legend(ax)


def _draw_kinetic_energy(ax, result, events):
    label = "KE = m1 v1\u00b2/2" + (" + m2 v2\u00b2/2" if result.v2 is not None else "")
    if _bodies(result.result)[1].shape[1] > 2 or not _every_body(result.result):
        label = "KE = \u03a3 m_i v_i\u00b2/2"
    _draw_energy(ax, result, "ke", label, "black", "kinetic energy (J)")


def _draw_potential_energy(ax, result, events):
    _draw_energy(ax, result, "pe", "PE of the springs", "tab:purple", "potential energy (J)")


def _draw_forces(ax, result, events):
    times, forces = result.forces
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    for body in (1, 2):
        name = f"f{body}"
        if name in forces:
            ax.plot(times, forces[name], color=_BODY_COLOR[body], linewidth=1.3, gid=name,
                    label=f"{name}(t) on body {body}")
    ax.set_ylabel("applied force (N)")
    _finish_time_axis(ax, result)
    _legend(ax)


def _draw_impacts(ax, result, events):
    contacts = _contacts_present(result, result.events)
    n = len(contacts)
    for row, contact in enumerate(contacts):
        y = n - 1 - row  # first contact on top
        color = _contact_color(contact, contacts)
        # A rest that began before the window still shows in it: bars from every event.
        bars = _rest_intervals(result.events, contact, *result.run)
        if bars:
            ax.broken_barh([(a, b - a) for a, b in bars], (y - 0.3, 0.6), facecolors=color,
                           alpha=0.45, gid=f"rest:{contact}")
        times = _event_times(events, contact)
        if times.size:
            ax.plot(times, np.full(times.size, float(y)), linestyle="none", marker="|",
                    markersize=14, markeredgewidth=1.3, color=color, gid=f"tick:{contact}")
        if not bars and times.size == 0:
            ax.text(0.5, y, "no contact", transform=ax.get_yaxis_transform(), ha="center",
                    va="center", fontsize="small", color="0.5")
    if n == 0:
        ax.text(0.5, 0.5, "no walls, no slot", transform=ax.transAxes, ha="center",
                va="center", fontsize="small", color="0.5")
    ax.set_yticks(range(n))
    ax.set_yticklabels([_CONTACT_LABEL.get(c, c) for c in reversed(contacts)])
    ax.set_ylim(-0.6, n - 0.4 if n else 0.6)
    ax.set_ylabel("impacts")
    _finish_time_axis(ax, result)
    ax.grid(False, axis="y")
    from matplotlib.patches import Patch
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], linestyle="none", marker="|", markersize=10, color="0.3",
                      label="impact"),
               Patch(facecolor="0.3", alpha=0.45, label="persistent contact")]
    _legend(ax, handles=handles)


def _draw_ledger(ax, result, events):
    t = np.asarray(result.t, dtype=float)
    ke = np.asarray(result.ke, dtype=float)
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    ax.plot(t, np.asarray(result.work, dtype=float), color="tab:green", linewidth=1.3,
            gid="work", label="work of forces W")
    ax.plot(t, np.asarray(result.friction_loss, dtype=float), color="tab:olive",
            linewidth=1.3, gid="friction_loss", label="friction loss D")
    ax.plot(t, np.asarray(result.impact_loss, dtype=float), color="tab:red", linewidth=1.3,
            gid="impact_loss", label="impact loss Q")
    names = ["work", "friction_loss", "impact_loss"]
    losses = "D \u2212 Q"
    gains = "W"
    if getattr(result, "drive_work", None) is not None:
        ax.plot(t, np.asarray(result.drive_work, dtype=float), color="tab:purple", linewidth=1.3,
                gid="drive_work", label="moving ground's work M")
        names.append("drive_work")
        gains = "W + M"
    if getattr(result, "damping_loss", None) is not None:
        ax.plot(t, np.asarray(result.damping_loss, dtype=float), color="tab:brown", linewidth=1.3,
                gid="damping_loss", label="damping loss C")
        names.append("damping_loss")
        losses += " \u2212 C"
    energy, what = ke, "KE"
    if getattr(result, "pe", None) is not None:
        energy, what = ke + np.asarray(result.pe, dtype=float), "(KE + PE)"
    if ke.size:
        ax.plot(t, energy - result.energy0, color="black", linewidth=1.0, linestyle="--", gid="ke_change",
                label=f"{what} \u2212 {what}(0) = {gains} \u2212 {losses}")
    # On the scale of the run's energy: a ledger that stays at rounding level
    # (no forces, no losses: case 3) reads as flat zero lines, not as noise.
    series = [np.asarray(getattr(result, n), dtype=float)
              for n in names] + [energy - result.energy0 if ke.size else ke]
    values = np.concatenate([s[np.isfinite(s)] for s in series] + [np.zeros(1)])
    scale = max(float(np.max(np.abs(values))), float(np.max(ke)) if ke.size else 0.0)
    lo, hi = float(values.min()), float(values.max())
    if scale > 0 and hi - lo < 0.05 * scale:
        mid = 0.5 * (lo + hi)
        ax.set_ylim(mid - 0.1 * scale, mid + 0.1 * scale)
    ax.set_ylabel("energy (J)")
    _finish_time_axis(ax, result)
    _legend(ax)


def _draw_residual(ax, result, events):
    t = np.asarray(result.t, dtype=float)
    residual = np.asarray(result.residual, dtype=float)
    label = "KE \u2212 KE(0) \u2212 W + D + Q"
    if getattr(result, "pe", None) is not None:
        label = "(KE + PE) \u2212 (KE + PE)(0) \u2212 W + D + Q"
    if getattr(result, "drive_work", None) is not None:
        label = label.replace(" \u2212 W", " \u2212 W \u2212 M")
    if getattr(result, "damping_loss", None) is not None:
        label += " + C"
    ax.plot(t, residual, color="tab:gray", linewidth=1.0, gid="residual", label=label)
    amax = float(np.max(np.abs(residual))) if residual.size else 0.0
    # Symmetric limits around zero: the reader sees the residual's size, not its shape.
    ax.set_ylim(-1.15 * amax, 1.15 * amax) if amax > 0 else ax.set_ylim(-1.0, 1.0)
    fmt = ScalarFormatter(useMathText=True)
    fmt.set_powerlimits((-2, 3))
    ax.yaxis.set_major_formatter(fmt)
    ax.locator_params(axis="y", nbins=3)
    ax.set_ylabel("residual (J)")
    _finish_time_axis(ax, result)
    _legend(ax)


# ----------------------------------------------------------------------------
# mechanisms of N bodies: what the space-time plot and the animation read
#
# Only the trajectory interface of DESIGN.md ("Mechanisms as data"): Result.t; Result.x,
# Result.v as (samples, N) arrays (or today's x1, v1, x2, v2); Result.ke; events with t,
# kind and, for N > 2, the contact's ends a, b (0 = ground); the scene's contact records
# (a, b, d_min, d_max, name, name_min, name_max; or today's walls and slot) and springs.

_MAP_ABOVE = 50         # more bodies than this: a colour map over body index and time
_LEGEND_UP_TO = 10      # bodies named in a legend (more: a colour bar of the body index)
_DOTS_CLEAR = 1000      # impacts on a map drawn at full strength (more: fainter)


def _field(record, name, default=None):
    """A record's field, the record a mapping or an object; `default` when absent."""
    value = record.get(name) if isinstance(record, dict) else getattr(record, name, None)
    return default if value is None else value


def _bodies(result):
    """(t, X, V): the sample times and the (samples, N) positions and velocities, from
    Result.x and Result.v when the result has them (N bodies), else from x1, v1 and x2,
    v2 (today's one- and two-body Result: x2 None for one body)."""
    t = np.asarray(result.t, dtype=float)
    if getattr(result, "x", None) is not None:
        x, v = result.x, result.v
    else:
        names = ("1", "2") if getattr(result, "x2", None) is not None else ("1",)
        x = np.column_stack([np.asarray(getattr(result, "x" + i), dtype=float) for i in names])
        v = np.column_stack([np.asarray(getattr(result, "v" + i), dtype=float) for i in names])
    X = np.asarray(x, dtype=float).reshape(t.size, -1)
    return t, X, np.asarray(v, dtype=float).reshape(t.size, -1)


def _written(result, columns):
    """(numbers, n): the body number of each of the `columns` columns of x (Result.bodies:
    every body, or those of &run bodies_out; 1, 2, ... when the result does not say) and
    the scene's number of bodies (its m's length, or 2 with m2, 1 with m1 alone; else the
    highest body written)."""
    numbers = tuple(int(b) for b in (getattr(result, "bodies", None) or ()))
    if len(numbers) != columns:
        numbers = tuple(range(1, columns + 1))
    m = _scene_value(result, "m")
    if isinstance(m, (list, tuple, np.ndarray)):
        n = len(m)
    elif _scene_value(result, "m2") is not None:
        n = 2
    else:
        n = 1 if _scene_value(result, "m1") is not None else 0
    return numbers, max([n, *numbers])


def _every_body(result):
    """Whether the result has the x and v of every body of its scene (not so for an output
    of &run bodies_out)."""
    numbers, n = _written(result, _bodies(result)[1].shape[1])
    return numbers == tuple(range(1, n + 1))


class _Row(NamedTuple):
    """One limit of a contact record: x_b - x_a >= limit ("min") or <= limit ("max")."""
    name: str           # the event kind of its impacts
    a: int              # the ends: 0 is the ground (then the limit is a wall's position)
    b: int
    side: str
    limit: float
    record: int         # the record it comes from (a slot's two rows share one)
    motion: tuple = ()  # its ground end's (v, amp, period, phase, table) when it moves (ground_*)


_MOTION_FIELDS = ("v", "amp", "period", "phase")


def _motion(values, table=None):
    """(v, amp, period, phase, table) from a record's ground_* values (None: not named) and
    its ground_table's path (None: none; the table read as (t, w) arrays), or () when none
    is named: the ground end stays at 0."""
    if all(value is None for value in values) and table is None:
        return ()
    if table is not None:
        rows = np.loadtxt(table, comments="#", ndmin=2)
        table = (rows[:, 0], rows[:, 1])
    return tuple(float(value) if value is not None else 0.0 for value in values) + (table,)


def _ground_line(row, t):
    """Where a limit of body b with the ground holds b over the times t: its limit plus the
    ground end's prescribed position w(t) = v t + amp sin(2 pi t / period + phase) + table(t)
    (linear between the table's corners, held at its ends: np.interp's rule; docs/method.md
    section 11), as the engine moves it."""
    line = np.full(np.shape(t), row.limit, dtype=float)
    if row.motion:
        v, amp, period, phase, table = row.motion
        line = line + v * np.asarray(t, dtype=float)
        if amp:
            line = line + amp * np.sin(2.0 * np.pi * np.asarray(t, dtype=float) / period + phase)
        if table is not None:
            line = line + np.interp(np.asarray(t, dtype=float), *table)
    return line


def _tutorial_records(result, n, joined=()):
    """Today's walls and slot as contact records (docs/nbody-plan.md, 'Today's scene in
    records'): left (0, 1) lower, right (0, N) upper, the slot (1, 2) with its meeting
    (none when a record joins the bodies, (1, 2) in `joined`, and the scene gives no d_min:
    the record replaces the meeting, as in the engine); more than two bodies: link i of
    the chain shorthand (_chain_links)."""
    value = {name: _float_or_none(_scene_value(result, name))
             for name in ("x_left", "x_right", "d_min", "d_max")}
    records = []
    for wall, side, body in (("left", "min", 1), ("right", "max", n)):
        if value["x_" + wall] is not None:
            # (a moving wall, &walls x_left_v ...: its record's ground_* fields, as the engine's)
            records.append(dict(a=0, b=body, name=wall, **{"d_" + side: value["x_" + wall]}, **{
                "ground_" + f: _float_or_none(_scene_value(result, f"x_{wall}_{f}")) for f in _MOTION_FIELDS},
                ground_table=_scene_value(result, f"x_{wall}_table")))
    if n > 2:
        return records + _chain_links(result, n, joined)
    if n == 2:
        slot = dict(a=1, b=2, name="slot", name_min="slot_min", name_max="slot_max")
        if value["d_min"] is not None or (1, 2) not in joined:
            slot["d_min"] = value["d_min"] or 0.0
        if value["d_max"] is not None:
            slot["d_max"] = value["d_max"]
        if "d_min" in slot or "d_max" in slot:
            records.append(slot)
    return records


def _chain_links(result, n, joined):
    """Link i of more than two bodies (on x(i+1) - x(i), named link<i>), as the engine makes
    it (impact1d_chain's link_records): its &link d_min (d_max) element, or the bodies'
    meeting (d_min = 0) unless a &contact record joins the pair (in `joined`)."""
    arrays = {name: _scene_value(result, name) for name in ("d_min", "d_max")}
    links = []
    for i in range(1, n):
        link = dict(a=i, b=i + 1, name=f"link{i}")
        for name, values in arrays.items():
            if isinstance(values, (list, tuple, np.ndarray)) and i <= len(values) and \
                    _float_or_none(values[i - 1]) is not None:
                link[name] = float(values[i - 1])
        if "d_min" not in link and (i, i + 1) not in joined:
            link["d_min"] = 0.0
        if len(link) > 3:
            links.append(link)
    return links


def _record_rows(j, record):
    """The rows of contact record j, named as the engine names their events: one limit
    the record's name, two `<name>_min`/`<name>_max` (or name_min, name_max when given).
    A record with b = 0 is turned round (the ground is end a), as the engine does."""
    a, b = int(_field(record, "a", 0)), int(_field(record, "b", 0))
    limits = {side: _float_or_none(_field(record, "d_" + side)) for side in ("min", "max")}
    name = str(_field(record, "name", f"contact{j + 1}"))
    both = None not in limits.values()
    motion = _motion([_float_or_none(_field(record, "ground_" + f)) for f in _MOTION_FIELDS],
                     _field(record, "ground_table"))
    rows = []
    for side, limit in limits.items():
        if limit is None:
            continue
        label = str(_field(record, "name_" + side, f"{name}_{side}" if both else name))
        if b == 0:
            rows.append(_Row(label, 0, a, "max" if side == "min" else "min", -limit, j, motion))
        else:
            rows.append(_Row(label, a, b, side, limit, j, motion))
    return rows


def _scene_records(result):
    """The scene's &contact records (scene.contacts), [] when it has none."""
    scene = getattr(result, "scene", None)
    return (None if scene is None else _field(scene, "contacts")) or []


def _scene_record_rows(result):
    """The rows of the scene's &contact records (unnamed: contact<j>, j counting them)."""
    return [row for j, record in enumerate(_scene_records(result)) for row in _record_rows(j, record)]


def _rows(result, n):
    """The contact rows in the engine's order: today's walls and slot (a one- or two-body
    scene's), then the scene's records."""
    joined = {tuple(sorted((int(_field(r, "a", 0)), int(_field(r, "b", 0))))) for r in _scene_records(result)}
    tutorial = _tutorial_records(result, n, joined)
    return [row for record in tutorial for row in _record_rows(0, record)] + _scene_record_rows(result)


class _Event(NamedTuple):
    t: float
    kind: str
    contact: Optional[str]      # the contact it concerns (None: stick<i>, slip<i>)
    ends: Optional[tuple]       # (a, b) of that contact; (0, i) for body i's stick/slip


def _event_records(result):
    events = getattr(result, "events", None)
    if events is None or len(events) == 0:
        return []
    names = getattr(getattr(events, "dtype", None), "names", None)
    return [dict(zip(names, row)) for row in events.tolist()] if names else list(events)


def _mechanism_events(result, rows, n):
    """The log as _Events in time order. A contact's ends come from the event's a, b
    fields for N > 2 (for N <= 2 the engine reports the pair (1, 2) on every event), else
    from the record of that name; None when neither knows them."""
    ends = {row.name: (row.a, row.b) for row in rows}
    out = []
    for record in _event_records(result):
        kind = _kind_str(_field(record, "kind", ""))
        t = float(_field(record, "t"))
        for prefix in ("stick", "slip"):
            if kind.startswith(prefix) and kind[len(prefix):].isdigit():
                out.append(_Event(t, kind, None, (0, int(kind[len(prefix):]))))
                break
        else:
            contact = kind.split("_", 1)[1] if kind.startswith(("rest_", "release_")) else kind
            a, b = _field(record, "a"), _field(record, "b")
            pair = tuple(sorted((int(a), int(b)))) if n > 2 and a is not None else ends.get(contact)
            out.append(_Event(t, kind, contact, pair))
    out.sort(key=lambda e: e.t)
    return out


def _samples_around(t, span):
    """The slice of the samples from t_from to t_to with the sample on each side of it."""
    first = max(int(np.searchsorted(t, span[0], side="right")) - 1, 0)
    last = min(int(np.searchsorted(t, span[1], side="left")) + 1, t.size)
    return slice(first, last)


class _Mechanism:
    """A run as the N-body pictures see it: t, X, V (samples, N) and ke (None when the
    result has none) in the window `span` (with a sample each side), its contact rows,
    its events (`log`: all; `events`: those in the window) and each contact's ends."""

    def __init__(self, result, t_from=None, t_to=None):
        t, X, V = _bodies(result)
        # (an output of &run bodies_out has some bodies: numbers says which, n counts all)
        self.numbers, self.n = _written(result, X.shape[1])
        self.column = {body: k for k, body in enumerate(self.numbers)}
        self.result = result
        self.run = (float(t[0]), float(t[-1])) if t.size else (0.0, 0.0)
        self.span = _span(self.run, t_from, t_to)
        inside = _samples_around(t, self.span)
        self.first = inside.start          # the result's index of self.t[0]
        self.t, self.X, self.V = t[inside], X[inside], V[inside]
        ke = getattr(result, "ke", None)
        self.ke = None if ke is None else np.asarray(ke, dtype=float)[inside]
        self.rows = _rows(result, self.n)
        self.log = _mechanism_events(result, self.rows, self.n)
        self.events = [e for e in self.log if self.span[0] <= e.t <= self.span[1]]
        self.ends = {row.name: (row.a, row.b) for row in self.rows}
        self.ends.update((e.contact, e.ends) for e in self.log if e.contact and e.ends)
        self._paths = {}            # body -> path(body)
        self.by_kind = {}           # kind -> [(index in the log, event)]
        for index, e in enumerate(self.log):
            self.by_kind.setdefault(e.kind, []).append((index, e))

    def position(self, body, times):
        """Body `body`'s position at `times`, linear along its path (NaN: not written)."""
        if body not in self.column:
            return np.full(np.shape(times), np.nan)
        return np.interp(times, *self.path(body))

    def path(self, body):
        """(times, positions) of a written body: its samples and, where the log gives the
        velocities of its impacts (va_before ... of more than two bodies), its position at
        each impact in the window, so that a line reaches the wall or the other body where
        the marker is instead of cutting the corner between samples (_impact_positions)."""
        if body not in self._paths:
            k = self.column[body]
            times, x = _impact_positions(self, body, self.X[:, k], self.V[:, k])
            order = np.argsort(np.concatenate([self.t, times]), kind="stable")
            self._paths[body] = (np.concatenate([self.t, times])[order], np.concatenate([self.X[:, k], x])[order])
        return self._paths[body]

    def held(self, begin, end):
        """(start, end) of each interval from a `begin` event to an `end` one (or the run's
        end; an `end` with no `begin` before it: held from the run's start), in the window."""
        lo, hi = self.span
        # Only the two kinds' events, in log order (a body's or contact's events among
        # 1e5 others: the loops over bodies and contacts stay O(events)).
        both = sorted(self.by_kind.get(begin, []) + self.by_kind.get(end, []))
        pairs = [(e.t, e.kind) for _, e in both]
        return [(max(a, lo), min(b, hi)) for a, b in _intervals(pairs, begin, end, *self.run)
                if b >= lo and a <= hi]


def _impact_positions(mech, body, x, v):
    """(times, positions) of body `body` at its impacts in the window, from the log's
    velocities (va_before, vb_before, va_after, vb_after: runs of more than two bodies):
    from the point before (a sample, or the impact before with its velocity after),
    x_e = x_p + (v_p + v_before) (t_e - t_p) / 2, exact under constant forces between the
    two. None known (another log): no points."""
    events = getattr(mech.result, "events", None)
    names = getattr(getattr(events, "dtype", None), "names", None) or ()
    if "va_before" not in names or len(events) == 0:
        return np.empty(0), np.empty(0)
    if not hasattr(mech, "_impacts"):
        kinds = [_kind_str(k) for k in events["kind"]]
        mech._impacts = np.array([is_impact_kind(k) for k in kinds], dtype=bool) & \
            (events["t"] >= mech.t[0]) & (events["t"] <= mech.t[-1])
    ends_a, ends_b = events["a"] == body, events["b"] == body
    mine = np.flatnonzero(mech._impacts & (ends_a | ends_b))
    times, positions = [], []
    last = (None, None, None)             # the impact before: (t, x, v after)
    for j in mine[np.argsort(events["t"][mine], kind="stable")]:
        te = float(events["t"][j])
        before, after = (("va_before", "va_after") if ends_a[j] else ("vb_before", "vb_after"))
        k = int(np.searchsorted(mech.t, te, side="right")) - 1
        if last[0] is not None and (k < 0 or last[0] >= mech.t[k]):
            tp, xp, vp = last
        elif k >= 0:
            tp, xp, vp = mech.t[k], x[k], v[k]
        else:
            continue
        xe = xp + 0.5 * (vp + float(events[before][j])) * (te - tp)
        times.append(te)
        positions.append(xe)
        last = (te, xe, float(events[after][j]))
    return np.array(times), np.array(positions)


def _body_colors(n):
    """The default cycle for a few bodies (1 and 2 keep today's blue and orange), a
    sequential map over the body index for more."""
    if n <= _LEGEND_UP_TO:
        return [f"C{i}" for i in range(n)]
    return [colormaps["viridis"](v) for v in np.linspace(0.0, 0.92, n)]


def _impact_points(mech):
    """{contact: (times, positions, on the ground)} of the impacts in the window: at the
    wall's position for a contact with the ground (its limit, when the scene gives it),
    midway between the ends' positions for two bodies (linear along their paths; at the one
    end written, when an output of &run bodies_out has only one)."""
    walls = {row.name: row.limit for row in mech.rows if row.a == 0}
    lo, hi = mech.span
    points = {}
    for contact, events in mech.by_kind.items():
        ends = mech.ends.get(contact)
        if not is_impact_kind(contact) or ends is None:
            continue
        times = np.array([e.t for _, e in events if lo <= e.t <= hi])
        if times.size == 0:
            continue
        a, b = ends
        if a == 0:
            y = np.full(times.size, walls[contact]) if contact in walls else mech.position(b, times)
        else:
            # (one end not written, &run bodies_out: at the end that is)
            y = np.nanmean([mech.position(a, times), mech.position(b, times)], axis=0) \
                if a in mech.column or b in mech.column else np.full(times.size, np.nan)
        points[contact] = (times, y, a == 0)
    return points


def _draw_holds(ax, mech, colors):
    """Under the paths: a grey band over a body while friction holds it (stick<i> to
    slip<i>), an orange one over a body held on a wall or stop and between two bodies
    held together (rest_<contact> to release_<contact>). One artist per body or contact,
    its stretches apart (a long run's thousands of sticks draw as fast as one)."""
    style = dict(alpha=0.35, linewidth=7.0 if mech.n <= _LEGEND_UP_TO else 4.0,
                 solid_capstyle="butt", zorder=1.5)
    label = "stuck (friction holds)"
    for body in range(1, mech.n + 1):
        stretches = mech.held(f"stick{body}", f"slip{body}")
        if stretches:
            ax.plot(*_stretches(mech, body, stretches), color="0.5", gid=f"stuck{body}",
                    label=label, **style)
            label = "_nolegend_"
    label = "held contact"
    for contact, (a, b) in mech.ends.items():
        stretches = mech.held("rest_" + contact, "release_" + contact)
        if not stretches:
            continue
        if a == 0:
            ax.plot(*_stretches(mech, b, stretches), color="tab:orange", gid=f"rest:{contact}",
                    label=label, **style)
        else:
            times, lower = _stretches(mech, a, stretches)
            ax.fill_between(times, lower, mech.position(b, times), color="tab:orange", alpha=0.3,
                            linewidth=0, zorder=1.5, gid=f"rest:{contact}", label=label)
        label = "_nolegend_"


def _stretches(mech, body, stretches):
    """Body `body`'s path over each (start, end) stretch: the samples inside, the ends
    interpolated, a NaN between stretches (a gap in a line or a fill)."""
    times = []
    for start, end in stretches:
        inside = (mech.t > start) & (mech.t < end)
        times += [[start], mech.t[inside], [end], [np.nan]]
    times = np.concatenate(times[:-1])
    return times, mech.position(body, times)


def _draw_ground_rows(ax, mech, colors):
    """Walls (body 1's lower limit, body N's upper one) as today's plot draws them; stops
    of the other bodies as dashed lines in the body's colour (a moving one where it is)."""
    for row in (r for r in mech.rows if r.a == 0):
        if _is_wall(row, mech.n) and row.motion:
            ax.plot(mech.t, _ground_line(row, mech.t), color="0.25", linewidth=1.5, gid=f"wall:{row.name}",
                    label=_row_label(row))
        elif _is_wall(row, mech.n):
            ax.axhline(row.limit, color="0.25", linewidth=1.5, gid=f"wall:{row.name}",
                       label=_row_label(row))
        else:
            _draw_stop(ax, row, colors[row.b - 1], mech.t)


def _is_wall(row, n):
    """Whether a contact row is a wall: a limit with the ground below body 1 or above
    body n, so that it bounds every body (another limit with the ground is a stop)."""
    return row.a == 0 and (row.b, row.side) in ((1, "min"), (n, "max"))


def _draw_stop(ax, row, color, t):
    """A stop: a limit of body b with the ground that is not a wall, dashed in b's colour
    (a moving one at its prescribed position over the times t)."""
    if row.motion:
        ax.plot(t, _ground_line(row, t), color=color, linewidth=1.0, linestyle="--", gid=f"wall:{row.name}",
                label=_row_label(row))
        return
    ax.axhline(row.limit, color=color, linewidth=1.0, linestyle="--", gid=f"wall:{row.name}",
               label=_row_label(row))


def _row_label(row):
    """What a limit says: 'left: x1 \u2265 0 m' with the ground, 'stop: x2 \u2265 x1 + 0.5 m'
    between two bodies."""
    sign = "\u2265" if row.side == "min" else "\u2264"
    if row.a == 0:
        return f"{row.name}: x{row.b} {sign} {row.limit:.4g} m" + (" + w(t)" if row.motion else "")
    offset = f"+ {row.limit:.4g}" if row.limit >= 0 else f"\u2212 {-row.limit:.4g}"
    return f"{row.name}: x{row.b} {sign} x{row.a} {offset} m"


def _draw_impact_marks(ax, mech):
    """A marker per impact where it happens (_impact_points): open circles between two
    bodies, crosses on a wall or stop; smaller when impacts crowd."""
    points = _impact_points(mech)
    size = 5 if sum(p[0].size for p in points.values()) <= 150 else 3
    labels = {False: "impact of two bodies", True: "impact on a wall or stop"}
    for contact, (times, y, ground) in points.items():
        ax.plot(times, y, linestyle="none", marker="x" if ground else "o", markersize=size,
                markerfacecolor="none", markeredgewidth=1.1, color="black" if ground else "0.15",
                zorder=5, gid=f"impact:{contact}", label=labels.pop(ground, "_nolegend_"))


def _draw_paths(ax, mech):
    """The lines of the space-time plot: a path per body over its holds, walls, impacts."""
    colors = _body_colors(mech.n)
    _draw_holds(ax, mech, colors)
    _draw_ground_rows(ax, mech, colors)
    width = 1.4 if mech.n <= _LEGEND_UP_TO else 0.8
    for k, i in enumerate(mech.numbers):
        ax.plot(*mech.path(i), color=colors[i - 1], linewidth=width, gid=f"x{i}",
                label=f"x{i} (body {i})" if len(mech.numbers) <= _LEGEND_UP_TO else "_nolegend_")
    _draw_impact_marks(ax, mech)
    walls = [row.limit for row in mech.rows if row.a == 0]
    values = np.concatenate([mech.X.ravel(), walls]) if mech.X.size else np.array(walls or [0.0, 1.0])
    lo, hi = float(values.min()), float(values.max())
    pad = 0.06 * (hi - lo) if hi > lo else 0.5
    ax.set_ylim(lo - pad, hi + pad)
    ax.set_ylabel("position (m)")
    if mech.n > _LEGEND_UP_TO:
        _index_bar(ax, colors)


def _index_bar(ax, colors):
    """A colour bar of the body index beside the axes, below the legend (an inset: the
    time axes of a figure stay aligned)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.cm import ScalarMappable

    n = len(colors)
    mappable = ScalarMappable(norm=BoundaryNorm(np.arange(0.5, n + 1), n), cmap=ListedColormap(colors))
    _inset_bar(ax, mappable, "body", ticks=MaxNLocator(6, integer=True).tick_values(1, n))


def _inset_bar(ax, mappable, label, ticks=None, extend="neither"):
    bar = ax.figure.colorbar(mappable, cax=ax.inset_axes([1.01, 0.0, 0.015, 0.45]), label=label,
                             extend=extend)
    if ticks is not None:
        bar.set_ticks([v for v in ticks if 1 <= v <= mappable.norm.boundaries[-1]])
    bar.ax.set_label("colorbar")
    return bar


def _map_columns(mech, count):
    """`count` times evenly over the window and, for each, the index of the sample at or
    before it (samples need not be even; the picture keeps velocity jumps sharp)."""
    times = np.linspace(*mech.span, count)
    return times, np.clip(np.searchsorted(mech.t, times, side="right") - 1, 0, mech.t.size - 1)


def _draw_map(ax, mech, quantity):
    """A colour map over time and body index: each body's velocity (diverging, 0 white),
    or each neighbour pair's gap x_{i+1} - x_i - d_min (d_min of their contact record,
    else 0). Impacts are dots at the contact's index (midway for two bodies)."""
    times, index = _map_columns(mech, max(min(mech.t.size, 4000), 2))
    if quantity == "gap":
        limits = {(r.a, r.b): r.limit for r in mech.rows if r.side == "min"}
        offset = np.array([limits.get((i, i + 1), 0.0) for i in range(1, mech.n)])
        data = (mech.X[index, 1:] - mech.X[index, :-1] - offset).T
        # The scale of most gaps: a body that leaves the chain would make all others black.
        top = float(np.percentile(data, 99)) if data.size else 1.0
        style = dict(cmap="magma", vmin=0.0, vmax=top if top > 0 else 1.0)
        rows, label = (0.5, mech.n - 0.5), "gap to the next body (m)"
    else:
        data = mech.V[index].T
        # The scale of most moving bodies' speeds (most bodies of a long chain are at rest):
        # one light ball thrown off fast would leave every other one white.
        speeds = np.abs(data[data != 0.0])
        top = float(np.percentile(speeds, 99)) if speeds.size else 1.0
        style = dict(cmap="RdBu_r", vmin=-(top or 1.0), vmax=top or 1.0)
        rows, label = (0.5, mech.n + 0.5), "velocity (m/s)"
    # Antialiased: a row or a column narrower than a pixel (one body moving among 1,000)
    # stays visible, averaged, where nearest-neighbour sampling would drop it.
    image = ax.imshow(data, aspect="auto", origin="lower", extent=(*mech.span, *rows),
                      interpolation="antialiased", gid=f"map:{quantity}", **style)
    clipped = bool(data.size) and (data.max() > style["vmax"] or data.min() < style["vmin"])
    _inset_bar(ax, image, label, extend="both" if clipped else "neither")
    # Velocity rows are bodies (a contact of two midway between them); gap rows are the
    # gaps after body a (a neighbours' contact on its gap's row; the ground's below body b's).
    if quantity == "gap":
        hits = [(e.t, e.ends[0] if e.ends[0] else e.ends[1] - 0.5)
                for e in mech.events if is_impact_kind(e.kind) and e.ends]
    else:
        hits = [(e.t, 0.5 * (e.ends[0] + e.ends[1]) if e.ends[0] else e.ends[1])
                for e in mech.events if is_impact_kind(e.kind) and e.ends]
    if hits:
        # Fainter as they crowd: thousands of dots at full strength hide the map under them.
        ax.plot(*np.array(hits).T, linestyle="none", marker=".", markersize=1.5, color="black",
                alpha=max(0.08, 0.4 * min(1.0, _DOTS_CLEAR / len(hits))), gid="impacts",
                label="impact")
    ax.set_ylim(*rows)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_ylabel("gap after body" if quantity == "gap" else "body")


def _draw_spacetime(ax, mech, mode="auto", quantity="v"):
    if mode not in ("auto", "lines", "map"):
        raise ValueError(f"mode must be 'auto', 'lines' or 'map', got {mode!r}")
    if quantity not in ("v", "gap"):
        raise ValueError(f"quantity must be 'v' or 'gap', got {quantity!r}")
    if mode == "map" or (mode == "auto" and len(mech.numbers) > _MAP_ABOVE):
        if len(mech.numbers) != mech.n:
            raise ValueError(f"the colour map is over every body: this output has "
                             f"{len(mech.numbers)} of the scene's {mech.n} (&run bodies_out); "
                             "draw mode='lines'")
        _draw_map(ax, mech, quantity)
    else:
        _draw_paths(ax, mech)
    if mech.span[1] > mech.span[0]:
        ax.set_xlim(*mech.span)
    if not ax.images:
        ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        _legend(ax)
        for handle in ax.get_legend().legend_handles:
            handle.set_alpha(1.0)       # (the map's faint impact dots: a dot that shows)


def _draw_spacetime_panel(ax, window, events):
    """figure()'s panel for N >= 3 bodies (its window's time span)."""
    span = (None, None) if window.span == window.run else window.span
    _draw_spacetime(ax, _Mechanism(window.result, *span))


def spacetime(result, *, mode="auto", quantity="v", t_from=None, t_to=None, path=None, dpi=100,
              figure_factory=None):
    """The space-time picture of a run of any number of bodies; returns the Figure (saved
    to `path` as well when given, written whole).

    ``mode="lines"``: each body's position against time (gid ``x<i>``; thin lines and a
    sequential colour map with a colour bar of the body index above 10 bodies, a legend up
    to 10), each impact where it happens (``impact:<contact>``: a cross at the wall for a
    contact with the ground, a circle midway between the two bodies' positions for a
    contact between bodies, positions linear along the paths: the samples and, for more than
    two bodies, each body's position at its impacts from the log's velocities), walls and stops
    (``wall:<name>``), and what holds: a grey band over a body stuck by friction
    (``stuck<i>``, stick<i> to slip<i>) and an orange one over a body held on a wall, or
    between two bodies held together (``rest:<contact>``). ``mode="map"``: a colour map
    over time and body index (``map:v``: velocity, 0 white; ``quantity="gap"``: the gap to
    the next body, ``map:gap``) with impacts as dots; ``"auto"`` (default) draws lines up
    to 50 bodies, the map above. Measured (best of 3 on a shared 2-core machine): N = 1,000
    bodies, 2,000 samples and 999 impacts (a long cradle) take 0.02 s to draw and 0.23 s
    to draw and write as a PNG (the map); N = 50 as lines 0.03 s and 0.19 s.

    ``result``: anything with t, x and v as (samples, N) arrays (or today's x1, v1, x2,
    v2), events with t, kind (and a, b, the contact's ends, 0 the ground, for N > 2), a
    scene with contact records (a, b, d_min, d_max, name) or today's walls and slot.
    ``t_from``, ``t_to``: a time window, as :func:`figure`'s."""
    mech = _Mechanism(result, t_from, t_to)
    fig = (figure_factory or Figure)(figsize=(_WIDTH, 5.5), layout="constrained")
    fig.set_label("spacetime")
    ax = fig.subplots()
    ax.set_label("spacetime")
    _draw_spacetime(ax, mech, mode, quantity)
    ax.set_xlabel("time t (s)")
    fig.suptitle(_title(result), fontsize="large", fontweight="bold")
    n_impacts = sum(1 for e in mech.events if is_impact_kind(e.kind))
    ax.set_title(f"{mech.n} bodies  \u00b7  {n_impacts} impacts", fontsize="small", loc="left",
                 color="0.3")
    if path is not None:
        _write(fig, path, dpi)
    return fig


_DRAW = {
    "positions": _draw_positions,
    "velocities": _draw_velocities,
    "forces": _draw_forces,
    "kinetic_energy": _draw_kinetic_energy,
    "potential_energy": _draw_potential_energy,
    "impacts": _draw_impacts,
    "ledger": _draw_ledger,
    "residual": _draw_residual,
    "spacetime": _draw_spacetime_panel,
}
# A panel of the separate mode = one or more of the drawn axes.
_PANEL_AXES = {
    "positions": ("positions",),
    "velocities": ("velocities",),
    "forces": ("forces",),
    "kinetic_energy": ("kinetic_energy",),
    "potential_energy": ("potential_energy",),
    "impacts": ("impacts",),
    "energy": ("ledger", "residual"),
    "spacetime": ("spacetime",),
}


# ----------------------------------------------------------------------------
# figures


def _heights(names, n_contacts):
    return [(_HEIGHT["impacts"] * max(n_contacts, 1) + 0.4) if n == "impacts" else _HEIGHT[n]
            for n in names]


def _build(window, names, factory, label):
    n_contacts = len(_contacts_present(window, window.events))
    heights = _heights(names, n_contacts)
    # A lone panel gets some height of its own, so it does not read as a strip.
    height = max(0.9 + 1.25 * sum(heights), 4.5)
    fig = factory(figsize=(_WIDTH, height), layout="constrained")
    fig.set_label(label)
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False,
                        gridspec_kw={"height_ratios": heights})[:, 0]
    events = window.within(window.events)
    for ax, name in zip(axes, names):
        ax.set_label(name)
        _DRAW[name](ax, window, events)
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel("time t (s)")
    fig.suptitle(_title(window), fontsize="large", fontweight="bold")
    axes[0].set_title(_subtitle(window, events), fontsize="small", loc="left", color="0.3")
    fig.align_ylabels(axes)
    return fig


def _panels(window, forces):
    """The panels this run has, in PANELS order (NBODY_PANELS for three bodies or more);
    sets window.forces when they are drawn."""
    if _bodies(window.result)[1].shape[1] > 2 or not _every_body(window.result):
        return [p for p in NBODY_PANELS if p != "potential_energy" or window.pe is not None]
    drawn = set(PANELS) - {"forces", "potential_energy"}
    if window.pe is not None:
        drawn.add("potential_energy")
    if forces is not False:
        try:
            terms = _force_terms(window.result)
        except ValueError as error:
            if forces:
                warnings.warn(f"no force panel: {error}", stacklevel=3)
        else:
            if forces or _forces_vary(terms):
                times = _force_times(terms, window)
                window.forces = (times, _force_values(terms, times))
                drawn.add("forces")
    return [p for p in PANELS if p in drawn]


def figure(result, separate=False, *, forces=None, t_from=None, t_to=None, figure_factory=None):
    """Draw a run.

    Returns one :class:`matplotlib.figure.Figure` with the run's panels stacked on a
    shared time axis, or with ``separate=True`` a list of figures, one per
    panel (in :data:`PANELS` order; each figure's ``get_label()`` is the panel name).
    A run of three bodies or more has the panels :data:`NBODY_PANELS` instead: the
    space-time plot (:func:`spacetime`'s picture) above its energies (no force panel).

    ``forces``: the applied-force panel (:func:`applied_forces`). None (default) draws it
    when a force changes in time (a table or a sine); True also for constant forces; False
    never. A result that does not know its forces (a file read back without its scene)
    gets no panel; with ``forces=True`` a warning says why.

    ``t_from``, ``t_to``: the time window drawn (default the whole run); ValueError when it
    is empty or misses the run. The ledger still counts from t = 0 and the subtitle counts
    the impacts in the window.

    ``figure_factory`` makes the figures (default ``matplotlib.figure.Figure``;
    pass ``matplotlib.pyplot.figure`` to get figures that ``pyplot.show``
    displays).  It is called with ``figsize=`` and ``layout=``.
    """
    factory = Figure if figure_factory is None else figure_factory
    window = _Window(result, t_from, t_to)
    panels = _panels(window, forces)
    if not separate:
        names = [n for p in panels for n in _PANEL_AXES[p]]
        return _build(window, names, factory, "impact1d")
    return [_build(window, _PANEL_AXES[p], factory, p) for p in panels]


def save(result, path, separate=False, *, forces=None, t_from=None, t_to=None, dpi=100,
         figure_factory=None):
    """Write the run's plot as PNG; return the list of paths written.

    With ``separate=True`` one file per panel: ``STEM_<panel>.png`` next to ``path``.
    ``forces``, ``t_from``, ``t_to`` and ``figure_factory`` are passed to :func:`figure`.
    """
    figs = figure(result, separate=separate, forces=forces, t_from=t_from, t_to=t_to,
                  figure_factory=figure_factory)
    paths = _paths(path, figs)
    for fig, p in zip(figs if separate else [figs], paths):
        _write(fig, p, dpi)
    return paths


def _paths(path, figs):
    """Where save() writes `figs` (a Figure, or a list of one per panel) for `path`."""
    path = os.fspath(path)
    stem, ext = os.path.splitext(path)
    ext = ext or ".png"
    if not isinstance(figs, list):
        return [stem + ext]
    return [f"{stem}_{fig.get_label()}{ext}" for fig in figs]


def _write(fig, path, dpi=100):
    """Save `fig` to `path` whole (missing folders made; an error names `path`)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    write_whole(path, lambda temporary: fig.savefig(temporary, dpi=dpi))


# ----------------------------------------------------------------------------
# the animation


def _springs(result, n):
    """The scene's springs as (a, b, rest), in the engine's order: today's k1/x1_rest (0, 1),
    k2/x2_rest (0, 2), k12/d_rest (1, 2), or for more than two bodies the chain's arrays (k,
    x_rest: body i to the ground; k_link, d_rest: link i), then the &spring records (a, b,
    d_rest)."""
    scene = getattr(result, "scene", None)
    records = (None if scene is None else _field(scene, "springs")) or []
    if n > 2:
        own = [(0, i + 1, rest) for i, rest in _elements(result, "k", "x_rest", n)]
        own += [(i + 1, i + 2, rest) for i, rest in _elements(result, "k_link", "d_rest", n - 1)]
    else:
        tutorial = (("k1", "x1_rest", 0, 1), ("k2", "x2_rest", 0, 2), ("k12", "d_rest", 1, 2))
        own = [(a, b, _float_or_none(_scene_value(result, rest)) or 0.0)
               for k, rest, a, b in tutorial if b <= n and _float_or_none(_scene_value(result, k))]
    return own + [(int(_field(r, "a", 0)), int(_field(r, "b", 0)), float(_field(r, "d_rest", 0.0)))
                  for r in records]


def _elements(result, stiffness, rest, count):
    """(index, rest) of each element of the chain arrays `stiffness` (count long) that is
    there and not 0, its rest from the array `rest` (0 when absent)."""
    ks, rests = _scene_value(result, stiffness), _scene_value(result, rest)
    if not isinstance(ks, (list, tuple, np.ndarray)):
        return []
    rests = rests if isinstance(rests, (list, tuple, np.ndarray)) else []
    return [(i, (_float_or_none(rests[i]) if i < len(rests) else None) or 0.0)
            for i in range(min(count, len(ks))) if _float_or_none(ks[i])]


def _zigzag(x0, x1, y, height, turns=8):
    """A spring's points from x0 to x1 at height y: straight ends, `turns` zigzags."""
    xs = np.linspace(x0, x1, 2 * turns + 3)
    ys = np.full(xs.size, y)
    ys[1:-1] += height * np.resize([0.0, 1.0, 0.0, -1.0], xs.size - 2)
    return xs, ys


class _Stage:
    """The mechanism drawn on a line: blocks (w wide, centred on the bodies' positions, w
    the least gap limit between neighbours, so neighbours touch when their contact
    closes), walls w/2 beyond their limits (a block touches a wall when its body reaches
    the limit), slots above (a body-body contact with an upper limit: the slot moves with
    body a, a pin marks body b), springs below (ground springs from their rest
    position), the clock and the kinetic energy. `show(k)` moves it to sample k."""

    def __init__(self, ax, mech, springs):
        from matplotlib.patches import Rectangle

        self.ax, self.mech, self.springs = ax, mech, springs
        self.colors = _body_colors(mech.n)
        gaps = [r.limit for r in mech.rows if r.a and r.b == r.a + 1 and r.side == "min" and r.limit > 0]
        span = float(np.ptp(mech.X)) if mech.X.size else 1.0
        self.w = min(gaps) if gaps else 0.04 * (span or 1.0)
        # A slot: (its upper row, its lower limit: 0 when the record has none).
        lows = {r.record: r.limit for r in mech.rows if r.side == "min"}
        # Links of a chain of more than two bodies with an upper limit (couplers with slack)
        # are drawn where the neighbours meet, coloured by their state (_Couplers); the
        # others as slots above the blocks.
        links = [r for r in mech.rows if r.a and r.side == "max" and mech.n > 2 and r.b == r.a + 1]
        self.slots = [(r, lows.get(r.record, 0.0)) for r in mech.rows
                      if r.a and r.side == "max" and r not in links]
        self.couplers = _Couplers(ax, [(r, lows.get(r.record)) for r in links]) if links else None
        self.blocks = [ax.add_patch(Rectangle((0.0, 0.0), self.w, 1.0, facecolor=c, edgecolor="black",
                                              linewidth=0.8, gid=f"block{i + 1}"))
                       for i, c in enumerate(self.colors)]
        self.names = [ax.text(0.0, 0.5, str(i + 1), ha="center", va="center", fontsize="small")
                      for i in range(mech.n)] if mech.n <= _LEGEND_UP_TO else []
        self.slot_art = [(ax.plot([], [], color="0.3", linewidth=1.0, gid=f"slot:{r.name}")[0],
                          ax.plot([], [], marker="o", markersize=4, color=self.colors[r.b - 1],
                                  linestyle="-", linewidth=1.0)[0]) for r, _ in self.slots]
        self.spring_art = [ax.plot([], [], color="0.35", linewidth=1.0, gid=f"spring{k + 1}")[0]
                           for k in range(len(springs))]
        for level, (a, _, rest) in enumerate(springs):
            if a == 0:          # the ground end: a post at the spring's rest position
                ax.plot([rest, rest], [-0.35 - 0.3 * level, -0.15 - 0.3 * level], color="0.35",
                        linewidth=3, gid=f"anchor{level + 1}")
        self.clock = ax.text(0.01, 0.97, "", transform=ax.transAxes, va="top", family="monospace")
        self._draw_walls()
        self._limits()

    def _draw_walls(self):
        for row in (r for r in self.mech.rows if r.a == 0):
            edge = row.limit - self.w / 2 if row.side == "min" else row.limit + self.w / 2
            wall = _is_wall(row, self.mech.n)
            # Stops' labels a line above the walls': a stop may stand near a wall.
            self.ax.text(edge, 0.02 if wall else 0.1, _row_label(row), fontsize="x-small",
                         transform=self.ax.get_xaxis_transform(), color="0.25",
                         ha="left" if row.side == "min" else "right")
            if wall:
                self.ax.axvline(edge, ymin=0.1, ymax=0.9, color="0.25", linewidth=3,
                                gid=f"wall:{row.name}")
            else:
                self.ax.plot([edge, edge], [-0.25, 0.3], color=self.colors[row.b - 1], linewidth=3,
                             gid=f"wall:{row.name}")

    def _limits(self):
        X, w = self.mech.X, self.w
        xs = [X.min() - w, X.max() + w] if X.size else [0.0, 1.0]
        xs += [r.limit + (w if r.side == "max" else -w) for r in self.mech.rows if r.a == 0]
        xs += [rest for a, _, rest in self.springs if a == 0]
        pad = 0.04 * (max(xs) - min(xs))
        self.ax.set_xlim(min(xs) - pad, max(xs) + pad)
        self.ax.set_ylim(-0.4 - 0.3 * len(self.springs), 1.6 + 0.3 * len(self.slots))
        self.ax.set_yticks([])
        self.ax.set_xlabel("position (m): blocks centred on the bodies")

    def show(self, k):
        x = self.mech.X[k]
        for block, xi in zip(self.blocks, x):
            block.set_x(xi - self.w / 2)
        for name, xi in zip(self.names, x):
            name.set_x(xi)
        for level, ((row, low), (slot, pin)) in enumerate(zip(self.slots, self.slot_art)):
            y = 1.3 + 0.3 * level
            xa, xb = x[row.a - 1], x[row.b - 1]
            slot.set_data([xa, xa, xa + low, xa + row.limit, xa + row.limit, xa + low, xa + low],
                          [1.0, y, y, y, y + 0.12, y + 0.12, y])
            pin.set_data([xb, xb], [1.0, y + 0.06])
        for level, ((a, b, rest), art) in enumerate(zip(self.springs, self.spring_art)):
            start = rest if a == 0 else x[a - 1]
            art.set_data(*_zigzag(start, x[b - 1], -0.25 - 0.3 * level, 0.08))
        if self.couplers is not None:
            self.couplers.show(x)
        ke = "" if self.mech.ke is None else f"   KE = {self.mech.ke[k]:.4g} J"
        self.clock.set_text(f"t = {self.mech.t[k]:.3f} s{ke}")
        return self.blocks


class _Couplers:
    """The links of a chain with an upper limit (a train's couplers): a square above where
    each pair of neighbours meets (above: the blocks' own colours are no state), red when the link is at its upper limit (taut), blue at its lower
    one (buffers touching), grey in between (in its slack). A slack of 6 cm between wagons
    16 m long is too small to see in the blocks' motion; its state is not."""

    Y = 1.17        # (the blocks stand from 0 to 1)
    STATES = (("tab:blue", "link at its lower limit"), ("0.6", "link in its slack"),
              ("tab:red", "link at its upper limit (taut)"))

    def __init__(self, ax, links):
        from matplotlib.lines import Line2D

        self.links = links          # (upper row, lower limit or None)
        self.art = ax.scatter(np.zeros(len(links)), np.full(len(links), self.Y), s=60, marker="s",
                              edgecolors="black", linewidths=0.6, zorder=4, gid="couplers")
        ax.legend(handles=[Line2D([], [], linestyle="none", marker="s", markersize=7,
                                  markeredgecolor="black", markeredgewidth=0.6, color=c, label=label)
                           for c, label in self.STATES],
                  loc="upper right", fontsize="x-small", frameon=False, ncol=3)

    def show(self, x):
        colours, where = [], []
        for row, low in self.links:
            gap, top = x[row.b - 1] - x[row.a - 1], row.limit
            # (a link held at a limit sits on it to rounding: a millionth of its slack)
            close = 1e-6 * abs(top - (low if low is not None else top - 1.0))
            state = 2 if gap >= top - close else 0 if low is not None and gap <= low + close else 1
            colours.append(self.STATES[state][0])
            where.append((0.5 * (x[row.a - 1] + x[row.b - 1]), self.Y))
        self.art.set_offsets(where)
        self.art.set_facecolor(colours)


def _frames(mech, max_frames):
    """The samples the frames show: those in the window, evenly thinned to max_frames."""
    inside = np.flatnonzero((mech.t >= mech.span[0]) & (mech.t <= mech.span[1]))
    if max_frames < 1:
        raise ValueError(f"max_frames must be at least 1, got {max_frames}")
    pick = np.unique(np.round(np.linspace(0, inside.size - 1, min(inside.size, max_frames))).astype(int))
    return inside[pick]


def animate(result, path=None, *, fps=20, max_frames=300, t_from=None, t_to=None, dpi=80,
            figure_factory=None):
    """The mechanism moving, for a run of any number of bodies: the bodies as blocks on a
    line (centred on their positions, as wide as the least gap limit between neighbours,
    so neighbours touch when their contact closes), walls drawn where a block touches them,
    each slot (a contact between two bodies with an upper limit) above the blocks, moving
    with its body a, a pin for body b, the scene's springs below (a ground spring from a
    post at its rest position), the clock and the kinetic energy. Returns a
    matplotlib.animation.FuncAnimation (in a notebook: ``HTML(anim.to_jshtml())``); its
    ``frame_samples`` are the indices of the samples the frames show.

    Frames: the samples in the window (``t_from``, ``t_to``), evenly thinned to at most
    ``max_frames`` (300: a 6 s run sampled every 1 ms plays in 15 s at 20 fps, not in
    real time; drawing takes about 50 ms a frame). ``path``: written whole as .gif
    (Pillow) or .mp4 (ffmpeg; without it a ValueError "ffmpeg not found: write .gif");
    another extension is a ValueError, before anything is drawn."""
    from matplotlib.animation import FuncAnimation

    writer = None if path is None else _writer(path, fps)     # a bad name before any work
    mech = _Mechanism(result, t_from, t_to)
    if len(mech.numbers) != mech.n:
        raise ValueError(f"the animation shows every body: this output has x of bodies "
                         f"{', '.join(map(str, mech.numbers))} of {mech.n} (&run bodies_out)")
    samples = _frames(mech, max_frames)
    fig = (figure_factory or Figure)(figsize=(9.0, 2.4 + 0.25 * mech.n ** 0.5), layout="constrained")
    fig.set_label("animation")
    ax = fig.subplots()
    ax.set_label("mechanism")
    ax.set_title(_title(result), fontsize="medium", fontweight="bold")
    stage = _Stage(ax, mech, _springs(result, mech.n))
    stage.show(samples[0])
    anim = FuncAnimation(fig, lambda k: stage.show(samples[k]), frames=samples.size,
                         interval=1000.0 / fps, blit=False, repeat=True)
    anim.frame_samples = samples + mech.first
    if path is not None:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        write_whole(path, lambda temporary: anim.save(temporary, writer=writer, dpi=dpi))
    return anim


def _writer(path, fps):
    """The matplotlib writer for `path`'s extension (.gif: Pillow; .mp4: ffmpeg)."""
    from matplotlib import animation

    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext == ".gif":
        writer = animation.PillowWriter(fps=fps)
    elif ext == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ValueError("ffmpeg not found: write .gif")
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise ValueError(f"an animation is written as .gif or .mp4, not {os.fspath(path)!r}")
    return writer


# Units of the sweep table's columns (summaries and the scene fields a sweep varies), for
# the axis labels; a name not here is shown bare (a restitution, a count).
_UNITS = {
    "x1_end": "m", "x2_end": "m", "v1_end": "m/s", "v2_end": "m/s", "ke_end": "J",
    "pe_end": "J", "t_rest": "s", "impact_loss": "J", "friction_loss": "J",
    "damping_loss": "J", "energy_residual": "J",
    "m1": "kg", "m2": "kg", "g": "m/s\u00b2", "x_left": "m", "x_right": "m", "d_min": "m",
    "d_max": "m", "x1": "m", "x2": "m", "v1": "m/s", "v2": "m/s", "f1": "N", "f2": "N",
    "f1_amp": "N", "f2_amp": "N", "f1_period": "s", "f2_period": "s", "f1_phase": "rad",
    "f2_phase": "rad", "t_end": "s", "dt": "s", "dt_out": "s", "zero_vel": "m/s",
    "k1": "N/m", "k2": "N/m", "k12": "N/m", "x1_rest": "m", "x2_rest": "m", "d_rest": "m",
    "c1": "N s/m", "c2": "N s/m", "c12": "N s/m",
    # The steady state over [settle, t_end] (sweep's settle=).
    **{f"{q}{i}_{m}": ("m" if q == "x" else "m/s") for q in "xv" for i in (1, 2) for m in ("p2p", "rms")},
}


def _axis_label(name):
    unit = _UNITS.get(name)
    return f"{name} ({unit})" if unit else name


def _is_count(name):
    """Counts (n_impacts, steps, ...): whole numbers, so their axes tick at whole numbers."""
    return name.startswith("n_") or name == "steps"


def _number(value):
    """A varied field's value for a legend: whole numbers whole (max_rows = 10000000, not
    1e+07), others as %g, text as it is."""
    if not isinstance(value, (int, float, np.number)):
        return str(value)
    if float(value).is_integer() and abs(value) < 1e15:
        return str(int(value))
    return f"{value:g}"


def _groups(table, x, y):
    """The table split by its other varied fields: [(label, rows)], one item (label None)
    when x (and y) are all that varies. A varied field is a column named as a scene field
    with more than one value in the table (one value, as make study's t_end, is no group)."""
    from ._scene import REAL_FIELDS, TEXT_FIELDS

    fields = [name for name in table.columns if name in REAL_FIELDS + TEXT_FIELDS
              and name not in (x, y) and table[name].nunique(dropna=False) > 1]
    if not fields:
        return fields, [(None, table)]
    groups = table.groupby(fields, sort=True, dropna=False)
    return fields, [(", ".join(f"{f} = {_number(v)}" for f, v in
                               zip(fields, key if isinstance(key, tuple) else (key,))), rows)
                    for key, rows in groups]


def _column(rows, name):
    """A column as float64, missing values (a failed run's, pandas' NA) as NaN: a gap."""
    return rows[name].to_numpy(dtype=float, na_value=np.nan)


def _sweep_lines(fig, table, x, values, fields, groups):
    """One axes per summary column (quantities of different units and scales never share
    one), a line per group of the other varied fields, each ordered along x."""
    axes = fig.subplots(len(values), 1, sharex=True, squeeze=False)[:, 0]
    cmap = colormaps["viridis"]
    colors = ([cmap(v) for v in np.linspace(0.0, 0.85, len(groups))] if len(groups) > 1
              else ["tab:blue"])
    for ax, name in zip(axes, values):
        for (label, rows), color in zip(groups, colors):
            ordered = rows.sort_values(x, kind="stable")
            ax.plot(ordered[x].to_numpy(), _column(ordered, name), marker=".", color=color,
                    label=label, gid=f"{name}:{label}" if label else name)
        ax.set_label(name)
        ax.set_ylabel(_axis_label(name))
        if _is_count(name):
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(True, alpha=0.3)
    for ax in axes[:-1]:
        ax.tick_params(labelbottom=False)
    axes[-1].set_xlabel(_axis_label(x))
    if fields:
        axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                       fontsize="small", frameon=False, ncol=1 if len(groups) <= 16 else 2)


def _sweep_maps(fig, table, x, y, value, groups):
    """A heatmap of `value` over x and y per group of the other varied fields, on one
    colour scale."""
    grids = [(label, rows.pivot_table(index=y, columns=x, values=value, aggfunc="mean",
                                      dropna=False)) for label, rows in groups]
    numbers = np.concatenate([g.to_numpy(float).ravel() for _, g in grids])
    finite = numbers[np.isfinite(numbers)]
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    columns = min(len(grids), 3)
    axes = fig.subplots(-(-len(grids) // columns), columns, squeeze=False).ravel()
    for ax, (label, grid) in zip(axes, grids):
        mesh = ax.pcolormesh(grid.columns.to_numpy(float), grid.index.to_numpy(float),
                             grid.to_numpy(float), shading="nearest", vmin=low, vmax=high)
        ax.set_label(label or value)
        ax.set_xlabel(_axis_label(x))
        ax.set_ylabel(_axis_label(y))
        if label:
            ax.set_title(label, fontsize="medium")
    for ax in axes[len(grids):]:
        ax.set_visible(False)
    bar = fig.colorbar(mesh, ax=list(axes[:len(grids)]), label=_axis_label(value))
    if _is_count(value):
        bar.locator = MaxNLocator(integer=True)
        bar.update_ticks()


def sweep(table, x, y=None, value=("t_rest",), path=None, *, dpi=100, figure_factory=None):
    """A figure of a sweep's table (impact1d.sweep or impact1d-sweep's CSV): with one varied
    field `x`, each summary column in `value` against it, on axes of its own (labelled with
    its name and unit); with two (`x`, `y`), a heatmap of the one column `value`. When the
    table varies other fields too, the lines are a line per value of them (a legend says
    which), the heatmaps one per value, on one colour scale. Counts tick at whole numbers.
    Failed runs (NaN) are gaps. Saved to `path` when given (written whole); the Figure is
    returned."""
    import pandas as pd

    if not isinstance(table, pd.DataFrame):
        check_input(table, "sweep table")
        table = pd.read_csv(table)
    values = [value] if isinstance(value, str) else list(value)
    for name in [x, y] + values:
        if name is not None and name not in table.columns:
            raise ValueError(f"no column {name!r} in the table (columns: {', '.join(table.columns)})")
    if y is not None and len(values) != 1:
        raise ValueError("a heatmap shows one value column")
    fields, groups = _groups(table, x, y)
    if y is None:
        size = (7.0 + (1.8 if fields else 0.0), max(5.0, 1.2 + 2.4 * len(values)))
    else:
        columns = min(len(groups), 3)
        size = (2.0 + 5.0 * columns, 0.8 + 4.2 * -(-len(groups) // columns))
    fig = (figure_factory or Figure)(figsize=size, layout="constrained")
    if y is None:
        _sweep_lines(fig, table, x, values, fields, groups)
    else:
        _sweep_maps(fig, table, x, y, values[0], groups)
    over = f"{x} and {y}" if y else x
    each = f", {'a line' if y is None else 'a map'} per {', '.join(fields)}" if fields else ""
    fig.suptitle(f"{', '.join(values)} over {over}{each}")
    if path is not None:
        _write(fig, path, dpi)
    return fig
