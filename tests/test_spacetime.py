"""Tests of the N-body pictures: impact1d.plot.spacetime, the N >= 3 default of
impact1d.plot.figure, impact1d.plot.animate and `impact1d-plot --animate`.

The engine runs one and two bodies today (issue 19 brings N), so the pictures are tested on
(a) Results of impact1d.simulate on the scenes in input/ and (b) synthetic N-body results:
the exact 50-digit solver tests/exact_nbody.py run on the scenes of tests/nbody_scenes.py,
its Solution.state(t) sampled on a grid, its events given the contact's ends from the
scene's records: the trajectory interface of DESIGN.md ("Mechanisms as data": t, x and v
as (samples, N) arrays, ke, events with t, kind, a, b, the scene's contact records).
What the figures show is checked against the closed forms (an impact marker at the wall,
midway between the balls of a cradle at the time the closed form gives), not only that a
file appears.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import matplotlib
matplotlib.use("Agg")
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

import exact_nbody as nb  # noqa: E402
import nbody_scenes as ns  # noqa: E402
import impact1d  # noqa: E402
from impact1d import plot  # noqa: E402
from tools import find_tool  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EVENT_DTYPE = np.dtype([("t", "f8"), ("kind", "U24"), ("a", "i4"), ("b", "i4")])


# ----------------------------------------------------------------------------
# results


def synthetic(scene, samples=201, title="synthetic"):
    """An N-body result of the exact solver: states on an even grid of `samples` times,
    events with the ends of their contact record (0, 0 for stick<i>/slip<i>), the ledger
    columns of a run without forces or friction (work 0, impact loss KE0 - KE)."""
    solution = nb.solve(scene)
    t = np.linspace(0.0, float(solution.t_end), samples)
    states = [solution.state(time) for time in t]
    X = np.array([[float(a) for a in x] for x, _ in states])
    V = np.array([[float(a) for a in v] for _, v in states])
    record = {limit.name: limit.record for limit in solution.model.limits}
    rows = []
    for e in solution.events:
        name = e.kind.split("_", 1)[1] if e.kind.startswith(("rest_", "release_")) else e.kind
        ends = (0, 0) if e.kind.startswith(("stick", "slip")) else \
            (scene["contacts"][record[name]]["a"], scene["contacts"][record[name]]["b"])
        rows.append((float(e.t), e.kind, *ends))
    ke = 0.5 * (V ** 2 * np.asarray(scene["m"], dtype=float)).sum(axis=1)
    zero = np.zeros_like(t)
    columns = {f"{q}{i + 1}": A[:, i] for i in range(X.shape[1]) for q, A in (("x", X), ("v", V))}
    return SimpleNamespace(**{"x2": None, "v2": None, **columns}, t=t, x=X, v=V, ke=ke, work=zero,
                           friction_loss=zero, impact_loss=ke[0] - ke, residual=zero,
                           events=np.array(rows, dtype=EVENT_DTYPE),
                           scene=SimpleNamespace(title=title, contacts=scene["contacts"]))


def long_cradle(n, samples, gap=0.01, d=0.1, v=1.0):
    """A cradle of n balls in closed form (equal masses, elastic): ball k moves alone at v
    from impact k - 1 to impact k at t_k = k gap / v (contact b<k>), then rests."""
    x0 = np.arange(n) * (d + gap)
    hits = np.arange(1, n) * gap / v
    t = np.linspace(0.0, 1.2 * n * gap / v, samples)
    start, stop = np.concatenate([[0.0], hits]), np.concatenate([hits, [np.inf]])
    X = x0 + v * np.clip(t[:, None] - start, 0.0, stop - start)
    V = np.where((t[:, None] >= start) & (t[:, None] < stop), v, 0.0)
    events = np.array([(time, f"b{k}", k, k + 1) for k, time in enumerate(hits, 1)], dtype=EVENT_DTYPE)
    contacts = [dict(a=i, b=i + 1, d_min=d, r_min=1.0, name=f"b{i}") for i in range(1, n)]
    return SimpleNamespace(t=t, x=X, v=V, ke=0.5 * (V ** 2).sum(axis=1), events=events,
                           scene=SimpleNamespace(title=f"{n} balls", contacts=contacts)), hits


def run(name, **overrides):
    return impact1d.simulate(impact1d.load_scene(ROOT / "input" / f"{name}.nml"), **overrides)


@pytest.fixture(scope="module")
def cradle():
    scene = ns.newtons_cradle(t_end=1.0)
    return scene, synthetic(scene, title="Newton's cradle")


def artist(fig, gid):
    found = [a for ax in fig.axes for a in ax.get_children() if a.get_gid() == gid]
    assert len(found) == 1, f"{len(found)} artists with gid {gid!r}"
    return found[0]


def gids(fig):
    return {a.get_gid() for ax in fig.axes for a in ax.get_children() if a.get_gid()}


# ----------------------------------------------------------------------------
# the adapter


def test_bodies_reads_todays_and_nbody_results(cradle):
    two = run("case3", t_end=0.5)
    t, X, V = plot._bodies(two)
    assert X.shape == (t.size, 2) and np.array_equal(X[:, 1], two.x2) and np.array_equal(V[:, 0], two.v1)
    one = run("stick_slip", t_end=0.5)
    t, X, V = plot._bodies(one)
    assert X.shape == (t.size, 1) and np.array_equal(X[:, 0], one.x1)
    _, result = cradle
    t, X, V = plot._bodies(result)
    assert X.shape == (t.size, 5) and np.array_equal(X, result.x) and np.array_equal(V, result.v)


def test_rows_of_todays_scene_and_of_records():
    rows = plot._rows(run("case3", t_end=0.1), 2)
    assert [(r.name, r.a, r.b, r.side, r.limit) for r in rows] == [
        ("left", 0, 1, "min", 0.0), ("right", 0, 2, "max", 10.0),
        ("slot_min", 1, 2, "min", 1.0), ("slot_max", 1, 2, "max", 2.0)]
    # A record on (body, ground) is turned round: x3 <= 2 is 0 - x3 >= -2.
    scene = SimpleNamespace(contacts=[dict(a=3, b=0, d_min=-2.0, name="stop3"),
                                      dict(a=1, b=2, d_min=0.25, d_max=0.5, name="link1")])
    rows = plot._rows(SimpleNamespace(scene=scene), 3)
    # (bodies 2 and 3 meet, as the engine has them: no record joins them)
    assert [(r.name, r.a, r.b, r.side, r.limit) for r in rows] == [
        ("link2", 2, 3, "min", 0.0),
        ("stop3", 0, 3, "max", 2.0), ("link1_min", 1, 2, "min", 0.25), ("link1_max", 1, 2, "max", 0.5)]


@pytest.mark.parametrize("name", ["newtons_cradle", "train", "ball_stack"])
def test_rows_of_the_chain_shorthand_are_the_engines(name):
    """The &link arrays of more than two bodies are contact rows (link<i>), named and ordered
    as the engine names its rows (event_kinds), with their limits: the cradle's balls touch
    at 0.0625 m, the train's couplers have 62.5 mm of slack. Before, the pictures knew no
    link of a chain (the Result's scene had lost its arrays, and _rows read scalars only)."""
    scene = impact1d.load_scene(ROOT / "input" / f"{name}.nml")
    result = impact1d.simulate(scene, t_end=0.01)
    rows = plot._rows(result, len(scene.m))
    assert [r.name for r in rows] == list(impact1d.event_kinds(scene)[:len(rows)])
    assert impact1d.event_kinds(scene)[len(rows)].startswith("rest_")
    limits = {(r.name, r.side): r.limit for r in rows}
    if name == "newtons_cradle":
        assert limits == {(f"link{i}", "min"): 0.0625 for i in range(1, 5)}
    elif name == "train":
        assert limits[("link9_max", "max")] == 16.0625 and limits[("link1_min", "min")] == 16.0
        assert len(rows) == 18


def test_chain_springs_for_the_animation():
    """The chain's spring arrays (k, x_rest per body; k_link, d_rest per link), then the
    &spring records."""
    scene = SimpleNamespace(k=[10.0, 0.0, 5.0], x_rest=[0.0, 1.0, 2.0], k_link=[0.0, 20.0],
                            d_rest=[0.3, 0.4], springs=[dict(a=1, b=3, k=1.0, d_rest=0.5)])
    assert plot._springs(SimpleNamespace(scene=scene), 3) == [(0, 1, 0.0), (0, 3, 2.0), (2, 3, 0.4), (1, 3, 0.5)]


# ----------------------------------------------------------------------------
# the space-time plot


def test_cradle_paths_and_impacts_where_the_balls_meet(cradle):
    scene, result = cradle
    fig = plot.spacetime(result)
    for i in range(5):
        line = artist(fig, f"x{i + 1}")
        assert np.array_equal(line.get_xdata(), result.t) and np.array_equal(line.get_ydata(), result.x[:, i])
    answer = ns.newtons_cradle_answer(scene)
    d = scene["contacts"][0]["d_min"]
    for k, (t, kind, _, _) in enumerate(answer["events"], start=1):
        marker = artist(fig, f"impact:{kind}")
        # Ball k stops where it meets ball k+1 (at rest at x_{k+1}(0)): the contact point
        # is d/2 short of ball k+1's centre.
        np.testing.assert_allclose(marker.get_xdata(), [float(t)], rtol=0, atol=1e-12)
        np.testing.assert_allclose(marker.get_ydata(), [scene["x"][k] - d / 2], rtol=0, atol=1e-12)
    assert fig.axes[0].get_legend() is not None         # five bodies: a legend names them


def test_galperin_wall_impacts_at_the_wall():
    scene = ns.galperin()
    fig = plot.spacetime(synthetic(scene, samples=801))
    answer = ns.galperin_answer(scene)
    for kind in ("wall", "meet"):
        times = [float(e[0]) for e in answer["events"] if e[1] == kind]
        marker = artist(fig, f"impact:{kind}")
        np.testing.assert_allclose(marker.get_xdata(), times, rtol=0, atol=1e-12)
        if kind == "wall":
            assert np.all(marker.get_ydata() == 0.0) and marker.get_marker() == "x"
        else:
            assert marker.get_marker() == "o" and np.all(marker.get_ydata() > 0.0)
    assert artist(fig, "wall:wall").get_ydata()[0] == 0.0


def test_todays_two_body_run_walls_and_slot():
    result = run("case3", t_end=3.0)
    fig = plot.spacetime(result)
    kinds = [str(k) for k in result.events["kind"]]
    for contact, y in (("left", 0.0), ("right", 10.0)):
        marker = artist(fig, f"impact:{contact}")
        assert marker.get_xdata().size == kinds.count(contact) > 0
        assert np.all(marker.get_ydata() == y)
    for contact, d in (("slot_min", 1.0), ("slot_max", 2.0)):
        marker = artist(fig, f"impact:{contact}")
        times = marker.get_xdata()
        assert times.size == kinds.count(contact) > 0
        # x2 - x1 = d at the impact: the contact point is x1 + d/2 (within a sample's travel).
        np.testing.assert_allclose(marker.get_ydata(), np.interp(times, result.t, result.x1) + d / 2,
                                   rtol=0, atol=0.02)


def test_stuck_bodies_and_held_contacts_of_the_friction_chain():
    scene = ns.friction_chain()
    answer = ns.friction_chain_answer(scene)
    fig = plot.spacetime(synthetic(scene, samples=301))
    t_break = float(answer["t_break"])
    for body in range(1, 9):        # each held by friction from the start until the break
        band = artist(fig, f"stuck{body}")
        assert band.get_xdata()[0] == 0.0 and band.get_xdata()[-1] == pytest.approx(t_break, abs=1e-12)
    for t, kind, _, _ in answer["events"]:
        if kind.startswith("rest_"):    # the load front: each contact held from its rest on
            band = artist(fig, "rest:" + kind[5:])
            assert isinstance(band, PolyCollection)
            x = band.get_paths()[0].vertices[:, 0]
            assert x.min() == pytest.approx(float(t), abs=1e-12)
            assert x.max() == pytest.approx(float(scene["t_end"]), abs=1e-12)


def test_todays_rests_and_sticks():
    result = run("case5")           # both bodies rest on their walls from t = 3 s
    fig = plot.spacetime(result)
    band = artist(fig, "rest:left")
    assert band.get_xdata()[0] == pytest.approx(3.0, abs=1e-9) and np.all(np.abs(band.get_ydata()) < 1e-9)
    assert artist(fig, "rest:right").get_ydata()[-1] == pytest.approx(10.0, abs=1e-9)
    result = run("stick_slip")          # sticks and slips by turns: one band, in stretches
    kinds = [str(k) for k in result.events["kind"]]
    sticks = [t for t, k in zip(result.events["t"], kinds) if k == "stick1"]
    slips = [t for t, k in zip(result.events["t"], kinds) if k == "slip1"]
    band = artist(plot.spacetime(result), "stuck1").get_xdata()
    gaps = np.flatnonzero(np.isnan(band))
    starts, ends = band[np.r_[0, gaps + 1]], band[np.r_[gaps - 1, band.size - 1]]
    # The block starts at rest, held: its first event is a slip, so it is stuck from t = 0.
    assert len(sticks) > 2 and slips[0] < sticks[0]
    np.testing.assert_array_equal(starts, [0.0] + sticks)
    np.testing.assert_array_equal(ends, slips + [result.t[-1]] * (len(sticks) + 1 - len(slips)))


def test_many_bodies_get_a_map_of_velocity_over_body_and_time():
    result, hits = long_cradle(1000, 2000)
    fig = plot.spacetime(result)
    image = artist(fig, "map:v")
    data = image.get_array()
    assert data.shape == (1000, 2000)
    np.testing.assert_array_equal(data, result.v.T)       # an even grid: every sample
    dots = artist(fig, "impacts")
    np.testing.assert_allclose(dots.get_xdata(), hits)
    np.testing.assert_allclose(dots.get_ydata(), np.arange(1, 1000) + 0.5)
    assert "x1" not in gids(fig)
    gap_fig = plot.spacetime(result, quantity="gap")
    gap = artist(gap_fig, "map:gap").get_array()
    assert gap.shape == (999, 2000)
    # (an impact of balls k, k+1 on the row of their gap, k: it was drawn at k + 0.5, between rows)
    np.testing.assert_allclose(artist(gap_fig, "impacts").get_ydata(), np.arange(1, 1000))
    np.testing.assert_allclose(gap[:, 0], 0.01)             # the initial gaps, d_min taken off
    few, _ = long_cradle(20, 200)
    fig = plot.spacetime(few)
    assert "x20" in gids(fig) and "map:v" not in gids(fig) and fig.axes[0].get_legend() is not None
    assert "map:v" in gids(plot.spacetime(few, mode="map"))
    with pytest.raises(ValueError, match="mode"):
        plot.spacetime(few, mode="bars")


def test_map_scale_is_that_of_most_moving_bodies_and_crowded_impacts_are_faint():
    """One body thrown off fast among many slow ones: the colour scale is the 99th
    percentile of the moving bodies' speeds (the fast one saturates, the bar says so), not
    the fastest (which left every other body white); thousands of impact dots are faint
    (at full strength they hid the map: 1,000 random balls, 7,264 impacts)."""
    result, hits = long_cradle(1000, 2000)
    result.v = result.v.copy()
    result.v[:, 0] *= 0.1                       # (ball 1 slower,)
    result.v[-1, -1] = 50.0                     # (one sample of the last ball fast)
    fig = plot.spacetime(result)
    image = artist(fig, "map:v")
    assert image.norm.vmax == pytest.approx(1.0) and image.norm.vmin == pytest.approx(-1.0)
    assert image.colorbar.extend == "both"
    assert artist(fig, "impacts").get_alpha() == pytest.approx(0.4)        # 999 impacts
    crowded = SimpleNamespace(**vars(result))
    crowded.events = np.concatenate([result.events] * 4)
    assert artist(plot.spacetime(crowded), "impacts").get_alpha() == pytest.approx(0.4 * 1000 / (4 * 999))
    crowded.events = np.concatenate([result.events] * 20)
    assert artist(plot.spacetime(crowded), "impacts").get_alpha() == 0.08        # (its floor)
    calm = artist(plot.spacetime(long_cradle(1000, 2000)[0]), "map:v")
    assert calm.norm.vmax == pytest.approx(1.0) and calm.colorbar.extend == "neither"


def test_figure_draws_the_spacetime_plot_for_three_bodies_or_more(cradle):
    _, result = cradle
    fig = plot.figure(result)
    assert [ax.get_label() for ax in fig.axes] == ["spacetime", "kinetic_energy", "ledger", "residual"]
    assert [f.get_label() for f in plot.figure(result, separate=True)] == \
        ["spacetime", "kinetic_energy", "energy"]
    two = plot.figure(run("case3", t_end=0.5))
    assert "spacetime" not in [ax.get_label() for ax in two.axes]
    window = plot.figure(result, t_from=0.2, t_to=0.6)
    assert window.axes[0].get_xlim() == (0.2, 0.6)


# ----------------------------------------------------------------------------
# the animation


def frames_of(path):
    with Image.open(path) as image:
        assert image.format == "GIF"
        frames = []
        for k in range(image.n_frames):
            image.seek(k)
            frames.append(np.asarray(image.convert("RGB")))
    return frames


def recorded():
    figures = []

    def factory(**kw):
        figures.append(Figure(**kw))
        return figures[-1]
    return figures, factory


@pytest.mark.parametrize("case", ["two_body", "cradle"])
def test_animation_gif(tmp_path, cradle, case):
    if case == "two_body":
        result, count, width = run("case3", t_end=1.0, dt_out=0.01), 12, 1.0
        X = np.column_stack([result.x1, result.x2])
    else:
        result, count, width = cradle[1], 15, 1.0
        X = result.x
    figures, factory = recorded()
    path = tmp_path / "sub" / "run.gif"
    anim = plot.animate(result, path, max_frames=count, figure_factory=factory)
    frames = frames_of(path)
    assert len(frames) == count == len(anim.frame_samples)
    assert len({frame.tobytes() for frame in frames}) == count       # every frame differs
    # After saving, the blocks stand where the last frame's sample puts the bodies.
    last = anim.frame_samples[-1]
    assert last == len(result.t) - 1
    for i in range(X.shape[1]):
        block = artist(figures[0], f"block{i + 1}")
        assert block.get_x() == pytest.approx(X[last, i] - width / 2) and block.get_width() == width


def test_animation_frames_of_a_time_window(tmp_path, cradle):
    _, result = cradle              # samples every 5 ms
    anim = plot.animate(result, tmp_path / "w.gif", t_from=0.2, t_to=0.6, max_frames=5)
    np.testing.assert_allclose(result.t[anim.frame_samples], [0.2, 0.3, 0.4, 0.5, 0.6], atol=1e-12)
    assert len(frames_of(tmp_path / "w.gif")) == 5


def test_animation_refuses_what_it_cannot_write(tmp_path, cradle):
    _, result = cradle
    with pytest.raises(ValueError, match="gif or .mp4"):
        plot.animate(result, tmp_path / "run.png")
    if shutil.which("ffmpeg") is None:
        with pytest.raises(ValueError, match="ffmpeg not found: write .gif"):
            plot.animate(result, tmp_path / "run.mp4")
    assert list(tmp_path.iterdir()) == []


def test_cli_animates_a_run(tmp_path):
    out = tmp_path / "case5.dat"
    done = subprocess.run([find_tool("impact1d"), str(ROOT / "input" / "case5.nml"), "-o", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    done = subprocess.run([find_tool("impact1d-plot"), "--animate", str(out), "--max-frames", "8"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    gif = tmp_path / "case5.gif"
    assert done.stdout.strip() == f"wrote {gif}" and len(frames_of(gif)) == 8
    if shutil.which("ffmpeg") is None:
        done = subprocess.run([find_tool("impact1d-plot"), "--animate", str(out), "-o",
                               str(tmp_path / "x.mp4")], capture_output=True, text=True)
        assert done.returncode == 1 and "ffmpeg not found: write .gif" in done.stderr
    done = subprocess.run([find_tool("impact1d-plot"), "--animate", "--separate", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 1 and "--animate writes one animation" in done.stderr


# ----------------------------------------------------------------------------
# the N-body scenes of input/ and outputs of some bodies (--bodies-out)


def test_cradle_animation_balls_touch_and_train_couplers_show_their_state():
    """The cradle's blocks are one diameter wide (its &link d_min: balls 2-5 touch; they
    were 4 % of the span wide, apart, when the pictures knew no chain link). The train's
    couplers are squares above the joints: at t = 0 every one blue (buffers touching), at
    0.25 s (after the locomotive's take-up at 0.224 s, before the next at 0.355 s) link 9
    red (taut), link 8 grey (in its slack), at 2 s all taut."""
    figures, factory = recorded()
    anim = plot.animate(run("newtons_cradle"), max_frames=3, figure_factory=factory)
    anim._draw_was_started = True       # (not saved: matplotlib's warning is not for this)
    assert artist(figures[0], "block3").get_width() == 0.0625
    train = run("train", t_end=2.0)
    ax = Figure().subplots()
    stage = plot._Stage(ax, plot._Mechanism(train), plot._springs(train, 10))
    couplers = artist(ax.figure, "couplers")
    blue, grey, red = (matplotlib.colors.to_rgba(c) for c, _ in plot._Couplers.STATES)
    for t, expected in ((0.0, [blue] * 9), (0.25, [blue] * 7 + [grey, red]), (2.0, [red] * 9)):
        stage.show(int(np.argmin(np.abs(train.t - t))))
        assert [tuple(c) for c in couplers.get_facecolors()] == expected, t
        np.testing.assert_allclose(couplers.get_offsets()[:, 0], 0.5 * (train.x[:, :-1] + train.x[:, 1:])[
            int(np.argmin(np.abs(train.t - t)))])


def bodies_out(tmp_path, scene, bodies):
    out = tmp_path / f"{scene}.dat"
    done = subprocess.run([find_tool("impact1d"), str(ROOT / "input" / f"{scene}.nml"), "--quiet",
                           "--bodies-out", bodies, "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out


def test_plot_of_an_output_of_some_bodies(tmp_path):
    """impact1d-plot on a --bodies-out output: case 3 with body 2 only used to fail ('x and y
    must have same first dimension': the panels assumed x1); now it is the space-time picture
    of body 2 with its impacts on it (the slot's, whose other end is not written, on x2), and
    a cradle of balls 1 and 5 has x1 and x5 (not x1 and x2). The animation refuses them."""
    out = bodies_out(tmp_path, "case3", "2")
    done = subprocess.run([find_tool("impact1d-plot"), str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "case3.png").stat().st_size > 0
    result = impact1d.read_output(out)
    fig = plot.figure(result)
    assert fig.axes[0].get_label() == "spacetime" and {"x2", "wall:left", "wall:right"} <= gids(fig)
    assert "x1" not in gids(fig)
    slot = artist(fig, "impact:slot_min")
    times = slot.get_xdata()
    assert times.size > 0 and np.all(np.isfinite(slot.get_ydata()))
    np.testing.assert_allclose(slot.get_ydata(), np.interp(times, result.t, result.x2))
    cradle = impact1d.read_output(bodies_out(tmp_path, "newtons_cradle", "1,5"))
    fig = plot.spacetime(cradle)
    assert {"x1", "x5"} <= gids(fig) and "x2" not in gids(fig)
    # The paths are the samples and each ball's position at its impact (from the log's
    # velocities): ball 1 reaches 0.1875 m at 0.375 s, where it meets ball 2, instead of
    # cutting the corner between the samples at 0.37 and 0.38 s.
    for body, where in ((1, 0.1875), (5, 0.4375)):
        line = artist(fig, f"x{body}")
        times, ys = line.get_xdata(), line.get_ydata()
        assert times.size == cradle.t.size + 1 and np.all(np.diff(times) >= 0)
        np.testing.assert_array_equal(np.delete(ys, np.flatnonzero(times == 0.375)[0]), getattr(cradle, f"x{body}"))
        assert ys[times == 0.375][0] == pytest.approx(where, abs=1e-12)
    with pytest.raises(ValueError, match="bodies 1, 5 of 5"):
        plot.animate(cradle)
    with pytest.raises(ValueError, match="every body"):
        plot.spacetime(cradle, mode="map")
