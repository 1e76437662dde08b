"""A held mode under a force table whose slope turns at a corner (issue 19/21, the tables'
mode crossing): the run stops at each corner (the force's rate jumps there), and the probe
that decides whether a held mode still holds sees the force's rate of the segment it is on;
at a step that ends on a corner, the rate after it (impact1d_forcing's `rate`, the right
derivative), which is the motion's next. (Checked: with the slope before the corner there
instead, every test below gives the same results: the probe's rate only breaks a tie of the
force with its bound, and a break-away counts only once the force is past it (mode_crossing's
`begun`); the event point at the corner solves the mode with the slope after it.) All on the
N-body engine (a still wall far away, x_left_v = 0, sends a one-body scene there).

(a) A block (m = 1, g = 10, mu = 0.3, mus = 0.5: the static bound S = 5) at rest on the
    floor, pushed by f(t) = s1 t up to a corner t_c (f(t_c) = s1 t_c < S), then by
    f(t_c) + s2 (t - t_c): it breaks away when f reaches S, just after the corner, at
        t_b = t_c + (S - s1 t_c) / s2,
    in closed form whatever dt, the corner inside a step of the grid or not; the same with a
    spring on the block (its force constant while the block is stuck: k (x0 - rest) more to
    overcome), whose steps are located RK4 steps instead of closed-form ones.
(b) The force reaching S exactly at the corner: turning down after it, the block stays stuck
    (static friction holds f <= S); turning up, it breaks away at the corner.
(c) Block on block (test_body_friction (b)): the lower block (m1, frictionless ground) under
    the table, the upper one (m2) held by the contact up to m2 f / (m1 + m2) = mus N: the
    slip at t_b with S replaced by mus N (m1 + m2) / m2.
"""

from __future__ import annotations

import pytest

import impact1d

M, G, MU, MUS = 1.0, 10.0, 0.3, 0.5
S = MUS * M * G
FAR_WALL = dict(x_left=-100.0, x_left_v=0.0)
STEPS = (1e-3, 0.07, 0.1, 0.3)


def write_table(path, rows):
    path.write_text("".join(f"{t!r} {f!r}\n" for t, f in rows))
    return str(path)


def turning_ramp(path, t_c, f_c, s2):
    """0 at t = 0, f_c at the corner t_c, then slope s2."""
    return write_table(path, [(0.0, 0.0), (t_c, f_c), (t_c + 100.0, f_c + 100.0 * s2)])


def events(result):
    return [(str(e["kind"]), float(e["t"])) for e in result.events]


@pytest.mark.parametrize("dt", STEPS)
@pytest.mark.parametrize("spring", [False, True])
@pytest.mark.parametrize("t_c, share, s2", [(0.45, 0.9, 100.0), (0.45, 0.999, 1.0e3), (0.45, 0.5, 1.0e5),
                                            (0.2, 0.99999, 3.0)])
def test_break_away_just_after_a_corner_is_the_closed_form(tmp_path, dt, spring, t_c, share, s2):
    """(a): f(t_c) = share of what breaks the block away."""
    k, x0 = (20.0, 0.1) if spring else (0.0, 0.0)
    need = S + k * x0
    f_c = share * need
    t_b = t_c + (need - f_c) / s2
    scene = impact1d.Scene(m1=M, mu1=MU, mus1=MUS, g=G, x1=x0, v1=0.0, k1=k, x1_rest=0.0,
                           f1_table=turning_ramp(tmp_path / "ramp.tab", t_c, f_c, s2), t_end=t_b + 0.2, dt=dt,
                           events="all", **FAR_WALL)
    log = events(impact1d.simulate(scene))
    assert log[0][0] == "slip1"
    assert log[0][1] == pytest.approx(t_b, abs=2e-15)


@pytest.mark.parametrize("dt", STEPS + (0.5, 1.0))
@pytest.mark.parametrize("after, slips", [(-5.0, False), (5.0, False), (15.0, True)])
def test_force_at_the_bound_on_a_corner_follows_the_slope_after_it(tmp_path, dt, after, slips):
    """(b): f = 10 t reaches S = 5 at the corner t = 0.5; then down to `after` at 1.5 (held
    at S for after = 5). The block slips at 0.5 only when f goes on rising: then v(1.2) =
    the integral of (f - mu m g) / m from 0.5 to 1.2 = 0.7 * 2 + 10 * 0.7^2 / 2."""
    table = write_table(tmp_path / "touch.tab", [(0.0, 0.0), (0.5, 5.0), (1.5, after)])
    scene = impact1d.Scene(m1=M, mu1=MU, mus1=MUS, g=G, x1=0.0, v1=0.0, f1_table=table, t_end=1.2, dt=dt,
                           events="all", **FAR_WALL)
    result = impact1d.simulate(scene)
    if slips:
        assert events(result) == [("slip1", 0.5)]
        assert result.v1[-1] == pytest.approx(0.7 * 2.0 + 10.0 * 0.7**2 / 2.0, abs=1e-14)
    else:
        assert events(result) == []
        assert result.v1[-1] == 0.0 and result.x1[-1] == 0.0


@pytest.mark.parametrize("dt", STEPS)
def test_block_on_block_slips_just_after_a_corner(tmp_path, dt):
    """(c): m1 = 2, m2 = 1, mu = 0.3, mus = 0.4, N = m2 g (g = 9.81); the lower block's force
    reaches 0.999 of mus N (m1 + m2) / m2 at the corner t_c = 0.45, then rises at 1000 N/s."""
    m1, m2, mu, mus, g = 2.0, 1.0, 0.3, 0.4, 9.81
    normal = m2 * g
    need = mus * normal * (m1 + m2) / m2
    t_c, s2 = 0.45, 1.0e3
    f_c = 0.999 * need
    t_b = t_c + (need - f_c) / s2
    scene = impact1d.Scene(m=[m1, m2], x=[0.0, 10.0], v=[0.0, 0.0], t_end=t_b + 0.2, dt=dt,
                           f_table=[turning_ramp(tmp_path / "ramp.tab", t_c, f_c, s2), None],
                           frictions=[{"a": 1, "b": 2, "mu": mu, "mus": mus, "normal": normal, "name": "pad"}])
    log = events(impact1d.simulate(scene))
    assert log[0][0] == "slip_pad"
    assert log[0][1] == pytest.approx(t_b, abs=2e-15)
