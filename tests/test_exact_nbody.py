"""tests/exact_nbody.py (the N-body reference) against the two-body references and closed forms.

The N-body engine does not exist yet: nothing here runs it.  What runs:

(a) exact_nbody against tests/exact_reference.py, the independent two-body reference the
    engine is already checked against (tests/test_reference.py), on the seed cases 2-6 and
    on the N_SCENES scenes test_reference.generate() builds, converted to contact records
    by exact_nbody.from_two_body: same events (kind, time within EVENT_TIME_TOL,
    velocities within VELOCITY_TOL) and final state within STATE_TOL.  exact_reference
    runs in float64 and stops a bounce series 1e-13 s before its accumulation time,
    exact_nbody at 50 digits follows it to ZENO_TIME (1e-16 s) and sums series alternating
    between contacts: the tails of such series differ (see TAIL_SPEED).
(b) one-body scenes against tests/exact_springs.py (the closed forms of issue 10): static
    friction above sliding friction (exact_reference has none), a body rattling to rest.
(c) the closed-form scenes of tests/nbody_scenes.py: every event time, the velocities
    around it and the final state to EXACT (50-digit rounding).
(d) random N-body scenes (nbody_scenes.random_scene, N = 3..12) with the invariants that
    hold exactly: no gap below zero, no impact raises the kinetic energy, impacts between
    bodies keep the momentum, the energy ledger closes.
"""

from __future__ import annotations

import pytest

mpmath = pytest.importorskip("mpmath", reason="mpmath is needed by tests/exact_nbody.py")
from mpmath import mp, mpf  # noqa: E402

import exact_nbody as nb  # noqa: E402
import exact_reference as ref  # noqa: E402
import exact_springs as xs  # noqa: E402
import nbody_scenes as ns  # noqa: E402

# --- tolerances --------------------------------------------------------------------------
# exact_reference is exact to float64 rounding: its event times agree with the 50-digit
# solver to 1e-13 s on every generated scene but the one listed in CHAOTIC.
EVENT_TIME_TOL = 1e-12   # s
VELOCITY_TOL = 1e-12     # m/s (relative to the speeds, floor 1)
STATE_TOL = 1e-12        # final x, v
# Scenes whose dynamics amplify float64 rounding (measured by test_chaotic_scene_is_ill_conditioned):
# index -> tolerance for times, velocities and the final state.
CHAOTIC = {20: 1e-10}    # a body rattling between the walls and the slot, speeds falling to 0.01 m/s
# The tails of bounce series: exact_reference stops a series when the rest of it lasts
# < 1e-13 s, exact_nbody at 1e-16 s, and sums series over several contacts (cycles), which
# exact_reference follows through rest/release bookkeeping at rounding-level speeds.  So
# slow events (impacts: normal speed below TAIL_SPEED; the others: every body slower) may be
# missing from one log when they lie within TAIL_TIME of a rest in either log: impacts,
# releases, stops and starts of a body with friction between the last bounces, and rests
# themselves inside a series over several contacts (slow impacts of two contacts within
# TAIL_TIME).  Everything else is matched one to one, rests at the end of a one-contact
# series included.
TAIL_SPEED = 1e-9        # m/s
TAIL_TIME = 1e-6         # s
# Impulse chains at one instant (a body pinned between two closed contacts, r < 1) converge
# geometrically; each solver stops at its own floor (exact_reference 1e-15 m/s): impacts
# slower than NOISE_SPEED may be in one log only (test_reference.py's convention 2).
NOISE_SPEED = 1e-12      # m/s
# A closed form and the 50-digit solver: both exact to the rounding of 50 digits.
EXACT = mpf(10) ** -35

N_SCENES = 150


@pytest.fixture(autouse=True)
def _precision():
    with mp.workdps(nb.DPS):
        yield


# --- (a) against exact_reference ----------------------------------------------------------

def _normal_speed(e):
    n = ref.NORMALS[e[1]]
    return abs(n[0] * e[2] + n[1] * e[3])


def _slow(e):
    if e[1] in ref.NORMALS:
        return _normal_speed(e) <= TAIL_SPEED
    return max(abs(u) for u in e[2:]) <= TAIL_SPEED


def _tail_filter(mine, theirs):
    """The events of both logs that lie in the tail of a bounce series (module docstring)."""
    both = mine + theirs
    rests = [e[0] for e in both if e[1].startswith("rest_")]
    slow_impacts = [e for e in both if e[1] in ref.NORMALS and _slow(e)]

    def tail(e):
        if e[1] in ref.NORMALS and _normal_speed(e) <= NOISE_SPEED:
            return True
        if not _slow(e):
            return False
        if not e[1].startswith("rest_"):
            return any(abs(e[0] - t) <= TAIL_TIME for t in rests)
        near = {i[1] for i in slow_impacts if abs(i[0] - e[0]) <= TAIL_TIME}
        return len(near) >= 2

    return tail


def compare_two_body(mine, theirs, tol, vel_tol):
    """Problems between two logs of (t, kind, v1b, v2b, v1a, v2a), compared per kind."""
    from test_reference import _match   # (the generated scenes' own matching: needs impact1d)

    tail = _tail_filter(mine, theirs)
    problems = []
    impacts = sorted(e[0] for e in theirs if e[1] in ref.NORMALS)
    for kind in sorted({e[1] for e in mine} | {e[1] for e in theirs}):
        a = sorted((e for e in mine if e[1] == kind and not tail(e)), key=lambda e: e[0])
        b = sorted((e for e in theirs if e[1] == kind and not tail(e)), key=lambda e: e[0])
        pairs, un_a, un_b = _match([e[0] for e in a], [e[0] for e in b], tol)
        problems += [f"{kind} at t = {a[i][0]!r} only in exact_nbody {a[i][2:]}" for i in un_a]
        problems += [f"{kind} at t = {b[j][0]!r} only in exact_reference {b[j][2:]}" for j in un_b]
        for i, j in pairs:
            scale = max([1.0] + [abs(u) for u in b[j][2:]])
            if kind in ref.NORMALS and sum(abs(t - b[j][0]) <= tol for t in impacts) > 1:
                # simultaneous impacts: the order of logging sets the other body's entries
                n = ref.NORMALS[kind]
                err = max(abs(n[0] * (a[i][k] - b[j][k]) + n[1] * (a[i][k + 1] - b[j][k + 1])) for k in (2, 4))
            else:
                err = max(abs(u - w) for u, w in zip(a[i][2:], b[j][2:]))
            if err > vel_tol * scale:
                problems.append(f"{kind} at t = {b[j][0]!r}: velocities {a[i][2:]} != {b[j][2:]}")
    return problems


def check_two_body(scene, label, chaotic=None):
    """exact_nbody on a tutorial scene against exact_reference; `chaotic`: one tolerance for
    times, velocities and the final state instead of the defaults (see CHAOTIC)."""
    theirs = ref.solve(scene)
    mine = nb.solve(nb.from_two_body(scene))
    problems = compare_two_body(nb.two_body_events(mine), theirs.events,
                                chaotic or EVENT_TIME_TOL, chaotic or VELOCITY_TOL)
    x, v = mine.final
    got = (float(x[0]), float(v[0]), float(x[1]), float(v[1]))
    err = max(abs(p - q) for p, q in zip(got, theirs.final))
    if err > (chaotic or STATE_TOL) * max([1.0] + [abs(q) for q in theirs.final]):
        problems.append(f"final state {got} != {theirs.final}")
    assert not problems, f"{label}:\n  " + "\n  ".join(problems[:12])
    return mine, theirs


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """test_reference's generated scenes (their tables written in a temporary folder)."""
    tr = pytest.importorskip("test_reference", reason="the generated scenes need impact1d")
    folder = str(tmp_path_factory.mktemp("exact_nbody_tables"))
    return lambda index: tr.generate(index, folder)[0]


_SOLVED = {}   # generated scene index -> exact_nbody's solution (for the coverage test)


@pytest.mark.parametrize("case", (2, 3, 4, 5, 6))
def test_seed_case_matches_exact_reference(case):
    impact1d = pytest.importorskip("impact1d")
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "input" / f"case{case}.nml"
    check_two_body(impact1d.load_scene(path), f"input/case{case}.nml")


def test_seed_case5_rests_at_three_seconds():
    """Case 5 by hand (docs/method.md 5): impacts at 3 - 2^(1-k) on both walls, rest at 3 s."""
    case5 = dict(m1=1.0, m2=2.0, g=10.0, x_left=0.0, r_left=0.5, x_right=10.0, r_right=0.5,
                 d_min=0.0, r_min=1.0, d_max=50.0, r_max=1.0, x1=1.0, x2=9.0, f1=-2.0, f2=4.0, t_end=3.2)
    sol = nb.solve(nb.from_two_body(case5))
    for kind in ("left", "right"):
        times = [e.t for e in sol.events if e.kind == kind]
        assert all(abs(t - (3 - mpf(2) ** (1 - k))) < EXACT for k, t in enumerate(times))
        assert 50 <= len(times) <= 60   # until the rest of the series lasts < ZENO_TIME = 1e-16 s
    rests = [e for e in sol.events if e.kind.startswith("rest_")]
    assert sorted(e.kind for e in rests) == ["rest_left", "rest_right"]
    assert all(abs(e.t - 3) < EXACT for e in rests)   # the series summed exactly
    assert sol.final == ((0, 10), (0, 0))


@pytest.mark.parametrize("index", range(N_SCENES))
def test_generated_scene_matches_exact_reference(index, generated):
    mine, _ = check_two_body(generated(index), f"generated scene {index}", CHAOTIC.get(index))
    _SOLVED[index] = mine


@pytest.mark.parametrize("index", sorted(CHAOTIC))
def test_chaotic_scene_is_ill_conditioned(index, generated):
    """The reason for CHAOTIC: one ulp more on v1 moves the scene's events by more than
    EVENT_TIME_TOL (so a float64 solver cannot do better), and less than the tolerance."""
    scene = nb.from_two_body(generated(index))
    base = nb.solve(scene)
    scene["v"] = [mpf(scene["v"][0]) * (1 + mpf(2) ** -52), scene["v"][1]]
    nudged = nb.solve(scene)
    shift = max(abs(a.t - b.t) for a, b in zip(base.events, nudged.events))
    assert [e.kind for e in base.events] == [e.kind for e in nudged.events]
    assert EVENT_TIME_TOL < shift < CHAOTIC[index] / 3


def test_generated_scenes_cover_the_model(generated):
    """The comparison above saw every kind of event of the two-body model."""
    kinds = set()
    for index in range(N_SCENES):
        if index not in _SOLVED:
            _SOLVED[index] = nb.solve(nb.from_two_body(generated(index)))
        kinds |= {e.kind for e in _SOLVED[index].events}
    for kind in ("left", "right", "slot_min", "slot_max", "rest_left", "rest_right", "rest_slot_min",
                 "release_left", "release_slot_min", "stick1", "stick2", "slip1", "slip2"):
        assert kind in kinds, kind


# --- (b) one body against exact_springs -----------------------------------------------------

def _springs_events(reference):
    """exact_springs' log without its two extra kinds (reverse1, graze1: not events here)."""
    return [e for e in reference.events if not e.kind.startswith(("reverse", "graze"))]


@pytest.mark.parametrize("mu, mus, f0, rate, v0", [
    (0.2, 0.5, 0.0, 3.0, 0.0),      # a ramp breaks a block away from static friction
    (0.2, 0.5, 1.0, -2.0, 0.0),     # the other way, later
    (0.3, 0.6, 4.0, 0.0, -2.0),     # slides into a constant force between the bounds: sticks
    (0.3, 0.3, 2.0, 0.0, -1.5),     # mus = mu, force below it: sticks
    (0.25, 0.25, 5.0, 0.0, -1.0),   # force above friction: stops and slides back (no event)
])
def test_one_block_with_static_friction(mu, mus, f0, rate, v0):
    m, g, t_end = 1.5, 9.80665, 4.0
    reference = xs.friction_block(m, mu, mus, f0, rate, t_end, v0=v0)
    table = None if rate == 0 else [([0.0, 64.0], [f0, f0 + 64.0 * rate])]
    scene = dict(m=[m], x=[0.0], v=[v0], mu=[mu], mus=[mus], f=[0.0 if table else f0], g=g,
                 f_table=table, contacts=[], t_end=t_end)
    sol = nb.solve(scene)
    want = _springs_events(reference)
    assert [e.kind for e in sol.events] == [e.kind for e in want]
    assert all(abs(a.t - b.t) < EXACT for a, b in zip(sol.events, want))
    x, v = reference.state(t_end)
    assert abs(sol.final[0][0] - x[0]) < EXACT and abs(sol.final[1][0] - v[0]) < EXACT


def test_one_body_rattles_to_rest_on_a_wall():
    """exact_springs sums the series to 1e-30 s; exact_nbody's impacts are its first ones
    and the rest is at the same accumulation time."""
    reference = xs.constant_force_bodies([1.0], [-2.0], [0.5], [0.0], 3.0, x_left=0.0, r_left=0.5)
    sol = nb.solve(dict(m=[1.0], x=[0.5], v=[0.0], f=[-2.0], t_end=3.0,
                        contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.5, name="left")]))
    want = [e for e in reference.events if e.kind == "left"]
    got = [e for e in sol.events if e.kind == "left"]
    assert 40 < len(got) < len(want)
    assert all(abs(a.t - b.t) < EXACT and abs(a.after[0] - b.v_after[0]) < EXACT for a, b in zip(got, want))
    rest = [e.t for e in reference.events if e.kind == "rest_left"]
    assert [e.kind for e in sol.events if not e.kind == "left"] == ["rest_left"]
    assert abs([e.t for e in sol.events if e.kind == "rest_left"][0] - rest[0]) < EXACT


# --- (c) closed forms -------------------------------------------------------------------------

def check_closed_form(scene, answer, kinds=None):
    """exact_nbody's log is the closed form's: kinds, times, velocities, and the final state."""
    sol = nb.solve(scene)
    got = [(e.t, e.kind, e.before, e.after) for e in sol.events]
    assert [e[1] for e in got] == [e[1] for e in answer["events"]]
    for (t, kind, before, after), (t_want, _, before_want, after_want) in zip(got, answer["events"]):
        assert abs(t - t_want) < EXACT, (kind, t, t_want)
        if before_want is not None:
            assert max(abs(a - b) for a, b in zip(before + after, before_want + after_want)) < EXACT, kind
    x_want, v_want = answer["final"]
    assert max(abs(a - b) for a, b in zip(sol.final[0] + sol.final[1], x_want + v_want)) < EXACT
    assert abs(sol.ledger["residual"]) < EXACT
    if kinds is not None:
        assert [e[1] for e in got] == kinds
    return sol


def test_newtons_cradle_passes_the_velocity_on():
    scene = ns.newtons_cradle()
    sol = check_closed_form(scene, ns.newtons_cradle_answer(scene), kinds=["b12", "b23", "b34", "b45"])
    assert [float(e.t) for e in sol.events] == [0.125, 0.1875, 0.4375, 0.46875]


def test_galperin_billiard_counts_pi():
    scene = ns.galperin(mass_ratio=100)
    sol = check_closed_form(scene, ns.galperin_answer(scene))
    assert len(sol.events) == ns.galperin_count(100) == 31       # 3.1|4...
    assert ns.galperin_count(10_000) == 314


@pytest.mark.parametrize("ratio", (1, 2, 16))
def test_galperin_billiard_other_ratios(ratio):
    scene = ns.galperin(mass_ratio=ratio, x1=0.75, speed=0.5)
    sol = check_closed_form(scene, ns.galperin_answer(scene))
    assert len(sol.events) == ns.galperin_count(ratio)


@pytest.mark.parametrize("x, v", [
    ((1.0, 2.5, 3.25), (0.5, -0.25, -1.5)),
    ((0.5, 1.25, 2.75), (-0.25, -0.5, -1.125)),   # nine events
])
def test_equal_masses_and_a_wall(x, v):
    scene = ns.equal_masses_wall(x=x, v=v)
    answer = ns.equal_masses_wall_answer(scene)
    assert len(answer["events"]) >= 5
    check_closed_form(scene, answer)


@pytest.mark.parametrize("r_floor, r_balls", [(1.0, (1.0, 1.0)), (0.75, (0.5, 0.875))])
def test_falling_stack(r_floor, r_balls):
    scene = ns.falling_stack(r_floor=r_floor, r_balls=r_balls)
    answer = ns.falling_stack_answer(scene)
    sol = check_closed_form(scene, answer, kinds=["floor", "b12", "b23"])
    if r_floor == r_balls[0] == r_balls[1] == 1.0:
        # elastic, 4:2:1 masses: the top ball leaves upward at more than twice the speed the
        # stack hit the floor with (2.47 times here: each light ball takes the heavier one's rebound)
        assert sol.events[-1].after[2] > 2 * abs(sol.events[0].before[2])


@pytest.mark.parametrize("push, held", [(3.0, 0), (9.0, 2), (32.0, 7), (33.0, 7), (40.0, 7)])
def test_friction_chain_under_a_constant_push(push, held):
    """S_k = 4, 7, 12, 16, 22, 26, 29, 33 N: the load front stops where S_k reaches the push;
    above S_8 = 33 N all eight blocks slide as one from t = 0."""
    scene = ns.friction_chain(push=push, t_end=0.5)
    answer = ns.friction_chain_answer(scene)
    sol = check_closed_form(scene, answer)
    assert sum(e.kind.startswith("rest_") for e in sol.events) == held
    moving = push > 33.0
    assert all((v > 0) == moving for v in sol.final[1])


@pytest.mark.parametrize("n", (8, 3, 2))
def test_friction_chain_under_a_ramp_breaks_away_at_once(n):
    """Two blocks: the pair holds until the push reaches s_1 + s_2 (docs/method.md 2, the
    engine's closed form for a stuck pair), not one's sliding bound plus the other's static one."""
    scene = ns.friction_chain(n=n)
    answer = ns.friction_chain_answer(scene)
    sol = check_closed_form(scene, answer)
    slips = [e for e in sol.events if e.kind.startswith("slip")]
    assert len(slips) == n and all(e.t == answer["t_break"] for e in slips)
    assert answer["t_break"] == {8: mpf(33) / 8, 3: mpf(12) / 8, 2: mpf(7) / 8}[n]


def test_rigid_link_is_one_body_for_other_contacts():
    """Bodies 2 and 3 joined by a rigid link (d_min = d_max) are hit by body 1, elastic: the
    pair answers as one body of mass M = m2 + m3, v1' = (m1 - M) v / (m1 + M) and
    v2' = v3' = 2 m1 v / (m1 + M), at t = gap / v; the link itself takes no impulse."""
    m1, m2, m3, v, gap = 2.0, 1.0, 0.5, 1.5, 0.75
    scene = dict(m=[m1, m2, m3], x=[0.0, gap, gap + 0.25], v=[v, 0.0, 0.0], t_end=1.0,
                 contacts=[dict(a=1, b=2, d_min=0.0, r_min=1.0, name="hit"),
                           dict(a=2, b=3, d_min=0.25, d_max=0.25, name="link")])
    sol = nb.solve(scene)
    big = mpf(m2 + m3)
    after = ((m1 - big) * v / (m1 + big), 2 * m1 * v / (m1 + big), 2 * m1 * v / (m1 + big))
    assert [(e.t, e.kind) for e in sol.events] == [(0, "rest_link_min"), (mpf(gap) / v, "hit")]
    assert max(abs(a - b) for a, b in zip(sol.events[1].after, after)) < EXACT
    t = 1 - mpf(gap) / v
    assert max(abs(a - b) for a, b in zip(sol.final[0], (gap + after[0] * t, gap + after[1] * t,
                                                         gap + 0.25 + after[2] * t))) < EXACT


def test_body_pinned_between_plastic_contacts_stops_at_once():
    """Body 1 resting on a plastic wall, hit by body 2 through a plastic contact: one joint
    projection (docs/method.md 4) stops both at the instant, not a geometric series of
    impulses; both contacts are logged as its impacts and then held."""
    scene = dict(m=[1.0, 3.0], x=[0.0, 0.5], v=[0.0, -2.0], t_end=1.0,
                 contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.0, name="wall"),
                           dict(a=1, b=2, d_min=0.0, r_min=0.0, name="meet")])
    sol = nb.solve(scene)
    assert [(e.t, e.kind, e.joint) for e in sol.events] == [
        (0, "rest_wall", False), (0.25, "wall", True), (0.25, "meet", True), (0.25, "rest_meet", False)]
    assert sol.events[1].after == (0, 0) and sol.final == ((0, 0), (0, 0))
    assert sol.ledger["impact_loss"] == 6   # all of 3 * 2^2 / 2


def test_series_over_two_contacts_is_summed_at_its_rate(monkeypatch):
    """A light body rattling between a wall and a heavier one pushed onto it (METHOD 9): the
    series alternates between the two contacts; cut at ZENO_TIME = 1e-16 s by the cycle's
    geometric rate, the accumulation time is the one found following the series eight
    decades further (1e-24 s), to far below the cut."""
    scene = dict(m=[1.0, 4.0], x=[1.0, 2.0], v=[0.0, -1.0], f=[0.0, -4.0], t_end=3.0,
                 contacts=[dict(a=0, b=1, d_min=0.0, r_min=0.5, name="wall"),
                           dict(a=1, b=2, d_min=0.0, r_min=0.5, name="meet")])
    cut = nb.solve(scene)
    monkeypatch.setattr(nb, "ZENO_TIME", mpf(10) ** -24)
    followed = nb.solve(scene)
    assert len(followed.impacts()) > len(cut.impacts()) + 50
    rests = [[(e.kind, e.t) for e in sol.events if e.kind.startswith("rest_")] for sol in (cut, followed)]
    assert [k for k, _ in rests[0]] == [k for k, _ in rests[1]] == ["rest_wall", "rest_meet"]
    assert abs(rests[0][0][1] - rests[1][0][1]) < 1e-22
    assert all(abs(a.t - b.t) < EXACT for a, b in zip(cut.impacts(), followed.impacts()))
    assert cut.final[1] == (0, 0)


def test_builders_write_the_design_format():
    """The scene dicts carry the DESIGN.md N-body fields, ready for the engine."""
    for scene in (ns.newtons_cradle(), ns.galperin(), ns.equal_masses_wall(), ns.falling_stack(),
                  ns.friction_chain(push=9.0), ns.friction_chain(), ns.random_scene(1)):
        n = len(scene["m"])
        assert all(len(scene[k]) == n for k in ("m", "x", "v", "mu", "mus", "f"))
        for rec in scene["contacts"]:
            assert set(rec) <= {"a", "b", "d_min", "r_min", "d_max", "r_max", "name"}
            assert 0 <= rec["a"] <= n and 0 <= rec["b"] <= n and "name" in rec


# --- (d) random N-body scenes: invariants ----------------------------------------------------

RANDOM_SEEDS = (1, 2, 3, 7, 10, 14)


def _gaps(model, x):
    return [lim.gap(x) for lim in model.limits]


@pytest.fixture(scope="module")
def random_runs():
    with mp.workdps(nb.DPS):
        return {seed: (ns.random_scene(seed), nb.solve(ns.random_scene(seed))) for seed in RANDOM_SEEDS}


@pytest.mark.parametrize("seed", RANDOM_SEEDS)
def test_random_scene_invariants(seed, random_runs):
    scene, sol = random_runs[seed]
    model = sol.model
    scale = sum(model.m) * (1 + sum(abs(u) for u in model.v0)) ** 2 + sol.ledger["work"] + sol.ledger["friction_loss"]
    # no gap below zero: at every phase's ends and middle, and at the end
    for ph in sol.phases:
        for t in (ph.t0, (ph.t0 + ph.t1) / 2, ph.t1):
            assert min(_gaps(model, ph.at(t)[0]) + [mpf(1)]) > -EXACT, (seed, t)
    assert min(_gaps(model, sol.final[0]) + [mpf(1)]) > -EXACT
    for e in sol.impacts():
        # an impact never raises the kinetic energy
        assert model.ke(e.after) <= model.ke(e.before) + EXACT * scale, (seed, e.kind, e.t)
        lim = next(lim for lim in model.limits if lim.name == e.kind)
        if len(lim.bodies) == 2 and not e.joint:
            # an impulse between two bodies keeps the momentum
            p_before = sum(m * u for m, u in zip(model.m, e.before))
            p_after = sum(m * u for m, u in zip(model.m, e.after))
            assert abs(p_after - p_before) < EXACT * scale, (seed, e.kind, e.t)
    # the ledger closes: KE - KE0 = W - D - Q
    assert abs(sol.ledger["residual"]) < EXACT * scale


def test_random_scenes_cover_the_model(random_runs):
    sizes = {len(scene["m"]) for scene, _ in random_runs.values()}
    assert min(sizes) <= 4 and max(sizes) >= 10
    restitutions = {rec.get(k) for scene, _ in random_runs.values() for rec in scene["contacts"]
                    for k in ("r_min", "r_max")}
    assert {0.0, 1.0} <= restitutions
    kinds = {e.kind.rstrip("0123456789").split("_")[0] + ("_" if "_" in e.kind else "")
             for _, sol in random_runs.values() for e in sol.events}
    assert {"rest_", "release_", "stick"} <= kinds   # (slip: a constant force rarely breaks a body away)
    assert any(e.joint for _, sol in random_runs.values() for e in sol.events)
    assert any(mu > 0 for scene, _ in random_runs.values() for mu in scene["mu"])


# --- the complementarity solver ----------------------------------------------------------------

@pytest.mark.parametrize("seed", range(6))
def test_lemke_solves_positive_semidefinite_problems(seed):
    """w = q + Q z, w, z >= 0, w.z = 0 on random PSD problems with many zero entries
    (degenerate: the lexicographic rule must not cycle)."""
    import random

    rng = random.Random(seed)
    n = 6
    a = [[mpf(rng.choice((-1, 0, 0, 1, 2))) for _ in range(n)] for _ in range(n - 2)]
    skew = [[mpf(0)] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            skew[i][j] = mpf(rng.choice((0, 1, -1)))
            skew[j][i] = -skew[i][j]
    Q = [[sum(a[k][i] * a[k][j] for k in range(n - 2)) + skew[i][j] for j in range(n)] for i in range(n)]
    # a solution by construction (complementary w0, z0 >= 0), so the problem is feasible
    z0 = [mpf(rng.choice((0, 0, 1, 2))) for _ in range(n)]
    w0 = [mpf(0) if z0[i] else mpf(rng.choice((0, 1))) for i in range(n)]
    q = [w0[i] - sum(Q[i][j] * z0[j] for j in range(n)) for i in range(n)]
    basic, binv = nb.lemke(Q, q, nb.TOL)
    w, z = nb._solve_values(basic, binv, q)
    for i in range(n):
        assert abs(w[i] - q[i] - sum(Q[i][j] * z[j] for j in range(n))) < EXACT
        assert w[i] > -EXACT and z[i] > -EXACT and abs(w[i] * z[i]) < EXACT


def test_zero_length_phase_keeps_closed_contacts():
    """Body 3 pinned between body 4 and the right wall, body 2 resting on body 3 and pulled
    away from it (n23 closed, separating), when n34 closes again 1e-98 s later: a phase
    shorter than the clock's resolution (t + s == t at 50 digits).  n23 was dropped from the
    closed contacts because it had a root of its own (its gap is still 0); then the impulse
    on n34 drove body 3 into body 2 across a contact no longer watched, n34 was dropped in
    turn, and the two contacts took turns at the same instant until 'events do not
    advance at t = 0.5704' (nbody_scenes.random_scene(33) with r = 1 made 0.875)."""
    scene = dict(m=[1.921875, 2.078125, 2.546875, 1.1875], x=[0.0, 0.4375, 0.9375, 1.5],
                 v=[1.421875, -0.4375, 2.078125, 2.5625], mu=[0.0, 0.0, 0.0, 0.28125],
                 mus=[0.0, 0.0, 0.0, 0.28125], f=[10.640625, -4.765625, -0.09375, 2.578125], g=9.8125,
                 contacts=[dict(a=1, b=2, d_min=0.328125, r_min=0.7, name="n12"),
                           dict(a=2, b=3, d_min=0.5, r_min=0.7, name="n23"),
                           dict(a=3, b=4, d_min=0.3125, r_min=0.875, name="n34"),
                           dict(a=0, b=1, d_min=-0.890625, r_min=0.0, name="left"),
                           dict(a=0, b=4, d_max=1.65625, r_max=0.046875, name="right"),
                           dict(a=0, b=3, d_min=0.703125, r_min=0.875, name="stop3")], t_end=0.625)
    sol = nb.solve(scene)
    at = [e for e in sol.events if abs(e.t - mpf("0.5704289111933493")) < 1e-15]
    assert {"n23", "n34", "right"} <= {e.kind for e in at}
    model = sol.model
    assert min(_gaps(model, sol.final[0])) > -EXACT
    assert abs(sol.ledger["residual"]) < EXACT * 100
