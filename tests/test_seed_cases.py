"""The six test cases of the VisSim tutorial (input/case1..6.nml) against exact answers.

With constant (or piecewise-linear) forces the motion between events is a polynomial
that RK4 reproduces exactly, so the event-driven engine should match closed forms to
rounding level whatever dt is (docs/method.md section 3).  Every expected number below is
worked out from the physics in the comments next to it.
"""

import math
from pathlib import Path

import numpy as np
import pytest

import impact1d
import exact_reference

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"

# --- tolerances ---------------------------------------------------------------
# Event times: the issue's bound. Location should be at rounding level (~1e-13) for
# polynomial motion; 1e-9 s is still 1e-6 of the smallest dt used here.
EVENT_TIME_TOL = 1e-9
# States against closed forms: rounding accumulated over at most 6000 RK4 steps of
# values <= 10 is ~1e-12; 1e-9 leaves room and still catches any real error.
STATE_TOL = 1e-9
# Kinetic energy and ledger columns (J): the issue's bound.
ENERGY_TOL = 1e-9
# The run's own accuracy monitor, max |KE - KE0 - W + D + Q| (J): the issue's bound.
RESIDUAL_TOL = 1e-9
# The pure-Python reference against hand-worked times (a few flights of O(1) values).
REFERENCE_TOL = 1e-14
# Numbers the issue quotes rounded to 6 decimals.
ISSUE_ROUNDING = 5e-7
# A body that friction holds has zero acceleration, so it must not drift at all
# beyond rounding of its (unchanged) position.
AT_REST_TOL = 1e-12
# No step may end with a gap below zero (docs/method.md 3); allow only the rounding of
# x2 - x1 at |x| <= 10 (~2e-15).
GAP_TOL = 1e-12
# Velocities jump at impacts; whether a sample exactly at an impact time shows the
# state before or after is a convention, so velocity checks skip samples this close.
JUMP_GUARD = 1e-6
# Output times are k * dt_out.
GRID_TOL = 1e-12
# KE 1 ms before a case-5 impact is within 0.4 % of its value at the impact.
ONE_MS_BEFORE_REL = 0.01
# KE after a rattling stop: both velocities are set to zero by the persistent contact.
KE_AT_REST_TOL = 1e-12

IMPACTS = ("left", "right", "slot_min", "slot_max")
CASES = (1, 2, 3, 4, 5, 6)

_runs = {}


def run(case, **overrides):
    """The run of input/case<N>.nml (cached: several tests look at the same run)."""
    key = (case, tuple(sorted(overrides.items())))
    if key not in _runs:
        scene = impact1d.load_scene(INPUT / f"case{case}.nml")
        _runs[key] = impact1d.simulate(scene, **overrides)
    return _runs[key]


def impacts(res):
    return res.events[np.isin(res.events["kind"], IMPACTS)]


def events_of(res, kind):
    return res.events[res.events["kind"] == kind]


def away_from(t, times, guard=JUMP_GUARD):
    """Mask of samples not within `guard` of any of `times`."""
    mask = np.ones(t.shape, dtype=bool)
    for te in np.atleast_1d(times):
        mask &= np.abs(t - te) > guard
    return mask


def assert_close(got, want, tol, what):
    got, want = np.broadcast_arrays(np.asarray(got, float), np.asarray(want, float))
    err = np.abs(got - want)
    if err.size and not np.all(err <= tol):
        i = int(np.argmax(err))
        raise AssertionError(f"{what}: max error {err[i]:.3e} > {tol:g} at index {i} "
                             f"(got {got.flat[i]!r}, want {want.flat[i]!r})")


# --- every seed case ----------------------------------------------------------

@pytest.mark.parametrize("case", CASES)
def test_energy_residual_small(case):
    res = run(case)
    assert res.energy_residual < RESIDUAL_TOL
    assert np.max(np.abs(res.residual)) < RESIDUAL_TOL
    # The contract: energy_residual is max |residual| over the samples, the same numbers.
    assert res.energy_residual == np.max(np.abs(res.residual))


@pytest.mark.parametrize("case", CASES)
def test_output_grid(case):
    res = run(case)
    s = res.scene
    n = round(s.t_end / s.dt_out) + 1
    assert len(res.t) == n
    assert_close(res.t, np.arange(n) * s.dt_out, GRID_TOL, "sample times")
    for name in res.columns:
        column = getattr(res, name)
        assert column.dtype == np.float64 and column.shape == (n,), name
        assert np.all(np.isfinite(column)), name


@pytest.mark.parametrize("case", CASES)
def test_no_penetration(case):
    res = run(case)
    s = res.scene
    assert np.all(res.x1 - s.x_left >= -GAP_TOL)
    assert np.all(s.x_right - res.x2 >= -GAP_TOL)
    assert np.all((res.x2 - res.x1) - s.d_min >= -GAP_TOL)
    assert np.all(s.d_max - (res.x2 - res.x1) >= -GAP_TOL)


@pytest.mark.parametrize("case", CASES)
def test_ke_column_is_kinetic_energy(case):
    res = run(case)
    s = res.scene
    assert_close(res.ke, 0.5 * s.m1 * res.v1**2 + 0.5 * s.m2 * res.v2**2,
                 ENERGY_TOL, "ke column")


@pytest.mark.parametrize("case", CASES)
def test_dat_input_matches_nml(case):
    """input<N>.dat (the tutorial's parameter files) runs the same scene as case<N>.nml."""
    nml = run(case)
    dat_scene = impact1d.load_scene(INPUT / f"input{case}.dat")
    assert dat_scene.g == 10.0  # the tutorial's g, implied by the .dat format
    for name in ("t_end", "dt", "dt_out"):  # these come from the command line
        assert getattr(dat_scene, name) is None, name
    for name in impact1d._scene.REAL_FIELDS:
        if name in ("t_end", "dt", "dt_out"):
            continue
        want = getattr(nml.scene, name)
        got = getattr(dat_scene, name)
        assert (got or 0.0) == (want or 0.0), name
    if case == 6:
        assert Path(dat_scene.f1_table).samefile(INPUT / "triangle.dat")
        assert Path(nml.scene.f1_table).samefile(INPUT / "triangle.dat")
    dat = impact1d.simulate(dat_scene, t_end=nml.scene.t_end, dt=nml.scene.dt,
                            dt_out=nml.scene.dt_out)
    assert np.array_equal(nml.samples, dat.samples)
    assert np.array_equal(nml.events, dat.events)


# --- case 1: every force is below its friction bound --------------------------
# c1 = mu m1 g = 10 N > |f1| = 6 N and c2 = 20 N > |f2| = 10 N: nothing moves.

def test_case1_nothing_moves():
    res = run(1)
    assert_close(res.x1, 1.0, AT_REST_TOL, "x1")
    assert_close(res.x2, 2.5, AT_REST_TOL, "x2")
    assert_close(res.v1, 0.0, AT_REST_TOL, "v1")
    assert_close(res.v2, 0.0, AT_REST_TOL, "v2")
    assert np.all(res.ke == 0.0) or np.max(res.ke) < AT_REST_TOL
    for name in ("work", "friction_loss", "impact_loss"):
        assert_close(getattr(res, name), 0.0, ENERGY_TOL, name)
    kinds = set(res.events["kind"])
    assert not kinds & {*IMPACTS, "slip1", "slip2"}, kinds


# --- case 2: both slide to a stop --------------------------------------------
# v1 = v2 = 1, no force; friction decelerates each at mu g = 10 m/s^2, so both stop
# at t = 0.1 after 1 * 0.1 - 5 * 0.01 = 0.05 m: x1 = 1.05, x2 = 2.55.

def test_case2_slide_to_stop():
    res = run(2)
    t_stop = 0.1
    for kind in ("stick1", "stick2"):
        ev = events_of(res, kind)
        assert len(ev) == 1, res.events
        assert abs(ev["t"][0] - t_stop) < EVENT_TIME_TOL
    assert len(impacts(res)) == 0
    t = np.minimum(res.t, t_stop)
    assert_close(res.x1, 1.0 + t - 5.0 * t**2, STATE_TOL, "x1")
    assert_close(res.x2, 2.5 + t - 5.0 * t**2, STATE_TOL, "x2")
    assert_close(res.v1, 1.0 - 10.0 * t, STATE_TOL, "v1")
    assert_close(res.v2, 1.0 - 10.0 * t, STATE_TOL, "v2")
    after = res.t >= t_stop
    assert_close(res.x1[after], 1.05, STATE_TOL, "x1 at rest")
    assert_close(res.x2[after], 2.55, STATE_TOL, "x2 at rest")
    assert_close(res.ke[after], 0.0, AT_REST_TOL, "ke at rest")
    # Friction dissipates c_i * distance (both move right only): 10 dx1 + 20 dx2.
    assert_close(res.friction_loss, 10.0 * (res.x1 - 1.0) + 20.0 * (res.x2 - 2.5),
                 ENERGY_TOL, "friction_loss")
    assert res.friction_loss[-1] == pytest.approx(1.5, abs=ENERGY_TOL)  # all of KE0


# --- case 3: elastic, frictionless: energy is conserved -----------------------
# KE0 = 1 * 81 / 2 + 2 * 1 / 2 = 41.5 J.  x2 - x1 = 1.5 grows at 10 m/s: slot_max at
# 0.05; Newton's law gives v = (13/3, -17/3), the slot closes at -10 m/s to slot_min at
# 0.15, which restores (-9, 1); so the pair alternates every 0.1 s while its centre
# drifts at -7/3 m/s.  x1 = 31/60 at 0.35, then -9 m/s reaches the wall at
# 0.35 + 31/540 = 11/27 s.

CASE3_FIRST = [(0.05, "slot_max"), (0.15, "slot_min"), (0.25, "slot_max"),
               (0.35, "slot_min"), (11.0 / 27.0, "left")]


def _case3_reference():
    scene = run(3).scene
    return exact_reference.simulate_exact(scene)


def test_case3_energy_conserved():
    res = run(3)
    assert_close(res.ke, 41.5, ENERGY_TOL, "ke")
    for name in ("work", "friction_loss", "impact_loss"):
        assert_close(getattr(res, name), 0.0, ENERGY_TOL, name)


def test_case3_first_impacts():
    ev = impacts(run(3))
    for (t, kind), e in zip(CASE3_FIRST, ev[:len(CASE3_FIRST)]):
        assert e["kind"] == kind
        assert abs(e["t"] - t) < EVENT_TIME_TOL, (kind, e["t"], t)
    first = ev[0]  # slot_max at 0.05: (-9, 1) -> (13/3, -17/3)
    assert_close([first["v1_before"], first["v2_before"], first["v1_after"],
                  first["v2_after"]], [-9.0, 1.0, 13.0 / 3.0, -17.0 / 3.0],
                 STATE_TOL, "velocities at the first impact")


def test_case3_wall_impacts_quoted_by_issue():
    ev = impacts(run(3))
    right = ev[ev["kind"] == "right"]["t"]
    left = ev[ev["kind"] == "left"]["t"]
    assert np.any(np.abs(right - 2.745614) < ISSUE_ROUNDING), right
    assert np.any(np.abs(left - 4.568075) < ISSUE_ROUNDING), left
    # The tutorial: "a right wall collision around 2.73 sec and a left wall collision
    # around 4.6 sec".
    assert len(right) == 1 and abs(right[0] - 2.73) < 0.02


def test_case3_reference_is_right():
    """The pure-Python reference itself reproduces the hand-worked numbers."""
    events, _ = _case3_reference()
    for (t, kind), e in zip(CASE3_FIRST, events):
        assert e[1] == kind and abs(e[0] - t) < REFERENCE_TOL
    walls = [(e[0], e[1]) for e in events if e[1] in ("left", "right")]
    assert [k for _, k in walls] == ["left", "right", "left", "left"]
    assert abs(walls[1][0] - 2.745614) < ISSUE_ROUNDING
    assert abs(walls[2][0] - 4.568075) < ISSUE_ROUNDING


def test_case3_all_impacts_match_exact_reference():
    res = run(3)
    events, _ = _case3_reference()
    got = impacts(res)
    assert [str(k) for k in got["kind"]] == [e[1] for e in events]
    assert_close(got["t"], [e[0] for e in events], EVENT_TIME_TOL, "impact times")
    for name, i in (("v1_before", 2), ("v2_before", 3), ("v1_after", 4), ("v2_after", 5)):
        assert_close(got[name], [e[i] for e in events], STATE_TOL, name)


def test_case3_trajectory_matches_exact_reference():
    res = run(3)
    events, segments = _case3_reference()
    want = np.array(exact_reference.state_at(segments, 0.0, 0.0, res.t))
    assert_close(res.x1, want[:, 0], STATE_TOL, "x1")
    assert_close(res.x2, want[:, 2], STATE_TOL, "x2")
    smooth = away_from(res.t, [e[0] for e in events])
    assert_close(res.v1[smooth], want[smooth, 1], STATE_TOL, "v1")
    assert_close(res.v2[smooth], want[smooth, 3], STATE_TOL, "v2")


# --- case 4: perfectly inelastic slot_min impact --------------------------------
# m1 slides at 10 m/s decelerating at 10 (m2 rests: no force on it): gap
# 1.8 - 10 t + 5 t^2 = 0 at t = 0.2 (v1 = 8).  r = 0: both move at 8/3 m/s, each
# decelerating at mu g = 10 m/s^2 (no link force needed), stopping after 4/15 s, at
# t = 7/15 = 0.466667, after (8/3)^2 / 20 = 16/45 m: x1 = x2 = 2.8 + 16/45 = 3.155556.
# KE: 50 J -> 32 J before the impact, 32/3 J after (Q = 64/3), rest dissipated.

CASE4_IMPACT = 0.2
CASE4_STOP = 7.0 / 15.0
CASE4_REST = 2.8 + 16.0 / 45.0


def test_case4_inelastic_impact():
    res = run(4)
    ev = impacts(res)
    assert len(ev) == 1, ev
    e = ev[0]
    assert e["kind"] == "slot_min"
    assert abs(e["t"] - CASE4_IMPACT) < EVENT_TIME_TOL
    assert_close([e["v1_before"], e["v2_before"], e["v1_after"], e["v2_after"]],
                 [8.0, 0.0, 8.0 / 3.0, 8.0 / 3.0], STATE_TOL, "impact velocities")


def test_case4_pair_stops_together():
    res = run(4)
    assert abs(CASE4_STOP - 0.466667) < ISSUE_ROUNDING
    assert abs(CASE4_REST - 3.155556) < ISSUE_ROUNDING
    for kind in ("stick1", "stick2"):
        ev = events_of(res, kind)
        assert len(ev) >= 1, res.events
        assert abs(ev["t"][-1] - CASE4_STOP) < EVENT_TIME_TOL, ev
    t = res.t
    before = t <= CASE4_IMPACT
    s = np.clip(t - CASE4_IMPACT, 0.0, CASE4_STOP - CASE4_IMPACT)
    x1 = np.where(before, 1.0 + 10.0 * t - 5.0 * t**2, 2.8 + 8.0 / 3.0 * s - 5.0 * s**2)
    x2 = np.where(before, 2.8, 2.8 + 8.0 / 3.0 * s - 5.0 * s**2)
    v1 = np.where(before, 10.0 - 10.0 * t, 8.0 / 3.0 - 10.0 * s)
    v2 = np.where(before, 0.0, 8.0 / 3.0 - 10.0 * s)
    assert_close(res.x1, x1, STATE_TOL, "x1")
    assert_close(res.x2, x2, STATE_TOL, "x2")
    smooth = away_from(t, [CASE4_IMPACT])
    assert_close(res.v1[smooth], v1[smooth], STATE_TOL, "v1")
    assert_close(res.v2[smooth], v2[smooth], STATE_TOL, "v2")
    rest = t >= CASE4_STOP
    assert_close(res.x1[rest], CASE4_REST, STATE_TOL, "x1 at rest")
    assert_close(res.x2[rest], CASE4_REST, STATE_TOL, "x2 at rest")
    assert_close(res.ke[rest], 0.0, AT_REST_TOL, "ke at rest")


def test_case4_ledger():
    res = run(4)
    # Friction: 10 N on m1 and 20 N on m2, all motion to the right.
    assert_close(res.friction_loss, 10.0 * (res.x1 - 1.0) + 20.0 * (res.x2 - 2.8),
                 ENERGY_TOL, "friction_loss")
    after = res.t > CASE4_IMPACT + JUMP_GUARD
    assert_close(res.impact_loss[after], 64.0 / 3.0, ENERGY_TOL, "impact_loss")
    assert res.friction_loss[-1] == pytest.approx(50.0 - 64.0 / 3.0, abs=ENERGY_TOL)
    assert_close(res.work, 0.0, ENERGY_TOL, "work")


# --- case 5: rattling stop against both walls -----------------------------------
# a1 = -2 / 1, a2 = 4 / 2 = 2: x1 = 1 - t^2 and x2 = 9 + t^2 reach the walls together
# at t = 1 with |v| = 2 (KE = 6 t^2 -> 6 J).  r = 0.5: each flight lasts 2 w / 2 = w
# (w = rebound speed), so the impacts are at t_k = 3 - 2^(1-k) = 1, 2, 2.5, 2.75, ...
# with speed 3 - t_k before (KE = 6 (3 - t_k)^2 / 4 -> 1.5 J before t = 2), and
# accumulate at t = 3.0, where both rest against their walls: x1 = 0, x2 = 10.

CASE5_REST = 3.0


def _case5_exact(t):
    """Closed-form state (x1, v1, x2, v2) of case 5 at the times t."""
    t = np.asarray(t, float)
    x1, v1, x2, v2 = (np.zeros_like(t) for _ in range(4))
    first = t < 1.0
    x1[first], v1[first] = 1.0 - t[first] ** 2, -2.0 * t[first]
    x2[first], v2[first] = 9.0 + t[first] ** 2, 2.0 * t[first]
    flying = (t >= 1.0) & (t < CASE5_REST)
    tf = t[flying]
    k = np.floor(-np.log2(CASE5_REST - tf))             # 3 - t in (2^-(k+1), 2^-k]
    tk = CASE5_REST - 2.0 ** (-k)                        # last impact at or before t
    # Guard the floor at exact powers of two against rounding of log2.
    tk = np.where(tk > tf, CASE5_REST - 2.0 ** (-k + 1), tk)
    w = (CASE5_REST - tk) / 2.0                          # rebound speed
    s = tf - tk
    x1[flying], v1[flying] = w * s - s**2, w - 2.0 * s
    x2[flying], v2[flying] = 10.0 - w * s + s**2, -w + 2.0 * s
    x2[t >= CASE5_REST] = 10.0
    return x1, v1, x2, v2


def test_case5_wall_impacts():
    res = run(5)
    ev = impacts(res)
    assert not np.any(np.isin(ev["kind"], ("slot_min", "slot_max")))
    for kind in ("left", "right"):
        times = ev[ev["kind"] == kind]["t"]
        assert len(times) >= 4, times
        assert_close(times[:4], [1.0, 2.0, 2.5, 2.75], EVENT_TIME_TOL, f"{kind} times")
        k = np.arange(len(times))
        assert_close(times, CASE5_REST - 2.0 ** (1 - k), EVENT_TIME_TOL,
                     f"all {kind} impact times")
        assert np.all(times < CASE5_REST + EVENT_TIME_TOL)
    # Each impact reverses the hitting body at half speed; speed before = 3 - t.
    for e in ev:
        u = CASE5_REST - e["t"]
        if e["kind"] == "left":
            got, want = [e["v1_before"], e["v1_after"]], [-u, u / 2.0]
        else:
            got, want = [e["v2_before"], e["v2_after"]], [u, -u / 2.0]
        assert_close(got, want, STATE_TOL, f"{e['kind']} at {e['t']}")


def test_case5_kinetic_energy_before_impacts():
    res = run(5)
    ev = impacts(res)
    for t_hit, ke_before in ((1.0, 6.0), (2.0, 1.5)):
        at = ev[np.abs(ev["t"] - t_hit) < EVENT_TIME_TOL]
        left = at[at["kind"] == "left"][0]
        right = at[at["kind"] == "right"][0]
        ke = 0.5 * 1.0 * left["v1_before"] ** 2 + 0.5 * 2.0 * right["v2_before"] ** 2
        assert ke == pytest.approx(ke_before, abs=ENERGY_TOL)
        i = int(np.argmin(np.abs(res.t - (t_hit - 1e-3))))  # the sample just before
        _, v1, _, v2 = _case5_exact(res.t[i:i + 1])
        assert res.ke[i] == pytest.approx(0.5 * v1[0] ** 2 + v2[0] ** 2, abs=ENERGY_TOL)
        assert res.ke[i] == pytest.approx(ke_before, rel=ONE_MS_BEFORE_REL)


def test_case5_rattles_to_rest_at_3s():
    res = run(5)
    for kind in ("rest_left", "rest_right"):
        ev = events_of(res, kind)
        assert len(ev) == 1, res.events
        assert abs(ev["t"][0] - CASE5_REST) < EVENT_TIME_TOL, ev
    rest = res.t >= CASE5_REST - GRID_TOL
    assert rest.sum() == 201  # 3.0, 3.001, ..., 3.2
    assert_close(res.x1[rest], 0.0, STATE_TOL, "x1 at rest")
    assert_close(res.x2[rest], 10.0, STATE_TOL, "x2 at rest")
    assert_close(res.ke[rest], 0.0, KE_AT_REST_TOL, "ke at rest")
    later = res.t > CASE5_REST + JUMP_GUARD
    assert np.all(res.v1[later] == 0.0) and np.all(res.v2[later] == 0.0)
    assert len(events_of(res, "release_left")) == 0
    assert len(events_of(res, "release_right")) == 0


def test_case5_trajectory():
    res = run(5)
    x1, v1, x2, v2 = _case5_exact(res.t)
    assert_close(res.x1, x1, STATE_TOL, "x1")
    assert_close(res.x2, x2, STATE_TOL, "x2")
    smooth = away_from(res.t, CASE5_REST - 2.0 ** (1 - np.arange(40)))
    assert_close(res.v1[smooth], v1[smooth], STATE_TOL, "v1")
    assert_close(res.v2[smooth], v2[smooth], STATE_TOL, "v2")


def test_case5_ledger():
    res = run(5)
    # Constant forces: W = f1 (x1 - x1(0)) + f2 (x2 - x2(0)).
    assert_close(res.work, -2.0 * (res.x1 - 1.0) + 4.0 * (res.x2 - 9.0), ENERGY_TOL, "work")
    assert_close(res.friction_loss, 0.0, ENERGY_TOL, "friction_loss")
    # At rest everything the forces did (2 J + 4 J) was lost in the impacts.
    assert res.impact_loss[-1] == pytest.approx(6.0, abs=ENERGY_TOL)


# --- dt independence ------------------------------------------------------------

def assert_same_times(a, b, tol, what):
    """Every time in a has one in b within tol and vice versa.  (Within one instant the
    order of simultaneous impacts, and in a Zeno cluster the number of impacts with
    speeds ~1e-13 m/s, are rounding artefacts: both stay within tol of each other.)"""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert len(a) and len(b), (what, a, b)
    assert_close(np.min(np.abs(a[:, None] - b[None, :]), axis=1), 0.0, tol, what)
    assert_close(np.min(np.abs(b[:, None] - a[None, :]), axis=1), 0.0, tol, what)


@pytest.mark.parametrize("case", (3, 5))
def test_impact_times_do_not_depend_on_dt(case):
    fine = run(case)
    coarse = run(case, dt=0.1, dt_out=0.1)
    kinds = (*IMPACTS, "rest_left", "rest_right", "rest_slot_min", "rest_slot_max")
    for kind in kinds:
        a, b = events_of(fine, kind)["t"], events_of(coarse, kind)["t"]
        assert (len(a) == 0) == (len(b) == 0), kind
        if len(a):
            assert_same_times(a, b, EVENT_TIME_TOL, f"{kind} times at dt = 0.1 vs 1e-3")
    if case == 3:  # no simultaneous impacts: the whole log is the same
        assert list(fine.events["kind"]) == list(coarse.events["kind"])
    assert coarse.energy_residual < RESIDUAL_TOL
    # The samples they share (every 0.1 s) agree too.
    common = np.arange(0, len(fine.t), 100)
    assert_close(coarse.x1, fine.x1[common], STATE_TOL, "x1 at dt = 0.1")
    assert_close(coarse.x2, fine.x2[common], STATE_TOL, "x2 at dt = 0.1")


# --- case 6: triangular force on m1 ---------------------------------------------
# f1 = 30 t on [0, 1] (our corners).  m1 is held until f1 exceeds c1 = 10 N at
# t = 1/3, then a1 = 30 t - 10: v1 = 15 (t - 1/3)^2, x1 = 1 + 5 (t - 1/3)^3.  m2 rests
# 1 m ahead (d_min = 0): slot_min when 5 (t - 1/3)^3 = 1, t = 1/3 + 0.2^(1/3) = 0.918,
# v1 = 15 * 0.2^(2/3) before; r = 1, m2 = 2 m1: v1' = -v1/3, v2' = 2 v1/3.

def test_case6_breakaway_and_first_impact():
    res = run(6)
    slip = events_of(res, "slip1")
    assert len(slip) >= 1
    assert abs(slip["t"][0] - 1.0 / 3.0) < EVENT_TIME_TOL
    ev = impacts(res)
    assert len(ev) >= 1
    e = ev[0]
    t_hit = 1.0 / 3.0 + 0.2 ** (1.0 / 3.0)
    u = 15.0 * 0.2 ** (2.0 / 3.0)
    assert e["kind"] == "slot_min"
    assert abs(e["t"] - t_hit) < EVENT_TIME_TOL
    assert_close([e["v1_before"], e["v2_before"], e["v1_after"], e["v2_after"]],
                 [u, 0.0, -u / 3.0, 2.0 * u / 3.0], STATE_TOL, "first impact velocities")
    early = res.t <= 1.0 / 3.0
    assert_close(res.x1[early], 1.0, AT_REST_TOL, "x1 held by friction")
    moving = (res.t > 1.0 / 3.0) & (res.t < t_hit)
    tm = res.t[moving] - 1.0 / 3.0
    assert_close(res.x1[moving], 1.0 + 5.0 * tm**3, STATE_TOL, "x1 before the impact")
    assert_close(res.v1[moving], 15.0 * tm**2, STATE_TOL, "v1 before the impact")
    assert_close(res.x2[res.t < t_hit], 2.0, AT_REST_TOL, "x2 before the impact")


def test_no_impact_no_impact_loss():
    """Case 2 has no impact: its bodies are stopped by friction, and the rounding-level
    energy left when a stopped body's velocity is zeroed is friction's (it read
    'impact loss = 4.6E-33')."""
    res = impact1d.simulate(impact1d.load_scene(INPUT / "case2.nml"))
    assert not np.isin(res.events["kind"], ["left", "right", "slot_min", "slot_max"]).any()
    assert np.all(res.impact_loss == 0.0)
    assert res.friction_loss[-1] == 1.5
