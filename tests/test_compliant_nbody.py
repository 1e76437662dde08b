"""Compliant stops on the N-body engine (issue 21 item 4; issue 19's "one engine"): the
`&contact ..., k, c /` records that push back with F = max(0, k p + c p') past their limit
(docs/method.md sections 9 and 10) on scenes of more than two bodies and scenes with a moving
ground, which run on the N-body engine.

(a) Three bilinear oscillators side by side (three bodies): each period pi/w1 + pi/w2, every
    engagement and release in closed form, at dt = 1e-3 and at coarse steps (order 4).
(b) Every two-body compliant scene of tests/test_compliant_stops.py through both engines (a
    record with `ground_v = 0` sends a scene to the N-body engine): the same events to 1e-12 s.
(c) A compliant stop on a wall moving at constant speed: the closed form in the wall's frame.
(d) A stack of three bodies dropped on a compliant floor: the closed form of a mass on a
    spring under gravity (the stack cannot part: the floor never pulls).
(e) input/ball_stack.nml's elastic balls on a compliant floor against an event-driven
    reference at 40 digits (closed forms per phase, events found by mpmath).
(f) A body, and a stack, set down at rest on a damped compliant floor (both engines).
(g) A body riding a compliant table that vibrates as a sine: the driven damped oscillator.

Each closed form is derived in its test's docstring and evaluated with mpmath at 50 digits.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import impact1d

mpmath = pytest.importorskip("mpmath")
mpmath.mp.dps = 50

# The closed forms (derived in their docstrings) of tests/test_compliant_stops.py: the
# bilinear oscillator's events (the amplitude drops out, and so does the side of the stop),
# and the Kelvin-Voigt contact's release and coefficient of restitution.
from test_compliant_stops import bilinear_times, damped_closed_form  # noqa: E402


def events(res, kind):
    return np.array([e["t"] for e in res.events if e["kind"] == kind])


# ---------------------------------------------------------------------------------------
# (a) Three bilinear oscillators: (m, k1, k_stop, amplitude); a negative amplitude starts the
# body below its equilibrium, against a stop above it (an upper limit, d_max).
OSCILLATORS = [(1.0, 4.0, 12.0, 1.0), (2.0, 3.0, 5.0, -0.5), (0.5, 8.0, 2.0, 0.7)]
SPACING = 10.0      # the equilibria apart: the bodies share no contact


def oscillators_scene(dt, t_end=10.0):
    """Body i on a spring k1 to the ground with its rest at its equilibrium e_i = 10 (i - 1),
    a stop of stiffness k_stop at e_i (below it for a positive amplitude, above for a
    negative one), started at rest at e_i + A."""
    eq = [SPACING * i for i in range(len(OSCILLATORS))]
    springs, contacts = [], []
    for i, (_, k1, k_stop, amp) in enumerate(OSCILLATORS):
        springs.append(dict(a=0, b=i + 1, k=k1, d_rest=eq[i]))
        limit = dict(d_min=eq[i]) if amp > 0 else dict(d_max=eq[i])
        contacts.append(dict(a=0, b=i + 1, k=k_stop, name=f"stop{i + 1}", **limit))
    return impact1d.Scene(m=[o[0] for o in OSCILLATORS], x=[eq[i] + o[3] for i, o in enumerate(OSCILLATORS)],
                          v=[0.0] * len(OSCILLATORS), springs=springs, contacts=contacts, t_end=t_end, dt=dt)


def oscillators_error(dt):
    res = impact1d.simulate(oscillators_scene(dt))
    worst = 0.0
    for i, (m, k1, k_stop, _) in enumerate(OSCILLATORS):
        engage, release, _ = bilinear_times(10.0, m, k1, k_stop)
        got_e, got_r = events(res, f"stop{i + 1}"), events(res, f"release_stop{i + 1}")
        assert len(got_e) == len(engage) and len(got_r) == len(release), (i, got_e, got_r)
        worst = max(worst, np.max(np.abs(got_e - engage)), np.max(np.abs(got_r - release)))
    return worst, res


def test_three_bilinear_oscillators_at_a_fine_step():
    """At dt = 1e-3 every engagement and release of the three oscillators over 10 s (14
    engagements, 12 releases) is within 1e-10 s of the closed form (measured: 2.5e-11 s,
    the fastest body's), so each period pi / w1 + pi / w2 is too; an engagement changes no
    velocity; without damping KE + PE is conserved to RK4's error and the ledger closes."""
    err, res = oscillators_error(1e-3)
    assert err < 1e-10
    assert res.x.shape[1] == 3
    for i, (m, k1, k_stop, _) in enumerate(OSCILLATORS):
        _, _, period = bilinear_times(10.0, m, k1, k_stop)
        assert np.max(np.abs(np.diff(events(res, f"stop{i + 1}")) - period)) < 2e-10
    for e in res.events:
        if e["kind"].startswith("stop"):
            assert e["va_before"] == e["va_after"] and e["vb_before"] == e["vb_after"]
    energy = 0.5 * sum(k1 * amp ** 2 for _, k1, _, amp in OSCILLATORS)
    assert np.max(np.abs(res.ke + res.pe - energy)) < 1e-9
    assert res.damping_loss is None
    assert res.energy_residual < 1e-9


def test_three_bilinear_oscillators_converge_at_order_four():
    """Halving a coarse step (dt = 0.05, 0.025, 0.0125: w2 dt up to 0.22) divides the worst
    event-time error by about 16: RK4's order 4 survives the switches on N bodies too."""
    errors = [oscillators_error(dt)[0] for dt in (0.05, 0.025, 0.0125)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[0] < 2e-4
    assert np.all((orders > 3.5) & (orders < 4.6)), (errors, orders)


# ---------------------------------------------------------------------------------------
# (b) One- and two-body compliant scenes, on a still ground and on one moving at 0 m/s (the
# two-body engine's scenes once, compared with the N-body engine through that record).
def two_body_scenes():
    bilinear = dict(m1=1.0, x1=1.0, v1=0.0, k1=4.0, x1_rest=0.0, t_end=10.0)
    thrown = dict(m1=1.0, x1=1.0, v1=-2.0, t_end=2.0)
    return {
        "bilinear": dict(bilinear, contacts=[dict(a=0, b=1, d_min=0.0, k=12.0, name="stop")]),
        "bilinear_damped": dict(bilinear, t_end=8.0, contacts=[dict(a=0, b=1, d_min=0.0, k=12.0, c=0.5,
                                                                     name="stop")]),
        "thrown": dict(thrown, contacts=[dict(a=0, b=1, d_min=0.0, k=100.0, name="wall")]),
        "thrown_damped": dict(thrown, t_end=1.5, contacts=[dict(a=0, b=1, d_min=0.0, k=100.0, c=4.0,
                                                                 name="wall")]),
        "buffer": dict(m1=1.0, m2=2.0, x1=0.0, x2=1.0, v1=1.0, v2=0.0, d_min=-1e9, t_end=2.0,
                       contacts=[dict(a=1, b=2, d_min=0.5, k=50.0, name="buffer"),
                                 dict(a=0, b=1, d_min=-100.0, name="far")]),
        # Two bodies on springs, a damped stop between them and a rigid wall the first hits.
        "pair": dict(m1=1.0, m2=0.5, x1=0.0, x2=1.0, v1=0.0, v2=-3.0, k1=20.0, x1_rest=0.0, k2=10.0,
                     x2_rest=1.0, d_min=-1e9, t_end=5.0,
                     contacts=[dict(a=1, b=2, d_min=0.6, k=400.0, c=2.0, name="buffer"),
                               dict(a=0, b=1, d_min=-0.05, r_min=0.7, name="wall")]),
    }


@pytest.mark.parametrize("dt", [1e-3, 0.02])
@pytest.mark.parametrize("name", sorted(two_body_scenes()))
def test_two_body_compliant_scenes_agree_across_engines(name, dt):
    """The same scene on a still ground and with its ground-end record moving at 0 m/s (the
    moving-ground path: the drives' exact w(t), the stages' drive power): the same events
    (kinds, times to 1e-12 s, velocities to 1e-12), the same samples and ledger to 1e-10."""
    scene = impact1d.Scene(dt=dt, **two_body_scenes()[name])
    contacts = [dict(c) for c in scene.contacts]
    ground = next(c for c in contacts if c["a"] == 0)
    ground["ground_v"] = 0.0
    a = impact1d.simulate(scene)
    b = impact1d.simulate(dataclasses.replace(scene, contacts=contacts))
    assert list(a.events["kind"]) == list(b.events["kind"])
    assert any(k.startswith("release_") for k in a.events["kind"])
    for field in a.events.dtype.names[2:] + ("t",):
        np.testing.assert_allclose(b.events[field], a.events[field], rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=1e-10)
    np.testing.assert_allclose(b.pe, a.pe, rtol=0, atol=1e-10)
    if a.damping_loss is not None:
        np.testing.assert_allclose(b.damping_loss, a.damping_loss, rtol=0, atol=1e-10)
    assert abs(b.energy_residual - a.energy_residual) < 1e-10


# ---------------------------------------------------------------------------------------
# (c) A stop on a moving wall.
@pytest.mark.parametrize("c", [0.0, 4.0])
@pytest.mark.parametrize("dt", [1e-3, 0.02])
def test_stop_on_a_wall_moving_at_constant_speed(c, dt):
    """A free body (m = 1) at rest at x = 0; a compliant wall (k = 100, damping c) whose limit
    is at w(t) - 1, w = u t, u = 0.5 (d_min = -1 on x - w, ground_v = u), reaches it at t0 =
    1 / u = 2. In the wall's frame (a Galilean one: the wall does not accelerate) the body
    comes in at u, so the contact is the Kelvin-Voigt one (damped_closed_form): released at
    t0 + t_r (pi / 10 for c = 0), the
    body leaving the wall at e u, in the lab at u (1 + e) (c = 0: e = 1, 2u after pi / 10
    s). The wall's work (drive_work) is the body's kinetic energy plus what the damper took,
    m u^2 (1 - e^2) / 2 (the loss in the wall's frame), and the ledger closes."""
    m, k, u = 1.0, 100.0, 0.5
    record = dict(a=0, b=1, d_min=-1.0, k=k, ground_v=u, name="wall")
    if c:
        record["c"] = c
    res = impact1d.simulate(impact1d.Scene(m1=m, x1=0.0, v1=0.0, t_end=3.0, dt=dt, dt_out=1e-2,
                                           contacts=[record]))
    t_r, e, _ = damped_closed_form(m, k, c, u)
    fine = dt == 1e-3
    assert np.allclose(events(res, "wall"), [2.0], rtol=0, atol=1e-12)
    release = events(res, "release_wall")
    assert len(release) == 1 and abs(release[0] - float(2 + t_r)) < (1e-10 if fine else 2e-5)
    v_end = float(u * (1 + e))
    assert abs(res.v1[-1] - v_end) < (1e-10 if fine else 1e-5)
    loss = float(m * u ** 2 * (1 - e ** 2) / 2)
    if c:
        assert abs(res.damping_loss[-1] - loss) < (1e-10 if fine else 1e-5)
    else:
        assert res.damping_loss is None
    assert abs(res.drive_work[-1] - (0.5 * m * v_end ** 2 + loss)) < (1e-10 if fine else 1e-5)
    assert res.energy_residual < (1e-10 if fine else 1e-5)


# ---------------------------------------------------------------------------------------
# (d) A stack of three bodies on a compliant floor.
G = 9.81


def stack_times(masses, k, c, drop, t_end):
    """Three bodies stacked (touching, plastic contacts between them) fall from rest, the
    bottom one's floor limit `drop` below it: the stack falls as one (equal accelerations
    -g) and meets the floor at t0 = sqrt(2 drop / g) at v0 = g t0. On the floor its total
    mass M is pushed by F = k p + c p' and pulled by M g; the floor cannot pull (F >= 0), so
    the stack's acceleration is at least -g and no contact between its bodies is ever
    pulled: the stack moves as one mass. With wn = sqrt(k / M), zeta = c / (2 sqrt(k M)),
    wd = wn sqrt(1 - zeta^2), p_eq = M g / k: p = p_eq + e^(-zeta wn t) (A cos(wd t) + B
    sin(wd t)), A = -p_eq, B = (v0 + zeta wn A) / wd. Released where k p + c p' = 0 (found by
    mpmath at 50 digits, the first root after the turn) at a depth p_r (> 0 with damping: the
    stack is released inside) at speed v_up = -p'; it flies freely (the released stop pushes
    on nothing), meets the limit again at v_in = sqrt(v_up^2 - 2 g p_r) after (v_up + v_in) /
    g, and again, until the force no longer falls to zero (the stack stays on the floor)."""
    M = mpmath.mpf(sum(masses))
    k, c, g = mpmath.mpf(k), mpmath.mpf(c), mpmath.mpf(G)
    wn = mpmath.sqrt(k / M)
    zeta = c / (2 * mpmath.sqrt(k * M))
    wd = wn * mpmath.sqrt(1 - zeta ** 2)
    p_eq = M * g / k
    t = mpmath.sqrt(2 * mpmath.mpf(drop) / g)
    v0 = g * t
    engage, release = [], []
    while t < t_end:
        engage.append(t)
        A, B = -p_eq, (v0 + zeta * wn * (-p_eq)) / wd

        def p(s):
            return p_eq + mpmath.exp(-zeta * wn * s) * (A * mpmath.cos(wd * s) + B * mpmath.sin(wd * s))

        def force(s):
            return k * p(s) + c * mpmath.diff(p, s)

        # The force is positive through the first quarter of the oscillation (deepest after
        # it); its zero, if any, lies within (pi / 2, 2 pi) / wd: bracketed by sampling. None
        # there: the stack stays (the force's swing about M g only decays after).
        grid = [mpmath.pi / wd * (mpmath.mpf(1) / 2 + j / mpmath.mpf(200)) for j in range(301)]
        lo = next((s for s, s_next in zip(grid, grid[1:]) if force(s_next) < 0), None)
        if lo is None:
            break
        hi = lo + mpmath.pi / wd / 200
        s_r = mpmath.findroot(force, (lo, hi), solver="anderson")
        if t + s_r >= t_end:
            break
        release.append(t + s_r)
        # Released inside (p > 0 where c > 0) at v_up: free from there, it leaves the stop's
        # region p_r higher and meets the limit again on the way down at v_in.
        v_up, p_r = -mpmath.diff(p, s_r), p(s_r)
        v_in = mpmath.sqrt(v_up ** 2 - 2 * g * p_r)
        t = t + s_r + (v_up + v_in) / g
        v0 = v_in
    return [float(x) for x in engage], [float(x) for x in release]


@pytest.mark.parametrize("c", [0.0, 20.0])
@pytest.mark.parametrize("dt", [1e-3, 0.01])
def test_stack_dropped_on_a_compliant_floor(c, dt):
    """Bodies of 1, 2 and 3 kg touching (d_min = 0.25 between neighbours, r = 0), the bottom
    one 0.2 m above a floor of k = 2000 N/m (and c = 0 or 20 N s/m): every floor engagement
    and release over 2 s as stack_times derives (within 5e-9 s at dt = 1e-3, 5e-5 s at dt =
    0.01; measured 1.2e-9 and 8.9e-6); the stack never parts (its gaps stay 0 to rounding).
    The ledger's residual is RK4's own energy error on the floor's oscillation (w = 18 rad/s:
    measured 4.8e-8 J at dt = 1e-3 and 4.4e-4 J at w dt = 0.18, of 11.8 J; the two-body
    engine gives the same for one body of 6 kg)."""
    masses, k, drop, t_end = [1.0, 2.0, 3.0], 2000.0, 0.2, 2.0
    x = [drop, drop + 0.25, drop + 0.5]
    floor = dict(a=0, b=1, d_min=0.0, k=k, name="floor")
    if c:
        floor["c"] = c
    scene = impact1d.Scene(m=masses, x=x, v=[0.0] * 3, f=[-G * m for m in masses], t_end=t_end, dt=dt,
                           dt_out=1e-2,
                           contacts=[floor, dict(a=1, b=2, d_min=0.25, r_min=0.0, name="b12"),
                                     dict(a=2, b=3, d_min=0.25, r_min=0.0, name="b23")])
    res = impact1d.simulate(scene)
    engage, release = stack_times(masses, k, c, drop, t_end)
    tol = 5e-9 if dt == 1e-3 else 5e-5
    got_e, got_r = events(res, "floor"), events(res, "release_floor")
    assert len(got_e) == len(engage) >= 2 and len(got_r) == len(release) >= 2, (got_e, engage, got_r, release)
    assert np.max(np.abs(got_e - engage)) < tol and np.max(np.abs(got_r - release)) < tol
    gaps = np.diff(res.x, axis=1) - 0.25
    assert np.max(np.abs(gaps)) < 1e-12
    assert res.energy_residual < (1e-7 if dt == 1e-3 else 1e-3)
    if not c:
        assert res.damping_loss is None


# ---------------------------------------------------------------------------------------
# (e) input/ball_stack.nml's three elastic balls dropped on a compliant floor, against an
# event-driven reference at 40 digits.
def ball_stack_reference(masses, x, k, limit, diameter, t_end, ds="0.0005"):
    """The reference: each phase's motion in closed form, the events found by mpmath. In
    flight a ball moves as x0 + v0 s - g s^2 / 2; the bottom ball below the floor's limit L
    (engaged, c = 0: released where its force k (L - x) is zero, at x = L again) as m x'' =
    -m g + k (L - x), harmonic about L - m g / k with w = sqrt(k / m). Events: the bottom
    ball crossing L (engagement downwards, release upwards) and neighbours meeting (their
    gap x_(i+1) - x_i - diameter falling through zero: Newton's elastic impulse, r = 1,
    momentum kept and the relative velocity reversed). The earliest root of each watched
    function is bracketed by sampling every ds (far below the contact's period 2 pi / w
    and any flight between impacts here) and polished by mpmath's findroot."""
    with mpmath.workdps(40):
        g = mpmath.mpf(G)
        m = [mpmath.mpf(v) for v in masses]
        k, floor, d, ds = mpmath.mpf(k), mpmath.mpf(limit), mpmath.mpf(diameter), mpmath.mpf(ds)
        w = mpmath.sqrt(k / m[0])
        centre = floor - m[0] * g / k
        t, xs, vs, engaged, log = mpmath.mpf(0), [mpmath.mpf(v) for v in x], [mpmath.mpf(0)] * len(x), False, []

        def pos(i, s):
            if i == 0 and engaged:
                return centre + (xs[0] - centre) * mpmath.cos(w * s) + vs[0] / w * mpmath.sin(w * s)
            return xs[i] + vs[i] * s - g * s * s / 2

        def vel(i, s):
            if i == 0 and engaged:
                return -(xs[0] - centre) * w * mpmath.sin(w * s) + vs[0] * mpmath.cos(w * s)
            return vs[i] - g * s

        while True:
            watched = [("release_floor" if engaged else "floor",
                        (lambda s: floor - pos(0, s)) if engaged else (lambda s: pos(0, s) - floor))]
            watched += [(f"b{i + 1}{i + 2}", lambda s, i=i: pos(i + 1, s) - pos(i, s) - d) for i in range(len(x) - 1)]
            best, s = None, ds
            while best is None and t + s - ds < t_end:
                for name, h in watched:
                    if h(s) < 0:
                        root = mpmath.findroot(h, (s - ds, s), solver="illinois")
                        if best is None or root < best[0]:
                            best = (root, name)
                s += ds
            if best is None or t + best[0] > t_end:
                return log
            s, name = best
            xs, vs, t = [pos(i, s) for i in range(len(x))], [vel(i, s) for i in range(len(x))], t + s
            if name in ("floor", "release_floor"):
                engaged = name == "floor"
            else:
                i = int(name[1]) - 1
                common = (m[i] * vs[i] + m[i + 1] * vs[i + 1]) / (m[i] + m[i + 1])
                vs[i], vs[i + 1] = 2 * common - vs[i], 2 * common - vs[i + 1]
            log.append((float(t), name))


@pytest.mark.parametrize("dt, tol", [(1e-3, 3e-7), (1e-4, 3e-11), (5e-3, 1e-3)])
def test_ball_stack_on_a_compliant_floor_against_the_reference(dt, tol):
    """input/ball_stack.nml (balls of 4, 2 and 1 kg, diameter 0.125 m, dropped together) on a
    compliant floor (k = 2e4 N/m: w = 70.7 rad/s on the bottom ball) instead of a rigid one,
    over 1.2 s: the bottom ball's engagements and releases and the balls' elastic impacts on
    one another (16 events) in the reference's order and at its times, within 3e-7 s at dt =
    1e-3 (measured 8.7e-8), 3e-11 at 1e-4 (5.7e-12: RK4's order 4) and 1e-3 at the coarse
    dt = 5e-3 (w dt = 0.35; measured 1.3e-4)."""
    masses, x, k = [4.0, 2.0, 1.0], [1.0, 1.375, 1.625], 2.0e4
    scene = impact1d.Scene(m=masses, x=x, v=[0.0] * 3, f=[-G * m for m in masses], t_end=1.2, dt=dt, dt_out=1e-2,
                           contacts=[dict(a=0, b=1, d_min=0.0625, k=k, name="floor"),
                                     dict(a=1, b=2, d_min=0.125, name="b12"),
                                     dict(a=2, b=3, d_min=0.125, name="b23")])
    res = impact1d.simulate(scene)
    reference = ball_stack_reference(masses, x, k, 0.0625, 0.125, 1.2)
    assert len(reference) == 16
    assert list(res.events["kind"]) == [name for _, name in reference]
    assert np.max(np.abs(res.events["t"] - [t for t, _ in reference])) < tol


# ---------------------------------------------------------------------------------------
# (f) Set down at rest on a compliant floor.
@pytest.mark.parametrize("bodies, ground_v", [(1, None), (1, 0.0), (3, None)])
def test_set_down_at_rest_on_a_compliant_floor(bodies, ground_v):
    """A body (or a stack of three touching, 6 kg in all) at rest exactly at a damped
    floor's limit (k = 1000, c = 20), under its weight: the stop engages at t = 0 (its ends
    at rest, accelerating into it; before, the gap closing was located at t = 0 again and
    again, and the run ended at the work limit) and the stack sinks to p_eq = M g / k as
    the damped oscillator from rest: p = p_eq (1 - e^(-zeta wn t) (cos(wd t) + zeta wn / wd
    sin(wd t))), wn = sqrt(k / M), zeta = c / (2 sqrt(k M)), wd = wn sqrt(1 - zeta^2). One
    body on a still floor and on one moving at 0 m/s (ground_v = 0), three on a still one; the samples within 1e-9 m of the closed form at dt = 1e-3, no other floor event."""
    masses = [6.0] if bodies == 1 else [1.0, 2.0, 3.0]
    k, c = 1000.0, 20.0
    floor = dict(a=0, b=1, d_min=0.0, k=k, c=c, name="floor")
    if ground_v is not None:
        floor["ground_v"] = ground_v
    links = [dict(a=i, b=i + 1, d_min=0.25, r_min=0.0, name=f"b{i}{i + 1}") for i in range(1, bodies)]
    res = impact1d.simulate(impact1d.Scene(m=masses, x=[0.25 * i for i in range(bodies)], v=[0.0] * bodies,
                                           f=[-G * m for m in masses], t_end=2.0, dt=1e-3, dt_out=1e-2,
                                           contacts=[floor] + links))
    assert list(events(res, "floor")) == [0.0] and len(events(res, "release_floor")) == 0
    M = mpmath.mpf(sum(masses))
    wn = mpmath.sqrt(k / M)
    zeta = c / (2 * mpmath.sqrt(k * M))
    wd = wn * mpmath.sqrt(1 - zeta ** 2)
    p_eq = M * G / k
    closed = [float(-p_eq * (1 - mpmath.exp(-zeta * wn * t) * (mpmath.cos(wd * t) + zeta * wn / wd *
                                                               mpmath.sin(wd * t)))) for t in res.t]
    assert np.max(np.abs(res.x[:, 0] - closed)) < 1e-9
    if bodies > 1:
        assert np.max(np.abs(np.diff(res.x, axis=1) - 0.25)) < 1e-12


# ---------------------------------------------------------------------------------------
# (g) A body resting on a compliant table vibrating as a sine.
@pytest.mark.parametrize("dt, tol", [(1e-3, 1e-10), (0.01, 2e-6)])
def test_body_on_a_vibrating_compliant_table(dt, tol):
    """A body (m = 1, weight m g) set down at rest at x = 0 on a compliant table (k = 1000,
    c = 40) whose surface moves as w = A sin(W t), A = 2 mm, W = 6 pi (ground_amp,
    ground_period = 1/3): the table rises at t = 0, so the stop engages at once, and its
    force k (w - x) + c (w' - x') stays positive (its least over the run is c A W = 1.5 N,
    at t = 0), so the body rides it as the driven damped oscillator m x'' + c x' + k x =
    -m g + k w + c w': x = -m g / k + Im(X e^(i W t)) + e^(-zeta wn t) (C1 cos(wd t) + C2
    sin(wd t)), X = (k + i c W) A / (k - m W^2 + i c W), C1 and C2 from x(0) = x'(0) = 0.
    The samples within tol of it (measured 4.4e-11 m at dt = 1e-3, 4.9e-7 at 0.01); the
    table's work through the stop (drive_work, the integral of F w') and the damper's loss
    (the integral of c (w' - x')^2), by mpmath's quadrature, within 100 tol (measured 2.4e-11
    and 2.9e-10 J at dt = 1e-3, 6e-7 and 5.8e-6 at 0.01); the ledger closes to RK4's
    quadrature of the drive's power (9.6e-10 and 1.1e-5 J)."""
    m, k, c, amp, period, t_end = 1.0, 1000.0, 40.0, 0.002, 1.0 / 3.0, 3.0
    res = impact1d.simulate(impact1d.Scene(
        m1=m, x1=0.0, v1=0.0, f1=-m * G, t_end=t_end, dt=dt, dt_out=1e-2,
        contacts=[dict(a=0, b=1, d_min=0.0, k=k, c=c, ground_amp=amp, ground_period=period, name="table")]))
    assert list(events(res, "table")) == [0.0] and len(res.events) == 1
    omega = 2 * mpmath.pi / period
    wn = mpmath.sqrt(mpmath.mpf(k) / m)
    zeta = c / (2 * mpmath.sqrt(mpmath.mpf(k) * m))
    wd = wn * mpmath.sqrt(1 - zeta ** 2)
    big_x = (k + 1j * c * omega) * amp / (k - m * omega ** 2 + 1j * c * omega)
    c1 = -(-m * G / k + mpmath.im(big_x))
    c2 = (-mpmath.im(1j * omega * big_x) + zeta * wn * c1) / wd

    def x(t):
        return (-m * G / k + mpmath.im(big_x * mpmath.exp(1j * omega * t)) +
                mpmath.exp(-zeta * wn * t) * (c1 * mpmath.cos(wd * t) + c2 * mpmath.sin(wd * t)))

    def rate(t):                       # w' - x', the penetration's rate
        return amp * omega * mpmath.cos(omega * t) - mpmath.diff(x, t)

    def push(t):
        return k * (amp * mpmath.sin(omega * t) - x(t)) + c * rate(t)

    assert np.max(np.abs(res.x1 - [float(x(t)) for t in res.t])) < tol
    assert min(float(push(t)) for t in np.linspace(0.0, t_end, 301)) > 1.0
    with mpmath.workdps(20):
        pieces = [i * period / 4 for i in range(int(4 * t_end / period) + 1)]
        work = mpmath.quad(lambda t: push(t) * amp * omega * mpmath.cos(omega * t), pieces)
        loss = mpmath.quad(lambda t: c * rate(t) ** 2, pieces)
    assert abs(res.drive_work[-1] - float(work)) < 100 * tol
    assert abs(res.damping_loss[-1] - float(loss)) < 100 * tol
    assert res.energy_residual < 100 * tol
