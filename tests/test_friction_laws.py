"""The friction laws beyond Coulomb against a still ground (issue 21 items 2 and 3; DESIGN
"Laws added on the records"): a moving friction surface, `belt_v` (per body, constant), and
Stribeck's sliding friction mu(u) = mu + (mus - mu) exp(-(|u|/v_s)^2) + c_v |u|, where u =
v - belt_v is the slip. Both run on the N-body engine, whatever the number of bodies.

The scene of every test: a block (mass m) on a belt moving at V > 0, tied to the ground by a
spring k (rest at x = 0). F = mu m g, S = mus m g, w = sqrt(k / m).

(a) Coulomb (stick-slip on a belt), closed forms: stuck, the block rides the belt (x = x0 + V t)
    until the spring's pull k x reaches S, at x = S / k. It then slips back (u < 0, friction +F
    forward): m x'' = -k x + F, a harmonic motion about F / k of amplitude R = sqrt(((S -
    F) / k)^2 + (V / w)^2), from y = x - F / k = (S - F) / k at velocity V, until its velocity is
    V again, by symmetry at y = -(S - F) / k, i.e. x = (2F - S) / k, where |k x| <= S: it sticks.
    With y = R cos(theta), v = -R w sin(theta): the slip runs from theta = -alpha to pi + alpha,
    alpha = atan((V / w) / ((S - F) / k)), so it lasts T_slip = (pi + 2 alpha) / w; the stick that
    follows carries x from (2F - S) / k to S / k: T_stick = 2 (S - F) / (k V). That is the limit
    cycle, reached at the first break-away from any start that sticks. Over one cycle the energy
    of block and spring returns: the belt's work equals friction's loss, F (V T_slip + 2 (S - F)
    / k) (F times the slip distance, integral of |u| dt = V T_slip - (x_end - x_start)).
(b) Stribeck, self-excited growth: sliding steadily (v = 0) needs k x_e = c(V), c(u) = F + (S
    - F) exp(-(u / v_s)^2) + C u (C = c_v m g). Near it, m y'' = -k y + c(V - y') - c(V), to
    first order m y'' + c'(V) y' + k y = 0: with c'(V) < 0 (friction falling with speed) a
    negative damping, the oscillation grows as exp(sigma t), sigma = -c'(V) / (2 m), until it
    reaches the belt's speed and sticks (stick-slip). The engine is held to a 50-digit
    reference of the nonlinear slip (taylor_reference: Taylor series of the ODE, mpmath) and
    the growth to its rate.
Each at dt = 1e-3 and a coarse dt; the ledger closes in every run (drive_work: the belt's).
"""

from __future__ import annotations

import dataclasses
import math
import subprocess

import mpmath as mp
import numpy as np
import pytest

import impact1d
import tools

M, K, V, MU, MUS, G = 1.0, 100.0, 0.1, 0.3, 0.5, 9.81
F, S = MU * M * G, MUS * M * G
W = math.sqrt(K / M)


def block_on_belt(dt, t_end, **laws):
    """The block of the module docstring, started stuck at x = 0 (moving with the belt)."""
    return impact1d.Scene(m1=M, mu1=MU, mus1=MUS, g=G, x1=0.0, v1=V, k1=K, x1_rest=0.0, t_end=t_end, dt=dt,
                          belt_v=[V], **laws)


def times_of(result, kind):
    return np.array([e["t"] for e in result.events if e["kind"] == kind])


# RK4 on the slip's harmonic motion: its error goes as (w dt)^4 and with the steps' cut at
# the samples (measured up to 2.8e-10 s on a phase's length at dt = 1e-3, 5.7e-6 s at 0.02).
@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-9), (0.02, 2e-5)])
def test_coulomb_belt_stick_slip_cycle_has_its_closed_form(dt, tol):
    """(a): first break-away at S / (k V), then slips of T_slip and sticks of T_stick; the
    block sticks at x = (2F - S) / k and breaks away at S / k; per cycle the belt's work and
    friction's loss are both F (V T_slip + 2 (S - F) / k); the ledger closes."""
    result = impact1d.simulate(block_on_belt(dt, 4.0))
    slips, sticks = times_of(result, "slip1"), times_of(result, "stick1")
    alpha = math.atan((V / W) / ((S - F) / K))
    t_slip = (math.pi + 2 * alpha) / W
    t_stick = 2 * (S - F) / (K * V)
    assert len(slips) >= 4 and len(sticks) >= 4
    assert slips[0] == pytest.approx(S / (K * V), abs=1e-12)
    np.testing.assert_allclose(sticks - slips[:len(sticks)], t_slip, rtol=0, atol=tol)
    np.testing.assert_allclose(slips[1:] - sticks[:len(slips) - 1], t_stick, rtol=0, atol=tol)
    # Where it sticks and breaks away (the events log the velocities: the belt's).
    frame = result.to_dataframe()
    stuck = [e for e in result.events if e["kind"] == "stick1"]
    assert all(e["v1_before"] == V and e["v1_after"] == V for e in stuck)
    x_stick = np.interp(sticks, frame["t"], frame["x1"])
    np.testing.assert_allclose(x_stick, (2 * F - S) / K, rtol=0, atol=max(tol, dt * 1e-3) * 10)
    # One cycle's loss, between two stick phases (friction_loss is constant while stuck: the
    # samples just after two sticks); the belt's work over it closes the ledger (residual).
    per_cycle = F * (V * t_slip + 2 * (S - F) / K)
    after = np.searchsorted(frame["t"], sticks[:3], side="right")
    loss = frame["friction_loss"].to_numpy()[after]
    np.testing.assert_allclose(np.diff(loss), per_cycle, rtol=1e-8 if dt < 0.01 else 1e-4)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


def test_belt_at_zero_speed_runs_as_the_still_ground():
    """belt_v = 0 (the belt law's path: the slip v - belt_v) on a Coulomb stick-slip scene:
    the same events and motion as on the still ground, to 1e-9."""
    still = dataclasses.replace(block_on_belt(1e-3, 3.0), belt_v=None, v1=0.6, x1=0.0, k1=K)
    belt = dataclasses.replace(still, belt_v=[0.0])
    a, b = impact1d.simulate(still), impact1d.simulate(belt)
    assert list(a.events["kind"]) == list(b.events["kind"]) and len(a.events) >= 1
    np.testing.assert_allclose(b.events["t"], a.events["t"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=1e-9)


# Stribeck's scene for (b): a gentle negative slope, sigma = -c'(V) / (2 m) = 0.376 / s.
V_S, C_V = 0.5, 0.02


def stribeck_bound(u, mp_=math):
    """c(u) for u >= 0 (the module docstring)."""
    return F + (S - F) * mp_.exp(-(u / V_S) ** 2) + C_V * M * G * u


def stribeck_slope(u):
    return -2 * u / V_S**2 * (S - F) * math.exp(-(u / V_S) ** 2) + C_V * M * G


def taylor_reference(x0, v0, times, digits=50, order=40, h="0.02", k=K):
    """The slip of (b), m x'' = -k x + c(V - x') (x' < V throughout), at 50 digits: Taylor
    series of order 40 on steps of h. With u = V - v, z = -(u / v_s)^2, e = exp(z), the
    coefficients follow from the series' products and e' = z' e: n e_n = sum_{j=1..n} j z_j
    e_{n-j}; a_n = (-k x_n + [n = 0] F + (S - F) e_n + C u_n) / m, x_{n+1} = v_n / (n + 1),
    v_{n+1} = a_n / (n + 1). (The terms at order 40 of a step are below 1e-60 here.) k: the
    stiffness (K; tests/test_combined_laws.py passes a compliant stop's, x then its penetration)."""
    with mp.workdps(digits + 10):
        m, k, vb, fs = mp.mpf(M), mp.mpf(k), mp.mpf(V), mp.mpf(F)
        ds, c, vs = mp.mpf(S) - mp.mpf(F), mp.mpf(C_V) * mp.mpf(M) * mp.mpf(G), mp.mpf(V_S)
        x, v, t, step = mp.mpf(x0), mp.mpf(v0), mp.mpf(0), mp.mpf(h)
        out = []
        for target in times:
            target = mp.mpf(target)
            while t < target:
                hh = min(step, target - t)
                xs, vs_, us, zs, es = [x], [v], [], [], []
                for n in range(order):
                    us.append((vb if n == 0 else 0) - vs_[n])
                    zs.append(-sum(us[j] * us[n - j] for j in range(n + 1)) / vs**2)
                    es.append(mp.exp(zs[0]) if n == 0 else sum(j * zs[j] * es[n - j] for j in range(1, n + 1)) / n)
                    a = (-k * xs[n] + (fs if n == 0 else 0) + ds * es[n] + c * us[n]) / m
                    xs.append(vs_[n] / (n + 1))
                    vs_.append(a / (n + 1))
                x = mp.fsum(cf * hh**n for n, cf in enumerate(xs))
                v = mp.fsum(cf * hh**n for n, cf in enumerate(vs_))
                t += hh
            out.append((float(x), float(v)))
        return np.array(out)


@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-10), (0.02, 1e-5)])
def test_stribeck_oscillation_grows_on_the_falling_branch(dt, tol):
    """(b): from the steady slide x_e = c(V) / k, a small kick (v0 = 0.01 V) grows as
    exp(sigma t), sigma = -c'(V) / (2 m): the engine's x and v against the 50-digit Taylor
    reference through 8 s of slip, successive maxima of x - x_e in the ratio exp(sigma T_d)
    (T_d = 2 pi / sqrt(w^2 - sigma^2)) within the nonlinearity (amplitude still < 5% of V),
    then stick-slip: the block reaches the belt's speed and sticks."""
    sigma = -stribeck_slope(V) / (2 * M)
    assert sigma > 0.3
    x_e = stribeck_bound(V) / K
    scene = dataclasses.replace(block_on_belt(dt, 20.0), x1=x_e, v1=0.01 * V, v_s=[V_S], c_v=[C_V])
    result = impact1d.simulate(scene)
    frame = result.to_dataframe()
    sticks = times_of(result, "stick1")
    assert len(sticks) >= 1 and len(times_of(result, "slip1")) >= 1
    check = np.arange(0.5, sticks[0], 0.5)
    assert len(check) >= 10
    reference = taylor_reference(x_e, 0.01 * V, check)
    rows = np.searchsorted(frame["t"], check)
    assert np.all(np.abs(frame["t"].to_numpy()[rows] - check) < 1e-12)
    np.testing.assert_allclose(frame["x1"].to_numpy()[rows], reference[:, 0], rtol=0, atol=tol)
    np.testing.assert_allclose(frame["v1"].to_numpy()[rows], reference[:, 1], rtol=0, atol=tol * W)
    # Growth: maxima of y = x - x_e before the first stick (one per damped period).
    period = 2 * math.pi / math.sqrt(W**2 - sigma**2)
    ratios = []
    for j in range(1, int(sticks[0] / period - 0.5)):
        window = frame[(frame["t"] > (j - 0.5) * period) & (frame["t"] <= (j + 0.5) * period)]
        before = frame[(frame["t"] > (j - 1.5) * period) & (frame["t"] <= (j - 0.5) * period)]
        if j > 1:
            ratios.append((window["x1"].max() - x_e) / (before["x1"].max() - x_e))
    assert all(r > 1 for r in ratios)
    # (the first at the smallest amplitude: measured 4e-4 from the linear rate)
    assert ratios[0] == pytest.approx(math.exp(sigma * period), rel=2e-3)
    np.testing.assert_allclose(ratios, math.exp(sigma * period), rtol=2e-2)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


def test_stribeck_break_away_is_continuous():
    """mus = mu(0): a block breaking away slides at first with the static bound S, so its
    acceleration just after break-away is 0 (k x = S) and grows from there: over the first
    10 ms of slip it lags the belt by less than under Coulomb's law, (S - F) / m t."""
    soft = dataclasses.replace(block_on_belt(1e-4, 0.51), v_s=[0.05], dt_out=1e-4)
    c = impact1d.simulate(soft)
    frame = c.to_dataframe()
    t0 = S / (K * V)
    after = frame[(frame["t"] > t0) & (frame["t"] <= t0 + 0.01)]
    lag = V - after["v1"].to_numpy()
    assert np.all(lag > 0)
    coulomb = (S - F) / M * (after["t"].to_numpy() - t0)
    assert np.all(lag < coulomb)


@pytest.mark.parametrize("fields, words", [
    ({"v_s": [0.0]}, "v_s(1)"),
    ({"c_v": [-1.0]}, "c_v(1)"),
    ({"belt_v": [math.inf]}, "belt_v(1)"),
    ({"method": "vissim"}, "belt_v"),
])
def test_friction_law_inputs_are_checked(fields, words):
    """Refused, each message naming the field: values not finite, v_s not positive, c_v
    negative; the vissim method with a law (the N-body engine has none: compliant stops
    with the laws are tests/test_combined_laws.py's)."""
    scene = dataclasses.replace(block_on_belt(1e-3, 1.0), **fields)
    with pytest.raises(impact1d.InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        impact1d.simulate(scene)


# (RK4's error on the slip with the steps cut at the samples: the periods measured within
# 1e-8 s of each other at dt = 1e-3)
@pytest.mark.parametrize("dt, tol", [(1e-3, 5e-8), (0.02, 1e-4)])
def test_drill_string_example_settles_on_one_stick_slip_cycle(dt, tol):
    """input/drill_string.nml: the bit at rest first breaks away where the spring's torque k
    Omega t reaches S, t = S / (k Omega) (exact: the stick is polynomial); every later cycle
    repeats the one that starts at the first stick (the same state there, each stick at rest
    with the same twist), so stick and slip phases keep their lengths; over a cycle the
    drive's work all goes to friction (drive_work and friction_loss grow by the same
    amount, the state repeating)."""
    scene = dataclasses.replace(impact1d.load_scene("input/drill_string.nml"), dt=dt, t_end=16.0)
    spring = scene.springs[0]
    result = impact1d.simulate(scene)
    slips, sticks = times_of(result, "slip1"), times_of(result, "stick1")
    s_bound = scene.mus1 * scene.m1 * scene.g
    assert slips[0] == pytest.approx(s_bound / (spring["k"] * spring["ground_v"]), abs=1e-12)
    assert len(sticks) >= 5
    np.testing.assert_allclose(np.diff(sticks), sticks[1] - sticks[0], rtol=0, atol=tol)
    np.testing.assert_allclose(sticks - slips[:len(sticks)], sticks[0] - slips[0], rtol=0, atol=tol)
    frame = result.to_dataframe()
    # Samples within the stick phases (at rest: friction_loss constant, the spring winding up):
    # each cycle loses the same, and the drive's work less the spring's energy gained matches.
    at = np.searchsorted(frame["t"], sticks[:4] + 0.05)
    loss = frame["friction_loss"].to_numpy()[at]
    drive = (frame["drive_work"] - frame["pe"] - frame["ke"]).to_numpy()[at]
    np.testing.assert_allclose(np.diff(loss), loss[1] - loss[0], rtol=1e-7 if dt < 0.01 else 1e-3)
    np.testing.assert_allclose(np.diff(drive), np.diff(loss), rtol=1e-9 if dt < 0.01 else 1e-4)
    assert abs(result.energy_residual) < (1e-9 if dt < 0.01 else 1e-4)


def test_cli_reads_and_writes_the_laws_of_one_body(tmp_path):
    """A one-body namelist with `&bodies belt_v = ..., v_s = ...` (arrays, no numbered
    names): the CLI runs it as Python does, its header writes the laws (`# belt_v = 0.1`)
    with the drive_work column, and read_output rebuilds the scene with them."""
    nml = tmp_path / "belt.nml"
    nml.write_text("&bodies m1 = 1.0, mu1 = 0.3, mus1 = 0.5, g = 9.81, belt_v = 0.1, v_s = 0.5 /\n"
                   "&initial x1 = 0.0, v1 = 0.1 /\n&springs k1 = 100.0, x1_rest = 0.0 /\n"
                   "&run t_end = 2.0, dt = 1.0e-3 /\n")
    out = tmp_path / "belt.dat"
    subprocess.run([tools.find_tool("impact1d"), str(nml), "-o", str(out)], check=True, capture_output=True)
    text = out.read_text()
    assert "# belt_v = 0.1" in text and "# v_s = 0.5" in text
    back = impact1d.read_output(out)
    assert back.scene.belt_v == [0.1] and back.scene.v_s == [0.5]
    assert "drive_work" in back.to_dataframe().columns
    again = impact1d.simulate(back.scene)
    assert list(again.events["kind"]) == list(back.events["kind"]) and len(again.events) >= 2
    np.testing.assert_allclose(again.events["t"], back.events["t"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("dt", [1e-3, 0.1])
def test_block_carried_by_a_belt_onto_a_wall(dt):
    """A block at rest (x = 0) on a belt moving at V = 0.5 toward a plastic wall at x = 0.2,
    no spring: it slips (u = -V), friction F forward accelerates it at F / m until it moves
    with the belt at t1 = m V / F, having gone V t1 / 2 (stick1 logged at v = V); it rides
    the belt to the wall, hits it at t2 = t1 + (0.2 - V t1 / 2) / V, losing m V^2 / 2, and
    then rests against it while the belt slides under it: friction's loss and the belt's work
    both grow at F V. Until the stick the belt's work is F V t (friction's loss F V t -
    m (F t / m)^2 / 2), while stuck it does no work (no force on the block). The motion is
    polynomial: exact at any dt, the ledger to rounding."""
    v_belt, wall = 0.5, 0.2
    scene = impact1d.Scene(m1=M, mu1=MU, mus1=MUS, g=G, x1=0.0, v1=0.0, x_right=wall, r_right=0.0, t_end=2.0,
                           dt=dt, dt_out=0.1, belt_v=[v_belt])
    result = impact1d.simulate(scene)
    t1 = M * v_belt / F
    t2 = t1 + (wall - v_belt * t1 / 2) / v_belt
    assert [e["kind"] for e in result.events] == ["stick1", "right", "rest_right"]
    assert result.events["t"] == pytest.approx([t1, t2, t2], abs=1e-12)
    frame = result.to_dataframe()
    end = frame.iloc[-1]
    assert end["x1"] == wall and end["v1"] == 0.0
    assert end["impact_loss"] == pytest.approx(M * v_belt**2 / 2, rel=1e-12)
    assert end["drive_work"] == pytest.approx(F * v_belt * t1 + F * v_belt * (2.0 - t2), rel=1e-12)
    assert end["friction_loss"] == pytest.approx(F * v_belt * t1 - M * v_belt**2 / 2 + F * v_belt * (2.0 - t2),
                                                 rel=1e-12)
    assert abs(result.energy_residual) < 1e-14


def test_bodies_on_their_own_belts_run_as_each_alone():
    """Three blocks far apart, each on its own belt (V = 0.1, -0.2, 0.3) with its own law
    (Coulomb, Stribeck, Stribeck with c_v) and spring: each moves as the same block alone
    (per-body arrays read at the right index; the others' events only cut the steps: within
    RK4's error: measured 1.4e-9 s on an event, 2e-13 m on x at dt = 1e-3; held to 1e-8),
    and its events are its own."""
    belts, v_s, c_v, rest = [0.1, -0.2, 0.3], [1e3, 0.3, 0.2], [0.0, 0.0, 0.05], [0.0, 10.0, 20.0]
    chain = impact1d.Scene(m=[M] * 3, mu=[MU] * 3, mus=[MUS] * 3, g=G, x=rest, v=belts, k=[K] * 3, x_rest=rest,
                           belt_v=belts, v_s=v_s, c_v=c_v, t_end=3.0, dt=1e-3)
    together = impact1d.simulate(chain)
    assert len(together.events) >= 9
    for i in range(3):
        alone = impact1d.simulate(impact1d.Scene(m1=M, mu1=MU, mus1=MUS, g=G, x1=rest[i], v1=belts[i], k1=K,
                                                 x1_rest=rest[i], belt_v=[belts[i]], v_s=[v_s[i]], c_v=[c_v[i]],
                                                 t_end=3.0, dt=1e-3))
        mine = together.events[(together.events["a"] == i + 1)]
        assert [k.replace(str(i + 1), "1") for k in mine["kind"]] == list(alone.events["kind"])
        np.testing.assert_allclose(mine["t"], alone.events["t"], rtol=0, atol=1e-8)
        np.testing.assert_allclose(together.x[:, i], alone.x[:, 0], rtol=0, atol=1e-8)
