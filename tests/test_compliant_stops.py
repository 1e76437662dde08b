"""Compliant stops (issue 21 item 4): a `&contact` record with a stiffness `k` (and a damping
`c`) pushes back with F = max(0, k p + c p') past its limit (p: the penetration, p' its rate)
instead of an impact. Engagement and release are events located inside the step
(docs/method.md section 10); while engaged the stop is a spring and damper between the row's
ends with its rest at the limit, so RK4 keeps its order 4 between events.

Each test derives its closed form in its docstring and evaluates it with mpmath at 50 digits.
"""

from __future__ import annotations

import numpy as np
import pytest

import impact1d

mpmath = pytest.importorskip("mpmath")
mpmath.mp.dps = 50


def events(res, kind):
    return np.array([e["t"] for e in res.events if e["kind"] == kind])


# ---------------------------------------------------------------------------------------
# The Shaw-Holmes bilinear oscillator: m x'' = -k1 x, and below x = 0 also -k_stop x.
M, K1, K_STOP, AMPLITUDE = 1.0, 4.0, 12.0, 1.0


def bilinear_scene(dt, t_end=10.0):
    return impact1d.Scene(m1=M, x1=AMPLITUDE, v1=0.0, k1=K1, x1_rest=0.0, t_end=t_end, dt=dt,
                          contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": K_STOP, "name": "stop"}])


def bilinear_times(t_end, m=M, k1=K1, k_stop=K_STOP):
    """Free vibration of the bilinear oscillator from x = A > 0 at rest (m, k1 and the stop's
    k_stop: this file's oscillator unless given; tests/test_compliant_nbody.py runs three).

    Above the stop (x > 0) the motion is x = A cos(w1 t), w1 = sqrt(k1 / m): it reaches the
    stop at t = pi / (2 w1) with speed A w1. Inside (x < 0) the stiffness is k1 + k_stop and
    the equilibrium is still x = 0, so x = -(A w1 / w2) sin(w2 (t - t_e)), w2 = sqrt((k1 +
    k_stop) / m): a half sine of duration pi / w2, leaving at x = 0 with speed A w1 (the
    force k_stop p reaches zero at p = 0, c = 0). Then a half period of w1 back to A and
    again: period T = pi / w1 + pi / w2. Engagements at pi / (2 w1) + n T, releases pi / w2
    after each.
    """
    w1 = mpmath.sqrt(mpmath.mpf(k1) / m)
    w2 = mpmath.sqrt((mpmath.mpf(k1) + k_stop) / m)
    period = mpmath.pi / w1 + mpmath.pi / w2
    engage, release = [], []
    n = 0
    while True:
        t_e = mpmath.pi / (2 * w1) + n * period
        if t_e > t_end:
            break
        engage.append(float(t_e))
        if t_e + mpmath.pi / w2 < t_end:
            release.append(float(t_e + mpmath.pi / w2))
        n += 1
    return np.array(engage), np.array(release), float(period)


def bilinear_error(dt):
    res = impact1d.simulate(bilinear_scene(dt))
    engage, release, _ = bilinear_times(10.0)
    got_e, got_r = events(res, "stop"), events(res, "release_stop")
    assert len(got_e) == len(engage) and len(got_r) == len(release), (got_e, got_r)
    return max(np.max(np.abs(got_e - engage)), np.max(np.abs(got_r - release))), res


def test_bilinear_oscillator_period_at_fine_step():
    """At dt = 1e-3 every engagement and release over 10 s (4 periods of 3 pi / 4) is within
    1e-10 s of the closed form, so the period is too; no impact changes a velocity."""
    err, res = bilinear_error(1e-3)
    assert err < 1e-10
    engage, _, period = bilinear_times(10.0)
    got = events(res, "stop")
    assert np.max(np.abs(np.diff(got) - period)) < 2e-10
    for e in res.events:
        if e["kind"] == "stop":
            assert e["v1_before"] == e["v1_after"]


def test_bilinear_oscillator_converges_at_order_four():
    """Halving a coarse step (w2 dt = 0.2, 0.1, 0.05) divides the event-time error by about
    16: RK4's order 4 survives the switches, which are located inside the step."""
    errors = [bilinear_error(dt)[0] for dt in (0.05, 0.025, 0.0125)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[0] < 1e-4
    assert np.all((orders > 3.5) & (orders < 4.6)), (errors, orders)


def test_undamped_stop_conserves_energy():
    """Without damping nothing dissipates: KE + PE (the spring's and the stop's k p^2 / 2)
    stays at its start, k1 A^2 / 2 = 2 J, through 13 engagements (the ledger's residual is
    RK4's energy error, order 4), and there is no damping_loss column."""
    res = impact1d.simulate(bilinear_scene(1e-3, t_end=30.0))
    assert len(events(res, "stop")) == 13
    assert res.damping_loss is None
    total = res.ke + res.pe
    assert np.max(np.abs(total - 0.5 * K1 * AMPLITUDE ** 2)) < 1e-9
    assert res.energy_residual < 1e-9


def test_mass_thrown_onto_an_undamped_compliant_wall():
    """A free mass (no spring, no force) at x0 = 1 moving at v0 = -2 toward a wall at 0 with
    k = 100: it reaches the wall at t = x0 / |v0| = 0.5; inside, m p'' = -k p with p(0) = 0,
    p'(0) = 2: p = (2 / w) sin(w t), w = sqrt(k / m) = 10, a half sine ending (force k p = 0)
    at p = 0 after pi / w, leaving at +2 m/s with its energy whole. Then it flies away."""
    for dt in (1e-3, 0.02):
        res = impact1d.simulate(impact1d.Scene(
            m1=1.0, x1=1.0, v1=-2.0, t_end=2.0, dt=dt,
            contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": 100.0, "name": "wall"}]))
        t_release = float(mpmath.mpf("0.5") + mpmath.pi / 10)
        assert np.allclose(events(res, "wall"), [0.5], rtol=0, atol=1e-14)
        tol = 1e-10 if dt == 1e-3 else 1e-5
        assert np.abs(events(res, "release_wall") - t_release).max() < tol
        assert abs(res.v1[-1] - 2.0) < (1e-10 if dt == 1e-3 else 1e-4)
        assert abs(res.x1[-1] - 2.0 * (2.0 - t_release)) < (1e-9 if dt == 1e-3 else 1e-4)
        # Between the events the minimum position is the half sine's -v0 / w = -0.2.
        assert np.min(res.x1) >= -0.2 - 1e-9


def damped_closed_form(m, k, c, v0):
    """The linear spring-damper contact (Kelvin-Voigt) from p(0) = 0, p'(0) = v0 > 0:
    m p'' + c p' + k p = 0, wn = sqrt(k / m), zeta = c / (2 sqrt(k m)) < 1 / sqrt 2,
    wd = wn sqrt(1 - zeta^2): p = (v0 / wd) e^(-zeta wn t) sin(wd t), p' = v0 e^(-zeta wn t)
    (cos(wd t) - (zeta wn / wd) sin(wd t)). The contact cannot pull: it lets go where its
    force k p + c p' reaches zero, not where p does (p > 0 then, p' < 0):
    (wn^2 (1 - 2 zeta^2) / wd) sin + 2 zeta wn cos = 0, so
    wd t_r = pi - atan(2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2)). The coefficient of
    restitution is e = -p'(t_r) / v0 (the body then flies off freely at that speed)."""
    m, k, c, v0 = (mpmath.mpf(x) for x in (m, k, c, v0))
    wn = mpmath.sqrt(k / m)
    zeta = c / (2 * mpmath.sqrt(k * m))
    wd = wn * mpmath.sqrt(1 - zeta ** 2)
    t_r = (mpmath.pi - mpmath.atan(2 * zeta * mpmath.sqrt(1 - zeta ** 2) / (1 - 2 * zeta ** 2))) / wd
    rate = v0 * mpmath.exp(-zeta * wn * t_r) * (mpmath.cos(wd * t_r) - zeta * wn / wd * mpmath.sin(wd * t_r))
    depth = v0 / wd * mpmath.exp(-zeta * wn * t_r) * mpmath.sin(wd * t_r)
    return float(t_r), float(-rate / v0), float(depth)


def test_damped_stop_coefficient_of_restitution():
    """m = 1, k = 100, c = 4 (zeta = 0.2) hit at 2 m/s from x0 = 1 (engaged at t = 0.5):
    released at 0.5 + t_r with p = depth > 0 (the force's zero, not the position's), leaving
    at e v0; the ledger closes with what the stop dissipated in damping_loss: m v0^2 (1 -
    e^2) / 2 at the end (the stop's k p^2 / 2 left at the release falls to zero unforced
    and is booked there too)."""
    t_r, e, depth = damped_closed_form(1.0, 100.0, 4.0, 2.0)
    assert 0.0 < e < 1.0 and depth > 0.0
    res = impact1d.simulate(impact1d.Scene(
        m1=1.0, x1=1.0, v1=-2.0, t_end=1.5, dt=1e-3, dt_out=1e-3,
        contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": 100.0, "c": 4.0, "name": "wall"}]))
    assert np.allclose(events(res, "wall"), [0.5], rtol=0, atol=1e-14)
    release = events(res, "release_wall")
    assert len(release) == 1 and abs(release[0] - (0.5 + t_r)) < 1e-10
    assert abs(res.v1[-1] - e * 2.0) < 1e-9
    i = np.searchsorted(res.t, release[0])
    assert res.x1[i - 1] < 0.0          # still inside at the release
    assert abs(res.damping_loss[-1] - 0.5 * 4.0 * (1 - e ** 2)) < 1e-9
    assert res.energy_residual < 1e-9


def test_python_and_namelist_give_the_same_bits(tmp_path):
    """The same damped bilinear scene as Scene(contacts=[{..., "k", "c"}]) and as a file."""
    path = tmp_path / "stop.nml"
    path.write_text("&bodies m1 = 1.0 /\n&initial x1 = 1.0 /\n&springs k1 = 4.0, x1_rest = 0.0 /\n"
                    "&contact a = 0, b = 1, d_min = 0.0, k = 12.0, c = 0.5, name = 'stop' /\n"
                    "&run t_end = 8.0, dt = 1.0e-3 /\n")
    from_file = impact1d.simulate(impact1d.load_scene(path))
    scene = impact1d.Scene(m1=1.0, x1=1.0, k1=4.0, x1_rest=0.0, t_end=8.0, dt=1e-3,
                           contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": 12.0, "c": 0.5, "name": "stop"}])
    from_python = impact1d.simulate(scene)
    assert len(events(from_python, "stop")) > 2
    assert np.array_equal(from_file.x1, from_python.x1) and np.array_equal(from_file.v1, from_python.v1)
    assert np.array_equal(from_file.events, from_python.events)
    assert from_python.scene.contacts[0]["k"] == 12.0 and from_python.scene.contacts[0]["c"] == 0.5


def test_two_bodies_meeting_on_a_compliant_stop_conserve_momentum():
    """Two free bodies (m1 = 1 at 0 moving at 1, m2 = 2 at 1 at rest) meet on an undamped
    stop between them (d_min = 0.5 on x2 - x1): a spring of the reduced mass mu = 2/3, so
    the contact lasts pi sqrt(mu / k) and ends as an elastic impact would, v1 = -1/3,
    v2 = 2/3; momentum is 1 throughout."""
    k = 50.0
    res = impact1d.simulate(impact1d.Scene(
        m1=1.0, m2=2.0, x1=0.0, x2=1.0, v1=1.0, v2=0.0, d_min=-1e9, t_end=2.0, dt=1e-3,
        contacts=[{"a": 1, "b": 2, "d_min": 0.5, "k": k, "name": "buffer"}]))
    duration = float(mpmath.pi * mpmath.sqrt(mpmath.mpf(2) / 3 / k))
    assert np.allclose(events(res, "buffer"), [0.5], atol=1e-14, rtol=0)
    assert abs(events(res, "release_buffer")[0] - (0.5 + duration)) < 1e-10
    assert abs(res.v1[-1] + 1 / 3) < 1e-10 and abs(res.v2[-1] - 2 / 3) < 1e-10
    assert np.max(np.abs(res.v1 + 2.0 * res.v2 - 1.0)) < 1e-12


@pytest.mark.parametrize("fields, message", [
    ({"k": 0.0}, "k = 0.0 must be positive"),
    ({"k": -5.0}, "must be positive"),
    ({"k": 10.0, "c": -1.0}, "c = -1.0"),
    ({"c": 1.0}, "c is given but k is not"),
])
def test_bad_stop_values_are_refused(fields, message):
    scene = impact1d.Scene(m1=1.0, x1=1.0, t_end=1.0, dt=1e-3,
                           contacts=[{"a": 0, "b": 1, "d_min": 0.0, **fields}])
    with pytest.raises(impact1d.InputError, match=message):
        impact1d.simulate(scene)


def test_compliant_stops_are_refused_by_vissim():
    """The vissim method (the tutorial's scheme) has rigid contacts only; the N-body engine
    runs compliant stops (tests/test_compliant_nbody.py)."""
    one = impact1d.Scene(m1=1.0, x1=1.0, t_end=1.0, dt=1e-3, method="vissim",
                         contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": 1e4, "name": "soft"}])
    with pytest.raises(impact1d.InputError, match="'soft' has k = .*method = 'event'"):
        impact1d.simulate(one)


def test_rigid_rows_come_first_in_the_event_kinds():
    """The stop's rows follow the rigid ones (the walls, then rigid records), whatever the
    record order."""
    scene = impact1d.Scene(m1=1.0, x1=1.0, x_left=-1.0, t_end=1.0, dt=1e-3, contacts=[
        {"a": 0, "b": 1, "d_min": 0.0, "k": 100.0, "name": "soft"},
        {"a": 0, "b": 1, "d_max": 3.0, "name": "hard"}])
    kinds = impact1d.event_kinds(scene)
    assert kinds[:3] == ("left", "hard", "soft")


def test_step_past_a_stiff_stops_limit_is_refused_naming_it():
    """The stability check counts a stop as if engaged: k = 1e6 on m = 1 is w = 1000 rad/s,
    past RK4's w dt <= 2 sqrt 2 at dt = 0.01 (refused, naming the stop), coarse at dt =
    1e-3 (w dt = 1 > 0.5: a warning)."""
    def scene(dt):
        return impact1d.Scene(m1=1.0, x1=1.0, v1=-1.0, t_end=2.0, dt=dt,
                              contacts=[{"a": 0, "b": 1, "d_min": 0.0, "k": 1e6, "name": "soft"}])
    with pytest.raises(impact1d.InputError, match="set by the stop 'soft' \\(k = 1000000.0, c = 0.0\\)"):
        impact1d.simulate(scene(0.01))
    res = impact1d.simulate(scene(1e-3))
    assert any("the stop 'soft'" in w for w in res.warnings)


def test_cli_output_header_keeps_the_stop_and_its_ledger(tmp_path):
    """The CLI's run of a damped stop: its header records k and c (read_output rebuilds the
    scene, which runs to the same events), and its columns carry pe and damping_loss."""
    import subprocess
    from tools import find_tool
    scene_file = tmp_path / "s.nml"
    scene_file.write_text("&bodies m1 = 1.0 /\n&initial x1 = 1.0, v1 = -2.0 /\n&run t_end = 1.5, dt = 1e-3 /\n"
                          "&contact a = 0, b = 1, d_min = 0.0, k = 100.0, c = 4.0, name = 'wall' /\n")
    out = tmp_path / "s.dat"
    done = subprocess.run([find_tool("impact1d"), str(scene_file), "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "wall 1" in done.stdout and "release_wall 1" in done.stdout
    res = impact1d.read_output(out)
    assert res.scene.contacts == [dict(a=0, b=1, d_min=0.0, k=100.0, c=4.0, name="wall")]
    assert res.pe is not None and res.damping_loss is not None
    again = impact1d.simulate(res.scene)
    assert again.events.tobytes() == res.events.tobytes()
