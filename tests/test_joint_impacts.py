"""Simultaneous perfectly inelastic impacts are one joint impact (issue 13, item 7).

A body pinned between a wall and the other body, every contact with r = 0: sequential
impulses only approach the answer geometrically (and never settled for m2/m1 >= 2). The
joint impact is the projection of the pre-impact velocity, in the kinetic-energy metric,
onto the velocities no closed contact lets approach; for a pinned body that is rest.
Expected numbers are closed forms worked out beside each test.
"""

from pathlib import Path

import numpy as np
import pytest

import impact1d

# Times of a few tenths of a second from quotients of short decimals: rounding is ~1e-16;
# the bound is far below any real error (a missed or extra flight is >= 1e-3 s).
TIME_TOL = 1e-14

INPUT = Path(__file__).resolve().parents[1] / "input"


def pinned_scene(m1, m2, v2=-5.0):
    """Body 1 against the left wall, body 2 against it through the slot, moving in."""
    return impact1d.Scene(m1=m1, m2=m2, x_left=0.0, r_left=0.0, d_min=1.0, r_min=0.0,
                          x1=0.0, v1=0.0, x2=1.0, v2=v2, t_end=1.0, dt=1e-3)


@pytest.mark.parametrize("m2_over_m1", [0.25, 1.0, 2.0, 3.0, 10.0, 1e6])
def test_pinned_body_stops_at_once(m2_over_m1):
    res = impact1d.simulate(pinned_scene(1.0, m2_over_m1))
    # Everything stops at t = 0: the whole kinetic energy m2 v2^2 / 2 is lost there.
    assert np.all(res.v1 == 0.0) and np.all(res.v2 == 0.0)
    assert np.all(res.x1 == 0.0) and np.all(res.x2 == 1.0)
    assert res.impact_loss[-1] == 0.5 * m2_over_m1 * 25.0
    impacts = res.events[np.isin(res.events["kind"], ["left", "slot_min"])]
    assert np.all(impacts["t"] == 0.0)
    # One joint impact: each contact takes its impulse once, all at the same instant.
    assert sorted(impacts["kind"]) == ["left", "slot_min"]
    assert res.energy_residual == 0.0


def test_leaving_body_is_not_held():
    # Body 2 moves away: only the wall acts on body 1 (v1 -> 0), body 2 keeps its speed.
    scene = pinned_scene(1.0, 2.0, v2=3.0)
    res = impact1d.simulate(scene, v1=-1.0, t_end=0.1)
    assert res.v1[-1] == 0.0 and res.v2[-1] == 3.0
    assert list(res.events["kind"][:1]) == ["left"]


def test_case3_perfectly_inelastic():
    """Case 3 with every restitution 0 (it failed at t = 0.714 s): a closed-form history.

    x1 = 1 - 9t, x2 = 2.5 + t: the slot opens to d_max = 2 at t = 0.05, where the bodies
    take the common velocity (1 * -9 + 2 * 1) / 3 = -7/3. Body 1 (at x1 = 0.55) reaches
    the wall at t = 0.05 + 0.55 / (7/3) = 2/7 and stops; body 2 (at x2 = 2) keeps -7/3
    until the slot closes to d_min = 1 at t = 2/7 + 1 / (7/3) = 5/7: body 2 pinned, both
    at rest, all 41.5 J lost.
    """
    scene = impact1d.load_scene(INPUT / "case3.nml")
    res = impact1d.simulate(scene, r_left=0.0, r_right=0.0, r_min=0.0, r_max=0.0)
    ev = res.events
    first = {k: ev["t"][ev["kind"] == k][0] for k in ("slot_max", "slot_min")}
    left = ev["t"][ev["kind"] == "left"]
    assert abs(first["slot_max"] - 0.05) < TIME_TOL
    assert abs(left[0] - 2.0 / 7.0) < TIME_TOL
    assert abs(first["slot_min"] - 5.0 / 7.0) < TIME_TOL
    assert res.v1[-1] == 0.0 and res.v2[-1] == 0.0
    assert res.x1[-1] == 0.0 and abs(res.x2[-1] - 1.0) < TIME_TOL
    assert abs(res.impact_loss[-1] - 41.5) < 1e-12
