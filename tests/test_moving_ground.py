"""Prescribed motion of the ground (issue 21 item 1; DESIGN "Laws added on the records"):
`ground_v`, `ground_amp`, `ground_period`, `ground_phase` on a &contact or &spring record
with a ground end, w(t) = ground_v t + ground_amp sin(2 pi t / ground_period + ground_phase).
Every scene that names one runs on the N-body engine, whatever its number of bodies.

(a) The yardstick for that engine on one and two bodies: frictionless scenes without a
    moving ground give the same events and samples through both engines (a record with
    `ground_v = 0`, a ground that moves at 0 m/s, sends a scene to the N-body engine).
(b) The bouncing ball on a sinusoidally vibrating table, in the lab frame: the period-1
    orbit and its flip bifurcation (closed forms in the docstrings).
(c) A ball resting on a table that accelerates downward faster than g lifts off where the
    contact force m (w'' + g) falls to zero (closed form).
(d) The Fermi-Ulam ball between a fixed and a sinusoidally moving wall against a 50-digit
    event-driven reference (mpmath, in this file).
(e) A spring to a moving anchor: the driven oscillator's closed form.
Each at dt = 1e-3 and a coarse dt; the energy ledger closes in every run.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import impact1d
import tools

G = 9.81
# The ledger's residual: rounding where the motion is piecewise polynomial; where a body is
# held to a sine or pulled by a spring, RK4's quadrature of the drive's power (measured:
# 1.4e-7 J at dt = 0.02 on the lift-off scene, 2e-11 J at dt = 1e-3).
RESIDUAL_TOL = 1e-12
RESIDUAL_TOL_QUADRATURE = 1e-6
# Event times on flights that are polynomials between exact roots of w: the location is
# polished by Newton's method on the exact gap.
EVENT_TOL = 1e-9


def moving_engine(scene):
    """The same scene with its first contact record's ground moving at 0 m/s."""
    contacts = [dict(c) for c in scene.contacts]
    contacts[0]["ground_v"] = 0.0
    return dataclasses.replace(scene, contacts=contacts)


def as_records(scene, right_body):
    return dataclasses.replace(scene, x_left=None, r_left=None, x_right=None, r_right=None,
                               contacts=tools.wall_records(scene, right_body))


@pytest.mark.parametrize("case, dt", [("case3", 1e-3), ("case3", 1e-2), ("case1", 1e-3),
                                      ("case5", 1e-3)])
def test_a_ground_moving_at_zero_runs_as_a_still_one(case, dt):
    """The seed cases' frictionless scenes (walls as records, the bodies' friction removed)
    on a still ground and with the first record's ground moving at 0 m/s (the moving-ground
    path of the engine: drives, exact w(t)): same event kinds, times and velocities, same
    samples, to 1e-12. (Until the two-body engine went this compared it with the N-body
    engine, which a ground_v record sent the scene to.)"""
    scene = impact1d.load_scene(f"input/{case}.nml")
    scene = dataclasses.replace(scene, mu1=0.0, mu2=0.0 if scene.m2 else None, dt=dt, t_end=4.0)
    if scene.m2 is None:
        scene = dataclasses.replace(scene, mu2=None)
    two = as_records(scene, 2 if scene.m2 else 1)
    a = impact1d.simulate(two)
    b = impact1d.simulate(moving_engine(two))
    assert list(a.events["kind"]) == list(b.events["kind"])
    assert len(a.events) > 3
    for name in a.events.dtype.names[2:] + ("t",):
        np.testing.assert_allclose(b.events[name], a.events[name], rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=1e-12)
    assert b.energy_residual < 1e-10


def one_ball_table(gamma, r, period, dt, kick, periods):
    """A ball (m = 1, weight -g as f1) on a table w(t) = A sin(2 pi t / T + phi) with
    A w^2 = gamma g, started at the period-1 orbit's impact point (phase phi) with its
    take-off speed times kick."""
    omega = 2 * math.pi / period
    amp = gamma * G / omega**2
    phi = math.acos(onset(r) / gamma)
    scene = impact1d.Scene(m1=1.0, f1=-G, x1=amp * math.sin(phi), v1=kick * G * period / 2,
                           t_end=periods * period, dt=dt, dt_out=period,
                           contacts=[dict(a=0, b=1, d_min=0.0, r_min=r, ground_amp=amp,
                                          ground_period=period, ground_phase=phi, name="table")])
    result = impact1d.simulate(scene)
    impacts = result.events["t"][result.events["kind"] == "table"]
    return impacts, phi, result


def onset(r):
    """Gamma at which the period-1 orbit appears: cos(phi) = 1 below."""
    return math.pi * (1 - r) / (1 + r)


def flip(r):
    """Gamma of the period-1 orbit's flip (period-doubling) bifurcation.

    Period-1 orbit: impacts at t_n = t_0 + n T, the table at phase phi, its velocity
    V = A w cos(phi). A flight of one period back to the same table height leaves at gT/2
    and lands at -gT/2; restitution on the relative velocity, gT/2 - V = r (gT/2 + V), gives
    A w cos(phi) = g T (1 - r) / (2 (1 + r)), i.e. Gamma cos(phi) = pi (1 - r) / (1 + r).
    Linearise the impact map (t_n, u_n) -> (t_n+1, u_n+1), u the take-off speed: the flight
    time tau solves w(t) + u tau - g tau^2 / 2 = w(t + tau), so d tau = c du with
    c = T / (gT/2 + V) = (1 + r) / g, and u' = (1 + r) w'(t') - r (u - g tau). The Jacobian
    [[1, c], [(1 + r) a, (1 + r) a c - r + r g c]] (a = w''(t_n) = -A w^2 sin(phi)) has
    det = r^2 and trace 1 + r^2 + (1 + r)^2 a / g: stable for
    -2 g (1 + r^2) / (1 + r)^2 < a < 0, the eigenvalue -1 at the lower end:
    Gamma sin(phi) = 2 (1 + r^2) / (1 + r)^2, so
    Gamma_flip = sqrt((pi (1 - r) / (1 + r))^2 + (2 (1 + r^2) / (1 + r)^2)^2).
    """
    return math.hypot(onset(r), 2 * (1 + r * r) / (1 + r) ** 2)


@pytest.mark.parametrize("dt", [1e-3, 2e-2])
def test_vibrating_table_period_one_orbit(dt):
    """A stable period-1 orbit (Gamma between onset and flip, r = 0.5, T = 0.5 s): from a
    take-off 5% too fast the ball settles onto impacts one period apart at the table phase
    phi with A w cos(phi) = g T (1 - r) / (2 (1 + r)) (flip's docstring); the eigenvalues'
    modulus is r, so 150 periods leave 0.5^150 of the kick."""
    period, r = 0.5, 0.5
    impacts, phi, result = one_ball_table(1.3, r, period, dt, 1.05, 150)
    assert len(impacts) == 150
    np.testing.assert_allclose(np.diff(impacts[-20:]), period, rtol=0, atol=1e-10)
    phase = np.mod(2 * math.pi * impacts[-20:] / period + phi, 2 * math.pi)
    np.testing.assert_allclose(phase, phi, rtol=0, atol=1e-9)
    assert 1.3 * math.cos(phi) == pytest.approx(math.pi * (1 - r) / (1 + r), rel=1e-14)
    assert result.energy_residual < RESIDUAL_TOL * 1e3


@pytest.mark.parametrize("side, dt", [(0.98, 1e-3), (1.02, 1e-3), (0.98, 2e-2), (1.02, 2e-2)])
def test_vibrating_table_flip_bifurcation(side, dt):
    """Just below Gamma_flip (flip's docstring) the period-1 orbit attracts (the eigenvalue
    -0.87 at 0.98 Gamma_flip: 150 periods leave 1e-9 of the kick); just above it has lost
    its stability to a period-2 orbit: flight times alternate about T, pairwise summing to 2T."""
    period, r = 0.5, 0.5
    impacts, phi, _ = one_ball_table(side * flip(r), r, period, dt, 1.05, 150)
    flights = np.diff(impacts[-21:])
    if side < 1:
        np.testing.assert_allclose(flights, period, rtol=0, atol=1e-8)
    else:
        deviation = flights - period
        assert np.all(np.abs(deviation) > 1e-2 * period)
        assert np.all(np.sign(deviation[1:]) == -np.sign(deviation[:-1]))
        np.testing.assert_allclose(flights[1:] + flights[:-1], 2 * period, rtol=0, atol=1e-9)


@pytest.mark.parametrize("dt", [1e-3, 2e-2])
def test_ball_lifts_off_a_table_accelerating_down_faster_than_g(dt):
    """A ball at rest on a table w = A sin(w t) (A w^2 = 2 g), started with the table's
    velocity A w: the row holds while the contact force m (w'' + g) >= 0 and releases when
    -A w^2 sin(w t) = -g, at t = asin(1 / Gamma) / w; until then the ball is on the table
    (x = w(t)), after it flies: x = w(t_l) + w'(t_l) (t - t_l) - g (t - t_l)^2 / 2."""
    period, gamma = 0.5, 2.0
    omega = 2 * math.pi / period
    amp = gamma * G / omega**2
    scene = impact1d.Scene(m1=1.0, f1=-G, x1=0.0, v1=amp * omega, t_end=0.1, dt=dt, dt_out=0.005,
                           contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.0, ground_amp=amp,
                                          ground_period=period, name="table")])
    result = impact1d.simulate(scene)
    t_lift = math.asin(1 / gamma) / omega
    assert list(result.events["kind"][:2]) == ["rest_table", "release_table"]
    assert result.events["t"][1] == pytest.approx(t_lift, abs=1e-12)
    held = result.t <= t_lift
    np.testing.assert_allclose(result.x1[held], amp * np.sin(omega * result.t[held]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.v1[held], amp * omega * np.cos(omega * result.t[held]), rtol=0, atol=1e-12)
    tau = result.t[~held] - t_lift
    flight = amp * math.sin(omega * t_lift) + amp * omega * math.cos(omega * t_lift) * tau - G * tau**2 / 2
    assert np.all(flight > amp * np.sin(omega * result.t[~held]))   # (no landing before t_end)
    np.testing.assert_allclose(result.x1[~held], flight, rtol=0, atol=1e-12)
    assert result.energy_residual < RESIDUAL_TOL_QUADRATURE


def fermi_ulam_reference(x0, v0, length, amp, period, r, t_end, digits=50):
    """The Fermi-Ulam ball at 50 digits: free flight between a fixed wall at x = 0 (elastic)
    and a wall at x = length + amp sin(2 pi t / period) (restitution r on the velocity
    relative to it: v+ = w' - r (v- - w')). Each next impact is the earliest root of either
    gap, bracketed on a grid of period / 400 and polished by mpmath's bisection-secant
    (anderson) to the working precision. Returns [(t, wall, v_before, v_after)]."""
    from mpmath import mp, mpf, sin, cos, pi, findroot
    mp.dps = digits
    omega = 2 * pi / mpf(period)
    t, x, v = mpf(0), mpf(x0), mpf(v0)
    length, amp, r = mpf(length), mpf(amp), mpf(r)
    events = []

    def right_gap(s):
        return length + amp * sin(omega * s) - (x + v * (s - t))

    while True:
        grid = mpf(period) / 400
        s0, found = t, None
        while s0 < t_end and found is None:
            s1 = s0 + grid
            if v < 0 and x + v * (s1 - t) <= 0:
                found = ("left", t - x / v)
            if right_gap(s1) < 0:
                root = findroot(right_gap, (s0 if s0 > t else s0 + mpf(10) ** -40, s1), solver="anderson")
                if found is None or root < found[1]:
                    found = ("right", root)
            s0 = s1
        if found is None:
            return events
        wall, t_hit = found
        if t_hit > t_end:
            return events
        x = x + v * (t_hit - t)
        t = t_hit
        if wall == "left":
            v_after = -v
        else:
            w_dot = amp * omega * cos(omega * t)
            v_after = w_dot - r * (v - w_dot)
        events.append((t, wall, v, v_after))
        v = v_after


@pytest.mark.parametrize("dt", [1e-3, 5e-2])
def test_fermi_ulam_ball_against_50_digit_reference(dt):
    """A ball without forces between a fixed wall (x >= 0) and a vibrating one
    (x <= 1 + 0.1 sin(2 pi t)), restitution 0.9 on the moving wall: every impact's time and
    the velocities around it against fermi_ulam_reference; the wall's work booked by the
    ledger (residual at rounding: the flights are polynomials)."""
    pytest.importorskip("mpmath")
    x0, v0, length, amp, period, r, t_end = 0.5, 1.3, 1.0, 0.1, 1.0, 0.9, 8.0
    reference = fermi_ulam_reference(x0, v0, length, amp, period, r, t_end)
    scene = impact1d.Scene(m1=1.0, x1=x0, v1=v0, t_end=t_end, dt=dt, dt_out=0.1, contacts=[
        dict(a=0, b=1, d_min=0.0, r_min=1.0, name="left"),
        dict(a=0, b=1, d_max=length, r_max=r, ground_amp=amp, ground_period=period, name="right")])
    result = impact1d.simulate(scene)
    assert len(reference) >= 8
    assert list(result.events["kind"]) == [wall for _, wall, _, _ in reference]
    np.testing.assert_allclose(result.events["t"], [float(t) for t, _, _, _ in reference], rtol=0, atol=EVENT_TOL)
    np.testing.assert_allclose(result.events["v1_before"], [float(v) for _, _, v, _ in reference], rtol=0,
                               atol=EVENT_TOL)
    np.testing.assert_allclose(result.events["v1_after"], [float(v) for _, _, _, v in reference], rtol=0,
                               atol=EVENT_TOL)
    assert result.energy_residual < RESIDUAL_TOL * 10


@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-9), (2e-2, 1e-4)])
def test_spring_to_a_moving_anchor(dt, tol):
    """x'' = -(k / m) (x - w(t)), w = A sin(W t), from rest at 0: with w0^2 = k / m,
    x = A w0^2 / (w0^2 - W^2) (sin(W t) - (W / w0) sin(w0 t)). The ledger books the anchor's
    work (-tension w'): its residual is RK4's quadrature error."""
    k, m, amp, big_w = 100.0, 1.0, 0.05, 3.0
    w0 = math.sqrt(k / m)
    scene = impact1d.Scene(m1=m, x1=0.0, v1=0.0, t_end=3.0, dt=dt, dt_out=0.05,
                           springs=[dict(a=0, b=1, k=k, d_rest=0.0, ground_amp=amp,
                                         ground_period=2 * math.pi / big_w)])
    result = impact1d.simulate(scene)
    t = result.t
    exact = amp * w0**2 / (w0**2 - big_w**2) * (np.sin(big_w * t) - big_w / w0 * np.sin(w0 * t))
    np.testing.assert_allclose(result.x1, exact, rtol=0, atol=tol)
    assert result.energy_residual < max(RESIDUAL_TOL_QUADRATURE, 10 * tol)


def test_moving_wall_at_constant_speed_gains_two_u_a_hit():
    """A ball (no forces) between a fixed wall at 0 and an elastic wall at 1 approaching at
    u = 0.1 m/s (ground_v = -0.1): each hit on the moving wall adds 2u to the speed, so the
    k-th return has speed v0 + 2 k u; the impact times follow in closed form, exactly (the
    motion is polynomial: rounding only), and the ledger's residual is rounding."""
    v0, u = 1.0, 0.1
    scene = impact1d.Scene(m1=1.0, x1=0.0, v1=v0, t_end=2.5, dt=1e-2, contacts=[
        dict(a=0, b=1, d_min=0.0, name="left"),
        dict(a=0, b=1, d_max=1.0, ground_v=-u, name="right")])
    result = impact1d.simulate(scene)
    t, x, v, expected = 0.0, 0.0, v0, []
    while True:
        if v > 0:
            hit = t + (1.0 - u * t - x) / (v + u)   # x + v s = 1 - u (t + s)
            kind, v_after = "right", -(v + 2 * u)
        else:
            hit, kind, v_after = t - x / v, "left", -v
        if hit > 2.5:
            break
        x, t, v = x + v * (hit - t), hit, v_after
        expected.append((kind, hit, v_after))
    assert list(result.events["kind"]) == [kind for kind, _, _ in expected]
    np.testing.assert_allclose(result.events["t"], [hit for _, hit, _ in expected], rtol=0, atol=1e-13)
    np.testing.assert_allclose(result.events["v1_after"], [v for _, _, v in expected], rtol=0, atol=1e-13)
    assert result.energy_residual < 1e-13
    # The wall's work is the drive_work column: all the kinetic energy the ball gained
    # (elastic walls, no forces), booked at each hit on the moving wall.
    assert "drive_work" in result.columns
    assert result.drive_work[-1] == pytest.approx((v0 + 2 * u * sum(k == "right" for k, _, _ in expected)) ** 2 / 2
                                                  - v0**2 / 2, abs=1e-13)
    np.testing.assert_array_equal(result.work, 0.0)


def test_drive_work_column_only_with_a_moving_ground():
    scene = impact1d.Scene(m1=1.0, x1=0.5, v1=1.0, t_end=1.0, dt=1e-3,
                           contacts=[dict(a=0, b=1, d_min=0.0), dict(a=0, b=1, d_max=1.0)])
    assert impact1d.simulate(scene).drive_work is None
    assert "drive_work" not in impact1d.simulate(scene).columns
    assert impact1d.simulate(moving_engine(scene)).drive_work is not None


@pytest.mark.parametrize("record, message", [
    (dict(a=1, b=2, d_min=0.1, ground_v=1.0), "joins two bodies"),
    (dict(a=0, b=1, d_min=0.0, ground_amp=0.1), "ground_amp and ground_period go together"),
    (dict(a=0, b=1, d_min=0.0, ground_phase=0.1), "a phase needs its sine"),
    (dict(a=0, b=1, d_min=0.0, ground_amp=0.1, ground_period=-1.0), "ground_period"),
])
def test_bad_ground_motion_is_refused(record, message):
    scene = impact1d.Scene(m1=1.0, m2=1.0, x1=0.0, x2=1.0, t_end=1.0, dt=1e-3, contacts=[record])
    with pytest.raises(impact1d.InputError, match=message):
        impact1d.simulate(scene)


def test_moving_walls_are_the_records_moving():
    """&walls x_right_amp, x_right_period (DESIGN's names) move the right wall as the same
    &contact record's ground_amp, ground_period do: the same run, bit for bit."""
    common = dict(m1=1.0, x1=0.5, v1=1.3, t_end=4.0, dt=1e-3, dt_out=0.01)
    walls = impact1d.Scene(x_left=0.0, x_right=1.0, r_right=0.9, x_right_amp=0.1, x_right_period=1.0,
                           x_right_phase=0.3, **common)
    records = impact1d.Scene(contacts=[
        dict(a=0, b=1, d_min=0.0, r_min=1.0, name="left"),
        dict(a=0, b=1, d_max=1.0, r_max=0.9, ground_amp=0.1, ground_period=1.0, ground_phase=0.3, name="right")],
        **common)
    a, b = impact1d.simulate(walls), impact1d.simulate(records)
    assert len(a.events) > 3
    np.testing.assert_array_equal(a.events, b.events)
    np.testing.assert_array_equal(a.samples, b.samples)
    assert a.columns == b.columns and "drive_work" in a.columns


@pytest.mark.parametrize("fields, message", [
    (dict(x_left_v=0.1), "x_left_v, _amp, _period, _phase, _table move the wall x_left, which is not given"),
    (dict(x_right=2.0, x_right_amp=0.1), "x_right_amp and x_right_period go together"),
    (dict(x_right=2.0, x_right_phase=0.1), "x_right_phase is given but x_right_amp is not"),
    (dict(x_left=-1.0, x_left_amp=1.5, x_left_period=1.0, x_left_phase=1.0), "violates the left"),
])
def test_bad_wall_motion_is_refused(fields, message):
    """Each wall's motion needs its wall and a whole sine; a wall whose motion starts it past
    the body (w(0) = amp sin(phase)) is refused as a wall placed there would be."""
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3, **fields)
    with pytest.raises(impact1d.InputError, match=message):
        impact1d.simulate(scene)


def test_a_start_inside_a_moving_ground_is_refused():
    """A body below a table that starts at w(0) = 0.1 sin(1.0) = 0.084 above it violates the
    contact at t = 0 (the check counts w(0))."""
    scene = impact1d.Scene(m1=1.0, m2=1.0, x1=0.0, x2=1.0, t_end=1.0, dt=1e-3, contacts=[
        dict(a=0, b=1, d_min=0.0, ground_amp=0.1, ground_period=1.0, ground_phase=1.0)])
    with pytest.raises(impact1d.InputError, match="violates the contact 'contact1': x1 - w"):
        impact1d.simulate(scene)


def test_two_balls_landing_on_a_vibrating_table_come_to_rest_on_it():
    """Two balls (the upper resting on the lower, r = 0.5) thrown up by a table that
    accelerates down faster than g land on it again at t = 0.27 s and rattle to rest on it.
    The rattle holds steps far below the clock's ulp while the lower ball is held to the
    table: the table's displacement over such a step was w(t + h) - w(t) = 0 in floating
    point while the upper ball moved by v h, which no step could keep ('no step keeps the
    constraints' at t = 0.292148 s); the displacement is now formed so that any h counts
    (impact1d_drives' displacement). At t_end both balls ride the table, the ledger closed.
    (The rattle takes 4.7e4 events: on a sine the held ball's steps and its snaps still
    differ at rounding level, see docs/method.md section 11, "Not yet"; max_step_events is
    raised for it.)"""
    period, gamma, t_end = 0.5, 1.2, 0.2925
    omega = 2 * math.pi / period
    amp = gamma * G / omega**2
    scene = impact1d.Scene(m=[1.0, 1.0], x=[0.0, 0.1], v=[amp * omega] * 2, f=[-G] * 2, t_end=t_end, dt=1e-3,
                           dt_out=0.01, max_step_events=10**6, contacts=[
                               dict(a=0, b=1, d_min=0.0, r_min=0.5, ground_amp=amp, ground_period=period,
                                    name="table"),
                               dict(a=1, b=2, d_min=0.1, r_min=0.5, name="pair")])
    result = impact1d.simulate(scene)
    assert result.x1[-1] == pytest.approx(amp * math.sin(omega * t_end), abs=1e-12)
    assert result.v1[-1] == pytest.approx(amp * omega * math.cos(omega * t_end), abs=1e-12)
    assert result.x2[-1] - result.x1[-1] == pytest.approx(0.1, abs=1e-12)
    assert result.v2[-1] == result.v1[-1]
    assert result.energy_residual < RESIDUAL_TOL_QUADRATURE


def test_vissim_refuses_a_moving_ground():
    scene = impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3, method="vissim",
                           contacts=[dict(a=0, b=1, d_min=0.0, ground_v=0.1)])
    with pytest.raises(impact1d.InputError, match="vissim.*moving ground"):
        impact1d.simulate(scene)


def test_output_header_rebuilds_the_moving_ground(tmp_path):
    """The example's output names the ground's motion in its header (as the force terms'),
    so read_output gives back a scene that runs the same."""
    import subprocess
    out = tmp_path / "table.dat"
    subprocess.run([tools.find_tool("impact1d"), "input/vibrating_table.nml", "-o", str(out), "--t-end", "2"],
                   check=True, capture_output=True)
    back = impact1d.read_output(out)
    contact = back.scene.contacts[0]
    assert contact["ground_amp"] == 0.08075931593692087
    assert contact["ground_period"] == 0.5
    assert contact["ground_phase"] == 0.6342158689257744
    again = impact1d.simulate(dataclasses.replace(back.scene, t_end=2.0))
    np.testing.assert_array_equal(again.x1, back.x1)
    np.testing.assert_array_equal(again.events["t"], back.events["t"])


@pytest.mark.parametrize("v1", [0.5, 0.3])
def test_rigid_link_to_a_moving_anchor_moves_with_it(v1):
    """A rigid link (d_min = d_max = 0) to an anchor moving at 0.5 m/s: the body moves with
    the anchor. Started at the anchor's velocity nothing hits (the link's lock once set the
    body still, and its impact then logged 'before' 0); started at 0.3 m/s the lock is one
    plastic impact, 0.3 -> 0.5, whose drive_work is the momentum the anchor gave times its
    velocity, m (0.5 - 0.3) 0.5 = 0.1 J, the impact loss the relative motion's energy,
    m 0.2^2 / 2 = 0.02 J."""
    scene = impact1d.Scene(m1=1.0, x1=0.0, v1=v1, t_end=1.0, dt=1e-3, dt_out=0.1, contacts=[
        dict(a=0, b=1, d_min=0.0, d_max=0.0, ground_v=0.5)])
    result = impact1d.simulate(scene)
    impacts = result.events[result.events["kind"] == "contact1_min"]
    if v1 == 0.5:
        assert len(impacts) == 0
    else:
        assert len(impacts) == 1
        assert (impacts["v1_before"][0], impacts["v1_after"][0]) == (0.3, 0.5)
    assert list(result.events["kind"][-1:]) == ["rest_contact1_min"]
    np.testing.assert_allclose(result.x1, 0.5 * result.t, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(result.v1, 0.5)
    assert result.drive_work[-1] == pytest.approx(0.5 * (0.5 - v1), abs=1e-15)
    assert result.impact_loss[-1] == pytest.approx((0.5 - v1) ** 2 / 2, abs=1e-15)
    assert result.energy_residual < 1e-15


def two_balls_on_a_floor(u, r_floor=0.5, r_pair=0.5):
    """Two balls dropped onto a floor and onto each other, the floor and the balls' start
    moving at u: the same motion seen from a frame moving at -u."""
    return impact1d.Scene(m=[1.0, 1.0], x=[0.5, 1.0], v=[u, u], f=[-G, -G], t_end=2.0, dt=1e-3, dt_out=0.01,
                          contacts=[dict(a=0, b=1, d_min=0.0, r_min=r_floor, ground_v=u, name="floor"),
                                    dict(a=1, b=2, d_min=0.1, r_min=r_pair, name="pair")])


@pytest.mark.parametrize("u", [-0.8, 0.3])
def test_rattle_on_a_floor_moving_at_constant_speed_is_frame_invariant(u):
    """The rattle to rest of two balls on a floor, in the floor's frame and in a frame the
    floor moves in: 555 events with the floor still; with the floor at -0.8 m/s they were
    346,946 (each snap put the lower ball at w(t) rounded, without the clock's low part,
    up to an ulp of its position away from where the step took it, while the upper ball
    flew: the noise kept the series from converging). Now the runs agree event for event
    (times to rounding) until the last few rounding-level impacts, and end at rest on the
    floor alike."""
    still = impact1d.simulate(two_balls_on_a_floor(0.0))
    moving = impact1d.simulate(two_balls_on_a_floor(u))
    assert 500 < len(still.events) < 600
    assert abs(len(moving.events) - len(still.events)) < 0.05 * len(still.events)
    same = 500
    assert list(moving.events["kind"][:same]) == list(still.events["kind"][:same])
    np.testing.assert_allclose(moving.events["t"][:same], still.events["t"][:same], rtol=0, atol=1e-15)
    impacts = np.isin(still.events["kind"][:same], ["floor", "pair"])
    for name in ("v1_before", "v2_before", "v1_after", "v2_after"):
        np.testing.assert_allclose(moving.events[name][:same][impacts] - u, still.events[name][:same][impacts],
                                   rtol=0, atol=1e-14)
    assert list(moving.events["kind"][-1:]) == ["rest_pair"]
    np.testing.assert_allclose(moving.x1 - u * moving.t, still.x1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(moving.x2 - u * moving.t, still.x2, rtol=0, atol=1e-13)
    assert moving.energy_residual < 1e-12


@pytest.mark.parametrize("u", [-0.8, 0.3])
def test_rattle_of_two_balls_keeps_its_events_on_a_moving_floor(u):
    """Two balls (floor r = 0.8, between them r = 0.3) rattle through 153 events to rest on
    a still floor; on the floor moving at u, the same 153 in the same order, at the same
    times to rounding. (The gap tolerance of a moving ground counted gap_rounding |w(t)|,
    2.5e-15 m at w = 0.7 m, though w's v t is formed exactly: the moving floor closed a gap
    of 2.6e-15 m that the still floor left to fly, and the runs parted at event 78, 153
    against 242 events.)"""
    still = impact1d.simulate(two_balls_on_a_floor(0.0, 0.8, 0.3)).events
    moving = impact1d.simulate(two_balls_on_a_floor(u, 0.8, 0.3)).events
    assert len(still) == 153
    assert list(moving["kind"]) == list(still["kind"])
    np.testing.assert_allclose(moving["t"], still["t"], rtol=0, atol=1e-15)


@pytest.mark.parametrize("u", [-7.3, -0.8, -0.3, -0.1, 0.1, 0.8])
def test_elastic_pair_on_a_floor_at_constant_speed_keeps_the_still_floors_events(u):
    """A ball lands elastically on another resting on a plastic floor: in the floor's frame
    5 events (the lower ball's impact and rest, the swap, its impact, the pair at rest). On
    the floor moving at u the lower ball, held to it, stood up to 5e-21 m above w(t) (v h
    rounded at every step, and the clock set to each sample stop a rounding away from where
    the steps took it), so the floor's row was not closed when the upper ball landed: the
    two impacts fell to two event points, the upper ball kept -2.2e-16 m/s against the lower
    one, and they met again twice (9 events at u = 0.8, -0.3, 0.1, -7.3; 7 at -0.1). Now the
    same events at the same times (to 1e-15 s), velocities and positions shifted by u and u t."""
    def run(u):
        return impact1d.simulate(impact1d.Scene(
            m=[1.0, 1.0], x=[0.5, 1.0], v=[u, u], f=[-G, -G], t_end=2.0, dt=1e-3,
            contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.0, ground_v=u), dict(a=1, b=2, d_min=0.1, r_min=1.0)]))
    still, moving = run(0.0), run(u)
    assert list(still.events["kind"]) == ["contact1", "rest_contact1", "contact2", "contact1", "rest_contact2"]
    assert list(moving.events["kind"]) == list(still.events["kind"])
    np.testing.assert_allclose(moving.events["t"], still.events["t"], rtol=0, atol=1e-15)
    for name in ("v1_before", "v2_before", "v1_after", "v2_after"):
        np.testing.assert_allclose(moving.events[name] - u, still.events[name], rtol=0, atol=1e-14)
    for x_moving, x_still in ((moving.x1, still.x1), (moving.x2, still.x2)):
        np.testing.assert_allclose(x_moving - u * moving.t, x_still, rtol=0, atol=4 * np.spacing(abs(u) * 2 + 1))


def test_a_release_on_the_nbody_engine_logs_the_bodies_velocities():
    """With one or two bodies an event reports (v1, v2) (or (v1, 0)) whatever the row; the
    N-body engine's release of a ground row logged its row's ends instead, (0, v_b): the
    ball lifting off a table (test_ball_lifts_off_a_table_accelerating_down_faster_than_g)
    was logged leaving at v1 = 0, and the lower of two balls leaving a floor that moves at
    -0.8 m/s at v1 = 0."""
    period, gamma = 0.5, 2.0
    omega = 2 * math.pi / period
    amp = gamma * G / omega**2
    scene = impact1d.Scene(m1=1.0, f1=-G, x1=0.0, v1=amp * omega, t_end=0.1, dt=1e-3, contacts=[
        dict(a=0, b=1, d_min=0.0, ground_amp=amp, ground_period=period, name="table")])
    release = impact1d.simulate(scene).events[1]
    assert release["kind"] == "release_table"
    t_lift = math.asin(1 / gamma) / omega
    assert release["v1_before"] == pytest.approx(amp * omega * math.cos(omega * t_lift), abs=1e-12)
    assert release["v1_after"] == release["v1_before"]
    still = impact1d.simulate(two_balls_on_a_floor(0.0)).events
    moving = impact1d.simulate(two_balls_on_a_floor(-0.8)).events
    for events, u in ((still, 0.0), (moving, -0.8)):
        # The lower ball leaves the floor near the floor's speed (its bounces are slower
        # than 0.5 m/s against it), not at 'v1 = 0' (the ground end's 0, logged in its place).
        at = np.flatnonzero(events["kind"] == "release_floor")
        assert len(at) > 5
        assert np.all(np.abs(events["v1_before"][at] - u) < 0.5)
        np.testing.assert_array_equal(events["v1_after"][at], events["v1_before"][at])


def sine_ground_travel(t, amp, omega, phase):
    """The distance a point on w(t) = amp sin(omega t + phase) has travelled by t (w' turns
    where omega t + phase = pi/2 + k pi)."""
    w = lambda s: amp * np.sin(omega * s + phase)
    turns = (np.pi / 2 - phase + np.pi * np.arange(0, 8)) / omega
    travel = np.zeros_like(t)
    start = np.zeros_like(t)
    for turn in turns[turns > 0]:
        passed = t > turn
        travel[passed] += np.abs(w(turn) - w(start[passed]))
        start[passed] = turn
    return travel + np.abs(w(t) - w(start))


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
@pytest.mark.parametrize("phase", [0.0, 0.3])
def test_a_body_held_to_a_sine_wall_slides_back_with_it_where_it_turns(dt, phase):
    """A body with floor friction (mu m g = 3 N) held on a wall w = A sin(omega t + phase) by
    f1 = -5 N rides it exactly and slides on the floor the way w' goes: friction takes
    3 N times the distance travelled, its force turning with w' at each turn (t = 0.25 and
    0.75 for phase 0). With phase 0, w' at the double 0.25 is +7.7e-18 and its zero falls
    before the next double: the run stopped there ("no step keeps the constraints"), no
    time left to locate the zero (now: a stop within the clock's rounding of w', taken at
    the next step's start). With phase 0.3 (or dt = 1e-2) the event point zeroed the body's
    velocity at the turn and the mode kept it stuck on the floor: friction lost while the
    body rode on. No stick or slip is logged: the body never sticks, it turns with the wall."""
    amp, omega = 0.02, 2 * math.pi
    result = impact1d.simulate(impact1d.Scene(
        m1=1.0, mu1=0.3, g=10.0, f1=-5.0, x1=amp * math.sin(phase), v1=amp * omega * math.cos(phase),
        t_end=1.0, dt=dt, contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.0, ground_amp=amp,
                                         ground_period=1.0, ground_phase=phase, name="wall")]))
    assert list(result.events["kind"]) == ["rest_wall"]
    np.testing.assert_allclose(result.x1, amp * np.sin(omega * result.t + phase), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.v1, amp * omega * np.cos(omega * result.t + phase), rtol=0, atol=1e-15)
    np.testing.assert_allclose(result.friction_loss, 3.0 * sine_ground_travel(result.t, amp, omega, phase),
                               rtol=0, atol=1e-7)
    assert result.energy_residual < RESIDUAL_TOL_QUADRATURE


def test_anchors_at_one_speed_put_in_that_speed_times_the_momentum_they_gave():
    """Three free blocks joined by springs, the outer two also tied (a spring, one with a
    damper) to anchors moving at one speed V: the links' tensions cancel in the momentum P,
    so the anchors' power V sum T_j integrates to V (P(t) - P(0)). RK4 steps P with the
    same stage forces whose power the ledger takes, so drive_work = V dP to rounding. Guards
    impact1d_elements' moving-ground loop, which forms the forces and the anchors' power in
    one pass (only its ground ends count; a sign or a link counted would move it by far more)."""
    big_v = 0.25
    m = np.array([1.0, 2.0, 1.5])
    scene = impact1d.Scene(m=list(m), x=[0.0, 1.0, 2.0], v=[0.0, 0.0, 0.0], k_link=[40.0, 30.0], d_rest=[1.0, 1.0],
                           c_link=[0.2, 0.0],
                           springs=[dict(a=0, b=1, k=4.0, c=0.5, d_rest=0.0, ground_v=big_v),
                                    dict(a=0, b=3, k=6.0, d_rest=2.0, ground_v=big_v)],
                           t_end=3.0, dt=1e-3, dt_out=0.5)
    result = impact1d.simulate(scene)
    momentum = result.v @ m
    assert momentum[-1] > 0.1
    np.testing.assert_allclose(result.drive_work, big_v * (momentum - momentum[0]), rtol=0, atol=1e-13)
    assert result.damping_loss[-1] > 0.0 and abs(result.energy_residual) < 1e-9
