"""Gear ratios (issue 21 item 6; DESIGN "Laws added on the records"): a &contact or &spring
record with `ratio = n` acts on g = x_b - n x_a instead of x_b - x_a, so a gear train with
backlash at each mesh is written in each shaft's own angle (inertia, torque and angle in
the places of mass, force and position). The row's normal is (-n, 1) on (x_a, x_b): an
impulse P on it acts on b by +P and on a by -n P (the gradient of g), so its effective mass
is 1 / (1/J_b + n^2/J_a) and Newton's restitution acts on g' = v_b - n v_a; a spring's
tension T = k (g - rest) + c g' pulls b by -T and a by +n T. Scenes with a ratio other than
1 run on the N-body engine.

(a) The rattle of two gears, closed form. Gear 1 (J1 = 1) is driven by a constant torque
    T = 2, gear 2 (J2 = 1/2) is free; the mesh has ratio n = 3 and backlash on g = x2 - 3 x1
    in [-d, d], d = 1/20, restitution r = 4/5 on both flanks. Between impacts both gears
    turn at constant acceleration, x1'' = T/J1, x2'' = 0, so g is the quadratic
        g(tau) = g0 + u tau - (n T / J1) tau^2 / 2,       u = v2 - n v1,
    and the next impact is its first root at -d (from above) or +d (from below). An impact
    with u approaching takes P = -(1 + r) u_n / (1/J2 + n^2/J1) (u_n the approach along the
    row's normal: u at the lower flank, -u at the upper), v1 -= n P_1, v2 += P_1 with P_1 =
    +P at the lower flank and -P at the upper: u -> -r u. The reference below
    (rattle_reference) steps these formulas in mpmath at 50 digits; gear 1 starts at
    v1 = 1, so the first impacts cross the backlash to the upper flank before the rattle
    settles on the drive flank. Once the flights no longer reach the upper flank (the
    excursion u'^2 / (2 n T / J1) < 2 d), each impact leaves u' = r u on the lower flank and
    the flight lasts 2 u' J1 / (n T): the series accumulates at
        t_inf = t_j + 2 r |u_j| J1 / (n T (1 - r))      (t_j, u_j: its first impact).
    The generalized momentum p = J1 v1 + n J2 v2 (conjugate to x1 with x2 following at n
    x1) takes no impulse (-n P J1/J1 + n P) and grows as T t, so after t_inf the gears turn
    together at v1 = p(t) / (J1 + n^2 J2), v2 = n v1, accelerating at T / (J1 + n^2 J2).
    Constant forces: RK4 is exact and the impacts are roots of quadratics, at dt = 1e-3
    and dt = 0.1 alike.
(b) A ratio of 1 is no ratio: the same bits on either engine.
(c) An elastic geared impact keeps the kinetic energy: (J1 v1^2 + J2 v2^2)/2 before and
    after (Newton's law with r = 1 on the row's effective mass), and the ledger closes.
(d) A spring with a ratio between two free bodies: its elongation e = x_b - n x_a - rest
    obeys e'' = x_b'' - n x_a'' = -k e / m_b - n (n k e) / m_a, so it oscillates at
    w^2 = k (1/m_b + n^2/m_a): e = e0 cos(w t) from rest; the energy in the spring and the
    bodies stays constant.
(e) A train of three gears (two meshes, ratios 3 and 1/2): once both meshes have taken up
    their backlash and the rattle has died, the train turns as one with shaft 2 at 3 times
    shaft 1 and shaft 3 at 3/2 times, accelerating at (T1 + (3/2) T3) / (J1 + 9 J2 +
    (9/4) J3) (virtual work on x1).
(f) Bad input refused by name: friction between bodies (&friction), the friction laws, the
    vissim method and moving grounds stay refused with gears.
(g) Bearing friction (mu, mus on &bodies: the friction torque mu_i J_i g against each
    shaft's own rotation; g = 1 here, so F_i = mu_i J_i). A geared group (bodies joined by
    held geared rows, x_i' = s_i V: s1 = 1, s2 = n across a held mesh on x2 - n x1) is one
    coordinate V: its mass M = J1 + n^2 J2, its load T1 + n T2 and its friction
    F_eff = F1 + n F2 (sum |s_i| F_i, virtual work) against the sign of V. So:
    (g1) from rest on the drive flank, a torque T on gear 1 above the static sum
         Fs1 + n Fs2 turns the pair at A = (T - F1 - n F2) / M, v1 = A t, v2 = n A t
         (the mesh stays pressed: gear 2's own motion under its friction alone would be
         slower, -F2/J2 < n (T - F1)/J1); below it the pair stays stuck.
    (g2) given V0 and no torque, the pair decelerates at F_eff / M (the mesh pressed when
         F2/J2 > n F1/J1: gear 2 alone would slow faster) and stops at t* = V0 M / F_eff,
         both shafts sticking there; turned backwards (V0 < 0) under a torque T it slows at
         (T + F_eff)/M, stops at t* = |V0| M / (T + F_eff), and then turns forward at
         (T - F_eff)/M if T > Fs_eff, or sticks.
    (g3) breakaway under a sine torque on gear 2, T2(t) = -(T0 + A sin(w t)) pressing the
         drive flank: the pair stays stuck while n (T0 + A sin(w t)) <= Fs1 + n Fs2 and
         breaks away at sin(w t_b) = ((Fs1 + n Fs2)/n - T0)/A (located on the mode
         failing: the group's load weighs each body's force and static bound by s_i).
    (g4) a rattle with friction on the free gear: gear 1 driven by T (no friction), gear 2
         with Coulomb friction F2 and no torque, the mesh with backlash [-d, d] and
         restitution r. Between events both move at constant acceleration (T/J1;
         -F2 sgn(v2)/J2 while gear 2 slides, 0 once it sticks: the open mesh puts no force on
         it), so each gap is a quadratic and gear 2's stop v2(t) = 0 is linear; the mpmath
         reference (friction_rattle_reference) steps the events at 50 digits. With
         T < n F2 every impact finds gear 2 stuck and leaves it sliding; the motion
         scales by one factor per cycle (all the gaps start at -d, velocities scale by q,
         times by q), so the impacts' intervals shrink geometrically by q and accumulate
         at t_1 + (t_2 - t_1) / (1 - q) after which the pair is stuck (T < n Fs2).
"""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import impact1d
import tools

J1, J2, N, T, D, R, V1 = 1.0, 0.5, 3.0, 2.0, 0.05, 0.8, 1.0


def rattle(dt, t_end, **extra):
    """Scene (a): two gears, ratio 3, backlash 2 d on x2 - 3 x1, torque T on gear 1."""
    return impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], v=[V1, 0.0], f=[T, 0.0], t_end=t_end, dt=dt,
                          contacts=[{"a": 1, "b": 2, "d_min": -D, "r_min": R, "d_max": D, "r_max": R,
                                     "ratio": N, "name": "mesh"}], **extra)


def rattle_reference(n_impacts=60):
    """(a)'s impacts at 50 digits: [(t, flank, v_before, v_after)], and t_inf, the limit of
    the lower flank's final series (module docstring)."""
    mp.mp.dps = 50
    j1, j2, n, torque, d, r = (mp.mpf(x) for x in (J1, J2, N, T, D, R))
    a1 = torque / j1                      # gear 1's acceleration; gear 2's is 0
    acc = -n * a1                         # g''
    t, x1, x2, v1, v2 = mp.mpf(0), mp.mpf(0), mp.mpf(0), mp.mpf(V1), mp.mpf(0)
    inverse = 1 / j2 + n**2 / j1
    impacts, t_inf = [], None
    while len(impacts) < n_impacts:
        g, u = x2 - n * x1, v2 - n * v1
        # First root of g0 + u tau + acc tau^2 / 2 = -d (acc < 0 reaches it surely), or of = +d.
        roots = []
        disc = u**2 - 2 * acc * (g + d)
        roots.append(((-u - mp.sqrt(disc)) / acc, "mesh_min"))
        disc = u**2 - 2 * acc * (g - d)
        if disc >= 0 and u > 0:
            tau = (-u + mp.sqrt(disc)) / acc
            if tau > 0:
                roots.append((tau, "mesh_max"))
        tau, flank = min(roots)
        t += tau
        x1 += v1 * tau + a1 * tau**2 / 2
        v1 += a1 * tau
        x2 += v2 * tau
        before = (v1, v2)
        u = v2 - n * v1
        p = -(1 + r) * u / inverse           # on the gap's direction (+ on b, -n on a)
        v1, v2 = v1 - n * p / j1, v2 + p / j2
        impacts.append((t, flank, before, (v1, v2)))
        u_after = v2 - n * v1
        if t_inf is None and flank == "mesh_min" and u_after**2 / (2 * n * a1) < 2 * d:
            # From here every flight stays on the lower flank: the geometric series.
            t_inf = t + 2 * u_after / (n * a1 * (1 - r))
    assert t_inf is not None, "the rattle did not settle on the drive flank"
    return impacts, t_inf


def momentum_velocity(t):
    """v1 of the gears turning together at t (after t_inf): p(t) / (J1 + n^2 J2)."""
    return (J1 * V1 + T * t) / (J1 + N**2 * J2)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_rattle_impacts_have_the_closed_form_times_and_velocities(dt):
    impacts, t_inf = rattle_reference()
    flanks = [kind for _, kind, _, _ in impacts]
    assert "mesh_max" in flanks and flanks[0] == "mesh_min"     # both flanks are struck
    r = impact1d.simulate(rattle(dt, 3.0))
    hits = [e for e in r.events if e[1] in ("mesh_min", "mesh_max")]
    assert len(hits) > 40
    for (t, kind, before, after), e in zip(impacts[:40], hits):
        assert e[1] == kind
        assert e[0] == pytest.approx(float(t), abs=1e-13 * (1 + float(t)))
        np.testing.assert_allclose([e[2], e[3]], [float(x) for x in before], rtol=0, atol=1e-12)
        np.testing.assert_allclose([e[4], e[5]], [float(x) for x in after], rtol=0, atol=1e-12)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_rattle_settles_at_the_series_limit_and_the_gears_turn_together(dt):
    _, t_inf = rattle_reference()
    r = impact1d.simulate(rattle(dt, 3.0))
    rests = [e for e in r.events if e[1] == "rest_mesh_min"]
    assert len(rests) == 1
    assert rests[0][0] == pytest.approx(float(t_inf), abs=1e-10)
    late = r.t > float(t_inf) + 1e-6
    v1 = momentum_velocity(r.t[late])
    np.testing.assert_allclose(r.v[late, 0], v1, rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.v[late, 1], N * v1, rtol=0, atol=3e-9)
    g = r.x[late, 1] - N * r.x[late, 0]
    np.testing.assert_allclose(g, -D, rtol=0, atol=1e-12)
    assert np.max(np.abs(r.residual)) < 1e-12


def three_bodies(contacts=(), springs=(), **extra):
    """Three bodies on the N-body engine, records as given."""
    return impact1d.Scene(m=[1.0, 0.5, 2.0], x=[0.0, 0.3, 1.0], v=[1.0, -0.5, 0.25], f=[0.5, 0.0, -0.25],
                          t_end=3.0, dt=1e-3, contacts=list(contacts), springs=list(springs), **extra)


def test_a_ratio_of_one_is_no_ratio():
    """(b): ratio = 1 written on every record gives the bits of the records without it
    (ratio 1 does not make a scene geared)."""
    contacts = [{"a": 1, "b": 2, "d_min": 0.1, "r_min": 0.7, "d_max": 0.5, "r_max": 0.9},
                {"a": 2, "b": 3, "d_min": 0.2, "r_min": 0.5}]
    springs = [{"a": 1, "b": 3, "k": 30.0, "d_rest": 1.0, "c": 0.3}]
    plain = impact1d.simulate(three_bodies(contacts, springs))
    ones = impact1d.simulate(three_bodies([dict(c, ratio=1.0) for c in contacts],
                                          [dict(s, ratio=1.0) for s in springs]))
    assert len(plain.events) > 2
    np.testing.assert_array_equal(plain.x, ones.x)
    np.testing.assert_array_equal(plain.v, ones.v)
    assert [tuple(e) for e in plain.events] == [tuple(e) for e in ones.events]
    two = dict(m=[1.0, 0.5], x=[0.0, 0.3], v=[1.0, -0.5], f=[0.5, 0.0], t_end=3.0, dt=1e-3)
    plain = impact1d.simulate(impact1d.Scene(**two, contacts=contacts[:1], springs=[dict(springs[0], b=2)]))
    ones = impact1d.simulate(impact1d.Scene(**two, contacts=[dict(contacts[0], ratio=1.0)],
                                            springs=[dict(springs[0], b=2, ratio=1.0)]))
    assert len(plain.events) > 2
    np.testing.assert_array_equal(plain.x, ones.x)
    np.testing.assert_array_equal(plain.v, ones.v)
    assert [tuple(e) for e in plain.events] == [tuple(e) for e in ones.events]


def test_an_elastic_geared_impact_keeps_the_kinetic_energy():
    """(c): gear 1 spins into the mesh's drive flank, no torque, r = 1: one impact per
    flank crossing, each with the velocities of Newton's law on the effective mass, and
    the kinetic energy the same after every impact."""
    scene = impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], v=[1.0, 0.0], t_end=1.0, dt=1e-3,
                           contacts=[{"a": 1, "b": 2, "d_min": -D, "d_max": D, "ratio": N, "name": "mesh"}])
    r = impact1d.simulate(scene)
    assert len(r.events) >= 3
    energy = 0.5 * J1 * 1.0**2
    for e in r.events:
        before = 0.5 * (J1 * e[2]**2 + J2 * e[3]**2)
        after = 0.5 * (J1 * e[4]**2 + J2 * e[5]**2)
        assert before == pytest.approx(energy, abs=1e-14)
        assert after == pytest.approx(energy, abs=1e-14)
        u = (e[3] - N * e[2], e[5] - N * e[4])
        assert u[1] == pytest.approx(-u[0], abs=1e-14)          # restitution 1 on v_b - n v_a
    # The first impact in closed form: u = -n v1 at t = (d / n) / v1 on the lower flank.
    p = 2 * N * 1.0 / (1 / J2 + N**2 / J1)
    assert r.events[0][0] == pytest.approx(D / N, abs=1e-15)
    assert r.events[0][4] == pytest.approx(1.0 - N * p / J1, abs=1e-15)
    assert r.events[0][5] == pytest.approx(p / J2, abs=1e-15)
    assert np.max(np.abs(r.residual)) < 1e-14


@pytest.mark.parametrize("n", [3.0, 0.25])
def test_a_geared_spring_oscillates_at_the_closed_form_frequency(n):
    """(d): e = x_b - n x_a - rest = e0 cos(w t), w^2 = k (1/m_b + n^2/m_a); RK4 at w dt
    = 0.02 is within (w dt)^4 of it over a few periods; the ledger (the spring's energy
    with the ratio) closes."""
    k, ma, mb, e0 = 40.0, 1.0, 0.5, 0.1
    scene = impact1d.Scene(m=[ma, mb], x=[0.0, e0 + 0.2], t_end=2.0, dt=1e-3,
                           springs=[{"a": 1, "b": 2, "k": k, "d_rest": 0.2, "ratio": n}])
    r = impact1d.simulate(scene)
    w = math.sqrt(k * (1 / mb + n**2 / ma))
    e = r.x[:, 1] - n * r.x[:, 0] - 0.2
    np.testing.assert_allclose(e, e0 * np.cos(w * r.t), rtol=0, atol=e0 * 1e-6)
    np.testing.assert_allclose(r.pe[0], 0.5 * k * e0**2, rtol=1e-14)
    # the momentum-like coordinate: m_a x_a' + n m_b x_b' stays 0 (no force on it)
    np.testing.assert_allclose(ma * r.v[:, 0] + n * mb * r.v[:, 1], 0.0, rtol=0, atol=1e-12)
    assert np.max(np.abs(r.residual)) < 1e-9


def test_a_three_gear_train_turns_as_one_with_its_ratios():
    """(e): after the rattle, shaft 2 at 3 x shaft 1, shaft 3 at (3/2) x shaft 1, and the
    train's acceleration (T1 + (3/2) T3) / (J1 + 9 J2 + (9/4) J3) on shaft 1."""
    torque = (2.0, 0.0, -0.1)
    masses = (1.0, 0.5, 2.0)
    scene = impact1d.Scene(m=list(masses), x=[0.0, 0.0, 0.0], f=list(torque), t_end=4.0, dt=1e-3,
                           contacts=[{"a": 1, "b": 2, "d_min": -0.01, "d_max": 0.01, "r_min": 0.5, "r_max": 0.5,
                                      "ratio": 3.0, "name": "mesh1"},
                                     {"a": 2, "b": 3, "d_min": -0.01, "d_max": 0.01, "r_min": 0.5, "r_max": 0.5,
                                      "ratio": 0.5, "name": "mesh2"}])
    r = impact1d.simulate(scene)
    last = max(e[0] for e in r.events)
    assert last < 3.0
    late = r.t > last + 1e-6
    scale = np.array([1.0, 3.0, 1.5])
    acc = (torque[0] + 1.5 * torque[2]) / (masses[0] + 9 * masses[1] + 2.25 * masses[2])
    np.testing.assert_allclose(r.v[late], np.outer(r.v[late, 0], scale), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.diff(r.v[late, 0]) / np.diff(r.t[late]), acc, rtol=1e-9)
    assert np.max(np.abs(r.residual)) < 1e-12


BAD = [
    ({"ratio": 0.0}, "ratio = 0"),
    ({"ratio": -2.0}, "must be positive"),
    ({"ratio": float("nan")}, "not a finite number"),
    ({"ratio": 3.0, "a": 0}, "ground end"),
    ({"ratio": 3.0, "k": 1e4}, "compliant stop"),
    ({"ratio": 3.0, "d_max": -D}, "rigid link"),
]


@pytest.mark.parametrize("change, message", BAD)
def test_bad_ratios_are_refused_by_name(change, message):
    contact = {"a": 1, "b": 2, "d_min": -D, "d_max": D, "name": "mesh"}
    contact.update(change)
    scene = impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], f=[T, 0.0], t_end=1.0, dt=1e-3, contacts=[contact])
    with pytest.raises(impact1d.InputError, match=message):
        impact1d.simulate(scene)


@pytest.mark.parametrize("extra, message", [
    ({"frictions": [{"a": 1, "b": 2, "mu": 0.1, "normal": 1.0, "name": "pad"}]}, r"friction between bodies \(&friction\)"),
    ({"method": "vissim"}, "vissim"),
    ({"belt_v": [0.0, 1.0]}, "belt_v"),
])
def test_what_gears_do_not_combine_with_yet_is_refused(extra, message):
    with pytest.raises(impact1d.InputError, match=f"gear ratio.*{message}"):
        impact1d.simulate(rattle(1e-3, 1.0, **extra))


def test_a_spring_ratio_on_a_ground_end_is_refused():
    scene = impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], t_end=1.0, dt=1e-3,
                           springs=[{"a": 0, "b": 1, "k": 10.0, "d_rest": 0.0, "ratio": 2.0}])
    with pytest.raises(impact1d.InputError, match="ground end"):
        impact1d.simulate(scene)


def test_a_moving_ground_in_a_geared_scene_is_refused():
    scene = rattle(1e-3, 1.0)
    scene.springs = [{"a": 0, "b": 1, "k": 10.0, "d_rest": 0.0, "ground_v": 1.0}]
    with pytest.raises(impact1d.InputError, match="gear ratio.*moving ground"):
        impact1d.simulate(scene)


def test_a_ground_table_in_a_geared_scene_is_refused_by_name(tmp_path):
    """A ground moved by a table is a moving ground too: refused, and the message names
    ground_table among the moving grounds' fields."""
    table = tmp_path / "lift.dat"
    table.write_text("0.0 0.0\n1.0 0.5\n")
    scene = rattle(1e-3, 1.0)
    scene.springs = [{"a": 0, "b": 1, "k": 10.0, "d_rest": 0.0, "ground_table": str(table)}]
    with pytest.raises(impact1d.InputError, match="gear ratio.*moving ground.*ground_table"):
        impact1d.simulate(scene)


def test_scene_file_cli_header_and_read_output_carry_the_ratio(tmp_path):
    """The namelist's `ratio` reaches the run; the output header writes it and read_output
    rebuilds the scene from it (the same run again)."""
    nml = tmp_path / "gears.nml"
    nml.write_text("&bodies m = 1.0, 0.5 /\n&initial x = 0.0, 0.0, v = 1.0, 0.0 /\n&forces f = 2.0, 0.0 /\n"
                   "&contact a = 1, b = 2, d_min = -0.05, r_min = 0.8, d_max = 0.05, r_max = 0.8, ratio = 3.0, "
                   "name = 'mesh' /\n&spring a = 1, b = 2, k = 5.0, d_rest = 0.0, ratio = 3.0 /\n"
                   "&run t_end = 0.5, dt = 1e-3 /\n")
    scene = impact1d.load_scene(str(nml))
    assert scene.contacts[0]["ratio"] == 3.0 and scene.springs[0]["ratio"] == 3.0
    out = tmp_path / "gears.dat"
    subprocess.run([tools.find_tool("impact1d"), str(nml), "-o", str(out)], check=True, capture_output=True)
    header = out.read_text()
    assert "# contact.1.ratio = 3.0" in header and "# spring.1.ratio = 3.0" in header
    back = impact1d.read_output(str(out))
    assert back.scene.contacts == scene.contacts and back.scene.springs == scene.springs
    mine = impact1d.simulate(scene)
    assert np.array_equal(back.x, mine.x) and np.array_equal(back.v, mine.v)
    assert len(back.events) == len(mine.events) > 0


def test_the_geared_train_example_turns_as_its_comment_says():
    """input/geared_train.nml: mesh 1's drive flank closes at sqrt(2 (0.01) J1 / (3 T)), and
    the train ends turning as one at 0.185 rad/s^2 with shaft speeds 1 : 3 : 1.5."""
    scene = impact1d.load_scene(str(Path(__file__).resolve().parent.parent / "input" / "geared_train.nml"))
    r = impact1d.simulate(scene)
    assert r.events[0]["kind"] == "mesh1_min"
    assert r.events[0]["t"] == pytest.approx(math.sqrt(2 * 0.01 * 1.0 / (3 * 2.0)), abs=1e-15)
    last = max(e["t"] for e in r.events)
    late = r.t > last + 1e-6
    np.testing.assert_allclose(np.diff(r.v[late, 0]) / np.diff(r.t[late]), 0.185, rtol=1e-9)
    np.testing.assert_allclose(r.v[-1], r.v[-1, 0] * np.array([1.0, 3.0, 1.5]), rtol=1e-12)


def test_the_initial_gap_of_a_geared_contact_is_on_x_b_minus_n_x_a():
    """The start is checked on x2 - 3 x1: x = (0.1, 0.3) is inside [-d, d] there (it would
    be outside on x2 - x1 = 0.2), x = (0.1, 0.1) is not (x2 - 3 x1 = -0.2), and the message
    names the geared difference."""
    contact = {"a": 1, "b": 2, "d_min": -D, "d_max": D, "ratio": N, "name": "mesh"}
    ok = impact1d.Scene(m=[J1, J2], x=[0.1, 0.3], t_end=0.1, dt=1e-3, contacts=[contact])
    assert len(impact1d.simulate(ok).events) == 0
    bad = impact1d.Scene(m=[J1, J2], x=[0.1, 0.1], t_end=0.1, dt=1e-3, contacts=[contact])
    with pytest.raises(impact1d.InputError, match=r"violates the contact 'mesh': x2 - 3.0 x1 = -0.2"):
        impact1d.simulate(bad)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_a_plastic_geared_impact_leaves_the_gears_turning_with_their_ratio(dt):
    """r = 0, no torque: gear 1 at v1 = 1 closes the drive flank at t = d / (n v1); the
    impact takes the generalized momentum J1 v1 + n J2 v2 whole, so the gears leave at v1' =
    J1 v1 / (J1 + n^2 J2), v2' = n v1' (not at one common velocity: the row's ends do not
    move alike), and turn so to the end, the mesh's gap staying at -d (one impact: no force
    presses the flank, so no rest is logged)."""
    scene = impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], v=[1.0, 0.0], t_end=1.0, dt=dt,
                           contacts=[{"a": 1, "b": 2, "d_min": -D, "r_min": 0.0, "d_max": D, "ratio": N,
                                      "name": "mesh"}])
    r = impact1d.simulate(scene)
    v1 = J1 * 1.0 / (J1 + N**2 * J2)
    assert [e["kind"] for e in r.events] == ["mesh_min"]
    assert r.events[0]["t"] == pytest.approx(D / N, abs=1e-15)
    assert r.events[0]["v1_after"] == pytest.approx(v1, abs=1e-15)
    assert r.events[0]["v2_after"] == pytest.approx(N * v1, abs=1e-15)
    np.testing.assert_allclose(r.v[-1], [v1, N * v1], rtol=0, atol=1e-15)
    late = r.t > D / N
    np.testing.assert_allclose(r.x[late, 1] - N * r.x[late, 0], -D, rtol=0, atol=1e-15)
    lost = 0.5 * J1 * 1.0**2 - 0.5 * (J1 * v1**2 + J2 * (N * v1)**2)
    assert r.impact_loss[-1] == pytest.approx(lost, abs=1e-15)
    assert np.max(np.abs(r.residual)) < 1e-15


def test_a_loop_of_gears_whose_ratios_do_not_multiply_to_one_jams():
    """Three shafts meshing in a loop, x2 = 2 x1, x3 = 2 x2 and x3 = 3 x1 (4 /= 3), plastic
    flanks, a torque on shaft 1: once the backlash is taken up the only motion the meshes
    allow is none, so the train stops and stays still (its held group is held, not moved
    at one common acceleration), the ledger closing on the impacts' loss."""
    scene = impact1d.Scene(m=[1.0, 0.5, 0.25], x=[0.0, 0.0, 0.0], f=[2.0, 0.0, 0.0], t_end=2.0, dt=1e-3,
                           contacts=[{"a": a, "b": b, "d_min": -0.01, "d_max": 0.01, "r_min": 0.0, "r_max": 0.0,
                                      "ratio": n, "name": f"m{a}{b}"} for a, b, n in ((1, 2, 2.0), (2, 3, 2.0),
                                                                                       (1, 3, 3.0))])
    r = impact1d.simulate(scene)
    last = max(e["t"] for e in r.events)
    assert last < 1.0
    late = r.t > last
    assert np.all(r.v[late] == 0.0)
    assert np.all(r.x[late] == r.x[-1])
    assert np.max(np.abs(r.residual)) < 1e-14


def test_a_geared_rattle_with_tooth_stiffness_closes_the_ledger():
    """The rattle of input/gear_rattle.nml written with a ratio: a sine torque on gear 1
    (on a shaft spring), a geared mesh with backlash and a geared tooth spring and damper on
    the same x2 - 3 x1: impacts on both flanks, the springs' energy (pe) and the damper's
    loss on the geared coordinate, and the ledger closes to rounding."""
    scene = impact1d.Scene(m=[1.0, 0.5], x=[0.0, 0.0], f_amp=[5.0, 0.0], f_period=[0.5, 1.0], t_end=3.0, dt=1e-4,
                           contacts=[{"a": 1, "b": 2, "d_min": -0.02, "d_max": 0.02, "r_min": 0.6, "r_max": 0.6,
                                      "ratio": 3.0, "name": "mesh"}],
                           springs=[{"a": 1, "b": 2, "k": 20.0, "d_rest": 0.0, "c": 0.2, "ratio": 3.0},
                                    {"a": 0, "b": 1, "k": 200.0, "d_rest": 0.0}])
    r = impact1d.simulate(scene)
    kinds = {e["kind"] for e in r.events}
    assert {"mesh_min", "mesh_max"} <= kinds
    g = r.x[:, 1] - 3.0 * r.x[:, 0]
    np.testing.assert_allclose(r.pe, 0.5 * 20.0 * g**2 + 0.5 * 200.0 * r.x[:, 0]**2, rtol=1e-12, atol=1e-15)
    assert r.damping_loss[-1] > 0
    assert np.max(np.abs(r.residual)) < 1e-12


# (g) Bearing friction on geared shafts. g = 1: the friction torque of shaft i is mu_i J_i.
DF = 0.0625     # a backlash of 1/8 (exact in binary): the start on the drive flank exactly


def geared_friction(torque, v0, mu, mus=None, dt=1e-3, t_end=1.5, **extra):
    """Gears 1, 2 (J1, J2, ratio N) on the drive flank of a mesh with backlash [-DF, DF] (x2
    - 3 x1 = -DF), turning as one at v1 = v0 (v2 = n v0), bearing friction mu (g = 1)."""
    kw = dict(m=[J1, J2], x=[0.5, 1.5 - DF], v=[v0, N * v0], f=list(torque), t_end=t_end, dt=dt, g=1.0,
              mu=list(mu), contacts=[{"a": 1, "b": 2, "d_min": -DF, "d_max": DF, "ratio": N, "name": "mesh"}],
              **extra)
    if mus is not None:
        kw["mus"] = list(mus)
    return impact1d.Scene(**kw)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_a_driven_geared_pair_with_bearing_friction_turns_at_the_group_acceleration(dt):
    """(g1): F1 = 0.5, F2 = 0.1, T = 2 > F1 + n F2 = 0.8: v1 = A t with A = (T - F1 - n F2) /
    (J1 + n^2 J2), v2 = n v1, x1 = x1(0) + A t^2 / 2; the ledger closes with friction's loss
    sum F_i |v_i| dt = (F1 + n F2) A t^2 / 2."""
    r = impact1d.simulate(geared_friction([2.0, 0.0], 0.0, [0.5, 0.2], dt=dt))
    acc = (2.0 - 0.5 - N * 0.1) / (J1 + N**2 * J2)
    assert [e["kind"] for e in r.events] == ["rest_mesh_min"]
    np.testing.assert_allclose(r.v[:, 0], acc * r.t, rtol=0, atol=1e-14)
    np.testing.assert_allclose(r.v[:, 1], N * acc * r.t, rtol=0, atol=1e-14)
    np.testing.assert_allclose(r.x[:, 0], 0.5 + acc * r.t**2 / 2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(r.friction_loss, (0.5 + N * 0.1) * acc * r.t**2 / 2, rtol=0, atol=1e-14)
    assert np.max(np.abs(r.residual)) < 1e-14


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_a_geared_pair_below_the_static_sum_stays_stuck(dt):
    """(g1): T = 0.75 exceeds gear 1's own static bound Fs1 = 0.5 but not Fs1 + n Fs2 = 0.8:
    the pair does not move (and 0.85 > 0.8 moves it)."""
    r = impact1d.simulate(geared_friction([0.75, 0.0], 0.0, [0.5, 0.2], dt=dt))
    assert np.all(r.v == 0.0) and np.all(r.x == r.x[0])
    r = impact1d.simulate(geared_friction([0.85, 0.0], 0.0, [0.5, 0.2], dt=dt))
    np.testing.assert_allclose(r.v[:, 0], 0.05 / (J1 + N**2 * J2) * r.t, rtol=0, atol=1e-14)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
@pytest.mark.parametrize("torque, v0", [(0.0, 0.2), (1.0, -0.2), (2.0, -0.2)])
def test_a_geared_pair_with_bearing_friction_stops_at_the_closed_form_instant(dt, torque, v0):
    """(g2): F1 = 0.1, F2 = 0.5 (F2/J2 = 1 > n F1/J1 = 0.3: the mesh stays pressed while the
    pair slows), F_eff = F1 + n F2 = 1.6, M = J1 + n^2 J2 = 5.5. The stop at t* = |V0| M /
    (F_eff + T sgn(-V0)), located within 1e-12 s; then both shafts stick (T = 0, or T = 1 <
    1.6), each logged, or (T = 2 > 1.6) the pair turns forward at (T - F_eff)/M with no
    event (a reversal, not a stick)."""
    mass, f_eff = J1 + N**2 * J2, 0.1 + N * 0.5
    t_stop = abs(v0) * mass / (f_eff + (torque if v0 < 0 else 0.0))
    r = impact1d.simulate(geared_friction([torque, 0.0], v0, [0.1, 1.0], dt=dt))
    before = r.t < t_stop
    np.testing.assert_allclose(r.v[before, 0], v0 * (1 - r.t[before] / t_stop), rtol=0, atol=1e-14)
    if torque < f_eff:
        assert [e["kind"] for e in r.events] == ["rest_mesh_min", "stick1", "stick2"]
        assert r.events[1]["t"] == pytest.approx(t_stop, abs=1e-12)
        assert r.events[2]["t"] == r.events[1]["t"]
        assert np.all(r.v[~before] == 0.0)
    else:
        assert [e["kind"] for e in r.events] == ["rest_mesh_min"]
        after = ~before
        np.testing.assert_allclose(r.v[after, 0], (torque - f_eff) / mass * (r.t[after] - t_stop), rtol=0,
                                   atol=1e-14)
    np.testing.assert_allclose(r.v[:, 1], N * r.v[:, 0], rtol=0, atol=1e-14)
    assert np.max(np.abs(r.residual)) < 1e-14


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_a_stuck_geared_pair_breaks_away_where_the_scaled_loads_reach_the_static_sum(dt):
    """(g3): mus = (0.6, 1.0) (Fs1 = 0.6, Fs2 = 0.5), a torque -(T0 + A sin(w t)) on gear 2,
    T0 = 0.5, A = 4, w = pi: the group's load n (T0 + A sin(w t)) reaches Fs1 + n Fs2 = 2.1
    at sin(w t_b) = (0.7 - 0.5) / 4; both shafts slip there, located within 1e-12 s."""
    r = impact1d.simulate(geared_friction([0.0, -0.5], 0.0, [0.1, 0.6], mus=[0.6, 1.0], dt=dt, t_end=1.0,
                                          f_amp=[0.0, -4.0], f_period=[1.0, 2.0]))
    t_b = math.asin(((0.6 + N * 0.5) / N - 0.5) / 4.0) / math.pi
    assert [e["kind"] for e in r.events] == ["rest_mesh_min", "slip1", "slip2"]
    assert r.events[1]["t"] == pytest.approx(t_b, abs=1e-12)
    assert r.events[2]["t"] == r.events[1]["t"]
    assert np.all(r.v[r.t < t_b] == 0.0)
    assert np.all(r.v[r.t > t_b, 0] < 0.0)
    np.testing.assert_allclose(r.v[:, 1], N * r.v[:, 0], rtol=0, atol=1e-14)


F2_RATTLE = 1.0     # gear 2's friction torque: T = 2 < n F2 = 3, gear 2 stops between impacts


def friction_rattle_reference(n_events=40):
    """(g4)'s events at 50 digits: [(t, kind, (v1, v2) before, (v1, v2) after)], kind a flank
    or 'stick2' (gear 2's stop)."""
    mp.mp.dps = 50
    j1, j2, n, torque, d, r, f2 = (mp.mpf(x) for x in (J1, J2, N, T, D, R, F2_RATTLE))
    t, x1, x2, v1, v2 = mp.mpf(0), mp.mpf(0), mp.mpf(0), mp.mpf(0), mp.mpf(0)
    a1 = torque / j1
    events = []
    while len(events) < n_events:
        a2 = -f2 / j2 * mp.sign(v2)
        g, u, acc = x2 - n * x1, v2 - n * v1, a2 - n * a1
        found = [(-v2 / a2, "stick2")] if v2 != 0 else []
        for limit, kind, side in ((-d, "mesh_min", -1), (d, "mesh_max", 1)):
            # g + u tau + acc tau^2 / 2 = limit, reached moving towards it (acc /= 0 here)
            disc = u**2 - 2 * acc * (g - limit)
            if disc < 0:
                continue
            roots = sorted(((-u - mp.sqrt(disc)) / acc, (-u + mp.sqrt(disc)) / acc))
            found += [(tau, kind) for tau in roots if tau > mp.mpf(10)**-40 and side * (u + acc * tau) > 0][:1]
        tau, kind = min(found)
        t += tau
        x1, v1 = x1 + v1 * tau + a1 * tau**2 / 2, v1 + a1 * tau
        x2, v2 = x2 + v2 * tau + a2 * tau**2 / 2, v2 + a2 * tau
        before = (v1, v2)
        if kind == "stick2":
            v2 = mp.mpf(0)
        else:
            p = -(1 + r) * (v2 - n * v1) / (1 / j2 + n**2 / j1)
            v1, v2 = v1 - n * p / j1, v2 + p / j2
        events.append((t, kind, before, (v1, v2)))
    return events


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_a_rattle_with_friction_on_the_free_gear_has_the_closed_form_stops_and_impacts(dt):
    """(g4): the first 40 events (impacts on the drive flank, gear 2's stops between them)
    at the reference's times within 1e-12 s and velocities within 1e-12; the series
    accumulates at t_1 + (t_2 - t_1) / (1 - q) (q from the reference's intervals, the same
    for every cycle), where the pair ends stuck."""
    ref = friction_rattle_reference()
    assert [kind for _, kind, _, _ in ref[:4]] == ["mesh_min", "stick2", "mesh_min", "stick2"]
    scene = impact1d.Scene(m=[J1, J2], x=[0.0, 0.0], f=[T, 0.0], t_end=1.5, dt=dt, g=1.0,
                           mu=[0.0, F2_RATTLE / J2],
                           contacts=[{"a": 1, "b": 2, "d_min": -D, "r_min": R, "d_max": D, "r_max": R,
                                      "ratio": N, "name": "mesh"}])
    r = impact1d.simulate(scene)
    for (t, kind, before, after), e in zip(ref, r.events):
        assert e["kind"] == kind
        assert e["t"] == pytest.approx(float(t), abs=1e-12)
        np.testing.assert_allclose([e[2], e[3]], [float(x) for x in before], rtol=0, atol=1e-12)
        np.testing.assert_allclose([e[4], e[5]], [float(x) for x in after], rtol=0, atol=1e-12)
    hits = [t for t, kind, _, _ in ref if kind == "mesh_min"]
    q = (hits[2] - hits[1]) / (hits[1] - hits[0])
    assert abs((hits[3] - hits[2]) / (hits[2] - hits[1]) - q) < mp.mpf(10)**-40
    t_inf = float(hits[0] + (hits[1] - hits[0]) / (1 - q))
    assert max(e["t"] for e in r.events) == pytest.approx(t_inf, abs=1e-10)
    assert np.all(r.v[r.t > t_inf + 1e-9] == 0.0)
    assert np.max(np.abs(r.residual)) < 1e-12


def test_a_three_gear_train_with_bearing_friction_turns_at_its_reduced_acceleration():
    """(g) on (e)'s train: friction torques F_i = mu_i J_i (g = 1) on all three shafts; after
    the rattle the train turns as one (1 : 3 : 3/2) at (T1 + (3/2) T3 - F1 - 3 F2 - (3/2)
    F3) / (J1 + 9 J2 + (9/4) J3): each shaft's friction weighed by its speed ratio."""
    torque, masses, mu = (2.0, 0.0, -0.1), (1.0, 0.5, 2.0), (0.05, 0.1, 0.02)
    scene = impact1d.Scene(m=list(masses), x=[0.0, 0.0, 0.0], f=list(torque), t_end=2.0, dt=1e-3, g=1.0,
                           mu=list(mu),
                           contacts=[{"a": 1, "b": 2, "d_min": -0.01, "d_max": 0.01, "r_min": 0.5, "r_max": 0.5,
                                      "ratio": 3.0, "name": "mesh1"},
                                     {"a": 2, "b": 3, "d_min": -0.01, "d_max": 0.01, "r_min": 0.5, "r_max": 0.5,
                                      "ratio": 0.5, "name": "mesh2"}])
    r = impact1d.simulate(scene)
    f = [m * u for m, u in zip(masses, mu)]
    acc = (torque[0] + 1.5 * torque[2] - f[0] - 3 * f[1] - 1.5 * f[2]) / (masses[0] + 9 * masses[1] + 2.25 * masses[2])
    last = max(e["t"] for e in r.events)
    assert last < 1.0
    late = r.t > last + 1e-6
    np.testing.assert_allclose(r.v[late], np.outer(r.v[late, 0], [1.0, 3.0, 1.5]), rtol=0, atol=1e-13)
    np.testing.assert_allclose(np.diff(r.v[late, 0]) / np.diff(r.t[late]), acc, rtol=1e-9)
    assert np.max(np.abs(r.residual)) < 1e-13
