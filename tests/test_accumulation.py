"""Accumulations over several contacts end in a joint rest at their limit time (issue 19
item 5; docs/method.md section 9, "Accumulation over several contacts").

(a) Issue 19's scene: a light body (m1 = 0.1, r = 0.5 at the wall) squeezed onto a wall by a
    heavy one (m2 = 6.0 pushed with 175 N, r_min = 0.93 between them). The bounces alternate
    between the wall and the slot, their durations shrinking by 0.5715 per cycle while the
    speeds shrink by only 0.90: a single-contact Zeno rule never applies, and the series
    chattered at 1e-13 m/s into the work limit. The exact answer (a 50-digit event-driven
    solution, the same from the cycle map's geometric rate): both bodies at rest on the wall
    from t* = 0.37055460858296240 s. Two-body engine.
(b) A three-contact accumulation: two light balls between a wall and a heavy body pressing
    them onto it (rows wall-1, 1-2, 2-3), against tests/exact_nbody.py. N-body engine.
Each at dt = 1e-3, 1e-2 and 0.1: the rests within 1e-12 s of the exact limit, every body at
rest after it, no work-limit error.
"""

from __future__ import annotations

import numpy as np
import pytest

import impact1d

mpmath = pytest.importorskip("mpmath", reason="mpmath is needed by tests/exact_nbody.py")
import exact_nbody as nb  # noqa: E402

LIMIT_TOL = 1e-12
STEPS = (1e-3, 1e-2, 0.1)

ISSUE_SCENE = impact1d.Scene(m1=0.1, m2=6.0, mu1=1.0, f1=-4.0, f2=-175.0, d_min=0.0, r_min=0.93, x1=2.0,
                             x2=2.0, x_left=0.0, r_left=0.5, t_end=1.0, dt=0.01)
ISSUE_LIMIT = 0.37055460858296240

STACK = dict(m=[0.1, 0.2, 6.0], x=[1.0, 1.5, 2.0], v=[0.0, 0.0, -1.0], mu=[0.0] * 3, mus=[0.0] * 3,
             f=[-1.0, -2.0, -150.0], g=9.80665, t_end=1.0,
             contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.5, name="wall"),
                       dict(a=1, b=2, d_min=0.25, r_min=0.8, name="s12"),
                       dict(a=2, b=3, d_min=0.25, r_min=0.9, name="s23")])


def rests(res) -> dict:
    """The time each row's last rest is logged at."""
    return {str(kind)[5:]: float(t) for t, kind in zip(res.events["t"], res.events["kind"])
            if str(kind).startswith("rest_")}


@pytest.mark.parametrize("dt", STEPS)
def test_issue_scene_rests_at_its_limit(dt):
    res = impact1d.simulate(ISSUE_SCENE, dt=dt)
    got = rests(res)
    assert abs(got["left"] - ISSUE_LIMIT) < LIMIT_TOL and abs(got["slot_min"] - ISSUE_LIMIT) < LIMIT_TOL
    assert res.v1[-1] == 0.0 and res.v2[-1] == 0.0 and res.x1[-1] == 0.0 and res.x2[-1] == 0.0
    # the last events are the two rests: nothing chatters after the limit
    assert sorted(str(k) for k in res.events["kind"][-2:]) == ["rest_left", "rest_slot_min"]


@pytest.fixture(scope="module")
def stack_limit():
    sol = nb.solve(STACK)
    limits = {e.kind[5:]: float(e.t) for e in sol.events if e.kind.startswith("rest_")}
    assert set(limits) == {"wall", "s12", "s23"} and len(set(limits.values())) == 1
    return limits["wall"]


@pytest.mark.parametrize("dt", STEPS)
def test_three_contact_stack_rests_at_its_limit(dt, stack_limit):
    scene = impact1d.Scene(m=STACK["m"], x=STACK["x"], v=STACK["v"], f=STACK["f"], g=STACK["g"],
                           t_end=STACK["t_end"], dt=dt, contacts=STACK["contacts"])
    res = impact1d.simulate(scene)
    got = rests(res)
    assert set(got) == {"wall", "s12", "s23"}
    assert all(abs(t - stack_limit) < LIMIT_TOL for t in got.values()), (got, stack_limit)
    assert np.array_equal(res.v[-1], np.zeros(3)) and np.array_equal(res.x[-1], [0.0, 0.25, 0.5])
