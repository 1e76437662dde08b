"""The engine against the exact event-driven reference (tests/exact_reference.py).

exact_reference solves docs/method.md sections 1-5 for constant and piecewise-linear forces
from the polynomials of each phase (no integrator, no dense output: roots of the
phase's own polynomials), so it shares no code path with the engine.  For those
forces the engine's event times and states are exact to rounding whatever dt is
(docs/method.md 3): here it runs at dt = 1e-2 with dt_out = t_end / 100, so that several
events fall inside one step, and must agree with the reference on
  - every impact: kind and time to EVENT_TIME_TOL, velocities before/after;
  - every other event (rest_*, release_*, stick*, slip*): kind and time;
  - the final state (x1, v1, x2, v2) at t_end to STATE_TOL.

(a) the seed cases 2-6 of input/; (b) N_SCENES scenes generated from a seeded numpy
Generator, covering friction on/off, 0-4 constraints, restitutions in {0, 0.3, 0.7, 1}
and random, constant forces of both signs below and above the friction bounds,
piecewise-linear tables, rigid links, and scenes built to rattle to rest (Zeno).

A failing scene prints its index, seed and namelist text; rerun it alone with
    pytest tests/test_reference.py -k "scene_017"
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest

import impact1d
import exact_reference as ref

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"

# --- tolerances (the bounds; never loosened to make a scene pass) -------------
EVENT_TIME_TOL = 1e-9    # s, every event time
STATE_TOL = 1e-8         # final x1, v1, x2, v2
VELOCITY_TOL = 1e-8      # impact velocities before/after
# Convention difference 1 (reported): the engine ends a bounce series when a flight is
# lower than 256 eps |position| (docs/method.md 5: "below what the state can resolve"), so it
# skips the last impacts of a series, those with a normal speed of a few um/s at most,
# within microseconds of the accumulation time; the reference follows the series until
# its remaining time is below 1e-13 s.  Such impacts of the contact that rests may be
# unmatched if they are slower than ZENO_TAIL_SPEED and lie within ZENO_TAIL_TIME
# before that contact's rest event (whose time must match).  Kept small: a flight of
# height h = 256 eps * 20 m under 50 m/s^2 starts at 3e-5 m/s.
# A body with friction in such a tail stops between bounces: its stick/slip events
# there are not compared either (the engine logs its stick at the end of what it
# resolves, the reference at the last stop of the series).
ZENO_TAIL_SPEED = 1e-4   # m/s
ZENO_TAIL_TIME = 1e-3    # s

# Convention difference 2: where the sequential impulses of a body pinned between two
# closed contacts converge geometrically at one instant, each solver stops at its own
# rounding floor (the reference at 1e-15 m/s); impacts slower than this are rounding.
NOISE_SPEED = 1e-12      # m/s

# Convention difference 3: a nested Zeno series (a body rattling between a wall and the
# other body; each wall series reopens the slot) has infinitely many rest/release cycles
# before its accumulation, their speeds falling geometrically (scene 56: 4.1e-11,
# 2.5e-12, 1.5e-13, 9.3e-15 m/s a cycle).  Each solver ends the nesting at its own floor
# (the reference at ZENO_TIME 1e-13 s and 1e-15 m/s, the engine at its clock's and
# velocities' rounding), so the last cycles' rest_/release_ entries exist in one log only.
# Checked against a 50-digit event-driven solution (issue 18): the engine's are real
# (scene 56's release_slot_min at 2.0849134173335839 s, exact 2.0849134173335844) and in
# scene 12 the engine is closer to exact than the reference.  Rule: a rest_/release_ entry
# in one log only, every velocity in it below NESTED_TAIL_SPEED, within NESTED_TAIL_TIME
# of another rest_/release_ entry (of either log: the cluster at the accumulation), is not
# compared.  Impacts above NOISE_SPEED, final states and every other entry still are.
NESTED_TAIL_SPEED = 1e-11   # m/s
NESTED_TAIL_TIME = 1e-12    # s

DT = 1e-2
N_SCENES = 150
SEED = 20240603

IMPACTS = ref.IMPACT_KINDS


# --- comparison -----------------------------------------------------------------------

def engine_events(res):
    return [(float(e["t"]), str(e["kind"]), float(e["v1_before"]), float(e["v2_before"]),
             float(e["v1_after"]), float(e["v2_after"])) for e in res.events]


def _normal_speed(kind, e):
    n = ref.NORMALS[kind]
    return abs(n[0] * e[2] + n[1] * e[3])


def _match(got, want, tol):
    """Greedy one-to-one matching of two sorted time lists within tol.
    Returns (pairs, unmatched got indices, unmatched want indices)."""
    pairs, un_got, un_want = [], [], []
    i = j = 0
    while i < len(got) and j < len(want):
        if abs(got[i] - want[j]) <= tol:
            pairs.append((i, j))
            i += 1
            j += 1
        elif got[i] < want[j]:
            un_got.append(i)
            i += 1
        else:
            un_want.append(j)
            j += 1
    un_got += range(i, len(got))
    un_want += range(j, len(want))
    return pairs, un_got, un_want


def _in_tail(t, rest_times):
    return any(tr - ZENO_TAIL_TIME <= t <= tr + EVENT_TIME_TOL for tr in rest_times)


def _persistence(kind):
    return kind.startswith(("rest_", "release_"))


def _in_nested_tail(e, got, want):
    """e (a rest_/release_ entry in one log only) is a rounding-level relabelling in the
    last cycles of a nested series: see NESTED_TAIL_SPEED."""
    if not _persistence(e[1]) or max(abs(v) for v in e[2:]) > NESTED_TAIL_SPEED:
        return False
    return any(o is not e and _persistence(o[1]) and abs(o[0] - e[0]) <= NESTED_TAIL_TIME
               for o in (*got, *want))


def compare_events(got, want):
    """Problems (list of text) between the engine's events `got` and the reference's
    `want`, both lists of (t, kind, v1b, v2b, v1a, v2a).  Compared per kind, sorted by
    time: the order of events logged at one instant is a convention (sequential impulses
    at equal approach speeds, simultaneous impacts of separate bodies located in
    different steps), their kinds and times are not."""
    problems = []
    kinds = sorted({e[1] for e in got} | {e[1] for e in want})
    rests = {e[1][5:]: e[0] for e in want if e[1].startswith("rest_")}
    for kind in kinds:
        g = sorted((e for e in got if e[1] == kind), key=lambda e: e[0])
        w = sorted((e for e in want if e[1] == kind), key=lambda e: e[0])
        pairs, un_g, un_w = _match([e[0] for e in g], [e[0] for e in w], EVENT_TIME_TOL)
        for side, unmatched, events in (("engine", un_g, g), ("reference", un_w, w)):
            for idx in unmatched:
                e = events[idx]
                if kind in IMPACTS and _normal_speed(kind, e) <= NOISE_SPEED:
                    continue  # a rounding-level impulse (see NOISE_SPEED)
                if kind in IMPACTS and kind in rests and _normal_speed(kind, e) <= ZENO_TAIL_SPEED \
                        and _in_tail(e[0], [rests[kind]]):
                    continue  # the last impacts of a Zeno series (see ZENO_TAIL_SPEED)
                if kind[:-1] in ("stick", "slip") and _in_tail(e[0], rests.values()):
                    continue  # stops and starts inside a Zeno tail (see ZENO_TAIL_SPEED)
                if _in_nested_tail(e, got, want):
                    continue  # the last cycles of a nested series (see NESTED_TAIL_SPEED)
                problems.append(f"{kind} at t = {e[0]!r} only in the {side} log {e[2:]}")
        if kind in IMPACTS:
            for i, j in pairs:
                if sum(abs(e[0] - w[j][0]) <= EVENT_TIME_TOL for e in want if e[1] in IMPACTS) > 1:
                    # Simultaneous impacts: the other body's velocity in the entry depends on
                    # the order they are logged in; the contact's own normal velocity not.
                    n = ref.NORMALS[kind]
                    dv = max(abs(n[0] * (g[i][k] - w[j][k]) + n[1] * (g[i][k + 1] - w[j][k + 1]))
                             for k in (2, 4))
                else:
                    dv = max(abs(a - b) for a, b in zip(g[i][2:], w[j][2:]))
                if dv > VELOCITY_TOL:
                    problems.append(f"{kind} at t = {w[j][0]!r}: velocities {g[i][2:]} "
                                    f"!= reference {w[j][2:]}")
    return problems


def compare(scene, res, sol):
    problems = compare_events(engine_events(res), sol.events)
    got = (res.x1[-1], res.v1[-1], res.x2[-1], res.v2[-1])
    err = max(abs(a - b) for a, b in zip(got, sol.final))
    if not res.t[-1] == pytest.approx(sol.t_end, abs=1e-12):
        problems.append(f"last sample at {res.t[-1]}, t_end = {sol.t_end}")
    if err > STATE_TOL:
        problems.append(f"final state {got} != reference {sol.final} (error {err:.3e})")
    return problems


def describe(scene, tables=None):
    """The scene as namelist text, enough to reproduce it."""
    groups = {
        "bodies": ("m1", "m2", "mu1", "mu2", "mus1", "mus2", "g"),
        "walls": ("x_left", "r_left", "x_right", "r_right"),
        "link": ("d_min", "r_min", "d_max", "r_max"),
        "initial": ("x1", "v1", "x2", "v2"),
        "forces": ("f1", "f2", "f1_table", "f2_table"),
        "run": ("t_end", "dt", "dt_out"),
    }
    lines = []
    for group, names in groups.items():
        parts = []
        for name in names:
            value = getattr(scene, name)
            if value is None:
                continue
            parts.append(f"{name} = '{value}'" if isinstance(value, str) else f"{name} = {value!r}")
        if parts:
            lines.append(f"&{group} " + ", ".join(parts) + " /")
    for name, table in (tables or {}).items():
        lines.append(f"! {name}: " + "; ".join(f"{t!r} {f!r}" for t, f in zip(*table)))
    return "\n".join(lines)


def check(scene, label, tables=None, dt=DT):
    res = impact1d.simulate(scene, dt=dt, dt_out=max(scene.t_end / 100, dt))
    sol = ref.solve(scene)
    problems = compare(scene, res, sol)
    if problems:
        shown = problems[:12] + ([f"... {len(problems) - 12} more"] if len(problems) > 12 else [])
        raise AssertionError(f"{label}: engine and reference disagree:\n  " + "\n  ".join(shown)
                             + "\nscene:\n" + describe(scene, tables))
    return res, sol


# --- (a) the seed cases ----------------------------------------------------------------

@pytest.mark.parametrize("case", (2, 3, 4, 5, 6))
def test_seed_case_matches_reference(case):
    scene = impact1d.load_scene(INPUT / f"case{case}.nml")
    res, sol = check(scene, f"input/case{case}.nml")
    if case in (2, 4):  # every event matched one to one, not only within tolerance
        assert [e[1] for e in sol.events] == list(res.events["kind"])


def test_seed_case5_events_by_hand():
    """The reference itself against the closed form of case 5: impacts at 3 - 2^(1-k) on
    both walls, rest at 3 s."""
    sol = ref.solve(impact1d.load_scene(INPUT / "case5.nml"))
    for kind in ("left", "right"):
        times = np.array([e[0] for e in sol.events if e[1] == kind])
        k = np.arange(len(times))
        assert np.max(np.abs(times - (3.0 - 2.0 ** (1 - k)))) < 1e-14
        assert 40 <= len(times) <= 50  # until the rest of the series lasts < 1e-13 s
    rest = [e for e in sol.events if e[1].startswith("rest_")]
    assert sorted(e[1] for e in rest) == ["rest_left", "rest_right"]
    assert all(abs(e[0] - 3.0) < 1e-13 for e in rest)
    assert sol.final == (0.0, 0.0, 10.0, 0.0)


def test_seed_case4_by_hand():
    sol = ref.solve(impact1d.load_scene(INPUT / "case4.nml"))
    kinds = [(e[1], e[0]) for e in sol.events]
    assert [k for k, _ in kinds] == ["slot_min", "rest_slot_min", "stick1", "stick2"]
    assert abs(kinds[0][1] - 0.2) < 1e-14 and abs(kinds[2][1] - 7.0 / 15.0) < 1e-14
    assert sol.final == pytest.approx((2.8 + 16.0 / 45.0, 0.0, 2.8 + 16.0 / 45.0, 0.0), abs=1e-14)


# --- (b) generated scenes ------------------------------------------------------------------

def _restitution(rng):
    choice = rng.integers(5)
    return (0.0, 0.3, 0.7, 1.0, round(float(rng.uniform(0.05, 0.95)), 4))[choice]


def _force(rng, c):
    """A constant force of either sign: zero, below the friction bound c, above it."""
    kind = rng.integers(4)
    sign = 1.0 if rng.random() < 0.5 else -1.0
    if kind == 0:
        return None
    if c > 0.0 and kind == 1:
        return sign * round(float(rng.uniform(0.1, 0.9)) * c, 4)
    if c > 0.0:
        return sign * round(float(rng.uniform(1.2, 3.0)) * c, 4)
    return sign * round(float(rng.uniform(0.5, 10.0)), 4)


def _table(rng, t_end):
    n = int(rng.integers(2, 6))
    times = np.sort(rng.choice(np.arange(1, 40), size=n, replace=False)) * (t_end / 40.0)
    values = np.round(rng.uniform(-15.0, 15.0, size=n), 3)
    return [round(float(t), 6) for t in times], [float(f) for f in values]


FAMILIES = ("random", "zeno_wall", "zeno_slot", "table_friction", "rigid_link", "box")


def generate(index, folder):
    """Scene number `index` (its own Generator seeded by (SEED, index)): the family
    cycles so each is covered.  Initial states are strictly inside the constraints
    (except the rigid link, whose limits coincide).

    Excluded by construction: exactly simultaneous impacts of separate contacts whose
    outcome depends on the order (random values make them a null set; the seed case 5
    and the Zeno families only produce simultaneous impacts the sequential rule settles
    the same way in both solvers) and grazing touches at zero speed."""
    rng = np.random.default_rng([SEED, index])
    family = FAMILIES[index % len(FAMILIES)]
    t_end = round(float(rng.uniform(2.0, 5.0)), 3)
    s = dict(m1=round(float(rng.uniform(0.5, 3.0)), 3), m2=round(float(rng.uniform(0.5, 3.0)), 3),
             t_end=t_end, title=f"generated scene {index} ({family})")
    if rng.random() < 0.5:
        s["g"] = 10.0
    g = s.get("g", ref.DEFAULT_G)
    friction = rng.random(2) < 0.5
    for i in (1, 2):
        if friction[i - 1]:
            s[f"mu{i}"] = round(float(rng.uniform(0.05, 0.5)), 3)
    c = [s.get(f"mu{i}", 0.0) * s[f"m{i}"] * g for i in (1, 2)]

    # Constraints: a random subset (family-specific below).
    x_left = round(float(rng.uniform(-2.0, 1.0)), 3)
    width = round(float(rng.uniform(4.0, 10.0)), 3)
    d_min = round(float(rng.uniform(0.2, 1.0)), 3)
    d_max = round(d_min + float(rng.uniform(0.3, 2.0)), 3)
    present = rng.random(4) < 0.5
    if family == "zeno_wall":
        present[0] = True
    if family in ("zeno_slot", "rigid_link"):
        present[2] = True
    if family == "rigid_link":
        present[3] = True
        d_max = d_min
    if family == "box":
        present[:] = True
    names = ("left", "right", "slot_min", "slot_max")
    for k, name in enumerate(names):
        if not present[k]:
            continue
        limit = {"left": x_left, "right": x_left + width, "slot_min": d_min, "slot_max": d_max}[name]
        s[ref.LIMIT[name]] = round(limit, 3)
        r = _restitution(rng)
        if family.startswith("zeno") and r == 1.0:
            r = 0.7
        if rng.random() < 0.9 or r != 1.0:  # a missing restitution means 1
            s[ref.RESTITUTION[name]] = r

    # Bodies on one line meet unless the scene says how far they may pass: a scene without
    # the link's lower limit gets one far beyond reach, so its bodies move independently.
    if not present[2]:
        s["d_min"] = -1.0e4

    # Initial separation and positions strictly inside.
    lo = d_min + 0.05 if present[2] else -2.0
    hi = d_max - 0.05 if present[3] else (lo + 3.0 if present[2] else 3.0)
    if family == "rigid_link":
        sep = d_min
    else:
        sep = round(float(rng.uniform(lo, hi)), 3)
    left = x_left + 0.05 if present[0] else x_left - 3.0
    right = x_left + width - 0.05 if present[1] else x_left + width + 3.0
    x1_lo = max(left, left - sep)
    x1_hi = min(right - sep, right)
    s["x1"] = round(float(rng.uniform(x1_lo, x1_hi)), 3)
    s["x2"] = round(s["x1"] + sep, 3) if family != "rigid_link" else s["x1"] + d_min
    if family != "rigid_link":
        # Rounding of x1 + sep must not touch a limit.
        assert s["x1"] > left - 0.04 and s["x2"] < right + 0.04
    s["v1"] = round(float(rng.uniform(-5.0, 5.0)), 3)
    s["v2"] = round(float(rng.uniform(-5.0, 5.0)), 3)

    s["f1"], s["f2"] = _force(rng, c[0]), _force(rng, c[1])
    if family == "zeno_wall":  # push body 1 into the left wall, harder than friction
        s["f1"] = -round(max(1.2 * c[0], 0.5) + float(rng.uniform(0.0, 6.0)), 4)
        s["v1"] = -abs(s["v1"])
    if family == "zeno_slot":  # push the bodies into each other
        s["f1"] = round(max(1.2 * c[0], 0.5) + float(rng.uniform(0.0, 6.0)), 4)
        s["f2"] = -round(max(1.2 * c[1], 0.5) + float(rng.uniform(0.0, 6.0)), 4)
        if s.get("r_min", 1.0) == 1.0:
            s["r_min"] = 0.5
    tables = {}
    p_table = 0.8 if family == "table_friction" else 0.2
    for i in (1, 2):
        if rng.random() < p_table:
            table = _table(rng, t_end)
            path = os.path.join(folder, f"scene{index:03d}_f{i}.dat")
            with open(path, "w", encoding="utf-8") as handle:
                handle.write(f"# generated scene {index}: f{i} table\n")
                for t, f in zip(*table):
                    handle.write(f"{t!r} {f!r}\n")
            s[f"f{i}_table"] = path
            tables[f"f{i}_table"] = table
    if family == "table_friction" and not any(friction):
        s["mu1"] = 0.3
    return impact1d.Scene(**s), tables


@pytest.fixture(scope="module")
def table_folder(tmp_path_factory):
    return str(tmp_path_factory.mktemp("reference_tables"))


# Scenes once marked here as engine bugs (56, 6, 12, 90) were nested Zeno series whose
# last cycles each solver cuts at its own floor: see NESTED_TAIL_SPEED.  A new
# disagreement is a failure to investigate (against a 50-digit solution) before either
# the engine or the reference changes.

def _params():
    return [pytest.param(i, id=f"scene_{i:03d}_{FAMILIES[i % len(FAMILIES)]}") for i in range(N_SCENES)]


@pytest.mark.parametrize("index", _params())
def test_generated_scene_matches_reference(index, table_folder):
    scene, tables = generate(index, table_folder)
    check(scene, f"generated scene {index} (SEED = {SEED}, family "
                 f"{FAMILIES[index % len(FAMILIES)]})", tables)


# Fine steps: 10^4..10^6 steps a run, most of them (under constant forces) taken in bulk
# between events, the rest located one by one; rounding must not build up over them.
FINE_DT = 1e-5
FINE_EVERY = 5      # every 5th generated scene (the seeds all)


@pytest.mark.parametrize("case", (2, 3, 4, 5, 6))
def test_seed_case_at_fine_step_matches_reference(case):
    scene = impact1d.load_scene(INPUT / f"case{case}.nml")
    check(scene, f"input/case{case}.nml at dt = {FINE_DT}", dt=FINE_DT)


@pytest.mark.parametrize("index", [p for p in _params() if p.values[0] % FINE_EVERY == 0])
def test_generated_scene_at_fine_step_matches_reference(index, table_folder):
    scene, tables = generate(index, table_folder)
    check(scene, f"generated scene {index} at dt = {FINE_DT}", tables, dt=FINE_DT)


# Found by running other seeds and steps against the reference, each once an engine bug:
# a nested bounce series (body 1 between the left wall and body 2) at dt = 0.1, whose
# 1e-9 s flights were lost in the rounding of the whole step's motion (seed 778, scene
# 35); a contact released at a force ramp that closed again at once, for ever (seed 777,
# scene 2, dt = 1e-3); a resting slot contact broken by a wall impact and at rest again
# at the same instant after the chain of impacts, logged as a release and a rest because
# the wall's rest flushed the pending release (seed 780, scene 137, dt = 3e-4).
NESTED_AT_COARSE_STEP = impact1d.Scene(
    m1=2.534, m2=2.944, x_left=-1.417, r_left=0.3, x_right=7.213, r_right=0.7, d_min=0.945,
    r_min=0.0, d_max=1.305, r_max=0.3, x1=4.781, v1=0.705, x2=5.903, v2=2.381, f1=6.5825,
    f2=9.8659, t_end=3.573)
RELEASE_AT_A_RAMP = dict(
    m1=2.345, m2=1.702, mu1=0.259, x_right=7.436, r_right=0.3, d_min=0.458, r_min=0.2384,
    x1=-0.648, v1=3.02, x2=2.548, v2=3.251, f1=12.7679, f2=-5.2699, t_end=3.381)


CHAIN_AT_ONE_INSTANT = dict(
    m1=1.832, m2=1.861, mu1=0.413, mu2=0.397, g=10.0, x_left=-0.264, r_left=0.7,
    x_right=6.616, r_right=0.8392, d_min=0.769, r_min=0.0, d_max=2.739, r_max=0.7,
    x1=2.927, v1=-4.536, x2=4.586, v2=-4.845, f1=-2.5556, f2=-20.308, t_end=2.977)


def test_nested_series_at_a_coarse_step():
    check(NESTED_AT_COARSE_STEP, "nested series at dt = 0.1", dt=0.1)


def test_release_at_a_force_ramp(tmp_path):
    table = tmp_path / "f2.dat"
    table.write_text("2.113125 13.208\n2.789325 -14.573\n")
    scene = impact1d.Scene(**RELEASE_AT_A_RAMP, f2_table=str(table))
    check(scene, "release at a force ramp, dt = 1e-3",
          {"f2_table": ((2.113125, 2.789325), (13.208, -14.573))}, dt=1e-3)


def test_release_and_rest_at_one_instant_cancel(tmp_path):
    table = tmp_path / "f2.dat"
    table.write_text("0.2977 -2.987\n0.372125 2.34\n2.82815 4.435\n")
    scene = impact1d.Scene(**CHAIN_AT_ONE_INSTANT, f2_table=str(table))
    check(scene, "chain of impacts at one instant, dt = 3e-4",
          {"f2_table": ((0.2977, 0.372125, 2.82815), (-2.987, 2.34, 4.435))}, dt=3e-4)


def test_generated_scenes_cover_the_physics(table_folder):
    """The generated set exercises what the issue asks for (checked on the reference)."""
    kinds = set()
    n_friction = n_table = n_rigid = 0
    n_constraints = set()
    for i in range(N_SCENES):
        scene, tables = generate(i, table_folder)
        kinds |= {e[1] for e in ref.solve(scene).events}
        n_friction += bool(scene.mu1 or scene.mu2)
        n_table += bool(tables)
        n_rigid += scene.d_min is not None and scene.d_min == scene.d_max
        # (a lower limit far beyond reach only lets the bodies pass: not a constraint)
        n_constraints.add(sum(getattr(scene, k) is not None
                              for k in ("x_left", "x_right", "d_min", "d_max"))
                          - (scene.d_min == -1.0e4))
    assert n_constraints == {0, 1, 2, 3, 4}
    assert n_friction >= 30 and n_table >= 20 and n_rigid >= 10
    for kind in ("left", "right", "slot_min", "slot_max", "rest_left", "rest_slot_min",
                 "release_left", "stick1", "stick2", "slip1", "slip2"):
        assert kind in kinds, kind


# Static friction above sliding friction (mus > mu): the generated scenes with friction,
# each body's static coefficient raised by a seeded factor in [1, 2]. (The reference
# ignored mus1/mus2 until issue 18's round: no test compared break-away thresholds above
# the sliding bound, which tests/exact_springs.py covers for one body only.)
N_STATIC = 40


def _static_params():
    return [pytest.param(i, id=f"scene_{i:03d}_static") for i in range(N_STATIC)]


@pytest.mark.parametrize("index", _static_params())
def test_static_above_sliding_friction_matches_reference(index, table_folder):
    scene, tables = generate(index, table_folder)
    rng = np.random.default_rng((SEED, index, 2))
    if not (scene.mu1 or scene.mu2):
        scene = dataclasses.replace(scene, mu1=0.3)
    raised = {f"mus{i}": getattr(scene, f"mu{i}") * float(rng.uniform(1.0, 2.0))
              for i in (1, 2) if getattr(scene, f"mu{i}")}
    scene = dataclasses.replace(scene, **raised)
    check(scene, f"generated scene {index} with static friction {raised}", tables)
