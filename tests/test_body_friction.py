"""Friction between two bodies (issue 21 item 2; DESIGN "Laws added on the records"): the
repeatable record `&friction a = 1, b = 2, mu = 0.3, mus = 0.4, normal = 9.81 /`, a friction
contact between bodies a and b pressed together by a given constant normal load N, acting on
their relative velocity u = v_b - v_a. It runs on the N-body engine, whatever N.

(a) Two blocks sliding on each other, closed form. The lower block (mass m1) lies on a
    frictionless ground at rest, the upper one (m2) is launched on it at v0 > 0. While they
    slide (u > 0) the contact pushes the upper block back with F = mu N and the lower one
    forward with F, and nothing else acts:
        x1 = F t^2 / (2 m1),        v1 = F t / m1,
        x2 = v0 t - F t^2 / (2 m2), v2 = v0 - F t / m2,
    so u = v0 - F t (1/m1 + 1/m2) reaches 0 at t* = v0 / (F (1/m1 + 1/m2)). Friction's loss is
    F times the distance slid, F (v0 t - F t^2 (1/m1 + 1/m2) / 2), which is the kinetic energy
    lost: the ledger closes. At t* the contact sticks (it needs no force to keep u = 0) and
    the pair moves on at m2 v0 / (m1 + m2). Constant forces: RK4 is exact, at dt = 1e-3 and
    at a coarse dt.
(b) Block on block under a ramp (above its test): the instant the upper block starts
    slipping, t_s = mus N (m1 + m2) / (m2 K), in closed form.
"""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

import impact1d
import tools

M1, M2, MU, MUS, G, V0 = 2.0, 1.0, 0.3, 0.4, 9.81, 1.0
NORMAL = M2 * G
F = MU * NORMAL
T_STAR = V0 / (F * (1.0 / M1 + 1.0 / M2))


def sliding_blocks(dt, t_end, **extra):
    """The two blocks of (a), the friction record named 'pad'."""
    return impact1d.Scene(m=[M1, M2], x=[0.0, 0.0], v=[0.0, V0], t_end=t_end, dt=dt,
                          frictions=[{"a": 1, "b": 2, "mu": MU, "mus": MUS, "normal": NORMAL, "name": "pad"}],
                          **extra)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_blocks_sliding_on_each_other_have_the_closed_form(dt):
    r = impact1d.simulate(sliding_blocks(dt, 0.9 * T_STAR))
    t = r.t
    scale = 1e-15 * (1 + V0 * T_STAR)
    np.testing.assert_allclose(r.x1, F * t**2 / (2 * M1), rtol=0, atol=scale)
    np.testing.assert_allclose(r.v1, F * t / M1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.x2, V0 * t - F * t**2 / (2 * M2), rtol=0, atol=scale)
    np.testing.assert_allclose(r.v2, V0 - F * t / M2, rtol=0, atol=1e-15)
    slid = V0 * t - F * t**2 * (1.0 / M1 + 1.0 / M2) / 2
    np.testing.assert_allclose(r.friction_loss, F * slid, rtol=0, atol=1e-14)
    assert np.max(np.abs(r.residual)) < 1e-14
    assert len(r.events) == 0


def test_the_contact_acts_on_its_two_bodies_only():
    """A third body (free, apart) keeps its velocity; the pair as in (a) whatever N, and the
    record's ends may be given either way round (the force acts on u = v_b - v_a)."""
    for frictions, order in (([{"a": 1, "b": 2, "mu": MU, "normal": NORMAL}], (0, 1)),
                             ([{"a": 2, "b": 1, "mu": MU, "normal": NORMAL}], (0, 1))):
        scene = impact1d.Scene(m=[M1, M2, 1.5], x=[0.0, 0.0, 5.0], v=[0.0, V0, 0.25], t_end=0.9 * T_STAR,
                               dt=1e-3, frictions=frictions)
        r = impact1d.simulate(scene)
        t = r.t[-1]
        assert r.x[-1][2] == pytest.approx(5.0 + 0.25 * t, abs=1e-15)
        assert r.v[-1][order[0]] == pytest.approx(F * t / M1, abs=1e-15)
        assert r.v[-1][order[1]] == pytest.approx(V0 - F * t / M2, abs=1e-15)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_sliding_blocks_stick_at_the_closed_form_instant_and_move_together(dt):
    """(a) past t*: the relative stop is located at t* (as a body's stop is), the contact
    sticks (|friction| = 0 <= mus N holds it), and the pair moves on at the common velocity
    m2 v0 / (m1 + m2) (momentum kept); friction has then taken the kinetic energy
    m2 v0^2 / 2 - (m1 + m2) v_c^2 / 2."""
    r = impact1d.simulate(sliding_blocks(dt, 2 * T_STAR))
    assert [e["kind"] for e in r.events] == ["stick_pad"]
    assert r.events[0]["t"] == pytest.approx(T_STAR, abs=1e-15)
    v_c = M2 * V0 / (M1 + M2)
    after = r.t > T_STAR
    np.testing.assert_allclose(r.v1[after], v_c, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.v2[after], v_c, rtol=0, atol=1e-15)
    x_star = F * T_STAR**2 / (2 * M1)
    np.testing.assert_allclose(r.x1[after], x_star + v_c * (r.t[after] - T_STAR), rtol=0, atol=1e-15)
    assert r.friction_loss[-1] == pytest.approx(0.5 * M2 * V0**2 - 0.5 * (M1 + M2) * v_c**2, abs=1e-15)
    assert np.max(np.abs(r.residual)) < 1e-14


# (b) Block on block under a ramp: the lower block (m1, frictionless ground) is pulled by
#     f1 = K t (a force table), the upper block (m2) rides on it through the contact, both at
#     rest at t = 0. Stuck, they move as one, a = K t / (m1 + m2), and the contact carries
#     the upper block's m2 a = m2 K t / (m1 + m2); the upper block starts slipping when that
#     reaches mus N:  t_s = mus N (m1 + m2) / (m2 K).  Then the upper block is pushed forward by
#     F = mu N (u = v2 - v1 < 0) and the lower one held back by it:
#         v2 = v_s + F (t - t_s) / m2,
#         v1 = v_s + (K (t^2 - t_s^2) / 2 - F (t - t_s)) / m1,  v_s = K t_s^2 / (2 (m1 + m2)).
#     An error d in the break-away instant moves v2 by (mus - mu) N d / m2: v2 at the end
#     measures where the slip began. The upper block is placed apart (x2 = 10): neighbours meet.
K_RAMP = 5.0
T_SLIP = MUS * NORMAL * (M1 + M2) / (M2 * K_RAMP)


@pytest.mark.parametrize("dt", [1e-3, 0.2])
def test_block_on_block_under_a_ramp_slips_at_the_closed_form_instant(tmp_path, dt):
    table = tmp_path / "ramp.tab"
    table.write_text(f"0 0\n100 {100 * K_RAMP}\n")
    t_end = 1.5 * T_SLIP
    scene = impact1d.Scene(m=[M1, M2], x=[0.0, 10.0], v=[0.0, 0.0], t_end=t_end, dt=dt, f_table=[str(table), None],
                           frictions=[{"a": 1, "b": 2, "mu": MU, "mus": MUS, "normal": NORMAL, "name": "pad"}])
    r = impact1d.simulate(scene)
    assert [e["kind"] for e in r.events] == ["slip_pad"]
    assert r.events[0]["t"] == pytest.approx(T_SLIP, abs=1e-14)
    stuck = r.t <= T_SLIP
    np.testing.assert_array_equal(r.v1[stuck], r.v2[stuck])
    np.testing.assert_allclose(r.v1[stuck], K_RAMP * r.t[stuck]**2 / (2 * (M1 + M2)), rtol=0, atol=1e-14)
    v_s = K_RAMP * T_SLIP**2 / (2 * (M1 + M2))
    v2 = v_s + F * (t_end - T_SLIP) / M2
    v1 = v_s + (K_RAMP * (t_end**2 - T_SLIP**2) / 2 - F * (t_end - T_SLIP)) / M1
    assert r.v1[-1] == pytest.approx(v1, abs=1e-14)
    assert r.v2[-1] == pytest.approx(v2, abs=1e-14)     # the break-away within 1e-14 s of t_s
    assert np.max(np.abs(r.residual)) < 1e-12


def test_scene_file_cli_header_and_read_output_carry_the_record(tmp_path):
    nml = tmp_path / "blocks.nml"
    nml.write_text("&bodies m = 2.0, 1.0 /\n&initial x = 0.0, 0.0, v = 0.0, 1.0 /\n"
                   "&friction a = 1, b = 2, mu = 0.3, mus = 0.4, normal = 9.81, name = 'pad' /\n"
                   "&run t_end = 0.3, dt = 1e-3 /\n")
    scene = impact1d.load_scene(str(nml))
    assert scene.frictions == [{"a": 1, "b": 2, "mu": 0.3, "mus": 0.4, "normal": 9.81, "name": "pad"}]
    out = tmp_path / "blocks.dat"
    proc = subprocess.run([tools.find_tool("impact1d"), str(nml), "-o", str(out)], check=True, capture_output=True,
                          text=True)
    # (the summary counts the contact's events by name)
    assert "events    stick_pad 1" in proc.stdout
    header = out.read_text()
    assert "# friction.1.normal = 9.81" in header and "# friction.1.name = pad" in header
    back = impact1d.read_output(str(out))
    assert back.scene.frictions == scene.frictions
    assert [e["kind"] for e in back.events] == ["stick_pad"]
    mine = impact1d.simulate(scene)
    assert np.array_equal(back.x2, mine.x2) and np.array_equal(back.v1, mine.v1)


@pytest.mark.parametrize("record, words", [
    ({"a": 0, "b": 2, "mu": 0.3, "normal": 1.0}, "a = 0 is the ground"),
    ({"a": 1, "b": 1, "mu": 0.3, "normal": 1.0}, "between two different bodies"),
    ({"a": 1, "b": 3, "mu": 0.3, "normal": 1.0}, "b = 3.0 is not a body"),
    ({"a": 1, "b": 2, "normal": 1.0}, "mu is required but not given"),
    ({"a": 1, "b": 2, "mu": 0.3}, "normal is required but not given"),
    ({"a": 1, "b": 2, "mu": -0.3, "normal": 1.0}, "mu = -0.3 must not be negative"),
    ({"a": 1, "b": 2, "mu": 0.3, "normal": -1.0}, "normal = -1.0 must not be negative"),
    ({"a": 1, "b": 2, "mu": 0.3, "mus": 0.2, "normal": 1.0}, "mus = 0.2 is below mu = 0.3"),
    ({"a": 1, "b": 2, "mu": 0.3, "normal": math.inf}, "normal = Inf is not a finite number"),
])
def test_friction_record_inputs_are_checked(record, words):
    scene = impact1d.Scene(m=[M1, M2], x=[0.0, 0.0], v=[0.0, V0], t_end=0.1, dt=1e-3, frictions=[record])
    with pytest.raises(impact1d.InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        impact1d.simulate(scene)


def test_vissim_refuses_the_record():
    """(compliant stops and the friction laws with the record: tests/test_combined_laws.py)"""
    with pytest.raises(impact1d.InputError, match="friction between two bodies"):
        impact1d.simulate(sliding_blocks(1e-3, 0.1, method="vissim"))


def test_a_stuck_pair_stays_stuck_while_another_contact_sticks():
    """Three bodies: 2 and 3 start together (contact friction1, stuck), 2 slides on 1
    (friction2, unnamed: named by its place). Friction2 pulls the stuck pair (m2 + m3) back
    with F, which needs m3 F / (m2 + m3) < mus N on body 3 (friction1 holds); its relative
    velocity V0 - F t (1/m1 + 1/(m2 + m3)) reaches 0 at t2, where all three move on at the
    common velocity (m2 + m3) V0 / (m1 + m2 + m3). One event: friction1 never slips."""
    m3 = 1.5
    frictions = [{"a": 2, "b": 3, "mu": MU, "normal": NORMAL}, {"a": 1, "b": 2, "mu": MU, "normal": NORMAL}]
    scene = impact1d.Scene(m=[M1, M2, m3], x=[0.0, 0.0, 5.0], v=[0.0, V0, V0], t_end=1.0, dt=1e-3,
                           frictions=frictions)
    r = impact1d.simulate(scene)
    t2 = V0 / (F * (1.0 / M1 + 1.0 / (M2 + m3)))
    assert [(e["kind"], e["a"], e["b"]) for e in r.events] == [("stick_friction2", 1, 2)]
    assert r.events[0]["t"] == pytest.approx(t2, abs=1e-15)
    np.testing.assert_array_equal(r.v[:, 1], r.v[:, 2])
    np.testing.assert_allclose(r.v[-1], (M2 + m3) * V0 / (M1 + M2 + m3), rtol=0, atol=1e-15)
    assert np.max(np.abs(r.residual)) < 1e-14


# (c) A friction damper: block 1 (m1, frictionless ground) on a spring k to the ground (rest
#     at 0), block 2 (m2) rubbing on it through the contact, both at rest, x1 = X0. Stuck, the
#     contact would need m2 k X0 / (m1 + m2) > mus N: it slips at once, block 2 dragged by -F
#     (u = v2 - v1 > 0 as block 1 leaves), block 1 held back by +F:
#         x1 = F / k + (X0 - F / k) cos(w1 t),  w1 = sqrt(k / m1);   v2 = -F t / m2,
#     so u(t) = -F t / m2 + (X0 - F / k) w1 sin(w1 t), whose first root t1 > 0 is the stick
#     (an mpmath root). There the contact needs m2 k |x1(t1)| / (m1 + m2) <= mus N: the pair
#     moves as one, x = x1(t1) cos(w0 s) + (v2(t1) / w0) sin(w0 s), w0 = sqrt(k / (m1 + m2)),
#     until |x| reaches mus N (m1 + m2) / (m2 k): the slip at t2 (the first root in s). RK4
#     on the harmonic motions: (w dt)^4 (measured 7.0e-12 s at dt = 1e-3, 1.2e-6 s at 0.02;
#     the stick 8.3e-11 s at 1e-3 when the relative stop was left on the step's cubic).
@pytest.mark.parametrize("dt, tol, residual", [(1e-3, 2e-11, 1e-10), (0.02, 3e-6, 5e-6)])
def test_friction_damper_sticks_and_slips_at_the_closed_form_instants(dt, tol, residual):
    import mpmath as mp
    mp.mp.dps = 40
    k, x0 = 100.0, 0.2
    S = MUS * NORMAL
    w1, w0 = mp.sqrt(k / M1), mp.sqrt(k / (M1 + M2))
    t1 = mp.findroot(lambda t: -F * t / M2 + (x0 - F / k) * w1 * mp.sin(w1 * t), 0.3)
    x_1, v_1 = F / k + (x0 - F / k) * mp.cos(w1 * t1), -F * t1 / M2
    assert M2 * k * abs(x_1) / (M1 + M2) <= S < M2 * k * x0 / (M1 + M2)
    limit = S * (M1 + M2) / (M2 * k)
    s = mp.findroot(lambda s: x_1 * mp.cos(w0 * s) + v_1 / w0 * mp.sin(w0 * s) + limit, 0.04)
    scene = impact1d.Scene(m=[M1, M2], x=[x0, 10.0], v=[0.0, 0.0], k=[k, 0.0], x_rest=[0.0, 0.0],
                           t_end=float(t1 + s) + 0.05, dt=dt,
                           frictions=[{"a": 1, "b": 2, "mu": MU, "mus": MUS, "normal": NORMAL, "name": "pad"}])
    r = impact1d.simulate(scene)
    assert [e["kind"] for e in r.events] == ["stick_pad", "slip_pad"]
    assert abs(r.events[0]["t"] - float(t1)) < tol
    assert abs(r.events[1]["t"] - float(t1 + s)) < tol
    assert np.max(np.abs(r.residual)) < residual


@pytest.mark.parametrize("dt", [1e-3, 0.05, 0.1])
@pytest.mark.parametrize("v_common", [0.0, 10.0, -3.0])
def test_relative_stop_under_constant_forces_is_a_lone_bodys(dt, v_common):
    """Two blocks (m1 = m2 = 1) moving at v_common, the upper one faster by u0 = 1 and pushed
    by P = 0.25, the lower one free on a frictionless ground; the contact (F = mu N = 0.5,
    S = mus N = 0.6). Sliding, u = v2 - v1 obeys u' = (P - F) / m2 - F / m1 = -0.75: the stick
    at t* = u0 / 0.75, after which the pair needs m1 P / (m1 + m2) = 0.125 <= S and moves as
    one. One body of the reduced mass m1 m2 / (m1 + m2) = 0.5 on the ground (mu = 1, g = 1:
    F) pushed by P m1 / (m1 + m2) has that equation: both stick at t* to rounding at every dt
    (constant forces: RK4 exact), whatever the pair's common velocity (the pair's rounding
    band, |v_a| + |v_b|, is a rounding's; measured 4e-15 s)."""
    t_star = 1.0 / 0.75
    pair = impact1d.Scene(m=[1.0, 1.0], x=[0.0, 10.0], v=[v_common, v_common + 1.0], f=[0.0, 0.25], t_end=2.0,
                          dt=dt, frictions=[{"a": 1, "b": 2, "mu": 0.5, "mus": 0.6, "normal": 1.0, "name": "pad"}])
    one = impact1d.Scene(m1=0.5, mu1=1.0, mus1=1.2, g=1.0, x1=0.0, v1=1.0, f1=0.125, t_end=2.0, dt=dt,
                         x_left=-100.0, x_left_v=0.0)     # (a still wall far away: the N-body engine)
    a, b = impact1d.simulate(one), impact1d.simulate(pair)
    assert list(a.events["kind"]) == ["stick1"] and list(b.events["kind"]) == ["stick_pad"]
    assert a.events["t"][0] == pytest.approx(t_star, abs=1e-15)
    assert b.events["t"][0] == pytest.approx(t_star, abs=1e-14)
    np.testing.assert_allclose(b.v2[b.t > t_star] - b.v1[b.t > t_star], 0.0, rtol=0, atol=1e-14)
