"""Tests of impact1d.plot and the impact1d-plot command: the figures hold the run's data.

They check what the plots show (the lines' data are the result's arrays, the
impact markers sit at the event times and body positions, walls and slot are
where the scene puts them), not only that a PNG appears.  Synthetic results
(built here by an exact event-driven solution of constant-force, frictionless
motion) keep the tests independent of the engine; when the compiled package is
installed the seed cases are rendered through impact1d.simulate as well.
"""

from __future__ import annotations

import importlib
import os
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

import matplotlib
matplotlib.use("Agg")
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from tools import find_tool  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SEED_CASES = [f"case{i}" for i in range(1, 7)]
CONTACTS = ("left", "right", "slot_min", "slot_max")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# Markers are placed by linear interpolation of the sampled positions at the
# event time; the check recomputes the same interpolation, so only rounding
# separates the two.
TIGHT = dict(rtol=0.0, atol=1e-12)


# The package must be installed (make test does it): a broken build fails here, loudly,
# rather than skipping the tests that need it.
IMPACT1D = importlib.import_module("impact1d")
plot = importlib.import_module("impact1d.plot")
# The panels every run has (a constant-force scene without springs: no force panel by
# default, no potential energy).
BASE_PANELS = [p for p in plot.PANELS if p not in ("forces", "potential_energy")]


# ----------------------------------------------------------------------------
# synthetic results


@dataclass
class FakeScene:
    m1: float = 1.0
    m2: float = 2.0
    mu1: float | None = 0.0
    mu2: float | None = 0.0
    g: float | None = 10.0
    x_left: float | None = 0.0
    r_left: float | None = 1.0
    x_right: float | None = 10.0
    r_right: float | None = 1.0
    d_min: float | None = 1.0
    r_min: float | None = 1.0
    d_max: float | None = 2.0
    r_max: float | None = 1.0
    x1: float = 1.0
    v1: float = 0.0
    x2: float = 2.5
    v2: float = 0.0
    f1: float | None = 0.0
    f2: float | None = 0.0
    f1_amp: float | None = None
    f1_period: float | None = None
    f1_phase: float | None = None
    t_end: float = 1.0
    dt: float = 1e-3
    dt_out: float | None = 1e-3
    title: str | None = "synthetic"
    method: str | None = "event"


@dataclass
class FakeResult:
    t: np.ndarray
    x1: np.ndarray
    v1: np.ndarray
    x2: np.ndarray
    v2: np.ndarray
    ke: np.ndarray
    work: np.ndarray
    friction_loss: np.ndarray
    impact_loss: np.ndarray
    residual: np.ndarray
    events: np.ndarray
    scene: object = field(default_factory=FakeScene)


EVENT_DTYPE = [("t", "f8"), ("kind", "U20"), ("v1_before", "f8"), ("v2_before", "f8"),
               ("v1_after", "f8"), ("v2_after", "f8")]


def exact_run(scene, zeno_speed=1e-7):
    """Exact piecewise-quadratic motion under constant forces, no friction.

    Impacts by Newton's restitution; a wall impact whose rebound speed falls
    below ``zeno_speed`` ends the rattling: the body then rests on the wall
    (``rest_<wall>`` event), which is all the seed-like scenes here need.
    """
    m = np.array([scene.m1, scene.m2])
    f = np.array([scene.f1 or 0.0, scene.f2 or 0.0])
    a_free = f / m
    x = np.array([scene.x1, scene.x2], dtype=float)
    v = np.array([scene.v1, scene.v2], dtype=float)
    resting = [False, False]
    # (gap(x), gap velocity(v), gap acceleration(a)) per contact present
    gaps = {}
    if scene.x_left is not None:
        gaps["left"] = (np.array([1.0, 0.0]), -scene.x_left, scene.r_left)
    if scene.x_right is not None:
        gaps["right"] = (np.array([0.0, -1.0]), scene.x_right, scene.r_right)
    if scene.d_min is not None:
        gaps["slot_min"] = (np.array([-1.0, 1.0]), -scene.d_min, scene.r_min)
    if scene.d_max is not None:
        gaps["slot_max"] = (np.array([1.0, -1.0]), scene.d_max, scene.r_max)

    t = 0.0
    segments = []  # (t0, x0, v0, a)
    events = []
    impact_loss = 0.0
    losses = []  # (t, cumulative impact loss after t)
    while t < scene.t_end:
        a = np.where(resting, 0.0, a_free)
        v = np.where(resting, 0.0, v)
        segments.append((t, x.copy(), v.copy(), a.copy()))
        best = (scene.t_end - t, None)
        for name, (n, c, _) in gaps.items():
            g0, g1, g2 = n @ x + c, n @ v, n @ a
            roots = np.roots([0.5 * g2, g1, g0]) if abs(g2) > 0 else (
                np.array([-g0 / g1]) if g1 != 0 else np.array([]))
            for tau in np.real(roots[np.isreal(roots)]):
                if 1e-12 < tau < best[0] and g1 + g2 * tau < 0:
                    best = (tau, name)
        tau, hit = best
        x = x + v * tau + 0.5 * a * tau**2
        v = v + a * tau
        t += tau
        if hit is None:
            break
        # Sequential impulses on every closed, approaching contact (both walls at
        # once in case 5), most approaching first.
        while True:
            closing = [(gaps[k][0] @ v, k) for k in gaps
                       if abs(gaps[k][0] @ x + gaps[k][1]) < 1e-9 and gaps[k][0] @ v < 0]
            if not closing:
                break
            hit = min(closing)[1]
            n, c, r = gaps[hit]
            before = v.copy()
            w = n / m
            v = v - (1.0 + r) * (n @ v) / (n @ w) * w
            impact_loss += 0.5 * m @ before**2 - 0.5 * m @ v**2
            losses.append((t, impact_loss))
            events.append((t, hit, before[0], before[1], v[0], v[1]))
            if hit in ("left", "right"):
                body = 0 if hit == "left" else 1
                if abs(v[body]) < zeno_speed:
                    resting[body] = True
                    impact_loss += 0.5 * m[body] * v[body] ** 2
                    losses.append((t, impact_loss))
                    vb = v.copy()
                    v[body] = 0.0
                    events.append((t, "rest_" + hit, vb[0], vb[1], v[0], v[1]))

    n_out = int(round(scene.t_end / scene.dt_out)) + 1
    ts = np.linspace(0.0, scene.t_end, n_out)
    starts = np.array([s[0] for s in segments])
    idx = np.clip(np.searchsorted(starts, ts, side="right") - 1, 0, len(segments) - 1)
    X = np.empty((n_out, 2))
    V = np.empty((n_out, 2))
    for k, (t_k, i) in enumerate(zip(ts, idx)):
        t0, x0, v0, a0 = segments[i]
        dt = t_k - t0
        X[k] = x0 + v0 * dt + 0.5 * a0 * dt**2
        V[k] = v0 + a0 * dt
    ke = 0.5 * (m[0] * V[:, 0] ** 2 + m[1] * V[:, 1] ** 2)
    work = f[0] * (X[:, 0] - scene.x1) + f[1] * (X[:, 1] - scene.x2)
    q = np.zeros(n_out)
    for t_e, cum in losses:
        q[ts >= t_e] = cum
    friction = np.zeros(n_out)
    residual = ke - ke[0] - work + friction + q
    return FakeResult(t=ts, x1=X[:, 0], v1=V[:, 0], x2=X[:, 1], v2=V[:, 1], ke=ke, work=work,
                      friction_loss=friction, impact_loss=q, residual=residual,
                      events=np.array(events, dtype=EVENT_DTYPE), scene=scene)


def case5_like():
    """Test case 5: both bodies rattle into the walls, impacts accumulate at t = 3 s, then rest."""
    return exact_run(FakeScene(r_left=0.5, r_right=0.5, d_min=0.0, d_max=50.0, x1=1.0, x2=9.0,
                               f1=-2.0, f2=4.0, t_end=3.2,
                               title="Test case 5: wall collisions with rattling stop"))


def case3_like():
    """Test case 3: elastic impacts of every kind, constant kinetic energy 41.5 J."""
    return exact_run(FakeScene(x1=1.0, v1=-9.0, x2=2.5, v2=1.0, t_end=6.0,
                               title="Test case 3: conservation of energy"))


def bare_result():
    """No walls, no slot, no events, no title: nothing optional is drawn."""
    scene = FakeScene(x_left=None, r_left=None, x_right=None, r_right=None, d_min=None,
                      r_min=None, d_max=None, r_max=None, x1=0.0, v1=1.0, x2=3.0, v2=-0.5,
                      t_end=2.0, title=None)
    return exact_run(scene)


def with_friction_events(res):
    """Add a stick of body 1 and a release of a rest, as a friction scene would log them."""
    extra = np.array([(0.5, "stick1", 0.0, 0.0, 0.0, 0.0), (0.7, "slip1", 0.0, 0.0, 0.0, 0.0),
                      (res.t[-1] - 0.05, "release_left", 0.0, 0.0, 0.0, 0.0)],
                     dtype=EVENT_DTYPE)
    res.events = np.sort(np.concatenate([res.events, extra]), order="t", kind="stable")
    return res


# ----------------------------------------------------------------------------
# helpers to read back figures


def axes_by_label(fig):
    return {ax.get_label(): ax for ax in fig.axes if ax.get_label()}


def artist(ax, gid):
    found = [a for a in ax.get_children() if a.get_gid() == gid]
    assert len(found) == 1, f"{gid}: {len(found)} artists"
    return found[0]


def maybe_artist(ax, gid):
    found = [a for a in ax.get_children() if a.get_gid() == gid]
    return found[0] if found else None


def impact_times(res, contact):
    return np.array([e["t"] for e in res.events if str(e["kind"]) == contact])


def check_figure_data(fig, res):
    """The checks shared by synthetic and real results."""
    ax = axes_by_label(fig)
    assert set(ax) >= {"positions", "velocities", "kinetic_energy", "impacts", "ledger",
                       "residual"}
    for gid, panel in (("x1", "positions"), ("x2", "positions"), ("v1", "velocities"),
                       ("v2", "velocities"), ("ke", "kinetic_energy"), ("work", "ledger"),
                       ("friction_loss", "ledger"), ("impact_loss", "ledger"),
                       ("residual", "residual")):
        line = artist(ax[panel], gid)
        np.testing.assert_array_equal(line.get_xdata(), res.t)
        np.testing.assert_array_equal(line.get_ydata(), getattr(res, gid))
    np.testing.assert_array_equal(artist(ax["ledger"], "ke_change").get_ydata(),
                                  res.ke - res.ke[0])

    # impact markers: at the event times, on the bodies involved
    pos = ax["positions"]
    for contact in CONTACTS:
        times = impact_times(res, contact)
        marker = maybe_artist(pos, f"impact:{contact}")
        tick = maybe_artist(ax["impacts"], f"tick:{contact}")
        if times.size == 0:
            assert marker is None and tick is None
            continue
        bodies = {"left": [res.x1], "right": [res.x2]}.get(contact, [res.x1, res.x2])
        np.testing.assert_array_equal(marker.get_xdata(), np.tile(times, len(bodies)))
        want = np.concatenate([np.interp(times, res.t, x) for x in bodies])
        np.testing.assert_allclose(marker.get_ydata(), want, **TIGHT)
        np.testing.assert_array_equal(tick.get_xdata(), times)

    # walls where the scene puts them; absent walls not drawn
    for side in ("left", "right"):
        where = getattr(res.scene, f"x_{side}", None)
        wall = maybe_artist(pos, f"wall:{side}")
        if where is None:
            assert wall is None
        else:
            assert np.all(np.asarray(wall.get_ydata(), dtype=float) == where)
            assert pos.get_ylim()[0] <= where <= pos.get_ylim()[1]

    # limits: the bodies' whole motion is in view
    lo, hi = pos.get_ylim()
    assert lo <= min(res.x1.min(), res.x2.min()) and hi >= max(res.x1.max(), res.x2.max())
    assert ax["kinetic_energy"].get_ylim()[0] == 0.0
    assert ax["kinetic_energy"].get_ylim()[1] >= res.ke.max()
    for a in fig.axes:
        if a.get_label() in ax:
            assert a.get_xlim() == (res.t[0], res.t[-1])


def rest_bars(ax, contact):
    bar = maybe_artist(ax, f"rest:{contact}")
    if bar is None:
        return []
    assert isinstance(bar, PolyCollection)
    out = []
    for path in bar.get_paths():
        xs = path.vertices[:, 0]
        out.append((xs.min(), xs.max()))
    return sorted(out)


# ----------------------------------------------------------------------------
# the synthetic data themselves (so the figures are checked against sane runs)


def test_synthetic_runs_are_physical():
    r5 = case5_like()
    left = impact_times(r5, "left")
    np.testing.assert_allclose(left[:4], [1.0, 2.0, 2.5, 2.75], atol=1e-9)
    assert abs(impact_times(r5, "rest_left")[0] - 3.0) < 1e-6
    np.testing.assert_allclose(r5.ke[r5.t < 1.0][-1], 6.0, rtol=1e-2)  # "about 6 J at t = 1"
    assert np.all(r5.ke[r5.t > 3.0] == 0.0)
    r3 = case3_like()
    np.testing.assert_allclose(r3.ke, 41.5, rtol=1e-12)
    assert {str(k) for k in r3.events["kind"]} == set(CONTACTS)
    for r in (r5, r3):
        assert np.max(np.abs(r.residual)) < 1e-9


# ----------------------------------------------------------------------------
# figures


@pytest.mark.parametrize("make", [case5_like, case3_like, bare_result])
def test_figure_holds_the_result(make):
    res = make()
    fig = plot.figure(res)
    check_figure_data(fig, res)


def test_object_api_only():
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    fig = plot.figure(case3_like())
    figs = plot.figure(case3_like(), separate=True)
    assert plt.get_fignums() == before
    assert fig.__class__.__name__ == "Figure"
    assert [f.get_label() for f in figs] == BASE_PANELS


def test_rest_bar_stays_to_the_end():
    res = case5_like()
    ax = axes_by_label(plot.figure(res))["impacts"]
    t_rest = impact_times(res, "rest_left")[0]
    bars = rest_bars(ax, "left")
    assert len(bars) == 1
    np.testing.assert_allclose(bars[0], (t_rest, res.t[-1]), rtol=0, atol=1e-12)
    assert len(rest_bars(ax, "right")) == 1
    assert rest_bars(ax, "slot_min") == [] and rest_bars(ax, "slot_max") == []
    rows = [t.get_text() for t in ax.get_yticklabels()]
    # case 5 has walls and (wide) slot limits: all four rows, top to bottom in CONTACTS order
    assert rows == ["slot max", "slot min", "right wall", "left wall"]


def test_release_ends_the_bar_and_friction_events_marked():
    res = with_friction_events(case5_like())
    fig = plot.figure(res)
    ax = axes_by_label(fig)
    t_rest = impact_times(res, "rest_left")[0]
    t_release = impact_times(res, "release_left")[0]
    np.testing.assert_allclose(rest_bars(ax["impacts"], "left"), [(t_rest, t_release)],
                               atol=1e-12)
    stick = artist(ax["velocities"], "stick1")
    np.testing.assert_array_equal(stick.get_xdata(), [0.5])
    np.testing.assert_allclose(stick.get_ydata(), np.interp([0.5], res.t, res.v1), **TIGHT)
    assert maybe_artist(ax["velocities"], "slip1") is not None


def test_contact_held_from_the_start():
    """A release with no rest before it: the contact held from t = 0 (a scene that starts in it)."""
    res = case3_like()
    res.events = np.array([(0.0, "rest_slot_max", 0, 0, 0, 0), (1.0, "release_slot_max", 0, 0, 0, 0),
                           (2.0, "release_slot_min", 0, 0, 0, 0), (5.0, "rest_slot_min", 0, 0, 0, 0)],
                          dtype=EVENT_DTYPE)
    ax = axes_by_label(plot.figure(res))["impacts"]
    assert rest_bars(ax, "slot_max") == [(0.0, 1.0)]
    assert rest_bars(ax, "slot_min") == [(0.0, 2.0), (5.0, 6.0)]


def test_slot_band_follows_x1():
    res = case3_like()
    pos = axes_by_label(plot.figure(res))["positions"]
    band = artist(pos, "slot_band")
    verts = band.get_paths()[0].vertices
    # fill_between's outline: lower edge forward, upper edge back
    lower = np.interp(res.t, verts[1:len(res.t) + 1, 0], verts[1:len(res.t) + 1, 1])
    # the band stops at the walls: x2 cannot pass them
    s = res.scene
    np.testing.assert_allclose(lower, np.clip(res.x1 + s.d_min, s.x_left, s.x_right), atol=1e-12)
    assert np.max(res.x1 + s.d_max) > s.x_right  # case 3 reaches the right wall...
    assert np.max(verts[:, 1]) == s.x_right  # ...where the band ends
    # x2 stays inside the band the figure draws
    assert np.all(res.x2 >= res.x1 + res.scene.d_min - 1e-9)
    assert np.all(res.x2 <= res.x1 + res.scene.d_max + 1e-9)


def test_one_slot_limit_is_a_line():
    res = case3_like()
    res.scene.d_max = None
    pos = axes_by_label(plot.figure(res))["positions"]
    assert maybe_artist(pos, "slot_band") is None
    np.testing.assert_allclose(artist(pos, "slot:min").get_ydata(),
                               np.clip(res.x1 + res.scene.d_min, 0.0, 10.0))


def test_records_limits_are_drawn_in_the_positions_panel():
    """inner_stop's &contact records drawn where they hold, named: 'stop' (x2 >= x1 + 0.5,
    between the bodies) a line at x1 + 0.5 in body 2's colour, as the slot's x1 + d is;
    'wall1' (x1 <= 0.25: a stop of body 1, no wall of the pair) dashed at 0.25 in body 1's;
    a record bounding body 2 from above (x2 <= 1.75) a wall, as the tutorial's are."""
    scene = IMPACT1D.load_scene(ROOT / "input" / "inner_stop.nml")
    scene.t_end = 4.0
    res = IMPACT1D.simulate(scene)
    pos = axes_by_label(plot.figure(res))["positions"]
    stop = artist(pos, "limit:stop")
    np.testing.assert_array_equal(stop.get_xdata(), res.t)
    # clipped at the left wall (x = -1), as the slot's lines are
    np.testing.assert_array_equal(stop.get_ydata(), np.maximum(res.x1 + 0.5, -1.0))
    assert stop.get_label() == "stop: x2 \u2265 x1 + 0.5 m"
    assert stop.get_color() == "tab:orange" and stop.get_linestyle() == "-."
    assert np.all(res.x2 >= stop.get_ydata() - 1e-9)        # x2 never crosses it
    wall1 = artist(pos, "wall:wall1")
    assert list(wall1.get_ydata()) == [0.25, 0.25] and wall1.get_label() == "wall1: x1 \u2264 0.25 m"
    assert wall1.get_color() == "tab:blue" and wall1.get_linestyle() == "--"
    scene.contacts = scene.contacts + [dict(a=2, b=0, d_min=-1.75, name="lid")]
    pos = axes_by_label(plot.figure(IMPACT1D.simulate(scene)))["positions"]
    lid = artist(pos, "wall:lid")
    assert list(lid.get_ydata()) == [1.75, 1.75] and lid.get_color() == "0.25"
    assert lid.get_label() == "lid: x2 \u2264 1.75 m" and pos.get_ylim()[1] > 1.75


def test_wide_slot_does_not_squash_positions():
    res = case5_like()  # d_max = 50 m, walls 10 m apart
    lo, hi = axes_by_label(plot.figure(res))["positions"].get_ylim()
    assert hi < 12.0 and lo > -2.0


def test_labels_units_and_title():
    res = case3_like()
    fig = plot.figure(res)
    ax = axes_by_label(fig)
    assert fig._suptitle.get_text() == "Test case 3: conservation of energy"
    assert "(m)" in ax["positions"].get_ylabel()
    assert "(m/s)" in ax["velocities"].get_ylabel()
    assert "(J)" in ax["kinetic_energy"].get_ylabel()
    assert "(J)" in ax["ledger"].get_ylabel() and "(J)" in ax["residual"].get_ylabel()
    assert "(s)" in ax["residual"].get_xlabel()  # the shared time axis, at the bottom
    # untitled scene: a fallback title, never an empty one
    assert plot.figure(bare_result())._suptitle.get_text()


def _overlap(a, b):
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("make", [case5_like, case3_like, lambda: simulated("case6"),
                                  lambda: simulated("stick_slip")],
                         ids=["case5_like", "case3_like", "case6 (forces)", "stick_slip (pe)"])
def test_layout_nothing_overlaps(make):
    fig = plot.figure(make())
    canvas = FigureCanvasAgg(fig)  # what save() renders through
    canvas.draw()
    renderer = canvas.get_renderer()
    fig_box = fig.bbox
    boxes = []
    for ax in fig.axes:
        for text in [ax.yaxis.label, ax.xaxis.label, ax.title, ax.get_legend()]:
            if text is None or (hasattr(text, "get_text") and not text.get_text()):
                continue
            box = text.get_window_extent(renderer)
            # inside the canvas, not cut off
            assert box.x0 >= fig_box.x0 - 1 and box.x1 <= fig_box.x1 + 1, text
            assert box.y0 >= fig_box.y0 - 1 and box.y1 <= fig_box.y1 + 1, text
            boxes.append((ax.get_label(), text, box))
    for i, (_, ti, bi) in enumerate(boxes):
        for _, tj, bj in boxes[i + 1:]:
            assert not _overlap(bi, bj), (ti, tj)
    # legends sit beside the plotting areas, not over the curves
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None:
            for other in fig.axes:
                assert not _overlap(legend.get_window_extent(renderer), other.bbox)


def is_png(path):
    with open(path, "rb") as fh:
        return fh.read(8) == PNG_SIGNATURE


def png_size(path):
    with open(path, "rb") as fh:
        head = fh.read(24)
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def test_save_png(tmp_path):
    paths = plot.save(case5_like(), tmp_path / "run.png")
    assert paths == [str(tmp_path / "run.png")]
    assert is_png(paths[0])
    w, h = png_size(paths[0])
    assert 800 <= w <= 2000 and 800 <= h <= 2500


def test_save_separate(tmp_path):
    paths = plot.save(case3_like(), tmp_path / "sub" / "run.png", separate=True)
    assert [Path(p).name for p in paths] == [f"run_{p}.png" for p in BASE_PANELS]
    for p in paths:
        assert is_png(p)
    assert not (tmp_path / "sub" / "run.png").exists()


def test_separate_panels_hold_the_data():
    res = case3_like()
    figs = {f.get_label(): f for f in plot.figure(res, separate=True)}
    np.testing.assert_array_equal(
        artist(axes_by_label(figs["positions"])["positions"], "x2").get_ydata(), res.x2)
    np.testing.assert_array_equal(
        artist(axes_by_label(figs["kinetic_energy"])["kinetic_energy"], "ke").get_ydata(), res.ke)
    assert set(axes_by_label(figs["energy"])) == {"ledger", "residual"}
    for f in figs.values():
        assert f._suptitle.get_text() == res.scene.title


def test_no_events_no_markers():
    res = case3_like()
    res.events = np.zeros(0, dtype=EVENT_DTYPE)
    fig = plot.figure(res)
    pos = axes_by_label(fig)["positions"]
    assert not [a for a in pos.get_children() if str(a.get_gid()).startswith("impact:")]
    res.events = None
    plot.figure(res)


# ----------------------------------------------------------------------------
# the command line, on files in the CLI's exact format


def write_cli_output(res, path, with_events=True):
    """Write `res` the way the impact1d CLI does (see the API contract)."""
    s = res.scene
    lines = ["# impact1d output", f"# title = {s.title}", "# scene = input/synthetic.nml",
             f"# method = {s.method}"]
    for name in ("m1", "m2", "mu1", "mu2", "g", "x_left", "r_left", "x_right", "r_right",
                 "d_min", "r_min", "d_max", "r_max", "x1", "v1", "x2", "v2", "f1", "f2",
                 "t_end", "dt", "dt_out"):
        value = getattr(s, name)
        if value is not None:
            lines.append(f"# {name} = {value!r}")
    lines.append("# t x1 v1 x2 v2 ke work friction_loss impact_loss residual")
    cols = np.column_stack([res.t, res.x1, res.v1, res.x2, res.v2, res.ke, res.work,
                            res.friction_loss, res.impact_loss, res.residual])
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
        np.savetxt(fh, cols, fmt="%24.16E")
    if with_events:
        ev_path = str(path)[:-4] + ".events.dat"
        with open(ev_path, "w") as fh:
            fh.write("# impact1d events\n# t kind v1_before v2_before v1_after v2_after\n")
            for e in res.events:
                fh.write(f"{e['t']:24.16E} {e['kind']} {e['v1_before']:24.16E} "
                         f"{e['v2_before']:24.16E} {e['v1_after']:24.16E} "
                         f"{e['v2_after']:24.16E}\n")


@pytest.fixture
def cli():
    """impact1d.plot_cli of the installed package (it reads files through impact1d.read_output)."""
    return importlib.import_module("impact1d.plot_cli")


def test_cli_writes_png_next_to_output(tmp_path, cli, capsys):
    res = case5_like()
    out = tmp_path / "case5.dat"
    write_cli_output(res, out)
    assert cli.main([str(out)]) == 0
    png = tmp_path / "case5.png"
    assert is_png(png)
    assert str(png) in capsys.readouterr().out


def test_cli_reads_events_and_scene(tmp_path, cli):
    """What the CLI plots from a file equals what plot.figure draws from the run itself."""
    res = case3_like()
    out = tmp_path / "case3.dat"
    write_cli_output(res, out)
    read = IMPACT1D.read_output(str(out))
    fig = plot.figure(read)
    ax = axes_by_label(fig)
    np.testing.assert_allclose(artist(ax["positions"], "x1").get_ydata(), res.x1, rtol=1e-15)
    for contact in CONTACTS:
        np.testing.assert_allclose(artist(ax["positions"], f"impact:{contact}").get_xdata()[
            :len(impact_times(res, contact))], impact_times(res, contact), rtol=1e-15)
    assert np.all(np.asarray(artist(ax["positions"], "wall:right").get_ydata()) == 10.0)
    assert maybe_artist(ax["positions"], "slot_band") is not None
    assert fig._suptitle.get_text() == res.scene.title


def test_cli_options(tmp_path, cli):
    res = case3_like()
    out = tmp_path / "run.dat"
    write_cli_output(res, out, with_events=False)
    assert cli.main([str(out), "-o", str(tmp_path / "pics" / "x.png"), "--separate"]) == 0
    for p in BASE_PANELS:
        assert is_png(tmp_path / "pics" / f"x_{p}.png")


def test_cli_missing_file(tmp_path, cli, capsys):
    assert cli.main([str(tmp_path / "nope.dat")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope.dat" in err


def test_cli_unreadable_file(tmp_path, cli, capsys):
    bad = tmp_path / "bad.dat"
    bad.write_text("# impact1d output\n# t x1 v1 x2 v2 ke work friction_loss impact_loss "
                   "residual\n1 2 three\n")
    assert cli.main([str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.dat" in err
    assert not (tmp_path / "bad.png").exists()


def test_console_script(tmp_path):
    out = tmp_path / "case5.dat"
    write_cli_output(case5_like(), out)
    done = subprocess.run([find_tool("impact1d-plot"), str(out)], capture_output=True, text=True,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    assert is_png(tmp_path / "case5.png")
    done = subprocess.run([find_tool("impact1d-plot"), str(tmp_path / "nope.dat")], capture_output=True,
                          text=True)
    assert done.returncode == 1 and done.stderr.count("\n") == 1


# ----------------------------------------------------------------------------
# the seed cases through the real engine


@pytest.mark.parametrize("case", SEED_CASES)
def test_seed_case_figures(case, tmp_path):
    scene = IMPACT1D.load_scene(str(ROOT / "input" / f"{case}.nml"))
    res = IMPACT1D.simulate(scene)
    fig = plot.figure(res)
    check_figure_data(fig, res)
    paths = plot.save(res, tmp_path / f"{case}.png")
    assert is_png(paths[0])


def test_seed_case5_through_both_commands(tmp_path):
    """impact1d writes case 5, impact1d-plot draws it; the file's data are what is drawn."""
    out = tmp_path / "case5.dat"
    run = subprocess.run([find_tool("impact1d"), str(ROOT / "input" / "case5.nml"), "-o", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    done = subprocess.run([find_tool("impact1d-plot"), str(out)], capture_output=True, text=True,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    assert is_png(tmp_path / "case5.png")
    res = IMPACT1D.read_output(str(out))
    assert len(res.events) > 0 and res.scene.x_right == 10.0
    fig = plot.figure(res)
    check_figure_data(fig, res)
    assert fig._suptitle.get_text() == "Test case 5: wall collisions with rattling stop"
    bars = rest_bars(axes_by_label(fig)["impacts"], "left")  # rattled to rest, stays there
    assert len(bars) == 1 and bars[0][1] == res.t[-1] and abs(bars[0][0] - 3.0) < 1e-3


def test_slot_limit_beyond_the_walls_is_not_drawn():
    """Case 5's d_max = 50 m is never nearer than the right wall: a band up to it would
    only shade the whole panel above x1, so only the limit that can bind (d_min) is drawn."""
    res = case5_like()
    pos = axes_by_label(plot.figure(res))["positions"]
    assert maybe_artist(pos, "slot_band") is None and maybe_artist(pos, "slot:max") is None
    np.testing.assert_allclose(artist(pos, "slot:min").get_ydata(),
                               np.clip(res.x1 + res.scene.d_min, 0.0, 10.0))


# ----------------------------------------------------------------------------
# messages


class FullDiskFigure(matplotlib.figure.Figure):
    """A figure whose save meets a full disk, reported as the OS reports it: naming the file
    being written (the temporary one save() writes first)."""

    def savefig(self, fname, *args, **kwargs):
        import errno
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), os.fspath(fname))


def test_write_error_names_the_file_asked_for(tmp_path):
    target = tmp_path / "run.png"
    with pytest.raises(OSError) as caught:
        plot.save(case5_like(), target, figure_factory=FullDiskFigure)
    assert caught.value.filename == str(target) and ".part" not in str(caught.value)
    assert "No space left" in str(caught.value)
    assert list(tmp_path.iterdir()) == []        # no temporary left behind


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")
def test_cli_write_error_names_the_png(tmp_path, cli, capsys):
    """/proc takes no new file, even from root: making the temporary fails there."""
    out = tmp_path / "run.dat"
    write_cli_output(case3_like(), out)
    assert cli.main([str(out), "-o", "/proc/impact1d_test.png"]) == 1
    err = capsys.readouterr().err
    assert err == "impact1d-plot: error: cannot write /proc/impact1d_test.png: No such file or directory\n"
    table = tmp_path / "table.csv"
    table.write_text("r_left,n_impacts,t_rest,error\n0,1,0.5,\n1,2,0.7,\n")
    assert cli.main([str(table), "--x", "r_left", "-o", "/proc/impact1d_test.png"]) == 1
    err = capsys.readouterr().err
    assert ".part" not in err and "cannot write /proc/impact1d_test.png" in err


# ----------------------------------------------------------------------------
# the applied-force panel, the time window, kinetic and potential energy apart


def simulated(name, **overrides):
    return IMPACT1D.simulate(IMPACT1D.load_scene(str(ROOT / "input" / f"{name}.nml")), **overrides)


def work_of(res, force):
    """The work of `force` on body 1 along the samples (trapezoids)."""
    power = force * res.v1
    return np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(res.t))])


# Work integrated from the samples (dt_out = 1e-3) against the engine's ledger: 2.4e-7 of
# it for the forces the engine applied; a force off by 1 % of its sine's amplitude misses
# by 7e-5.
WORK_RTOL = 2e-6


def test_applied_forces_do_the_runs_work():
    """The forces the panel draws are the engine's: their work along the motion is the
    run's `work` column (a constant, a table, and a sine with a phase, on one free body)."""
    res = IMPACT1D.simulate(IMPACT1D.Scene(
        m1=1.0, x1=0.0, f1=0.5, f1_table=str(ROOT / "input" / "triangle.dat"), f1_amp=3.0,
        f1_period=0.7, f1_phase=0.5, t_end=5.0, dt=1e-3))
    forces = plot.applied_forces(res)
    assert list(forces) == ["f1"]
    np.testing.assert_allclose(work_of(res, forces["f1"]), res.work,
                               rtol=0, atol=WORK_RTOL * np.max(np.abs(res.work)))


def test_case6_force_panel_shows_the_triangle():
    res = simulated("case6")
    ax = axes_by_label(plot.figure(res))
    f1, f2 = artist(ax["forces"], "f1"), artist(ax["forces"], "f2")
    t = np.asarray(f1.get_xdata())
    # the corners are drawn exactly (a triangle stays sharp whatever dt_out is)
    for corner, value in ((1.0, 30.0), (2.0, 0.0), (3.0, -30.0), (4.0, 0.0)):
        assert f1.get_ydata()[np.flatnonzero(t == corner)[0]] == value
    np.testing.assert_array_equal(f1.get_ydata(), np.interp(t, [0, 1, 2, 3, 4], [0, 30, 0, -30, 0]))
    assert np.all(np.asarray(f2.get_ydata()) == 0.0)
    assert "(N)" in ax["forces"].get_ylabel()
    assert list(ax).index("forces") == list(ax).index("velocities") + 1


def test_sine_force_drawn_finer_than_the_samples():
    scene = FakeScene(f1_amp=5.0, f1_period=0.1, f1_phase=0.3, x_right=None, r_right=None)
    res = exact_run(scene)      # the sine is not in the motion: the panel reads the scene only
    res.t = res.t[::50]         # samples 0.05 s apart: two a period
    for name in ("x1", "v1", "x2", "v2", "ke", "work", "friction_loss", "impact_loss", "residual"):
        setattr(res, name, getattr(res, name)[::50])
    line = artist(axes_by_label(plot.figure(res))["forces"], "f1")
    t = np.asarray(line.get_xdata())
    assert np.max(np.diff(t)) <= 0.1 / 40
    np.testing.assert_allclose(line.get_ydata(), 5.0 * np.sin(2 * np.pi * t / 0.1 + 0.3), atol=1e-12)


def test_force_panel_by_default_only_when_a_force_varies():
    res = case5_like()          # constant forces
    assert "forces" not in axes_by_label(plot.figure(res))
    ax = axes_by_label(plot.figure(res, forces=True))["forces"]
    assert np.all(np.asarray(artist(ax, "f1").get_ydata()) == -2.0)
    assert np.all(np.asarray(artist(ax, "f2").get_ydata()) == 4.0)
    assert "forces" not in axes_by_label(plot.figure(simulated("case6"), forces=False))
    assert [f.get_label() for f in plot.figure(res, separate=True, forces=True)][:3] == \
        ["positions", "velocities", "forces"]


def test_file_read_back_knows_its_forces_only_with_its_scene(tmp_path):
    """The output's header names no force table: read back alone, the forces are unknown (no
    panel; asked for, a warning says why); with its scene, the panel is the run's."""
    out = tmp_path / "case6.dat"
    done = subprocess.run([find_tool("impact1d"), str(ROOT / "input" / "case6.nml"), "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    alone = IMPACT1D.read_output(out)
    assert alone.forces_known is False and alone.scene.f1_table is None
    assert "forces" not in axes_by_label(plot.figure(alone))
    with pytest.warns(UserWarning, match="does not record its force tables"):
        assert "forces" not in axes_by_label(plot.figure(alone, forces=True))
    with pytest.raises(ValueError, match="force tables"):
        plot.applied_forces(alone)
    whole = IMPACT1D.read_output(out, scene=ROOT / "input" / "case6.nml")
    assert whole.forces_known is True
    np.testing.assert_array_equal(plot.applied_forces(whole)["f1"],
                                  plot.applied_forces(simulated("case6"))["f1"])
    with pytest.raises(IMPACT1D.InputError, match="f1 = 0.0.*f1 = -2.0"):
        IMPACT1D.read_output(out, scene=ROOT / "input" / "case5.nml")


def test_cli_takes_the_force_tables_from_the_scene(tmp_path, cli, capsys, monkeypatch):
    """From the scene file the header names (relative to where impact1d ran), or --scene;
    when neither can be had, a note on stderr says why there is no force panel."""
    monkeypatch.chdir(ROOT)
    out = tmp_path / "case6.dat"
    done = subprocess.run([find_tool("impact1d"), "input/case6.nml", "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert cli.main([str(out), "--separate", "-o", str(tmp_path / "a.png")]) == 0
    assert is_png(tmp_path / "a_forces.png") and capsys.readouterr().err == ""
    monkeypatch.chdir(tmp_path)         # the header's input/case6.nml is not here
    assert cli.main([str(out), "--separate", "-o", str(tmp_path / "b.png")]) == 0
    err = capsys.readouterr().err
    assert not (tmp_path / "b_forces.png").exists() and is_png(tmp_path / "b_positions.png")
    assert err.startswith("impact1d-plot: note: no force panel:") and "--scene" in err
    assert err.count("\n") == 1
    assert cli.main([str(out), "--separate", "-o", str(tmp_path / "c.png"),
                     "--scene", str(ROOT / "input" / "case6.nml")]) == 0
    assert is_png(tmp_path / "c_forces.png")
    assert cli.main([str(out), "--separate", "-o", str(tmp_path / "d.png"), "--no-forces",
                     "--scene", str(ROOT / "input" / "case6.nml")]) == 0
    assert not (tmp_path / "d_forces.png").exists() and capsys.readouterr().err == ""
    assert cli.main([str(out), "--scene", str(ROOT / "input" / "case5.nml")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "f1" in err


def test_kinetic_and_potential_energy_on_their_own_axes():
    """Stick-slip: about 0.5 J of kinetic energy beside 5,000 J in the spring; each gets an
    axis scaled to it."""
    res = simulated("stick_slip")
    ax = axes_by_label(plot.figure(res))
    ke, pe = ax["kinetic_energy"], ax["potential_energy"]
    assert [line.get_gid() for line in ke.get_lines()] == ["ke"]
    np.testing.assert_array_equal(artist(pe, "pe").get_ydata(), res.pe)
    assert ke.get_ylim() == (0.0, 1.1 * res.ke.max()) and res.ke.max() < 1.0
    assert pe.get_ylim() == (0.0, 1.1 * res.pe.max()) and res.pe.max() > 4000.0
    assert "kinetic energy (J)" == ke.get_ylabel() and "potential energy (J)" == pe.get_ylabel()
    assert [f.get_label() for f in plot.figure(res, separate=True)] == list(plot.PANELS)


def test_time_window():
    res = simulated("case6")
    lo, hi = 2.5005, 3.9995                 # between samples (dt_out = 1e-3)
    fig = plot.figure(res, t_from=lo, t_to=hi)
    ax = axes_by_label(fig)
    for a in ax.values():
        assert a.get_xlim() == (lo, hi)
    inside = (res.t >= lo - 1e-3) & (res.t <= hi + 1e-3)        # and the sample either side
    assert res.t[inside][0] < lo and res.t[inside][-1] > hi
    x1 = artist(ax["positions"], "x1")
    np.testing.assert_array_equal(x1.get_xdata(), res.t[inside])
    np.testing.assert_array_equal(x1.get_ydata(), res.x1[inside])
    # the ledger still counts from t = 0
    np.testing.assert_array_equal(artist(ax["ledger"], "ke_change").get_ydata(),
                                  res.ke[inside] - res.ke[0])
    impacts = [t for t, kind in zip(res.events["t"], res.events["kind"])
               if kind in CONTACTS and lo <= t <= hi]
    assert f"{len(impacts)} impacts in t = {lo:g} to {hi:g} s" in ax["positions"].get_title(loc="left")
    np.testing.assert_array_equal(artist(ax["impacts"], "tick:left").get_xdata(),
                                  [t for t in impacts if t in impact_times(res, "left")])
    drawn = np.asarray(artist(ax["forces"], "f1").get_xdata())
    assert drawn[0] == lo and drawn[-1] == hi


def test_time_window_keeps_a_rest_that_began_before_it():
    res = case5_like()                      # both bodies rest from t = 3
    ax = axes_by_label(plot.figure(res, t_from=3.1))["impacts"]
    np.testing.assert_allclose(rest_bars(ax, "left"), [(impact_times(res, "rest_left")[0], 3.2)],
                               atol=1e-12)
    assert ax.get_xlim() == (3.1, 3.2)


@pytest.mark.parametrize("window, message", [
    (dict(t_from=3.0, t_to=2.0), "empty"), (dict(t_from=7.0), "misses the run"),
    (dict(t_to=-1.0), "misses the run"), (dict(t_from=float("nan")), "finite")])
def test_bad_time_window(window, message):
    with pytest.raises(ValueError, match=message):
        plot.figure(case5_like(), **window)


def test_cli_time_window(tmp_path, cli, capsys):
    out = tmp_path / "run.dat"
    write_cli_output(case5_like(), out)
    assert cli.main([str(out), "--t-from", "2", "--t-to", "3", "--separate"]) == 0
    assert is_png(tmp_path / "run_positions.png")
    capsys.readouterr()
    assert cli.main([str(out), "--t-from", "7"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "misses the run" in err


def test_moving_grounds_are_drawn_where_they_are():
    """A limit whose ground end moves (ground_v, ground_amp ...; &walls x_left_v ...) is
    drawn at its prescribed position over the run, not at its limit: the vibrating table
    (input/vibrating_table.nml) at w(t) = A sin(2 pi t / T + phi), which the ball meets at
    each impact (it was drawn still at 0 while the ball met it near 0.05 m), a wall closing
    at constant speed, and a moving stop of one body of three (dashed, in its colour)."""
    scene = IMPACT1D.load_scene(ROOT / "input" / "vibrating_table.nml")
    scene.t_end = 2.0
    res = IMPACT1D.simulate(scene)
    pos = axes_by_label(plot.figure(res))["positions"]
    table = artist(pos, "wall:table")
    (record,) = scene.contacts
    w = record["ground_amp"] * np.sin(2 * np.pi * res.t / record["ground_period"] + record["ground_phase"])
    np.testing.assert_array_equal(table.get_xdata(), res.t)
    np.testing.assert_allclose(table.get_ydata(), w, rtol=0, atol=1e-15)
    assert table.get_label() == "table: x1 \u2265 0 m + w(t)"
    impacts = res.events["t"][res.events["kind"] == "table"]
    assert len(impacts) > 2
    # (the samples 1 ms apart: the ball and the table 3 m/s apart there)
    np.testing.assert_allclose(np.interp(impacts, res.t, table.get_ydata()), np.interp(impacts, res.t, res.x1),
                               rtol=0, atol=5e-3)
    assert np.all(np.abs(np.interp(impacts, res.t, res.x1)) > 0.03)      # not where a still table is
    assert np.all(res.x1 >= table.get_ydata() - 1e-12)

    walls = IMPACT1D.Scene(m1=1.0, x1=0.0, v1=1.0, x_left=0.0, x_right=1.0, x_right_v=-0.1, t_end=2.0, dt=1e-3,
                           dt_out=0.01)
    res = IMPACT1D.simulate(walls)
    pos = axes_by_label(plot.figure(res))["positions"]
    right = artist(pos, "wall:right")
    np.testing.assert_allclose(right.get_ydata(), 1.0 - 0.1 * res.t, rtol=0, atol=1e-15)
    assert list(artist(pos, "wall:left").get_ydata()) == [0.0, 0.0]       # a still wall as before
    assert np.all(res.x1 <= right.get_ydata() + 1e-12)

    three = IMPACT1D.Scene(m=[1.0, 1.0, 1.0], x=[0.0, 1.0, 2.0], v=[0.0, 0.5, 0.0], t_end=1.0, dt=1e-3,
                           dt_out=0.01, contacts=[dict(a=0, b=2, d_max=1.2, ground_v=0.1, name="pusher")])
    res = IMPACT1D.simulate(three)
    for fig in (plot.figure(res), plot.spacetime(res)):
        line = [a for ax in fig.axes for a in ax.get_children() if a.get_gid() == "wall:pusher"]
        assert len(line) == 1
        assert line[0].get_linestyle() == "--"
        np.testing.assert_allclose(line[0].get_ydata(), 1.2 + 0.1 * np.asarray(line[0].get_xdata()), rtol=0,
                                   atol=1e-15)
