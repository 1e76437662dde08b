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
only one limit exists), impact markers on the position panel
``impact:<contact>``, impact ticks ``tick:<contact>`` and persistent-contact
bars ``rest:<contact>`` on the impact panel, friction events ``stick1`` etc. on
the velocity panel.  Axes are labelled (``Axes.get_label()``) ``positions
velocities forces kinetic_energy potential_energy impacts ledger residual``.
"""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
from matplotlib.figure import Figure
from matplotlib import colormaps
from matplotlib.ticker import MaxNLocator, ScalarFormatter

from ._files import check_input, write_whole

__all__ = ["figure", "save", "sweep", "applied_forces", "PANELS", "CONTACTS"]

#: Panel names, in drawing order; ``save(..., separate=True)`` appends them to the file stem.
#: A run has those of its content: ``forces`` when drawn (see :func:`figure`),
#: ``potential_energy`` with springs (a ``pe`` column), the others always.
PANELS = ("positions", "velocities", "forces", "kinetic_energy", "potential_energy", "impacts",
          "energy")

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
    """Contacts drawn in the impact panel: those the scene has, plus any that had events."""
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
    return [c for c in CONTACTS if c in seen or _float_or_none(_scene_value(result, limits[c])) is not None]


def _rest_intervals(events, contact, t_start, t_end):
    """(start, end) of each persistent contact: rest_<c> to release_<c> or the end of the run.

    A release with no rest before it means the run started in that contact.
    """
    out = []
    start = None
    for t, kind in events:
        if kind == "rest_" + contact and start is None:
            start = t
        elif kind == "release_" + contact:
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
    n_impacts = sum(1 for _, k in events if k in CONTACTS)
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
            "damping_loss", "residual")


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
        first = max(int(np.searchsorted(t, self.span[0], side="right")) - 1, 0)
        last = min(int(np.searchsorted(t, self.span[1], side="left")) + 1, t.size)
        for name in _SAMPLES:
            column = getattr(result, name, None)
            setattr(self, name, None if column is None else np.asarray(column, dtype=float)[first:last])
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
    (amp, period, phase) or None), ...} (table: its corner times and values), "f2" only with
    a second body. ValueError saying why when the result does not know its forces."""
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
        sine = (amp, period, phase) if amp and period else None
        terms[f"f{body}"] = (constant, table, sine)
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
    """f_i(t) = f_i + table_i(t) + amp sin(2 pi t / period + phase), each term when named
    (a table held at its end values outside its times, as the core does)."""
    out = {}
    for name, (constant, table, sine) in terms.items():
        f = np.full(t.shape, constant)
        if table is not None:
            f = f + np.interp(t, *table)
        if sine is not None:
            amp, period, phase = sine
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
    for _, table, sine in terms.values():
        if table is not None:
            parts.append(table[0][(table[0] > lo) & (table[0] < hi)])
        if sine is not None:
            count = min(int(_SINE_POINTS * (hi - lo) / abs(sine[1])) + 2, _MAX_FORCE_POINTS)
            parts.append(np.linspace(lo, hi, count))
    return np.unique(np.concatenate(parts))


def applied_forces(result, t=None) -> dict:
    """The applied forces of the result's scene, f_i(t) = f_i + table_i(t) + f_i_amp
    sin(2 pi t / f_i_period + f_i_phase), at the times `t` (default: the result's samples):
    {"f1": array, "f2": array} ("f2" only with a second body). Springs, dampers, friction
    and contacts are not applied forces. ValueError saying why when the result does not
    know its forces: no scene, a file read back without its scene (the header does not
    record force tables), a force table that cannot be read."""
    times = np.asarray(result.t if t is None else t, dtype=float)
    return _force_values(_force_terms(result), times)


def _forces_vary(terms) -> bool:
    """Whether some force changes in time (a table or a sine): a constant one is flat."""
    return any(table is not None or sine is not None for _, table, sine in terms.values())


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
    x_left = _float_or_none(_scene_value(result, "x_left"))
    x_right = _float_or_none(_scene_value(result, "x_right"))
    d_min = _float_or_none(_scene_value(result, "d_min"))
    d_max = _float_or_none(_scene_value(result, "d_max"))

    # Limits from the bodies and the walls only: a wide slot (case 5 has
    # d_max = 50 m) must not squash the motion.
    lo = [np.min(x1)] + ([np.min(x2)] if x2.size else []) if t.size else [0.0]
    hi = [np.max(x1)] + ([np.max(x2)] if x2.size else []) if t.size else [1.0]
    for w in (x_left, x_right):
        if w is not None:
            lo.append(w)
            hi.append(w)
    lo, hi = float(min(lo)), float(max(hi))
    pad = 0.06 * (hi - lo) if hi > lo else 0.5
    ylim = (lo - pad, hi + pad)

    wall_lo = -np.inf if x_left is None else x_left
    wall_hi = np.inf if x_right is None else x_right

    def inside_walls(y):
        # x2 cannot pass a wall, so neither does the band that says where it may be.
        return np.clip(y, wall_lo, wall_hi)

    # A slot limit that stays beyond the walls (or out of view) all run never binds before
    # a wall does: drawn, it would only shade the panel (case 5: d_max = 50 m, walls 10 m
    # apart). Such a limit is left out.
    view_lo, view_hi = max(wall_lo, ylim[0]), min(wall_hi, ylim[1])
    if d_min is not None and not np.any(x1 + d_min > view_lo):
        d_min = None
    if d_max is not None and not np.any(x1 + d_max < view_hi):
        d_max = None

    if d_min is not None and d_max is not None:
        ax.fill_between(t, inside_walls(x1 + d_min), inside_walls(x1 + d_max), color=_BODY_COLOR[2], alpha=0.10,
                        linewidth=0, gid="slot_band",
                        label=f"slot: x1 + [{d_min:g}, {d_max:g}] m")
    else:
        for name, d in (("min", d_min), ("max", d_max)):
            if d is not None:
                ax.plot(t, inside_walls(x1 + d), color=_BODY_COLOR[2], linestyle=":", linewidth=1.0,
                        gid=f"slot:{name}", label=f"slot {name}: x1 + {d:g} m")

    for name, w, beyond in (("left", x_left, ylim[0] - 1e3 * (pad + 1)),
                            ("right", x_right, ylim[1] + 1e3 * (pad + 1))):
        if w is None:
            continue
        ax.axhspan(min(w, beyond), max(w, beyond), color="0.85", zorder=0)
        ax.axhline(w, color="0.25", linewidth=1.5, gid=f"wall:{name}",
                   label=f"{name} wall x = {w:g} m")

    ax.plot(t, x1, color=_BODY_COLOR[1], linewidth=1.4, gid="x1", label="x1 (body 1)")
    if x2.size:
        ax.plot(t, x2, color=_BODY_COLOR[2], linewidth=1.4, gid="x2", label="x2 (body 2)")

    # Smaller markers when impacts crowd (long runs), so the paths stay visible.
    n_impacts = sum(1 for _, k in events if k in CONTACTS)
    size = 5 if n_impacts <= 150 else 3
    for contact in CONTACTS:
        times = _event_times(events, contact)
        if times.size == 0:
            continue
        xs, ys = [], []
        # One body: both walls hold body 1.
        for body in (_CONTACT_BODIES[contact] if x2.size else (1,)):
            pos = x1 if body == 1 else x2
            xs.append(times)
            ys.append(np.interp(times, t, pos))
        ax.plot(np.concatenate(xs), np.concatenate(ys), linestyle="none", marker="o",
                markersize=size, markerfacecolor="none", markeredgewidth=1.2,
                color=_CONTACT_COLOR[contact], gid=f"impact:{contact}", zorder=5,
                label=f"impact, {_CONTACT_LABEL[contact]}")

    ax.set_ylim(*ylim)
    ax.set_ylabel("position (m)")
    _finish_time_axis(ax, result)
    _legend(ax)


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
        color = _CONTACT_COLOR[contact]
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
    ax.set_yticklabels([_CONTACT_LABEL[c] for c in reversed(contacts)])
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
                label=f"{what} \u2212 {what}(0) = W \u2212 {losses}")
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


_DRAW = {
    "positions": _draw_positions,
    "velocities": _draw_velocities,
    "forces": _draw_forces,
    "kinetic_energy": _draw_kinetic_energy,
    "potential_energy": _draw_potential_energy,
    "impacts": _draw_impacts,
    "ledger": _draw_ledger,
    "residual": _draw_residual,
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
    """The panels this run has, in PANELS order; sets window.forces when they are drawn."""
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
