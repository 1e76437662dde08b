"""The N-body engine's closed-form steps (src/impact1d_nbody_glide.f90) against the 50-digit
reference (tests/exact_nbody.py) on constant-force scenes of five bodies, at dt = 1e-3 and at
dt = 0.1: under constant forces RK4 is exact, so the glided steps and the located ones give
the reference's events and final state at either step.  (One and two bodies, which ran on
the two-body engine until session 12: tests/fortran/test_nbody_glide.f90 runs them through
run_nbody, glide on and off, bit for bit, and against closed forms.)
"""

from __future__ import annotations

import pytest

import impact1d

mpmath = pytest.importorskip("mpmath", reason="mpmath is needed by tests/exact_nbody.py")
from mpmath import mp, mpf  # noqa: E402

import exact_nbody as nb  # noqa: E402
from test_nbody_engine import (assert_final_matches, assert_log_matches, engine_scene,  # noqa: E402
                               random_chain)

FIVE_BODY_SEEDS = (22, 38)      # random_chain's chains of five bodies
STEPS = (1e-3, 0.1)


@pytest.fixture(autouse=True)
def _precision():
    with mp.workdps(nb.DPS):
        yield


@pytest.mark.parametrize("dt", STEPS)
@pytest.mark.parametrize("seed", FIVE_BODY_SEEDS)
def test_five_body_chain_matches_the_reference(seed, dt):
    scene = random_chain(seed)
    assert len(scene["m"]) == 5
    sol = nb.solve(scene)
    res = impact1d.simulate(engine_scene(scene, dt=dt, dt_out=0.1))
    assert_log_matches(res, sol, at_least=2)
    assert_final_matches(res, *sol.final)


def free_five(t_end: float = 2.0) -> dict:
    """Five bodies under constant forces moving apart, with links and walls they do not
    reach before t_end: a free flight, x0 + v0 t + f t^2 / 2m."""
    return dict(m=[1.0, 2.0, 0.5, 1.5, 3.0], x=[0.0, 2.0, 4.0, 6.0, 8.0], v=[-0.5, -0.25, 0.0, 0.25, 0.5],
                mu=[0.0, 0.0, 0.0, 0.0, 0.0], f=[-0.25, -0.125, 0.0, 0.25, 1.0], g=9.8125,
                contacts=[dict(a=i, b=i + 1, d_min=0.25, r_min=0.5, name=f"link{i}") for i in range(1, 5)] +
                [dict(a=0, b=1, d_min=-5.0, r_min=0.5, name="left"), dict(a=0, b=5, d_max=20.0, r_max=0.5,
                                                                            name="right")],
                t_end=t_end)


@pytest.mark.parametrize("dt", STEPS)
def test_five_body_free_flight_is_the_closed_form(dt):
    scene = free_five()
    sol = nb.solve(scene)
    assert not sol.events
    t = mpf(scene["t_end"])
    x = [mpf(a) + mpf(u) * t + mpf(f) / mpf(m) * t**2 / 2
         for a, u, f, m in zip(scene["x"], scene["v"], scene["f"], scene["m"])]
    v = [mpf(u) + mpf(f) / mpf(m) * t for u, f, m in zip(scene["v"], scene["f"], scene["m"])]
    assert max(abs(a - b) for a, b in zip(x, sol.final[0])) < mpf(10) ** -30
    res = impact1d.simulate(engine_scene(scene, dt=dt, dt_out=0.5))
    assert not len(res.events)
    assert_final_matches(res, x, v)


def test_five_bodies_under_tables_match_the_reference(tmp_path):
    """Under force tables (the forces linear between corners, the motion a cubic) the glided
    steps end where RK4's located ones do: five bodies with friction, body 1 under case 6's
    triangle (0 -> 30 -> 0 -> -30 -> 0 N over 4 s), body 5 under a ramp that breaks it away
    from static friction at 1.5 s; links and walls that the motion reaches, at dt = 1e-3 and
    0.1, against tests/exact_nbody.py's events and final state."""
    from test_nbody_stress import engine_scene_with_tables
    scene = free_five(t_end=5.0)
    scene.update(f=[0.0, -0.125, 0.0, 0.25, 0.0], mu=[0.25, 0.0, 0.125, 0.0, 0.0625], mus=[0.25, 0.0, 0.125, 0.0, 0.125],
                 f_table=[([0.0, 1.0, 2.0, 3.0, 4.0], [0.0, 30.0, 0.0, -30.0, 0.0]), None, None, None,
                          ([0.0, 4.0], [0.0, 8.0])])
    scene["v"][4] = 0.0
    sol = nb.solve(scene)
    for dt in STEPS:
        res = impact1d.simulate(engine_scene_with_tables(scene, dt, tmp_path))
        assert_log_matches(res, sol, at_least=2)
        assert_final_matches(res, *sol.final)
