"""A belt whose speed is prescribed in time (issue 21 item 2): V(t) = belt_v + belt_amp
sin(2 pi t / belt_period + belt_phase) under each body (&bodies arrays, any N; the names
follow the ground motion's ground_amp, ground_period, ground_phase: a design addition, DESIGN
names only belt_v). docs/method.md section 12.

The scene: a block (mass m, no other force) on a belt V(t) = A - A cos(w t) (belt_v = A,
belt_amp = A, belt_phase = -pi/2), started at x = 0 with the belt's speed V(0) = 0. The belt
accelerates at V'(t) = A w sin(w t), at most A w.

(a) mus g >= A w: static friction can always give the block the belt's acceleration, so it
    sticks throughout and rides the belt: x(t) = integral of V = A t - (A / w) sin(w t),
    v = V(t). Friction, the belt's force on it, is m V'(t); the belt's work m V' V integrates
    to the kinetic energy m V^2 / 2, friction loses nothing (no slip).
(b) mus g < A w: it sticks until the force the stick needs, m V'(t), reaches mus m g:
    t_b = asin(mus g / (A w)) / w (the first root of the sine). It then lags the belt
    (slip u = v - V < 0), friction mu m g pushing it forward: v = V(t_b) + mu g (t - t_b),
    x = x(t_b) + V(t_b) (t - t_b) + mu g (t - t_b)^2 / 2, until the slip is zero again:
    V(t_b) + mu g (t - t_b) = A (1 - cos(w t)), a root of a sine plus a line, t_s
    (mpmath.findroot at 50 digits is the reference). Here |V'(t_s)| < mus g: it sticks, and
    breaks away again where V' falls to -mus g, t_2 = P / 2 + t_b. Friction's loss over the
    slide is mu m g times the slip distance, the integral of V - v from t_b to t_s (mpmath's
    quad, 50 digits).
Each at dt = 1e-3 and a coarse dt = 0.05 (w dt = 0.63): the break-away is a root of the
exact forces (bisection), the stick a root of the exact slip (Newton on the integrator's
state, whose constant-force motion is exact), so both are exact at any dt; the ledger closes.
"""

from __future__ import annotations

import dataclasses
import math

import mpmath as mp
import numpy as np
import pytest

import impact1d

M, G, A, P = 2.0, 9.81, 0.5, 0.5
W = 2 * math.pi / P


def block(mus, mu, dt, t_end=0.5):
    """The module docstring's block on its belt, at rest on it at t = 0."""
    return impact1d.Scene(m1=M, mu1=mu, mus1=mus, g=G, x1=0.0, v1=0.0, t_end=t_end, dt=dt,
                          belt_v=[A], belt_amp=[A], belt_period=[P], belt_phase=[-math.pi / 2])


@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-9), (0.05, 1e-4)])
def test_stuck_block_rides_the_belt(dt, tol):
    """(a): no event, x = A t - (A / w) sin(w t) and v = V(t) at every sample to rounding
    (the stuck body is moved by the belt's exact integral, not integrated); the belt's work
    is the kinetic energy (RK4's quadrature of m V' V: to tol), friction's loss 0."""
    result = impact1d.simulate(block(mus=1.0, mu=0.8, dt=dt, t_end=2.0))
    assert len(result.events) == 0
    frame = result.to_dataframe()
    t = frame["t"].to_numpy()
    np.testing.assert_allclose(frame["x1"], A * t - A / W * np.sin(W * t), rtol=0, atol=1e-14)
    np.testing.assert_allclose(frame["v1"], A - A * np.cos(W * t), rtol=0, atol=1e-14)
    assert np.all(frame["friction_loss"] == 0.0)
    np.testing.assert_allclose(frame["drive_work"], frame["ke"], rtol=0, atol=tol)
    assert abs(result.energy_residual) < tol


def break_and_stick():
    """(b)'s instants t_b, t_s at 50 digits, and friction's loss over the slide per unit of
    mu m g (the slip distance)."""
    with mp.workdps(50):
        w = 2 * mp.pi / mp.mpf(P)
        a, g = mp.mpf(A), mp.mpf(G)
        t_b = mp.asin(mp.mpf("0.5") * g / (a * w)) / w
        speed = lambda t: a * (1 - mp.cos(w * t))
        block_v = lambda t: speed(t_b) + mp.mpf("0.3") * g * (t - t_b)
        t_s = mp.findroot(lambda t: block_v(t) - speed(t), t_b + mp.mpf("0.2"))
        assert abs(a * w * mp.sin(w * t_s)) < mp.mpf("0.5") * g
        distance = mp.quad(lambda t: speed(t) - block_v(t), [t_b, t_s])
        return t_b, t_s, distance


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_block_breaks_away_where_the_belt_outruns_static_friction(dt):
    """(b): slip1 at t_b = asin(mus g / (A w)) / w, stick1 at t_s (mpmath.findroot), slip1
    again at P / 2 + t_b, each within 1e-12 s; between t_b and t_s the block follows the
    constant-acceleration closed form; friction's loss over the slide is mu m g times the
    slip distance; the ledger closes."""
    result = impact1d.simulate(block(mus=0.5, mu=0.3, dt=dt))
    t_b, t_s, distance = break_and_stick()
    assert [e["kind"] for e in result.events] == ["slip1", "stick1", "slip1"]
    assert result.events["t"] == pytest.approx([float(t_b), float(t_s), P / 2 + float(t_b)], abs=1e-12)
    # (logged at the belt's speed: the slip is zero at each)
    speed = A - A * np.cos(W * result.events["t"])
    np.testing.assert_allclose(result.events["v1_before"], speed, rtol=0, atol=1e-14)
    frame = result.to_dataframe()
    t = frame["t"].to_numpy()
    sliding = (t > float(t_b)) & (t < float(t_s))
    assert np.count_nonzero(sliding) >= (4 if dt > 0.01 else 200)
    tb, v_b = float(t_b), A - A * math.cos(W * float(t_b))
    x_b = A * tb - A / W * math.sin(W * tb)
    tau = t[sliding] - tb
    np.testing.assert_allclose(frame["v1"][sliding], v_b + 0.3 * G * tau, rtol=0, atol=1e-13)
    np.testing.assert_allclose(frame["x1"][sliding], x_b + v_b * tau + 0.3 * G * tau**2 / 2, rtol=0, atol=1e-13)
    # friction_loss stays constant while stuck: the samples between t_s and the next slip
    # (RK4's quadrature of mu m g |v - V|, whose V is a sine: measured 1.0e-11 off at dt = 1e-3;
    # at dt = 0.05 no sample falls there)
    stuck = (t > float(t_s)) & (t < P / 2 + float(t_b))
    assert np.any(stuck) == (dt < 0.01)
    if np.any(stuck):
        np.testing.assert_allclose(frame["friction_loss"][stuck], 0.3 * M * G * float(distance), rtol=1e-10)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


def test_constant_belt_written_with_belt_amp_zero_runs_the_same_bits():
    """belt_amp = 0 (with a period) is the constant belt: the stick-slip block of
    tests/test_friction_laws.py (a spring, V = 0.1) runs bit for bit as without it."""
    scene = impact1d.Scene(m1=1.0, mu1=0.3, mus1=0.5, g=9.81, x1=0.0, v1=0.1, k1=100.0, x1_rest=0.0,
                           t_end=4.0, dt=1e-3, belt_v=[0.1])
    plain = impact1d.simulate(scene)
    zero = impact1d.simulate(dataclasses.replace(scene, belt_amp=[0.0], belt_period=[0.3], belt_phase=[1.0]))
    assert len(plain.events) >= 8
    assert plain.events.tobytes() == zero.events.tobytes()
    assert plain.samples.tobytes() == zero.samples.tobytes()


def test_bodies_on_their_own_belts_for_any_n():
    """Three blocks far apart: the first on the belt of (b), the second on a constant belt,
    the third with none: the first moves as the block alone ((b)'s events at their closed
    forms, within 1e-12 s), the others never slip (started with their belt's speed, no force)."""
    chain = impact1d.Scene(m=[M] * 3, mu=[0.3] * 3, mus=[0.5] * 3, g=G, x=[0.0, 10.0, 20.0], v=[0.0, 0.2, 0.0],
                           belt_v=[A, 0.2, 0.0], belt_amp=[A, 0.0, 0.0], belt_period=[P, 1.0, 1.0],
                           belt_phase=[-math.pi / 2, 0.0, 0.0], t_end=0.5, dt=1e-3)
    result = impact1d.simulate(chain)
    t_b, t_s, _ = break_and_stick()
    assert [e["kind"] for e in result.events] == ["slip1", "stick1", "slip1"]
    assert result.events["t"] == pytest.approx([float(t_b), float(t_s), P / 2 + float(t_b)], abs=1e-12)
    frame = result.to_dataframe()
    np.testing.assert_allclose(frame["x2"], 10.0 + 0.2 * frame["t"], rtol=0, atol=1e-12)
    assert np.all(frame["x3"] == 20.0)
    assert abs(result.energy_residual) < 1e-9


@pytest.mark.parametrize("fields, words", [
    ({"belt_period": [0.0]}, "belt_period(1)"),
    ({"belt_amp": [math.nan]}, "belt_amp(1)"),
    ({"belt_period": None}, "belt_period"),
    ({"belt_amp": None, "belt_period": None}, "belt_phase"),
    ({"method": "vissim"}, "belt_amp"),
    ({"m1": None, "mu1": None, "mus1": None, "x1": None, "v1": None, "m": [M, M], "mu": [0.3, 0.3],
      "mus": [0.5, 0.5], "x": [0.0, 1.0], "v": [0.0, 0.0], "belt_v": [A, 0.0], "belt_amp": [A, 0.0],
      "belt_period": [P, P], "belt_phase": [-math.pi / 2, 0.0],
      "frictions": [{"a": 1, "b": 2, "mu": 0.1, "mus": 0.2, "normal": 1.0}]}, "&friction"),
])
def test_belt_speed_inputs_are_checked(fields, words):
    """Refused, naming the field: a period not positive, values not finite, a sine without
    its period, a phase without its sine, the vissim method, and a friction contact between
    bodies (&friction) on a body whose belt has a sine speed (stuck, it accelerates with
    its own belt: the contact would join it to a frame the mode solve does not take yet)."""
    scene = dataclasses.replace(block(0.5, 0.3, 1e-3), **fields)
    with pytest.raises(impact1d.InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        impact1d.simulate(scene)


# A block against the right wall (x_right = 0 = x1) pushed into it by a constant force P,
# on a belt V(t) = V0 + A cos(w t) (V0 = -0.1: belt_phase = pi / 2). While V > 0 the belt
# drags the block into the wall: it slides (slip -V < 0, friction +F), held there. At t0,
# V's first zero (w t0 = acos(-V0 / A)), the belt turns away from the wall, accelerating at
# V'(t0) = -A w sin(w t0): the block, at rest on its belt with the wall closed, is solved in
# the belt's frame against the still wall (the row's acceleration n.a' + n.V'):
# (A) P + m A w sin(w t0) <= S: it sticks and rides the belt off the wall,
#     x = V0 (t - t0) + (A / w) (sin(w t) - sin(w t0)), v = V(t) (stuck throughout: |m V' - P|
#     <= S for every t; the belt's mean V0 < 0 never brings it back);
# (B) S < P + m A w sin(w t0) and P < F: it breaks away and leaves the wall sliding, a =
#     (P - F) / m, until its slip a (t - t0) - V(t) is zero again (mpmath.findroot), where
#     it sticks (|m V' - P| <= S there);
# (C) P > F: the wall holds it (contact force P - F), its slip -V(t) turns at each zero of V:
#     x = 0 throughout, friction's loss F times the integral of |V| (the belt's work).
V0 = -0.1
WALL_T0 = math.acos(-V0 / A) / W


def walled(mus, mu, push, dt, t_end):
    """The block against the right wall, pushed into it, on the belt V0 + A cos(w t)."""
    return impact1d.Scene(m1=M, mu1=mu, mus1=mus, g=G, x1=0.0, v1=0.0, f1=push, x_right=0.0, t_end=t_end,
                          dt=dt, belt_v=[V0], belt_amp=[A], belt_period=[P], belt_phase=[math.pi / 2])


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_block_stuck_on_its_belt_rides_off_the_wall(dt):
    """(A): stick1 and release_right at t0 (the belt's zero, 1e-15 s), then x and v the
    belt's integral and speed at every sample (1e-14); the ledger closes. Before this change
    the run ended at t0 (a contact on a body at rest on its belt was refused)."""
    push = 3.0
    assert push + M * A * W * math.sin(W * WALL_T0) <= 1.0 * M * G
    result = impact1d.simulate(walled(1.0, 0.5, push, dt, 0.6))
    assert [e["kind"] for e in result.events] == ["rest_right", "stick1", "release_right"]
    assert result.events["t"][1:] == pytest.approx([WALL_T0, WALL_T0], abs=1e-15)
    frame = result.to_dataframe()
    t = frame["t"].to_numpy()
    after = t > WALL_T0
    assert np.all(frame["x1"][~after] == 0.0)
    np.testing.assert_allclose(frame["x1"][after], V0 * (t[after] - WALL_T0) + A / W * (np.sin(W * t[after]) -
                               math.sin(W * WALL_T0)), rtol=0, atol=1e-14)
    np.testing.assert_allclose(frame["v1"][after], V0 + A * np.cos(W * t[after]), rtol=0, atol=1e-14)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_block_breaks_away_from_its_belt_and_the_wall(dt):
    """(B): release_right at t0, x = a (t - t0)^2 / 2 and v = a (t - t0) while it slides
    (1e-13), stick1 where the slip is zero again (50-digit findroot, 1e-12 s)."""
    push, mus, mu = 3.0, 0.6, 0.4
    assert push + M * A * W * math.sin(W * WALL_T0) > mus * M * G and push < mu * M * G
    result = impact1d.simulate(walled(mus, mu, push, dt, 0.4))
    acc = (push - mu * M * G) / M
    with mp.workdps(50):
        w, t0 = 2 * mp.pi / mp.mpf(P), mp.acos(-mp.mpf(V0) / mp.mpf(A)) / (2 * mp.pi / mp.mpf(P))
        t_s = mp.findroot(lambda t: mp.mpf(acc) * (t - t0) - (mp.mpf(V0) + mp.mpf(A) * mp.cos(w * t)), mp.mpf("0.3"))
        assert abs(M * A * w * mp.sin(w * t_s) + push) <= mus * M * G
    assert [e["kind"] for e in result.events] == ["rest_right", "release_right", "stick1"]
    assert result.events["t"][1:] == pytest.approx([WALL_T0, float(t_s)], abs=1e-12)
    frame = result.to_dataframe()
    t = frame["t"].to_numpy()
    sliding = (t > WALL_T0) & (t < float(t_s))
    assert np.count_nonzero(sliding) >= (3 if dt > 0.01 else 150)
    np.testing.assert_allclose(frame["v1"][sliding], acc * (t[sliding] - WALL_T0), rtol=0, atol=1e-13)
    np.testing.assert_allclose(frame["x1"][sliding], acc * (t[sliding] - WALL_T0) ** 2 / 2, rtol=0, atol=1e-13)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_block_pressed_harder_than_friction_stays_at_the_wall(dt):
    """(C): x = v = 0 at every sample through five of V's zeros (no stick: it slides on the
    belt there, the wall holding it); friction's loss is F times the integral of |V| (mpmath's
    quad), the belt's work the same."""
    mu = 0.2
    result = impact1d.simulate(walled(0.6, mu, 6.0, dt, 1.2))
    assert [e["kind"] for e in result.events] == ["rest_right"]
    frame = result.to_dataframe()
    assert np.all(frame["x1"] == 0.0) and np.all(frame["v1"] == 0.0)
    with mp.workdps(30):
        w = 2 * mp.pi / mp.mpf(P)
        first = mp.acos(-mp.mpf(V0) / A) / w
        zeros = sorted(z for n in range(3) for z in (first + n * P, n * P + P - first) if z < mp.mpf("1.2"))
        assert len(zeros) == 5
        loss = mu * M * G * mp.quad(lambda t: abs(mp.mpf(V0) + A * mp.cos(w * t)), [0] + zeros + [mp.mpf("1.2")])
    assert frame["friction_loss"].iloc[-1] == pytest.approx(float(loss), rel=1e-9 if dt < 0.01 else 1e-4)
    assert frame["drive_work"].iloc[-1] == pytest.approx(frame["friction_loss"].iloc[-1], rel=1e-12)


def test_body_held_against_one_stuck_on_its_belt_ends_the_run():
    """Two blocks touching (d_min = 0), each on its own belt: block 2 at rest on a belt of sine
    speed with ample static friction, block 1 (no friction) pushed into it by f1: held
    against it, block 1 would ride block 2's belt, which the groups' motion does not take
    yet: the run ends (SimulationError) naming the stuck body and the contact."""
    scene = impact1d.Scene(m=[M, M], mu=[0.0, 0.8], mus=[0.0, 1.0], g=G, x=[0.0, 0.0], v=[0.0, 0.0], f=[3.0, 0.0],
                           d_min=0.0, belt_v=[0.0, A], belt_amp=[0.0, A], belt_period=[P, P],
                           belt_phase=[0.0, -math.pi / 2], t_end=0.5, dt=1e-3)
    with pytest.raises(impact1d.SimulationError, match="body 2, stuck on its belt of sine speed"):
        impact1d.simulate(scene)


def test_cli_and_read_output_keep_the_belt_speed(tmp_path):
    """A namelist's `&bodies belt_amp = ..., belt_period = ..., belt_phase = ...` runs in the
    CLI as in Python; the header writes the arrays and read_output rebuilds the scene."""
    import subprocess
    import tools
    nml = tmp_path / "belt.nml"
    nml.write_text(f"&bodies m1 = {M}, mu1 = 0.3, mus1 = 0.5, g = {G}, belt_v = {A}, belt_amp = {A}, "
                   f"belt_period = {P}, belt_phase = {-math.pi / 2!r} /\n"
                   "&initial x1 = 0.0, v1 = 0.0 /\n&run t_end = 0.5, dt = 1.0e-3 /\n")
    out = tmp_path / "belt.dat"
    subprocess.run([tools.find_tool("impact1d"), str(nml), "-o", str(out)], check=True, capture_output=True)
    text = out.read_text()
    assert f"# belt_amp = {A}" in text and f"# belt_period = {P}" in text
    back = impact1d.read_output(out)
    assert back.scene.belt_amp == [A] and back.scene.belt_period == [P]
    t_b, t_s, _ = break_and_stick()
    assert back.events["t"][:2] == pytest.approx([float(t_b), float(t_s)], abs=1e-12)
    again = impact1d.simulate(back.scene)
    np.testing.assert_allclose(again.events["t"], back.events["t"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_block_on_a_spring_breaks_away_where_the_stick_needs_static_friction(dt):
    """(a)'s block tied to the ground by a spring k (rest at x = 0), stuck from t = 0: it rides
    the belt, x = A t - (A / w) sin(w t), while the force the stick needs, m V'(t) + k x(t) =
    m A w sin(w t) + k (A t - (A / w) sin(w t)), stays within mus m g; slip1 where it reaches
    it (a root of a sine plus a line: mpmath.findroot at 50 digits), within 1e-15 s at both
    steps (the mode crossing's bisection on the exact forces); the ledger closes."""
    k = 40.0
    scene = dataclasses.replace(block(0.5, 0.3, dt, t_end=0.3), k1=k, x1_rest=0.0)
    result = impact1d.simulate(scene)
    with mp.workdps(50):
        w, a = 2 * mp.pi / mp.mpf(P), mp.mpf(A)
        need = lambda t: (mp.mpf(M) * a * w * mp.sin(w * t) + mp.mpf(k) * (a * t - a / w * mp.sin(w * t))
                          - mp.mpf("0.5") * mp.mpf(M) * mp.mpf(G))
        t_b = mp.findroot(need, mp.mpf("0.06"))
    assert result.events["kind"][0] == "slip1"
    assert result.events["t"][0] == pytest.approx(float(t_b), abs=1e-15)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)
