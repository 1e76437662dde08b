"""Yardsticks for the N-body engine (issue 19 items 3-5, issue 20 item 3): scenes of three
bodies or more run through `impact1d.simulate`, against tests/exact_nbody.py (the 50-digit
event-driven reference) and closed forms.

Each yardstick comes twice:
- `test_reference_*` checks the expected values on the reference alone (closed form
  against exact_nbody, to EXACT): these run today and prove the yardstick;
- `test_engine_*` runs the engine on the same scene and holds it to the reference with the
  tolerances of tests/test_reference.py (EVENT_TIME_TOL on every event time, STATE_TOL on
  the final state).

(a) Newton's cradle, equal masses, r = 1, no gaps (input/newtons_cradle.nml and k balls
    in): k balls out at the incoming speed, the others at rest.
(b) Galperin's billiard (a light body between a wall and a heavy one, elastic) with a
    third body beside it: ceil(pi / atan(sqrt(m/M))) - 1 collisions, pi's digits.
(c) Random chains of 3-6 bodies (constant forces, friction, gaps, walls, restitutions
    below 1): every event up to the first bounce series, and the final state.
(d) Momentum and centre of mass with no friction and no walls: P(t) = P0 + F t.
(e) A train's start-up (input/train.nml and a frictionless train): the instant each
    coupler's slack is taken up, in closed form.
And the N-body scenes of input/ against the reference (the ball stack against its closed
form, tests/nbody_scenes.py falling_stack).

The engine's N-body Result is read in two helpers only, `engine_events` and
`engine_samples` (DESIGN "Mechanisms as data": `Result.x`, `Result.v` (samples, N)).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import impact1d

mpmath = pytest.importorskip("mpmath", reason="mpmath is needed by tests/exact_nbody.py")
from mpmath import mp, mpf  # noqa: E402

import exact_nbody as nb  # noqa: E402
import nbody_scenes as ns  # noqa: E402
from tools import wall_records  # noqa: E402

INPUT = Path(__file__).resolve().parent.parent / "input"

# --- the engine's expected failure, in one place ------------------------------------------

# --- tolerances -----------------------------------------------------------------------------
EVENT_TIME_TOL = 1e-9    # s: every event time (tests/test_reference.py, tests/test_records_run.py)
STATE_TOL = 1e-8         # final x, v (tests/test_reference.py), relative to the values, floor 1
EXACT = mpf(10) ** -30   # a closed form against the 50-digit reference
# Events at one instant: within INSTANT of the instant's first (the engine may locate
# independent simultaneous impacts as separate event points, docs/nbody-plan.md stage 5).
INSTANT = 1e-12          # s
# Compared: the instants up to the first bounce series (instants closer than SERIES_GAP:
# the engine and the reference end a series' tail at their own resolution) or a grazing
# touch (an impact changing no velocity by GRAZING), as tests/test_records_run.py does.
SERIES_GAP = 1e-4        # s
GRAZING = 1e-6           # m/s
RESERVED = nb.RESERVED_PREFIXES
DT = 1e-3


@pytest.fixture(autouse=True)
def _precision():
    with mp.workdps(nb.DPS):
        yield


# --- scenes: the engine's form and the reference's -------------------------------------------

def engine_scene(scene: dict, dt: float = DT, dt_out: float | None = None) -> impact1d.Scene:
    """An exact_nbody scene dict as an impact1d.Scene: arrays and &contact records (a
    neighbour pair without a record meets: x(i+1) >= x(i), r = 1, named link<i>)."""
    keys = ("a", "b", "d_min", "r_min", "d_max", "r_max", "name")
    n = len(scene["m"])
    zeros = [0.0] * n
    return impact1d.Scene(m=list(scene["m"]), x=list(scene["x"]), v=list(scene.get("v") or zeros),
                          mu=list(scene.get("mu") or zeros), mus=list(scene.get("mus") or scene.get("mu") or zeros),
                          f=list(scene.get("f") or zeros), g=scene.get("g", nb.DEFAULT_G),
                          contacts=[{k: rec[k] for k in keys if k in rec} for rec in scene["contacts"]],
                          t_end=float(scene["t_end"]), dt=dt, dt_out=dt_out or dt)


def reference_scene(scene: impact1d.Scene) -> dict:
    """An N-body impact1d.Scene as the reference's dict, the records in the engine's row order
    (docs/formats.md "Scenes of N bodies"): walls `left` (body 1) and `right` (body N), link i
    on x(i+1) - x(i) (its d_min and d_max, else the meeting d_min = 0 with r_meet, unless a
    &contact joins the pair), then the &contact records (b = 0 turned round, unnamed ones
    `contact<j>`). Constant forces only (no sine, table or spring: out of the reference's
    scope)."""
    n = len(scene.m)
    if any(getattr(scene, name) for name in ("f_amp", "f_table", "k", "c", "k_link", "c_link", "springs")):
        raise ValueError("reference_scene: constant forces and contacts only")

    def item(values, i, default=None):
        return default if values is None or values[i] is None else values[i]

    def given(name, default):
        value = getattr(scene, name)
        return default if value is None else value

    contacts = wall_records(scene, n)
    records = scene.contacts or []
    joined = {tuple(sorted((rec["a"], rec["b"]))) for rec in records}
    for i in range(1, n):
        link = dict(a=i, b=i + 1, name=f"link{i}")
        if item(scene.d_min, i - 1) is not None:
            link.update(d_min=scene.d_min[i - 1], r_min=item(scene.r_min, i - 1, 1.0))
        elif (i, i + 1) not in joined:
            link.update(d_min=0.0, r_min=item(scene.r_min, i - 1, given("r_meet", 1.0)))
        if item(scene.d_max, i - 1) is not None:
            link.update(d_max=scene.d_max[i - 1], r_max=item(scene.r_max, i - 1, 1.0))
        if "d_min" in link or "d_max" in link:
            contacts.append(link)
    for j, rec in enumerate(records):
        rec = dict(rec)
        rec.setdefault("name", f"contact{j + 1}")
        if rec["b"] == 0:     # on x_a - x_b = -(x_b - x_a): the limits negate and swap
            turned = dict(a=0, b=rec["a"], name=rec["name"])
            if "d_min" in rec:
                turned.update(d_max=-rec["d_min"], r_max=rec.get("r_min", 1.0))
            if "d_max" in rec:
                turned.update(d_min=-rec["d_max"], r_min=rec.get("r_max", 1.0))
            rec = turned
        contacts.append(rec)
    zeros = [0.0] * n
    return dict(m=list(scene.m), x=list(scene.x), v=list(scene.v or zeros), mu=list(scene.mu or zeros),
                mus=list(scene.mus or scene.mu or zeros), f=list(scene.f or zeros),
                g=given("g", nb.DEFAULT_G), contacts=contacts, t_end=scene.t_end)


def load(name: str) -> impact1d.Scene:
    return impact1d.load_scene(INPUT / name)


# --- the engine's results ----------------------------------------------------------------------

def run_engine(scene: impact1d.Scene, **overrides):
    """impact1d.simulate (the N-body engine for more than two bodies)."""
    return impact1d.simulate(scene, **overrides)


def engine_events(res) -> list:
    """(t, kind) of every event of an engine run."""
    return [(float(e["t"]), str(e["kind"])) for e in res.events]


def engine_samples(res):
    """t, x, v of every sample: x and v (samples, N) (DESIGN: Result.x, Result.v)."""
    return np.asarray(res.t), np.asarray(res.x), np.asarray(res.v)


# --- comparing logs --------------------------------------------------------------------------

def instants(events) -> list:
    """(t, sorted kinds) per instant of a log of (t, kind): events within INSTANT of an
    instant's first are at that instant (their order within it is the solver's)."""
    out = []
    for t, kind in events:
        if out and t - out[-1][0] <= INSTANT:
            out[-1][1].append(kind)
        else:
            out.append((t, [kind]))
    return [(t, sorted(kinds)) for t, kinds in out]


def reference_log(sol) -> list:
    """The reference's instants that an engine log is held to: up to the first bounce
    series or grazing touch (module tolerances)."""
    events = []
    for e in sol.events:
        grazing = not e.kind.startswith(RESERVED) and \
            max(abs(float(a - b)) for a, b in zip(e.before, e.after)) < GRAZING
        if grazing:
            break
        events.append((float(e.t), e.kind))
    out = instants(events)
    for k in range(1, len(out)):
        if out[k][0] - out[k - 1][0] < SERIES_GAP:
            return out[:k]   # (instant k - 1 starts the series: its first impact is compared)
    return out


def assert_log_matches(res, sol, at_least=1):
    """The engine's instants are the reference's (times within EVENT_TIME_TOL, the same kinds)
    as far as the reference's log is compared; returns the number of instants compared."""
    want = reference_log(sol)
    assert len(want) >= at_least, "a scene that tests nothing"
    got = instants(engine_events(res))[:len(want)]
    assert [kinds for _, kinds in got] == [kinds for _, kinds in want], (got, want)
    error = max(abs(a - b) for (a, _), (b, _) in zip(got, want))
    assert error < EVENT_TIME_TOL, error
    return len(want)


def assert_state_close(got, want):
    """Final positions and velocities within STATE_TOL (relative, floor 1)."""
    got, want = np.asarray(got, dtype=float), np.asarray([float(u) for u in want])
    scale = max([1.0] + list(np.abs(want)))
    assert np.max(np.abs(got - want)) < STATE_TOL * scale, (got, want)


def assert_final_matches(res, x, v):
    t, xs, vs = engine_samples(res)
    assert t[-1] == res.scene.t_end
    assert_state_close(xs[-1], x)
    assert_state_close(vs[-1], v)


# --- (a) Newton's cradle ------------------------------------------------------------------------

def cradle(k: int, n: int = 5, v: float = 0.5, d: float = 0.0625, gap: float = 0.1875, t_end: float = 1.0):
    """n equal balls (1 kg, diameter d) on a line, the first k touching and moving at v toward
    the other n - k, touching and at rest, `gap` away: links link<i> with d_min = d, r = 1
    (the chain shorthand of input/newtons_cradle.nml, which is cradle(1))."""
    x = [i * d for i in range(k)] + [(k - 1) * d + d + gap + i * d for i in range(n - k)]
    return impact1d.Scene(m=[1.0] * n, x=x, v=[v] * k + [0.0] * (n - k), d_min=[d] * (n - 1),
                          r_min=[1.0] * (n - 1), t_end=t_end, dt=DT, dt_out=0.01)


def cradle_answer(scene: impact1d.Scene, k: int) -> dict:
    """k balls in, k balls out.  The k incoming balls close the gap at t1 = gap / v (they
    move together at v: nothing acts between them).  At t1 every contact is closed; the
    engine's rule (docs/method.md 4) is sequential impulses, the most approaching closed
    contact first.  With equal masses and r = 1 an impulse on a pair approaching at
    (v, 0) swaps their velocities (P = -(1 + r) n.v / (n.M^-1 n) = m v), so whatever the
    order the velocities are permuted, one adjacent inversion (a v before a 0) removed per
    impulse, until none approaches: the row ends (0, ..., 0, v, ..., v), k balls out, after
    k (n - k) impulses, contact link<p> taking #{j in 1..k : j <= p <= n - k + j - 1} of
    them (the j-th moving velocity goes from ball j to ball n - k + j).  After t1 balls
    1..n-k stay where they are at t1 (the incoming ones moved `gap`), balls n-k+1..n move at v.
    Momentum and kinetic energy are kept: no impact loss."""
    n = len(scene.m)
    x0 = [mpf(a) for a in scene.x]
    v = mpf(scene.v[0])
    gap = x0[k] - x0[k - 1] - mpf(scene.d_min[k - 1])
    t1 = gap / v
    at_t1 = [a + (gap if i < k else 0) for i, a in enumerate(x0)]
    flight = mpf(scene.t_end) - t1
    x = tuple(a + (v * flight if i >= n - k else 0) for i, a in enumerate(at_t1))
    counts = {f"link{p}": sum(1 for j in range(1, k + 1) if j <= p <= n - k + j - 1) for p in range(1, n)}
    return dict(t1=t1, counts=counts, final=(x, tuple(v if i >= n - k else mpf(0) for i in range(n))))


def test_cradle_file_is_cradle_one():
    file = load("newtons_cradle.nml")
    assert reference_scene(file) == reference_scene(cradle(1))
    assert file.title == "Newton's cradle: one ball in, one ball out"


@pytest.mark.parametrize("k", (1, 2, 3))
def test_reference_cradle_k_in_k_out(k):
    scene = cradle(k)
    answer = cradle_answer(scene, k)
    sol = nb.solve(reference_scene(scene))
    impacts = sol.impacts()
    assert all(abs(e.t - answer["t1"]) < EXACT for e in impacts)
    assert {name: sum(e.kind == name for e in impacts) for name in answer["counts"]} == answer["counts"]
    assert len(impacts) == k * (5 - k)
    for got, want in zip(sol.final[0] + sol.final[1], answer["final"][0] + answer["final"][1]):
        assert abs(got - want) < EXACT
    assert abs(sol.ledger["impact_loss"]) < EXACT
    if k == 1:   # one impulse per contact, down the row, each passing the whole velocity on
        assert [e.kind for e in impacts] == ["link1", "link2", "link3", "link4"]
        assert [e.after for e in impacts][-1] == (0, 0, 0, 0, mpf(0.5))


@pytest.mark.parametrize("k", (1, 2, 3))
def test_engine_cradle_k_in_k_out(k):
    scene = cradle(k)
    answer = cradle_answer(scene, k)
    res = run_engine(scene)
    impacts = [(t, kind) for t, kind in engine_events(res) if not kind.startswith(RESERVED)]
    assert all(abs(t - float(answer["t1"])) < EVENT_TIME_TOL for t, _ in impacts)
    assert {name: sum(kind == name for _, kind in impacts) for name in answer["counts"]} == answer["counts"]
    assert_final_matches(res, *answer["final"])
    assert abs(res.impact_loss[-1]) < 1e-12


# --- (b) Galperin's billiard, with a third body ----------------------------------------------------

def galperin3(ratio: float, speed: float = 1.0, x1: float = 1.0, x2: float = 2.0) -> impact1d.Scene:
    """tests/nbody_scenes.py's Galperin billiard (light body 1, m = 1, at rest at x1; heavy body
    2, M = ratio, at x2 moving at -speed; contacts `wall` (x1 >= 0) and `meet` (x2 >= x1),
    elastic) with a third body (m = 1) a metre beyond the heavy one, moving away at 2 speed:
    the heavy body never goes faster than `speed` (energy), so their meeting (link2) never
    closes. The scene runs as three bodies; body 3 must not change the billiard."""
    base = ns.galperin(mass_ratio=ratio, speed=speed, x1=x1, x2=x2)
    return impact1d.Scene(m=base["m"] + [1.0], x=base["x"] + [x2 + 1.0], v=base["v"] + [2 * speed],
                          contacts=base["contacts"], t_end=base["t_end"], dt=DT, dt_out=base["t_end"] / 64)


def galperin3_answer(scene: impact1d.Scene) -> dict:
    """Unfold the billiard (nbody_scenes.galperin_answer, derived there): in y = (sqrt(m) x1,
    sqrt(M) x2) the motion is straight, the configuration space the wedge of angle
    theta = atan(sqrt(m/M)), each collision a reflection in a side; the straight path
    crosses the images of the sides at angles alpha - j theta (alpha = atan2(sqrt M,
    sqrt m)) while they are above -pi/2, so the count is #{j >= 0 : (j + 1) theta < pi}
    = ceil(pi / theta) - 1: floor(pi / theta) unless pi / theta is a whole number (M = m:
    theta = pi/4, 3 collisions).  For M/m = 100^d, theta ~ 10^-d and the count is the first
    d + 1 digits of pi (31, 314).  Body 3 moves freely: x3 = x3(0) + 2 speed t."""
    pair = dict(m=scene.m[:2], x=scene.x[:2], v=scene.v[:2], t_end=scene.t_end, contacts=scene.contacts)
    answer = ns.galperin_answer(pair)
    x3, v3 = mpf(scene.x[2]), mpf(scene.v[2])
    x, v = answer["final"]
    return dict(events=answer["events"], final=(x + (x3 + v3 * mpf(scene.t_end),), v + (v3,)))


@pytest.mark.parametrize("ratio, count", [(1, 3), (2, 5), (16, 12), (100, 31)])
def test_reference_galperin_with_a_third_body(ratio, count):
    scene = galperin3(ratio)
    answer = galperin3_answer(scene)
    assert ns.galperin_count(ratio) == count == len(answer["events"])
    sol = nb.solve(reference_scene(scene))
    assert [e.kind for e in sol.events] == [kind for _, kind, _, _ in answer["events"]]
    for e, (t, _, before, after) in zip(sol.events, answer["events"]):
        assert abs(e.t - t) < EXACT
        assert max(abs(a - b) for a, b in zip(e.after[:2], after)) < EXACT
    for got, want in zip(sol.final[0] + sol.final[1], answer["final"][0] + answer["final"][1]):
        assert abs(got - want) < EXACT


@pytest.mark.parametrize("ratio, count", [(1, 3), (16, 12), (100, 31), (10_000, 314)])
def test_engine_galperin_with_a_third_body(ratio, count):
    scene = galperin3(ratio)
    answer = galperin3_answer(scene)
    res = run_engine(scene)
    got = engine_events(res)
    assert len(got) == count
    assert [kind for _, kind in got] == [kind for _, kind, _, _ in answer["events"]]
    assert max(abs(t - float(want[0])) for (t, _), want in zip(got, answer["events"])) < EVENT_TIME_TOL
    assert_final_matches(res, *answer["final"])


# --- (c) random chains against the reference -----------------------------------------------------

CHAIN_SEEDS = (4, 20, 5, 21, 22, 38, 3, 15)   # (3, 3, 4, 4, 5, 5, 6, 6 bodies; each solved in < 1 s)


def random_chain(seed: int) -> dict:
    """nbody_scenes.random_scene with 3 to 6 bodies (masses, friction with static >= sliding,
    constant forces, gaps some closed, neighbour records some with slots, walls and a stop)
    and every restitution below 1 (r = 1 becomes 0.875)."""
    scene = ns.random_scene(seed, n=3 + seed % 4)
    for rec in scene["contacts"]:
        for key in ("r_min", "r_max"):
            if rec.get(key) == 1.0:
                rec[key] = 0.875
    return scene


@pytest.fixture(scope="module")
def chains():
    with mp.workdps(nb.DPS):
        return {seed: nb.solve(random_chain(seed)) for seed in CHAIN_SEEDS}


def test_reference_random_chains_are_what_the_engine_reads(chains):
    """The engine's form of each chain reads back as the reference's (no meeting added, the
    records in order), the chains have 3 to 6 bodies, and their logs have enough to compare
    before any bounce series."""
    sizes, compared = set(), 0
    for seed in CHAIN_SEEDS:
        scene = random_chain(seed)
        back = reference_scene(engine_scene(scene))
        assert back["contacts"] == scene["contacts"] and back["m"] == scene["m"]
        assert all(r < 1 for rec in scene["contacts"] for r in (rec.get("r_min", 0), rec.get("r_max", 0)))
        sizes.add(len(scene["m"]))
        compared += len(reference_log(chains[seed]))
    assert sizes == {3, 4, 5, 6}
    assert compared >= 3 * len(CHAIN_SEEDS)


@pytest.mark.parametrize("seed", CHAIN_SEEDS)
def test_engine_random_chain(seed, chains):
    sol = chains[seed]
    res = run_engine(engine_scene(random_chain(seed)))
    assert_log_matches(res, sol, at_least=2)
    assert_final_matches(res, *sol.final)


# --- (d) momentum with no friction and no walls ---------------------------------------------------

MOMENTUM_SEEDS = (2, 3, 13, 21)   # (5, 6, 4, 4 bodies; 21 has joint impacts)


def free_chain(seed: int) -> dict:
    """random_chain without friction and without any contact to the ground (walls, stops):
    only body-body contacts, restitutions 0 to 0.875, constant forces."""
    scene = random_chain(seed)
    n = len(scene["m"])
    scene.update(mu=[0.0] * n, mus=[0.0] * n,
                 contacts=[rec for rec in scene["contacts"] if rec["a"] != 0 and rec["b"] != 0])
    return scene


def momentum_answer(scene: dict, t):
    """Body-body impulses and contact forces come in equal and opposite pairs and nothing
    else acts but the constant forces: P(t) = P0 + F t (F = sum f_i), and the centre of mass
    X(t) = X0 + (P0 t + F t^2 / 2) / M (X = sum m_i x_i / M)."""
    m = [mpf(a) for a in scene["m"]]
    total = sum(m)
    p0 = sum(a * mpf(u) for a, u in zip(m, scene["v"]))
    x0 = sum(a * mpf(u) for a, u in zip(m, scene["x"])) / total
    force = sum(mpf(a) for a in scene["f"])
    t = mpf(t)
    return p0 + force * t, x0 + (p0 * t + force * t * t / 2) / total


@pytest.mark.parametrize("seed", MOMENTUM_SEEDS)
def test_reference_momentum_without_friction_or_walls(seed):
    scene = free_chain(seed)
    sol = nb.solve(scene)
    m = sol.model.m
    assert len(sol.impacts()) >= 3
    for t in [e.t for e in sol.events] + [sol.t_end]:
        x, v = sol.state(t)
        p, centre = momentum_answer(scene, t)
        assert abs(sum(a * u for a, u in zip(m, v)) - p) < EXACT
        assert abs(sum(a * u for a, u in zip(m, x)) / sum(m) - centre) < EXACT


@pytest.mark.parametrize("seed", MOMENTUM_SEEDS)
def test_engine_momentum_without_friction_or_walls(seed):
    scene = free_chain(seed)
    res = run_engine(engine_scene(scene, dt_out=0.01))
    t, x, v = engine_samples(res)
    m = np.asarray(scene["m"])
    scale = float(np.sum(m * np.abs(v), axis=1).max()) + abs(sum(scene["f"])) * scene["t_end"]
    for k in range(len(t)):
        p, centre = momentum_answer(scene, t[k])
        assert abs(float(m @ v[k]) - float(p)) < 1e-12 * scale, t[k]
        assert abs(float(m @ x[k]) / m.sum() - float(centre)) < STATE_TOL, t[k]


# --- (e) a train's start-up --------------------------------------------------------------------------

def train(n: int = 10, m_wagon: float = 40.0, m_loco: float = 80.0, pull: float = 200.0, length: float = 16.0,
          slack: float = 0.0625, mu: float = 0.0, mus: float = 0.0, g: float = 9.81, t_end: float = 4.0):
    """Wagons 1..n-1 and a locomotive n at the head pulling with `pull` toward +x, standing
    with their buffers touching: coupler i (link<i>) on x(i+1) - x(i) in [length, length +
    slack], both limits plastic (r = 0), uniform friction (input/train.nml is
    train(mu=0.002, mus=0.004))."""
    return impact1d.Scene(m=[m_wagon] * (n - 1) + [m_loco], mu=[mu] * n, mus=[mus] * n, g=g,
                          x=[length * i for i in range(n)], f=[0.0] * (n - 1) + [pull],
                          d_min=[length] * (n - 1), r_min=[0.0] * (n - 1), d_max=[length + slack] * (n - 1),
                          r_max=[0.0] * (n - 1), t_end=t_end, dt=DT, dt_out=0.01)


def train_answer(scene: impact1d.Scene) -> dict:
    """The slack taken up coupler by coupler, from the locomotive back.

    While couplers n-1 .. n-k+1 are taut and wagon n-k still stands, the moving part (bodies
    n-k+1 .. n, mass M_k) moves as one body: the pull F acts on its head and every coupler in
    it carries the tension that drags the bodies behind (with uniform friction mu, the
    tension ahead of a body group of mass m' is m' F / M_k > 0, so no coupler goes slack).
    Its acceleration is a_k = (F - mu g M_k) / M_k (sliding friction on every moving body;
    the standing wagons are held by static friction, and the locomotive breaks away at
    t = 0 when F > mus g m_n).  Coupler n-k has its full slack s (buffers touching, wagon at
    rest), so starting at speed V_k the part covers s in
        tau_k = 2 s / (V_k + sqrt(V_k^2 + 2 a_k s))   (the root of V_k tau + a_k tau^2 / 2 = s,
                                                        written without cancellation)
    reaching U_k = sqrt(V_k^2 + 2 a_k s) (V_1 = 0: the locomotive alone from rest).  The
    take-up is a plastic impact of the moving part on wagon n-k: all the closed couplers are
    plastic, so the velocity after is the joint projection (docs/method.md 4), here the
    momentum-keeping common velocity V_{k+1} = M_k U_k / M_{k+1}: the coupler `link<n-k>_max`
    takes up at t_k = tau_1 + ... + tau_k.  (Plastic, because an elastic take-up is no
    impact of a block: the taut couplers are contacts, not rigid links, so the impulses run
    along them one pair at a time, as in Newton's cradle, and the moving part comes apart.)
    After the last take-up (k = n-1) the train moves
    as one at a = (F - mu g M) / M; at t_end > t_{n-1} its head is at
        x_n(0) + (n - 1) s + V_n tau + a tau^2 / 2   (tau = t_end - t_{n-1})
    and body j one stretched coupler length (length + s) per coupler behind it."""
    n = len(scene.m)
    m = [mpf(a) for a in scene.m]
    pull, g = mpf(scene.f[-1]), mpf(scene.g)
    mu = {mpf(a) for a in scene.mu}
    if len(mu) != 1 or pull <= mpf(scene.mus[-1]) * g * m[-1]:
        raise ValueError("train_answer: uniform friction, a pull that starts the locomotive")
    mu = mu.pop()
    slack = [mpf(b) - mpf(a) for a, b in zip(scene.d_min, scene.d_max)]
    takeups, t, speed = [], mpf(0), mpf(0)
    for k in range(1, n):
        mass = sum(m[n - k:])
        accel = (pull - mu * g * mass) / mass
        reach = speed * speed + 2 * accel * slack[n - k - 1]
        if reach <= 0:
            raise ValueError("train_answer: the moving part stops before the next coupler")
        t += 2 * slack[n - k - 1] / (speed + mp.sqrt(reach))
        speed = mass * mp.sqrt(reach) / (mass + m[n - k - 1])
        takeups.append((t, f"link{n - k}_max", speed))
    tau = mpf(scene.t_end) - t
    if tau <= 0:
        raise ValueError("train_answer: t_end before the last take-up")
    accel = (pull - mu * g * sum(m)) / sum(m)
    head = mpf(scene.x[-1]) + sum(slack) + speed * tau + accel * tau * tau / 2
    stretched = [mpf(b) for b in scene.d_max]
    x = tuple(head - sum(stretched[j:]) for j in range(n))
    return dict(takeups=takeups, final=(x, tuple(speed + accel * tau for _ in range(n))))


def test_train_file_is_the_train():
    assert reference_scene(load("train.nml")) == reference_scene(train(mu=0.002, mus=0.004))


@pytest.mark.parametrize("friction", [(0.0, 0.0), (0.002, 0.004)], ids=["frictionless", "train.nml"])
def test_reference_train_start_up(friction):
    """Every take-up instant, the common velocity after it and the final state to EXACT;
    at each take-up the moving part's couplers take the impulse together (one joint
    projection: the new coupler and the taut ones behind the locomotive)."""
    scene = train(mu=friction[0], mus=friction[1])
    answer = train_answer(scene)
    sol = nb.solve(reference_scene(scene))
    impacts = sol.impacts()
    first = {}
    for e in impacts:
        first.setdefault(e.kind, e)
    assert [first[kind].t for _, kind, _ in answer["takeups"]] == sorted(first[kind].t for kind in first)
    for t, kind, speed in answer["takeups"]:
        e = first[kind]
        assert abs(e.t - t) < EXACT, kind
        n_moving = len(scene.m) - int(kind[4:-4]) + 1
        assert all(abs(u - speed) < EXACT for u in e.after[-n_moving:]) and all(u == 0 for u in e.after[:-n_moving])
    assert len(impacts) == sum(range(1, len(scene.m)))   # take-up k moves couplers n-k .. n-1
    for got, want in zip(sol.final[0] + sol.final[1], answer["final"][0] + answer["final"][1]):
        assert abs(got - want) < EXACT
    if friction[0]:   # the numbers input/train.nml's comments give
        assert abs(float(answer["takeups"][-1][0]) - 1.1712) < 1e-4
        assert abs(float((200 - 0.002 * 9.81 * 440) / 440) - 0.435) < 1e-3


@pytest.mark.parametrize("friction", [(0.0, 0.0), (0.002, 0.004)], ids=["frictionless", "train.nml"])
def test_engine_train_start_up(friction):
    scene = train(mu=friction[0], mus=friction[1])
    answer = train_answer(scene)
    res = run_engine(scene)
    first = {}
    for t, kind in engine_events(res):
        if not kind.startswith(RESERVED):
            first.setdefault(kind, t)
    assert sorted(first) == sorted(kind for _, kind, _ in answer["takeups"])
    assert max(abs(first[kind] - float(t)) for t, kind, _ in answer["takeups"]) < EVENT_TIME_TOL
    assert_final_matches(res, *answer["final"])


# --- the N-body scenes of input/ ------------------------------------------------------------------

NBODY_FILES = ("newtons_cradle.nml", "train.nml", "ball_stack.nml", "gear_train.nml")
# Held to their closed forms in tests/test_example_scenes.py (burridge_knopoff: its springs
# and moving driver are beyond exact_nbody) and tests/test_gears.py (geared_train: its gear
# ratios are).
EXAMPLE_FILES = ("burridge_knopoff.nml", "geared_train.nml")


def stack() -> dict:
    """input/ball_stack.nml as tests/nbody_scenes.py builds it (the closed form's scene)."""
    return ns.falling_stack(m=(4.0, 2.0, 1.0), heights=(1.0, 1.375, 1.625), diameter=0.125, g=9.81,
                            r_floor=1.0, r_balls=(1.0, 1.0), t_end=1.6)


def test_reference_ball_stack():
    """The file is nbody_scenes.falling_stack's scene (f = -m g: 4 g and 2 g are exact in
    binary); its three impacts against the closed form (cut at t_safe, before the next
    event), and what its comments say: the top ball leaves at 10.57 m/s, 2.46 times the
    4.29 m/s the stack hits the floor with, and rises to about 6.2 m, its apex at 1.55 s."""
    file = reference_scene(load("ball_stack.nml"))
    want = stack()
    assert file["contacts"] == want["contacts"] and file["t_end"] == want["t_end"]
    assert all(file[key] == want[key] for key in ("m", "x", "v", "f", "g"))
    answer = ns.falling_stack_answer(dict(want, t_end=None))
    sol = nb.solve(dict(want, t_end=answer["t_safe"]))
    assert [(e.kind) for e in sol.events] == ["floor", "b12", "b23"]
    for e, (t, _, before, after) in zip(sol.events, answer["events"]):
        assert abs(e.t - t) < EXACT and max(abs(a - b) for a, b in zip(e.after, after)) < EXACT
    top, hit = answer["events"][2][3][2], -answer["events"][0][2][2]
    assert abs(top - mpf("10.567")) < 1e-3 and abs(hit - mpf("4.289")) < 1e-3 and 2.46 < top / hit < 2.47
    t3 = float(answer["events"][2][0])
    apex = 1.625 - 9.81 * t3 ** 2 / 2 + float(top) ** 2 / (2 * 9.81)
    assert 6.1 < apex < 6.3 and 1.5 < t3 + float(top) / 9.81 < 1.6


def test_reference_cradle_file_one_out():
    sol = nb.solve(reference_scene(load("newtons_cradle.nml")))
    assert sol.final[1] == (0, 0, 0, 0, mpf(0.5))
    assert [e.kind for e in sol.impacts()] == ["link1", "link2", "link3", "link4"]


@pytest.mark.parametrize("name", NBODY_FILES)
def test_engine_input_scene_matches_reference(name):
    scene = load(name)
    sol = nb.solve(reference_scene(scene))
    res = run_engine(scene)
    assert_log_matches(res, sol, at_least=2)
    assert_final_matches(res, *sol.final)


def test_input_scenes_of_n_bodies_are_guarded_by_the_golden_hashes():
    """The scenes of more than two bodies in input/ are these, and tests/golden/hashes.json
    holds their samples' and events' hashes (a change of their results is seen)."""
    import json
    many = sorted(path.name for path in INPUT.glob("*.nml") if len(load(path.name).m or ()) > 2)
    assert many == sorted(NBODY_FILES + EXAMPLE_FILES)
    hashes = json.loads((Path(__file__).resolve().parent / "golden" / "hashes.json").read_text())
    assert all(f"input/{name}" in hashes for name in many)


def test_sweep_of_an_n_body_scene_agrees_with_its_runs():
    """impact1d.sweep runs scenes of more than two bodies through the summary path (the
    core's batch, threads too): each row's final state and counts are its own run's."""
    scene = load("newtons_cradle.nml")
    ends = [0.25, 0.5, 1.0]
    for workers in (None, 2):
        table = impact1d.sweep(scene, {"t_end": ends}, workers=workers)
        assert list(table["error"]) == [""] * len(ends)
        for row, t_end in zip(table.itertuples(), ends):
            res = impact1d.simulate(scene, t_end=t_end)
            assert row.x1_end == res.x1[-1] and row.v2_end == res.v2[-1]
            assert row.n_impacts == sum(not str(k).startswith(RESERVED) for k in res.events["kind"])


def test_sweep_of_an_n_body_scene_has_every_bodys_columns():
    """A sweep of N > 2 bodies adds x3_end v3_end .. xN_end vN_end (and with settle
    x3_p2p x3_rms v3_p2p v3_rms ..): the core's batch and the per-run path (keep='results',
    which raised on the N-body event log's missing v1_after) give the same table, each
    body's end its run's last sample; t_rest from the samples alone (three blocks sliding
    to a stop: the first sample from which no body moves)."""
    cradle = load("newtons_cradle.nml")
    table = impact1d.sweep(cradle, {"t_end": [0.5, 1.0]})
    kept, results = impact1d.sweep(cradle, {"t_end": [0.5, 1.0]}, keep="results")
    n = len(cradle.m)
    columns = [f"{q}{i}_end" for i in range(3, n + 1) for q in "xv"]
    assert list(table.columns[-1 - len(columns):-1]) == columns
    __import__("pandas").testing.assert_frame_equal(table, kept)
    for row, res in zip(table.to_dict("records"), results):
        assert [row[f"x{i}_end"] for i in range(1, n + 1)] == list(res.x[-1])
        assert [row[f"v{i}_end"] for i in range(1, n + 1)] == list(res.v[-1])
    steady = impact1d.sweep(cradle, {"t_end": [2.0]}, settle=1.0)
    assert steady["x5_p2p"][0] == pytest.approx(0.5) and steady["v5_rms"][0] == 0.0
    assert steady["x4_p2p"][0] == 0.0
    blocks = impact1d.Scene(m=[1.0, 2.0, 1.0], x=[0.0, 1.0, 2.0], v=[1.0, 0.5, -0.5], mu=[0.5] * 3,
                            t_end=1.0, dt=0.01)
    rest = impact1d.simulate(blocks)
    moving = np.any(rest.v != 0.0, axis=1)
    assert not moving[-1] and moving[0]
    expected = rest.t[np.flatnonzero(moving)[-1] + 1]     # the first sample after the last stop
    assert 0.2 < expected < 0.22
    table = impact1d.sweep(blocks, {"t_end": [1.0]})
    kept, _ = impact1d.sweep(blocks, {"t_end": [1.0]}, keep="results")
    assert table["t_rest"][0] == kept["t_rest"][0] == expected
