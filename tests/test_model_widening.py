"""Issue 10: static friction above sliding friction, springs and dampers, bodies that meet.

Every scene is checked against the closed forms of tests/exact_springs.py (50 digits):
exact to rounding where the motion is polynomial, at the integrator's order with springs.
Body 2 is parked far to the right (at rest, no force) where a scene is about one body: it
never reaches body 1, so body 1's motion is the one-body reference's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import impact1d
from impact1d import InputError

import exact_springs as xs

G = 10.0
FAR = 1.0e3          # where body 2 is parked in the one-body scenes


def one_body(**fields):
    """A scene about body 1, body 2 parked at rest far to its right."""
    return impact1d.Scene(m2=1.0, x2=FAR, **fields)


def engine_events(res, kinds):
    return [(str(e["kind"]), float(e["t"])) for e in res.events if e["kind"] in kinds]


def reference_events(ref, kinds):
    return [(e.kind, float(e.t)) for e in ref.events if e.kind in kinds]


def ramp_table(tmp_path, t_end, f_end, name="ramp.dat"):
    path = tmp_path / name
    path.write_text(f"0 0\n{t_end!r} {f_end!r}\n")
    return str(path)


# --- static friction ------------------------------------------------------------------

@pytest.mark.parametrize("dt", [0.1, 1e-3])
def test_ramp_breaks_away_at_the_static_bound_then_follows_the_cubic(tmp_path, dt):
    """f = 4 t against mus m g = 5 N (mu m g = 3 N): at rest until t = 1.25 exactly, then
    m a = 4 t - 3: the cubic, to rounding, at dt = 0.1 and 1e-3."""
    m, mu, mus, rate, t_end = 1.0, 0.3, 0.5, 4.0, 3.0
    table = ramp_table(tmp_path, 10.0, 40.0)
    res = impact1d.simulate(one_body(m1=m, mu1=mu, mus1=mus, g=G, x1=0.0, f1_table=table,
                                     t_end=t_end, dt=dt, dt_out=0.05))
    ref = xs.friction_block(m, mu, mus, 0.0, rate, t_end, g=G)
    assert float(xs.ramp_breakaway_time(m, mus, 0.0, rate, g=G)) == 1.25
    got = engine_events(res, ("slip1", "stick1"))
    want = reference_events(ref, ("slip1", "stick1"))
    assert [k for k, _ in got] == [k for k, _ in want] == ["slip1"]
    assert got[0][1] == pytest.approx(1.25, rel=1e-15, abs=0)
    for t, x, v in zip(res.t, res.x1, res.v1):
        (x_ref,), (v_ref,) = ref.state(t)
        assert x == pytest.approx(float(x_ref), rel=1e-13, abs=1e-13), t
        assert v == pytest.approx(float(v_ref), rel=1e-13, abs=1e-13), t
    assert res.energy_residual < 1e-12


@pytest.mark.parametrize("dt", [0.1, 1e-3])
def test_sliding_into_a_force_static_friction_holds_stops_and_stays(dt):
    """v0 = 2 m/s against f = -4 N, mu m g = 3 N, mus m g = 5 N: sliding friction alone
    cannot hold 4 N, static can: the body stops at m v0 / (c + |f|) = 2/7 s and stays."""
    m, mu, mus, f, v0 = 1.0, 0.3, 0.5, -4.0, 2.0
    res = impact1d.simulate(one_body(m1=m, mu1=mu, mus1=mus, g=G, x1=0.0, v1=v0, f1=f,
                                     t_end=2.0, dt=dt, dt_out=0.1))
    ref = xs.friction_block(m, mu, mus, f, 0.0, 2.0, v0=v0, g=G)
    want = reference_events(ref, ("stick1", "slip1", "reverse1"))
    assert want == [("stick1", pytest.approx(2.0 / 7.0, rel=1e-15))]
    got = engine_events(res, ("stick1", "slip1"))
    assert len(got) == 1 and got[0][0] == "stick1"
    assert got[0][1] == pytest.approx(2.0 / 7.0, rel=1e-14, abs=0)
    after = res.t > got[0][1]
    assert np.all(res.v1[after] == 0.0)
    (x_stop,), _ = ref.state(1.0)
    np.testing.assert_allclose(res.x1[after], float(x_stop), rtol=1e-14)
    # Without static friction above sliding friction it slides back.
    back = impact1d.simulate(one_body(m1=m, mu1=mu, g=G, x1=0.0, v1=v0, f1=f, t_end=2.0, dt=dt))
    assert back.v1[-1] < 0.0


@pytest.mark.parametrize("dt", [0.1, 0.01, 1e-3])
def test_sine_force_breaks_away_where_static_equals_sliding_friction(dt):
    """mus = mu (the default): a body stuck under f = -5 + 2 sin(2 pi t) N breaks away when
    the force reaches -mu m g = -4 N again, at t = 5/12 s, with zero acceleration (the net
    force is zero there). The step's cubic dipped the velocity below zero at once, and the
    stop was located at the break-away instant again and again (SimulationError)."""
    scene = impact1d.Scene(m1=1.0, mu1=0.4, g=10.0, x1=0.0, f1=-5.0, f1_amp=2.0, f1_period=1.0,
                           t_end=1.0, dt=dt)
    res = impact1d.simulate(scene)
    assert list(res.events["kind"]) == ["stick1", "slip1"]
    assert res.events["t"][1] == pytest.approx(5.0 / 12.0, abs=1e-12)
    assert res.v1[-1] < 0.0


def test_spring_breaks_away_where_static_equals_sliding_friction():
    """A spring k12 pulled by a constant force on body 2 (frictionless) against body 1 held
    by friction (mus = mu = 1): body 1 breaks away when k12 d = mu m1 g, on the harmonic arc
    d(t) = f2/k12 (1 - cos(w t)), w = sqrt(k12/m2), with zero net force on it there."""
    scene = impact1d.Scene(m1=3.0, m2=1.0, mu1=1.0, g=10.0, f2=32.0, d_min=0.0, r_min=0.0,
                           x1=0.0, x2=0.0, k12=28.0, d_rest=0.0, t_end=0.5, dt=1e-3)
    t_break = math.acos(1.0 - 3.0 * 10.0 / 32.0) / math.sqrt(28.0)
    res = impact1d.simulate(scene)
    assert list(res.events["kind"]) == ["slip1"]
    assert res.events["t"][0] == pytest.approx(t_break, abs=1e-10)


def test_static_friction_is_the_vissim_methods_bound_at_rest():
    """The tutorial's scheme holds a body at rest while |f| <= mus m g too."""
    held = impact1d.simulate(one_body(m1=1.0, mu1=0.3, mus1=0.5, g=G, x1=0.0, f1=4.0,
                                      t_end=1.0, dt=1e-3, method="vissim"))
    assert np.all(held.v1 == 0.0) and np.all(held.x1 == 0.0)
    moved = impact1d.simulate(one_body(m1=1.0, mu1=0.3, g=G, x1=0.0, f1=4.0,
                                       t_end=1.0, dt=1e-3, method="vissim"))
    assert moved.x1[-1] == pytest.approx(0.5, rel=1e-2)      # (4 - 3) t^2 / 2


# --- springs ----------------------------------------------------------------------------

def oscillator_impacts(dt, n_checked=None):
    m, k, x_left = 1.0, 4.0, 0.0
    res = impact1d.simulate(one_body(m1=m, x1=0.5, k1=k, x1_rest=x_left, x_left=x_left,
                                     r_left=0.8, t_end=20.0, dt=dt, dt_out=0.01))
    got = [t for kind, t in engine_events(res, ("left",))]
    want = [float(t) for t in xs.equilibrium_wall_impact_times(m, k, x_left, 0.5, 0.0, len(got))]
    assert len(got) == 13          # 20 s of half periods pi/2 after the first quarter
    return max(abs(a - b) for a, b in zip(got, want)), res


def test_impact_oscillator_at_its_equilibrium_hits_on_the_closed_form_order_4():
    """A spring-mass whose equilibrium is the wall: every arc is half a period, so impact n
    is at (2 n - 1) pi/4 s; within 1e-9 s at dt = 1e-3, the error falling as dt^4."""
    errors = {dt: oscillator_impacts(dt)[0] for dt in (4e-3, 2e-3, 1e-3)}
    assert errors[1e-3] < 1e-9
    order = math.log2(errors[2e-3] / errors[1e-3])
    assert 3.5 < order < 4.6, errors
    _, res = oscillator_impacts(1e-3)
    assert res.columns == ("t", "x1", "v1", "x2", "v2", "ke", "pe", "work", "friction_loss",
                           "impact_loss", "residual")
    np.testing.assert_allclose(res.pe[0], 0.5 * 4.0 * 0.25)
    assert res.energy_residual < 1e-12


def test_stick_slip_oscillator_follows_the_closed_form_limit_cycle(tmp_path):
    """A block on a spring to the ground pulled by an anchor at V = 0.5 m/s (written as
    the ramp k V t): stick and slip instants within 1e-8 s of the closed form over 60 s
    (over 90 cycles) at dt = 1e-3; the cycle settles on stick_slip_cycle's durations."""
    m, k, mu, mus, t_end = 1.0, 100.0, 0.3, 0.5, 60.0
    pull = 0.5 * k
    table = ramp_table(tmp_path, t_end, pull * t_end)
    res = impact1d.simulate(one_body(m1=m, x1=0.0, k1=k, x1_rest=0.0, mu1=mu, mus1=mus,
                                     g=xs.DEFAULT_G, f1_table=table, t_end=t_end, dt=1e-3,
                                     dt_out=0.01))
    ref = xs.stick_slip(m, k, 0.0, pull, mu, mus, 0.0, 0.0, t_end)
    got = engine_events(res, ("stick1", "slip1"))
    want = reference_events(ref, ("stick1", "slip1"))
    assert [kind for kind, _ in got] == [kind for kind, _ in want]
    assert len(want) >= 2 * 20
    assert max(abs(a - b) for (_, a), (_, b) in zip(got, want)) < 1e-8
    cycle = xs.stick_slip_cycle(m, k, pull, mu, mus)
    slips = [t for kind, t in got if kind == "slip1"]
    period = float(cycle["period"])
    assert slips[-1] - slips[-2] == pytest.approx(period, abs=1e-8)
    assert res.energy_residual < 1e-6          # the ramp's work: order 4 (4e-7 J measured), not rounding


@pytest.mark.parametrize("c12", [0.0, 0.5, 4.0, 8.0])   # undamped, under, critical, over
def test_damped_pair_keeps_momentum_and_closes_its_ledger(c12):
    """A spring and damper between free bodies, every damping regime: momentum constant to
    rounding, the ledger residual <= 1e-9 J, the state and the dampers' loss on the
    closed form at the integrator's order."""
    m1, m2, k12, d_rest = 1.0, 2.0, 6.0, 1.0
    x1, v1, x2, v2 = 0.0, 1.0, 1.5, -0.25
    scene = impact1d.Scene(m1=m1, m2=m2, x1=x1, v1=v1, x2=x2, v2=v2, k12=k12, d_rest=d_rest,
                           c12=c12, t_end=10.0, dt=1e-3, dt_out=0.05)
    res = impact1d.simulate(scene)
    assert len(res.events) == 0               # the bodies never meet
    momentum = m1 * res.v1 + m2 * res.v2
    np.testing.assert_allclose(momentum, m1 * v1 + m2 * v2, rtol=0, atol=1e-14)
    assert res.energy_residual <= 1e-9
    ref = xs.damped_pair(m1, m2, k12, c12, d_rest, x1, v1, x2, v2)
    for j in range(0, len(res.t), 20):
        (rx1, rx2), (rv1, rv2) = ref.state(res.t[j])
        assert res.x1[j] == pytest.approx(float(rx1), abs=1e-10)
        assert res.x2[j] == pytest.approx(float(rx2), abs=1e-10)
        assert res.pe[j] == pytest.approx(float(ref.pe(res.t[j])), abs=1e-10)
        assert res.damping_loss[j] == pytest.approx(float(ref.damping_loss(res.t[j])), abs=1e-9)


def test_dampers_to_the_ground_alone_have_no_potential_energy_column():
    res = impact1d.simulate(one_body(m1=2.0, x1=0.0, v1=1.0, c1=0.5, t_end=4.0, dt=1e-3, dt_out=0.5))
    assert "pe" not in res.columns and "damping_loss" in res.columns
    # m v' = -c v: v = e^{-t/4}, all kinetic energy lost to the damper.
    np.testing.assert_allclose(res.v1, np.exp(-res.t / 4.0), rtol=1e-11)
    np.testing.assert_allclose(res.damping_loss, 1.0 - np.exp(-res.t / 2.0), rtol=0, atol=1e-11)


def test_vissim_method_runs_spring_scenes():
    """The tutorial's scheme with the spring force added: its impact times are O(dt) off."""
    _, event_run = oscillator_impacts(1e-3)
    res = impact1d.simulate(one_body(m1=1.0, x1=0.5, k1=4.0, x1_rest=0.0, x_left=0.0,
                                     r_left=0.8, t_end=20.0, dt=1e-3, dt_out=0.01,
                                     method="vissim"))
    hits = [t for kind, t in engine_events(res, ("left",))]
    assert len(hits) == 13
    assert abs(hits[0] - math.pi / 4.0) < 5e-3
    assert np.all(res.x1 >= 0.0)
    assert abs(res.pe[-1] + res.ke[-1] - (event_run.pe[-1] + event_run.ke[-1])) < 1e-2 * res.pe[0]


# --- bodies that meet --------------------------------------------------------------------

@pytest.mark.parametrize("r_min", [None, 0.5])
def test_bodies_without_a_link_meet_and_exchange_momentum(r_min):
    """No d_min: the bodies collide at x2 = x1 (restitution r_min, default 1), at the
    closed-form instant, momentum kept."""
    m, f, x0, v0 = (1.0, 3.0), (0.5, -1.5), (0.0, 2.0), (1.0, -0.5)
    fields = dict(m1=m[0], m2=m[1], f1=f[0], f2=f[1], x1=x0[0], v1=v0[0], x2=x0[1], v2=v0[1],
                  t_end=3.0, dt=0.1, dt_out=0.1)
    if r_min is not None:
        fields["r_min"] = r_min
    res = impact1d.simulate(impact1d.Scene(**fields))
    ref = xs.constant_force_bodies(m, f, x0, v0, 3.0, r_meet=1.0 if r_min is None else r_min)
    want = reference_events(ref, ("slot_min",))
    got = engine_events(res, ("slot_min",))
    assert len(want) >= 1 and [k for k, _ in got] == [k for k, _ in want]
    for (_, a), (_, b) in zip(got, want):
        assert a == pytest.approx(b, rel=1e-14)
    hit = res.events[res.events["kind"] == "slot_min"][0]
    assert m[0] * hit["v1_before"] + m[1] * hit["v2_before"] == pytest.approx(
        m[0] * hit["v1_after"] + m[1] * hit["v2_after"], rel=1e-15)
    assert np.all(res.x2 >= res.x1)


def test_bodies_that_start_crossed_are_refused():
    with pytest.raises(InputError, match=r"slot_min constraint \(d_min = 0.* by default: the bodies meet"):
        impact1d.simulate(impact1d.Scene(m1=1.0, m2=1.0, x1=1.0, x2=0.0, t_end=1.0, dt=0.1))
    # Given a far lower limit, they may pass each other.
    res = impact1d.simulate(impact1d.Scene(m1=1.0, m2=1.0, x1=1.0, x2=0.0, v2=1.0, d_min=-10.0,
                                           t_end=3.0, dt=0.1))
    assert res.x2[-1] > res.x1[-1]


# --- input -------------------------------------------------------------------------------

@pytest.mark.parametrize("fields, message", [
    (dict(mu1=0.5, mus1=0.3), r"mus1 = 0.3 is below mu1 = 0.5"),
    (dict(mus2=-0.1), r"mus2 = -0.1 must not be negative"),
    (dict(k1=10.0), r"k1 is given but x1_rest is not: a spring needs its rest position"),
    (dict(x2_rest=1.0), r"x2_rest is given but k2 is not"),
    (dict(k12=-1.0, d_rest=1.0), r"k12 = -1.0? must not be negative"),
    (dict(c1=-0.5), r"c1 = -0.5 must not be negative"),
    (dict(d_max=-1.0), r"d_max = -1.0? is negative, but without d_min the bodies meet"),
])
def test_bad_springs_and_friction_are_refused(fields, message):
    scene = impact1d.Scene(m1=1.0, m2=1.0, x1=0.0, x2=2.0, t_end=1.0, dt=0.1, **fields)
    with pytest.raises(InputError, match=message):
        impact1d.simulate(scene)


def test_namelist_springs_group_and_cli_columns(tmp_path):
    """&springs in a namelist; the CLI's output names pe and damping_loss only when the scene
    has them, and read_output reads them back."""
    from tools import find_tool
    import subprocess
    scene = tmp_path / "pair.nml"
    scene.write_text("&bodies m1 = 1.0, m2 = 2.0, mu1 = 0.1, mus1 = 0.2 /\n"
                     "&initial x1 = 0.0, v1 = 1.0, x2 = 1.5 /\n"
                     "&springs k12 = 6.0, d_rest = 1.0, c12 = 0.5 /\n"
                     "&run t_end = 2.0, dt = 1e-3, dt_out = 0.1 /\n")
    loaded = impact1d.load_scene(scene)
    assert (loaded.k12, loaded.d_rest, loaded.c12, loaded.mus1) == (6.0, 1.0, 0.5, 0.2)
    out = tmp_path / "pair.dat"
    run = subprocess.run([find_tool("impact1d"), str(scene), "-o", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "PE =" in run.stdout and "damping loss =" in run.stdout
    header = [line for line in out.read_text().splitlines() if line.startswith("#")]
    assert header[-1] == "# t x1 v1 x2 v2 ke pe work friction_loss impact_loss damping_loss residual"
    back = impact1d.read_output(out)
    direct = impact1d.simulate(loaded)
    assert back.columns == direct.columns
    for name in direct.columns:
        np.testing.assert_allclose(getattr(back, name), getattr(direct, name), rtol=1e-15, atol=1e-300)


@pytest.mark.parametrize("dt", [0.1, 1e-3])
def test_a_ramp_against_two_touching_blocks_breaks_away_at_the_sum_of_static_bounds(tmp_path, dt):
    """A ramp of 4 N/s pushes block 1 into block 2 (they touch: the bodies meet): the pair
    holds until the ramp reaches (mus1 m1 + mus2 m2) g = 13 N, at 3.25 s (not at one
    body's sliding bound plus the other's static one, 11 N), then slides as one body:
    3 a = 4 t - 7, to rounding (input/breakaway.nml)."""
    table = ramp_table(tmp_path, 10.0, 40.0)
    res = impact1d.simulate(impact1d.Scene(m1=1.0, m2=2.0, mu1=0.3, mus1=0.5, mu2=0.2, mus2=0.4,
                                           g=G, x1=0.0, x2=0.0, f1_table=table, t_end=5.0,
                                           dt=dt, dt_out=0.05))
    slips = [t for kind, t in engine_events(res, ("slip1", "slip2"))]
    assert len(slips) == 2 and slips == pytest.approx([3.25, 3.25], rel=1e-15)
    t = res.t
    moving = t > 3.25
    v = (2.0 * (t**2 - 3.25**2) - 7.0 * (t - 3.25)) / 3.0
    x = (2.0 / 3.0 * (t**3 - 3.25**3) - 2.0 * 3.25**2 * (t - 3.25) - 3.5 * (t - 3.25)**2) / 3.0
    np.testing.assert_allclose(res.v1[moving], v[moving], rtol=1e-13)
    np.testing.assert_allclose(res.x1[moving], x[moving], rtol=1e-12)
    np.testing.assert_array_equal(res.x1, res.x2)
    assert np.all(res.v1[~moving] == 0.0)


# --- one-body scenes -----------------------------------------------------------------------

def test_one_body_between_two_walls_follows_the_closed_form():
    """m1 only: both walls bound body 1; the outputs carry only what exists."""
    res = impact1d.simulate(impact1d.Scene(m1=2.0, x1=1.0, v1=3.0, f1=-1.0, x_left=0.0, r_left=0.5,
                                           x_right=2.0, r_right=0.9, t_end=4.0, dt=0.1, dt_out=0.1))
    ref = xs.constant_force_bodies((2.0,), (-1.0,), (1.0,), (3.0,), 4.0, x_left=0.0, x_right=2.0,
                                   r_left=0.5, r_right=0.9)
    kinds = ("left", "right")
    got, want = engine_events(res, kinds), reference_events(ref, kinds)
    assert len(want) >= 3 and [k for k, _ in got] == [k for k, _ in want]
    for (_, a), (_, b) in zip(got, want):
        assert a == pytest.approx(b, rel=1e-13, abs=1e-13)
    assert res.columns == ("t", "x1", "v1", "ke", "work", "friction_loss", "impact_loss", "residual")
    assert res.x2 is None and res.v2 is None
    assert res.events.dtype == impact1d.ONE_BODY_EVENT_DTYPE
    assert np.all((res.x1 >= 0.0) & (res.x1 <= 2.0))
    assert res.energy_residual < 1e-12


def test_one_body_impact_oscillator_on_its_own(tmp_path):
    """The spring-mass on a wall without a parked second body: the same impacts."""
    res = impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.5, k1=4.0, x1_rest=0.0, x_left=0.0,
                                           r_left=0.8, t_end=20.0, dt=1e-3, dt_out=0.01))
    _, parked = oscillator_impacts(1e-3)
    np.testing.assert_array_equal(res.events["t"], parked.events["t"])
    np.testing.assert_array_equal(res.x1, parked.x1)


@pytest.mark.parametrize("field", ["x2", "v2", "mu2", "f2", "k12", "d_min", "r_max", "k2"])
def test_one_body_scene_refuses_what_needs_a_second_body(field):
    extra = {"k12": dict(k12=1.0, d_rest=1.0), "k2": dict(k2=1.0, x2_rest=0.0)}.get(field, {field: 0.5})
    with pytest.raises(InputError, match=f"{field} is given but m2 is not: a scene without m2 has one body"):
        impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.0, t_end=1.0, dt=0.1, **extra))


def test_one_body_files_name_their_columns(tmp_path):
    """CLI output of a one-body scene: no x2/v2 columns, events without v2, read back whole;
    the plot and a sweep take it too."""
    from tools import find_tool
    import subprocess
    scene = tmp_path / "block.nml"
    scene.write_text("&bodies m1 = 1.0, mu1 = 0.2, mus1 = 0.4 /\n"
                     "&walls x_left = 0.0, r_left = 0.5, x_right = 1.0 /\n"
                     "&initial x1 = 0.5, v1 = 4.0 /\n&run t_end = 2.0, dt = 1e-3, dt_out = 0.01 /\n")
    out = tmp_path / "block.dat"
    run = subprocess.run([find_tool("impact1d"), str(scene), "-o", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "x2 =" not in run.stdout
    header = [line for line in out.read_text().splitlines() if line.startswith("#")]
    assert header[-1] == "# t x1 v1 ke work friction_loss impact_loss residual"
    events_header = (tmp_path / "block.events.dat").read_text().splitlines()[1]
    assert events_header == "# t kind v1_before v1_after"
    back = impact1d.read_output(out)
    direct = impact1d.simulate(impact1d.load_scene(scene))
    assert back.columns == direct.columns and back.x2 is None
    np.testing.assert_allclose(back.x1, direct.x1, rtol=1e-15)
    assert list(back.events["kind"]) == list(direct.events["kind"])
    np.testing.assert_allclose(back.events["v1_after"], direct.events["v1_after"], rtol=1e-15)
    import matplotlib
    matplotlib.use("Agg")
    impact1d.plot.save(direct, tmp_path / "block.png")
    assert (tmp_path / "block.png").stat().st_size > 0
    table = impact1d.sweep(impact1d.load_scene(scene), {"v1": [1.0, 4.0]}, workers=1)
    assert table["x2_end"].isna().all() and table["error"].eq("").all()
    np.testing.assert_allclose(table["x1_end"].iloc[1], direct.x1[-1], rtol=0, atol=0)


def test_vissim_method_runs_one_body_scenes():
    """The tutorial's scheme on a one-body scene: both walls clamp body 1, the impacts are
    the event method's to O(dt)."""
    scene = impact1d.Scene(m1=2.0, x1=1.0, v1=3.0, f1=-1.0, x_left=0.0, r_left=0.5, x_right=2.0,
                           r_right=0.9, t_end=4.0, dt=1e-3)
    exact, approx = impact1d.simulate(scene), impact1d.simulate(scene, method="vissim")
    assert approx.columns == exact.columns and approx.x2 is None
    assert np.all((approx.x1 >= 0.0) & (approx.x1 <= 2.0))
    assert list(approx.events["kind"]) == list(exact.events["kind"])
    np.testing.assert_allclose(approx.events["t"], exact.events["t"], rtol=0, atol=5e-3)


def test_spring_mass_released_from_a_wall_by_a_turning_sine_force_leaves_it():
    """Resting on a wall, pressed by a sine force against its spring: when the force turns,
    the contact is released with a rounding-level acceleration away. The step's Hermite
    cubic (the motion is not a cubic with a spring and a damper) dipped 3e-21 m below the
    wall, which was located again and again at the same instant (found by the
    bifurcation study: 'more than 100000 events within one step')."""
    scene = impact1d.Scene(m1=1.0, x1=0.0, x_left=-0.05, r_left=0.8, k1=40.0, x1_rest=0.0, c1=0.4,
                           f1_amp=4.2142857142857135, f1_period=2.4, t_end=5.0, dt=1e-3, dt_out=0.01)
    res = impact1d.simulate(scene)
    releases = res.events[res.events["kind"] == "release_left"]
    assert len(releases) >= 1 and releases["t"][0] == pytest.approx(4.6111215688, abs=1e-9)
    assert res.x1[-1] > -0.05 and np.all(res.x1 >= -0.05)
    assert res.energy_residual < 1e-8


def _random_spring_scene(rng):
    """A random scene with springs, dampers, static friction, walls, a link, sine forcing."""
    kw = dict(m1=float(rng.uniform(0.3, 3)), x1=0.0, v1=float(rng.uniform(-3, 3)), t_end=3.0, dt=1e-3,
              dt_out=0.01)
    if rng.random() < 0.6:
        kw["mu1"] = float(rng.uniform(0, 0.5))
        kw["mus1"] = kw["mu1"] + float(rng.uniform(0, 0.4))
    if rng.random() < 0.7:
        kw.update(k1=float(rng.uniform(0, 200)), x1_rest=float(rng.uniform(-1, 1)))
    if rng.random() < 0.5:
        kw["c1"] = float(rng.uniform(0, 5))
    if rng.random() < 0.6:
        kw.update(x_left=-float(rng.uniform(0, 1)), r_left=float(rng.choice([0, 0.5, 1])))
    if rng.random() < 0.6:
        kw.update(x_right=float(rng.uniform(1.5, 3)), r_right=float(rng.choice([0, 0.5, 1])))
    if rng.random() < 0.5:
        kw.update(f1_amp=float(rng.uniform(0, 30)), f1_period=float(rng.uniform(0.2, 3)))
    if rng.random() < 0.7:
        kw.update(m2=float(rng.uniform(0.3, 3)), x2=float(rng.uniform(0.0, 1.0)), v2=float(rng.uniform(-3, 3)),
                  r_min=float(rng.choice([0, 0.5, 1])))
        if rng.random() < 0.5:
            kw["mu2"] = float(rng.uniform(0, 0.5))
            kw["mus2"] = kw["mu2"] + float(rng.uniform(0, 0.4))
        if rng.random() < 0.5:
            kw.update(k12=float(rng.uniform(0, 300)), d_rest=float(rng.uniform(0, 1)),
                      c12=float(rng.uniform(0, 3)))
        if rng.random() < 0.5:
            kw.update(d_max=kw["x2"] + float(rng.uniform(0, 0.5)), r_max=float(rng.choice([0, 0.5, 1])))
    return impact1d.Scene(**kw)


@pytest.mark.parametrize("seed", range(4))
def test_random_spring_scenes_keep_their_constraints_and_ledger(seed):
    """Seeded random mechanisms (springs, dampers, static friction, walls, link, sine): at
    dt = 1e-3 every run ends, no body crosses a wall or the other body, and the ledger
    closes to the integrator's order (<= 1e-6 of the run's energy scale)."""
    rng = np.random.default_rng([10, seed])
    for n in range(25):
        scene = _random_spring_scene(rng)
        res = impact1d.simulate(scene)
        x_left = -np.inf if scene.x_left is None else scene.x_left
        x_right = np.inf if scene.x_right is None else scene.x_right
        assert res.x1.min() >= x_left - 1e-12, (n, scene)
        if res.x2 is not None:
            assert res.x2.max() <= x_right + 1e-12 and np.all(res.x2 - res.x1 >= -1e-12), (n, scene)
        else:
            assert res.x1.max() <= x_right + 1e-12, (n, scene)
        energy = res.ke + (res.pe if res.pe is not None else 0.0)
        scale = max(1.0, float(energy.max()), abs(float(res.work[-1])))
        assert res.energy_residual <= 1e-6 * scale, (n, res.energy_residual, scene)


def test_spring_pressing_a_mass_into_a_wall_rattles_to_rest_at_the_closed_form_time():
    """The spring's rest position 0.2 m behind the wall: each impact (r = 0.5) shortens the
    next arc, the impacts accumulate (closed form: tests/exact_springs.py sums the series)
    and the mass rests on the wall from then on."""
    m, k, x_rest, r = 1.0, 4.0, -0.2, 0.5
    ref = xs.impact_oscillator(m, k, x_rest, 0.0, r, 0.3, 0.0, 5.0)
    t_rest = float(ref.times("rest_left")[0])
    res = impact1d.simulate(one_body(m1=m, x1=0.3, k1=k, x1_rest=x_rest, x_left=0.0, r_left=r,
                                     t_end=5.0, dt=1e-3, dt_out=0.01))
    rests = res.events[res.events["kind"] == "rest_left"]
    assert len(rests) == 1 and abs(rests["t"][0] - t_rest) < 1e-8
    first = [float(t) for t in ref.times("left")[:4]]
    np.testing.assert_allclose(res.events[res.events["kind"] == "left"]["t"][:4], first, rtol=0, atol=1e-9)
    after = res.t > t_rest
    assert np.all(res.x1[after] == 0.0) and np.all(res.v1[after] == 0.0)
