"""A ground end moved by a piecewise-linear table (issue 21 item 1; DESIGN "Laws added on the
records": `ground_table` on a &contact or &spring record): w(t) = table(t), linear between
the table's corners, held at its ends (as a force table), added to ground_v t and the sine.
The table's velocity jumps at its corners; the run stops there (as at a force table's
corners) and the event point sees the velocity after the corner: a body held to the ground
takes a jump toward it as an impact (restitution on the relative velocity) and lifts off a
jump away from it; a spring to a table anchor follows (its force is continuous, its rate
jumps). Closed forms in each test's docstring, at dt = 1e-3 and a coarse dt; the energy
ledger (drive_work) closes in every run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import impact1d

G = 9.81


def write_table(path, rows):
    path.write_text("# t w\n" + "".join(f"{t!r} {w!r}\n" for t, w in rows))
    return str(path)


def lift_scene(tmp_path, dt, r=0.5, speed=1.0, t0=0.5, t1=1.5, t_end=2.0):
    """A ball (m = 1, weight -g) resting on a floor that stays still until t0, rises at
    `speed` until t1 and stops there (held at speed (t1 - t0))."""
    table = write_table(tmp_path / "lift.dat", [(0.0, 0.0), (t0, 0.0), (t1, speed * (t1 - t0))])
    return impact1d.Scene(m1=1.0, f1=-G, x1=0.0, v1=0.0, t_end=t_end, dt=dt, dt_out=0.01, contacts=[
        dict(a=0, b=1, d_min=0.0, r_min=r, ground_table=table, name="floor")])


@pytest.mark.parametrize("dt", [1e-3, 5e-2])
def test_ball_on_a_floor_that_starts_to_rise_bounces_off_it(tmp_path, dt):
    """The floor jumps from rest to V at t0 under the resting ball: an impact with
    restitution r on the relative velocity -V, so the ball leaves at V + r V = (1 + r) V
    (relative -> lab). In the floor's frame (it moves at constant V, no force on the ball
    but -g) the ball then bounces from relative speed r V: the k-th flight lasts
    2 r^k V / g and lands at relative velocity -r^k V, the lab's V - r^k V, leaving at
    V + r^(k+1) V. The flights accumulate at t0 + 2 r V / (g (1 - r)), after which the ball
    rides the floor at V (the motion is polynomial: event times exact but for rounding)."""
    r, speed, t0 = 0.5, 1.0, 0.5
    result = impact1d.simulate(lift_scene(tmp_path, dt, r, speed, t0))
    events = result.events
    impacts = events[events["kind"] == "floor"]
    assert impacts["t"][0] == t0
    assert impacts["v1_before"][0] == 0.0
    assert impacts["v1_after"][0] == pytest.approx((1 + r) * speed, abs=1e-14)
    t, expected = t0, []
    for k in range(1, 6):
        t += 2 * r**k * speed / G
        expected.append((t, speed - r**k * speed, speed + r ** (k + 1) * speed))
    np.testing.assert_allclose(impacts["t"][1:6], [e[0] for e in expected], rtol=0, atol=1e-12)
    np.testing.assert_allclose(impacts["v1_before"][1:6], [e[1] for e in expected], rtol=0, atol=1e-12)
    np.testing.assert_allclose(impacts["v1_after"][1:6], [e[2] for e in expected], rtol=0, atol=1e-12)
    t_rest = t0 + 2 * r * speed / (G * (1 - r))
    rest = events[(events["kind"] == "rest_floor") & (events["t"] > t0)]
    assert rest["t"][0] == pytest.approx(t_rest, abs=1e-9)
    riding = (result.t > t_rest + 1e-6) & (result.t <= 1.5)
    np.testing.assert_allclose(result.x1[riding], speed * (result.t[riding] - t0), rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.v1[riding], speed, rtol=0, atol=1e-12)
    assert result.energy_residual < 1e-12


@pytest.mark.parametrize("dt", [1e-3, 5e-2])
def test_ball_riding_a_floor_that_stops_flies_on(tmp_path, dt):
    """The floor, rising at V with the ball on it, stops at t1 (w = V (t1 - t0) after): the
    ball keeps its velocity V (the floor slows away from it: no impact) and flies,
    x = w1 + V tau - g tau^2 / 2, rising V^2 / (2 g) above the stop point; it lands at
    t1 + 2 V / g at -V and leaves at r V (the floor is still)."""
    r, speed, t0, t1 = 0.5, 1.0, 0.5, 1.5
    result = impact1d.simulate(lift_scene(tmp_path, dt, r, speed, t0, t1))
    events = result.events
    release = events[events["kind"] == "release_floor"]
    assert release["t"][-1] == t1
    flight = (result.t > t1) & (result.t < t1 + 2 * speed / G)
    tau = result.t[flight] - t1
    w1 = speed * (t1 - t0)
    np.testing.assert_allclose(result.x1[flight], w1 + speed * tau - G * tau**2 / 2, rtol=0, atol=1e-12)
    assert result.x1[flight].max() <= w1 + speed**2 / (2 * G) + 1e-12
    assert result.x1[flight].max() >= w1 + speed**2 / (2 * G) - 1e-3    # (a sample within 0.01 s of the apex)
    landing = events[(events["kind"] == "floor") & (events["t"] > t1)][0]
    assert landing["t"] == pytest.approx(t1 + 2 * speed / G, abs=1e-12)
    assert landing["v1_before"] == pytest.approx(-speed, abs=1e-12)
    assert landing["v1_after"] == pytest.approx(r * speed, abs=1e-12)
    assert result.energy_residual < 1e-12


def exact_anchor_oscillator(k, c, m, corners, t, digits=30):
    """x(t) of x'' = -(k (x - w) + c (v - w')) / m from rest at 0, w the piecewise-linear
    table through `corners` (held after the last), at 30 digits: on each segment
    w = w0 + s tau, so (x, v, 1, tau) obeys a linear system z' = M z with constant M, solved
    exactly by the matrix exponential (mpmath's expm), segment by segment."""
    from mpmath import mp, mpf, matrix, expm
    mp.dps = digits
    k, c, m = mpf(k), mpf(c), mpf(m)
    knots = [(mpf(a), mpf(b)) for a, b in corners]
    segments = [(knots[j][0], knots[j][1], (knots[j + 1][1] - knots[j][1]) / (knots[j + 1][0] - knots[j][0]))
                for j in range(len(knots) - 1)] + [(knots[-1][0], knots[-1][1], mpf(0))]

    def system(w0, s):
        return matrix([[0, 1, 0, 0], [-k / m, -c / m, (k * w0 + c * s) / m, k * s / m], [0, 0, 0, 0],
                       [0, 0, 1, 0]])

    out = []
    start, x, v = knots[0][0], mpf(0), mpf(0)
    assert start == 0
    index = 0
    for time in t:
        time = mpf(float(time))
        while index + 1 < len(segments) and segments[index + 1][0] <= time:
            t_next = segments[index + 1][0]
            z = expm(system(segments[index][1], segments[index][2]) * (t_next - start)) * matrix([x, v, 1, 0])
            x, v, start, index = z[0], z[1], t_next, index + 1
        z = expm(system(segments[index][1] + segments[index][2] * (start - segments[index][0]),
                        segments[index][2]) * (time - start)) * matrix([x, v, 1, 0])
        out.append(float(z[0]))
    return np.array(out)


@pytest.mark.parametrize("c", [0.0, 4.0])
@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-9), (2e-2, 1e-4)])
def test_spring_to_an_anchor_moved_by_a_ramp_table(tmp_path, c, dt, tol):
    """A mass on a spring (and a damper, c = 4) to an anchor that stays at 0 until
    t0 = 0.3, ramps at V = 0.2 m/s until t1 = 1.1, then back down at -0.1 m/s until 1.9 and
    stays: without the damper, x = V (tau - sin(w tau) / w) on the ramp (tau = t - t0,
    w^2 = k / m: the particular solution of the ramp plus the harmonic that starts from
    rest), the same pieces after each corner from the state there; with it, against the
    exact solution of each segment's linear system (exact_anchor_oscillator, 30 digits),
    which checks that the damper sees the slope before a corner at a step's end and the one
    after it from there. The ledger books the anchor's work: its residual is RK4's
    quadrature error."""
    pytest.importorskip("mpmath")
    k, m = 100.0, 1.0
    corners = [(0.0, 0.0), (0.3, 0.0), (1.1, 0.16), (1.9, 0.08)]
    table = write_table(tmp_path / "anchor.dat", corners)
    scene = impact1d.Scene(m1=m, x1=0.0, v1=0.0, t_end=3.0, dt=dt, dt_out=0.05,
                           springs=[dict(a=0, b=1, k=k, d_rest=0.0, c=c, ground_table=table)])
    result = impact1d.simulate(scene)
    if c == 0.0:
        w0 = math.sqrt(k / m)
        on_ramp = (result.t >= 0.3) & (result.t <= 1.1)
        tau = result.t[on_ramp] - 0.3
        np.testing.assert_allclose(result.x1[on_ramp], 0.2 * (tau - np.sin(w0 * tau) / w0), rtol=0, atol=tol)
    np.testing.assert_allclose(result.x1, exact_anchor_oscillator(k, c, m, corners, result.t), rtol=0, atol=tol)
    assert result.energy_residual < max(1e-6, 10 * tol)
    assert result.drive_work is not None


def test_table_drive_adds_to_the_sine_and_velocity(tmp_path):
    """ground_table adds to ground_v t and the sine: a table of slope -u cancels ground_v = u
    (the ball of test_moving_ground's constant-speed wall sees a still wall): same events as
    the still wall, to rounding."""
    u = 0.1
    table = write_table(tmp_path / "back.dat", [(0.0, 0.0), (10.0, -10 * u)])
    common = dict(m1=1.0, x1=0.0, v1=1.0, t_end=2.5, dt=1e-2)
    still = impact1d.simulate(impact1d.Scene(contacts=[dict(a=0, b=1, d_min=0.0, name="left"),
                                                       dict(a=0, b=1, d_max=1.0, ground_v=0.0, name="right")],
                                             **common))
    cancelled = impact1d.simulate(impact1d.Scene(contacts=[
        dict(a=0, b=1, d_min=0.0, name="left"),
        dict(a=0, b=1, d_max=1.0, ground_v=u, ground_table=table, name="right")], **common))
    assert list(cancelled.events["kind"]) == list(still.events["kind"])
    np.testing.assert_allclose(cancelled.events["t"], still.events["t"], rtol=0, atol=1e-13)
    np.testing.assert_allclose(cancelled.events["v1_after"], still.events["v1_after"], rtol=0, atol=1e-13)


@pytest.mark.parametrize("rows, message", [
    ("0 0\n0 1\n", "time 0.0 does not increase"),
    ("0 0\n1 x\n", "malformed row"),
    ("# nothing\n", "the table has no rows"),
])
def test_bad_ground_table_is_refused_as_a_force_table_is(tmp_path, rows, message):
    path = tmp_path / "bad.dat"
    path.write_text(rows)
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3,
                           contacts=[dict(a=0, b=1, d_min=0.0, ground_table=str(path), name="floor")])
    with pytest.raises(impact1d.InputError, match="the contact 'floor's ground_table: .*bad.dat.*" + message):
        impact1d.simulate(scene)


def test_missing_ground_table_is_refused(tmp_path):
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3,
                           springs=[dict(a=0, b=1, k=1.0, d_rest=0.0, ground_table=str(tmp_path / "none.dat"))])
    with pytest.raises(impact1d.InputError, match="ground_table: .*none.dat"):
        impact1d.simulate(scene)


@pytest.mark.parametrize("walls, side", [
    (dict(x_left=-1.0), "left"), (dict(x_right=1.0), "right"),
    (dict(x_left=-1.0, x_right=1.0), "left"), (dict(x_left=-1.0, x_right=1.0), "right")])
@pytest.mark.parametrize("rows", [None, "0 0\n1 x\n"])
def test_bad_wall_table_is_refused_by_the_name_written(tmp_path, walls, side, rows):
    """&walls x_left_table = 'missing.dat' (or a bad table) is refused naming x_left_table and
    the file, not the record made of the wall ('left's ground_table); the other wall's table
    is good. A &contact record named 'right' keeps its record's name."""
    good = write_table(tmp_path / "good.dat", [(0.0, 0.0), (1.0, 0.0)])
    path = tmp_path / "bad.dat"
    if rows is not None:
        path.write_text(rows)
    tables = {f"x_{wall}_table": str(path) if wall == side else good
              for wall in ("left", "right") if f"x_{wall}" in walls}
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3, **walls, **tables)
    with pytest.raises(impact1d.InputError, match=f"^x_{side}_table: .*bad.dat"):
        impact1d.simulate(scene)
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3, x_left=-1.0, x_left_table=good,
                           contacts=[dict(a=0, b=1, d_max=1.0, ground_table=str(path), name="right")])
    with pytest.raises(impact1d.InputError, match="^the contact 'right's ground_table: .*bad.dat"):
        impact1d.simulate(scene)


def test_ground_table_between_two_bodies_is_refused(tmp_path):
    table = write_table(tmp_path / "w.dat", [(0.0, 0.0), (1.0, 1.0)])
    scene = impact1d.Scene(m1=1.0, m2=1.0, x1=0.0, x2=1.0, t_end=1.0, dt=1e-3,
                           contacts=[dict(a=1, b=2, d_min=0.1, ground_table=table)])
    with pytest.raises(impact1d.InputError, match="ground_table move the ground end, but this record joins two"):
        impact1d.simulate(scene)


def test_a_start_inside_a_table_ground_is_refused(tmp_path):
    """The start check counts the table's w(0) (held before its first corner)."""
    table = write_table(tmp_path / "w.dat", [(0.5, 0.2), (1.0, 0.0)])
    scene = impact1d.Scene(m1=1.0, x1=0.1, t_end=1.0, dt=1e-3,
                           contacts=[dict(a=0, b=1, d_min=0.0, ground_table=table, name="floor")])
    with pytest.raises(impact1d.InputError, match="violates the contact 'floor': x1 - w"):
        impact1d.simulate(scene)


def test_namelist_ground_table_is_relative_to_the_scene_file(tmp_path):
    """&contact ground_table = 'lift.dat' names a file beside the scene (as f1_table does);
    the CLI runs it as Python's Scene does."""
    import subprocess
    import tools
    write_table(tmp_path / "lift.dat", [(0.0, 0.0), (0.5, 0.0), (1.5, 1.0)])
    (tmp_path / "lift.nml").write_text(
        "&bodies m1 = 1.0 /\n&initial x1 = 0.0, v1 = 0.0 /\n&forces f1 = -9.81 /\n"
        "&run t_end = 2.0, dt = 1e-3, dt_out = 0.01 /\n"
        "&contact a = 0, b = 1, d_min = 0.0, r_min = 0.5, ground_table = 'lift.dat', name = 'floor' /\n")
    scene = impact1d.load_scene(tmp_path / "lift.nml")
    assert scene.contacts[0]["ground_table"] == str(tmp_path / "lift.dat")
    result = impact1d.simulate(scene)
    assert result.events["v1_after"][result.events["kind"] == "floor"][0] == pytest.approx(1.5, abs=1e-14)
    out = tmp_path / "lift_out.dat"
    subprocess.run([tools.find_tool("impact1d"), str(tmp_path / "lift.nml"), "-o", str(out)], check=True,
                   capture_output=True, cwd="/")
    back = impact1d.read_output(out)
    np.testing.assert_array_equal(back.x1, result.x1)


def test_lift_example_and_its_plot():
    """input/lift_table.nml (make demo): the ball leaves the starting floor at (1 + r) V,
    rests on it before it stops, flies on when it stops; the plot draws the floor where the
    table puts it (np.interp: linear between corners, held at the ends), and the header
    rebuilds the scene with its table (read_output)."""
    import subprocess
    import tools
    from impact1d import plot
    scene = impact1d.load_scene("input/lift_table.nml")
    assert scene.contacts[0]["ground_table"].endswith("input/lift_table.dat")
    result = impact1d.simulate(scene)
    floor = result.events[result.events["kind"] == "floor"]
    assert floor["t"][0] == 0.5 and floor["v1_after"][0] == pytest.approx(1.5, abs=1e-14)
    assert "release_floor" in set(result.events["kind"][result.events["t"] == 1.5])
    w = np.interp(result.t, [0.0, 0.5, 1.5], [0.0, 0.0, 1.0])
    assert np.all(result.x1 >= w - 1e-12)
    lines = [a for ax in plot.figure(result).axes for a in ax.get_children() if a.get_gid() == "wall:floor"]
    assert len(lines) == 1
    np.testing.assert_allclose(lines[0].get_ydata(), np.interp(lines[0].get_xdata(), [0.0, 0.5, 1.5], [0.0, 0.0, 1.0]),
                               rtol=0, atol=1e-15)
    assert np.ptp(lines[0].get_ydata()) == 1.0
    # (the drive lifts the ball by 1 m: its work is at least m g h)
    assert result.drive_work[-1] > 9.81
    assert result.energy_residual < 1e-12
    import tempfile
    with tempfile.TemporaryDirectory() as folder:
        out = f"{folder}/lift.dat"
        subprocess.run([tools.find_tool("impact1d"), "input/lift_table.nml", "-o", out, "--t-end", "2"], check=True,
                       capture_output=True)
        back = impact1d.read_output(out)
        assert back.scene.contacts[0]["ground_table"] == "input/lift_table.dat"
        again = impact1d.simulate(back.scene)
        np.testing.assert_array_equal(again.x1, back.x1)


def test_wall_tables_are_the_records_tables(tmp_path):
    """&walls x_left_table, x_right_table (DESIGN's names; Scene fields) move the walls as
    a &contact record's ground_table does: the same run, bit for bit; the right wall closes
    in at 0.2 m/s from t = 1 s and stops at 0.8 m."""
    table = write_table(tmp_path / "closing.dat", [(1.0, 0.0), (2.0, -0.2)])
    common = dict(m1=1.0, x1=0.5, v1=1.3, t_end=4.0, dt=1e-3, dt_out=0.01)
    walls = impact1d.Scene(x_left=0.0, x_right=1.0, r_right=0.9, x_right_table=table, **common)
    records = impact1d.Scene(contacts=[
        dict(a=0, b=1, d_min=0.0, r_min=1.0, name="left"),
        dict(a=0, b=1, d_max=1.0, r_max=0.9, ground_table=table, name="right")], **common)
    a, b = impact1d.simulate(walls), impact1d.simulate(records)
    assert len(a.events) > 3
    np.testing.assert_array_equal(a.events, b.events)
    np.testing.assert_array_equal(a.samples, b.samples)
    assert a.columns == b.columns and "drive_work" in a.columns
    assert np.all(a.x1 <= 1.0 + np.interp(a.t, [1.0, 2.0], [0.0, -0.2]) + 1e-12)


def test_wall_table_in_a_namelist_runs_and_rebuilds(tmp_path):
    """&walls x_left_table = 'floor.dat' (beside the scene file) through the CLI: the output
    header names it (# x_left_table = ...), read_output rebuilds the scene, which runs the
    same; the plot draws the wall where the table puts it."""
    import subprocess
    import tools
    from impact1d import plot
    write_table(tmp_path / "floor.dat", [(0.0, 0.0), (0.5, 0.0), (1.5, 1.0)])
    (tmp_path / "lift.nml").write_text(
        "&bodies m1 = 1.0 /\n&walls x_left = 0.0, r_left = 0.5, x_left_table = 'floor.dat' /\n"
        "&initial x1 = 0.0, v1 = 0.0 /\n&forces f1 = -9.81 /\n&run t_end = 2.0, dt = 1e-3, dt_out = 0.01 /\n")
    scene = impact1d.load_scene(tmp_path / "lift.nml")
    assert scene.x_left_table == str(tmp_path / "floor.dat")
    result = impact1d.simulate(scene)
    left = result.events[result.events["kind"] == "left"]
    assert left["t"][0] == 0.5 and left["v1_after"][0] == pytest.approx(1.5, abs=1e-14)
    out = tmp_path / "out.dat"
    subprocess.run([tools.find_tool("impact1d"), str(tmp_path / "lift.nml"), "-o", str(out)], check=True,
                   capture_output=True)
    back = impact1d.read_output(out)
    assert back.scene.x_left_table == str(tmp_path / "floor.dat")
    np.testing.assert_array_equal(back.x1, result.x1)
    np.testing.assert_array_equal(impact1d.simulate(back.scene).x1, back.x1)
    lines = [a for ax in plot.figure(back).axes for a in ax.get_children() if a.get_gid() == "wall:left"]
    assert len(lines) == 1
    np.testing.assert_allclose(lines[0].get_ydata(), np.interp(lines[0].get_xdata(), [0.0, 0.5, 1.5], [0.0, 0.0, 1.0]),
                               rtol=0, atol=1e-15)


def test_wall_table_needs_its_wall(tmp_path):
    table = write_table(tmp_path / "w.dat", [(0.0, 0.0), (1.0, 1.0)])
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3, x_left_table=table)
    with pytest.raises(impact1d.InputError, match="x_left_v, _amp, _period, _phase, _table move the wall x_left, "
                                                  "which is not given"):
        impact1d.simulate(scene)
