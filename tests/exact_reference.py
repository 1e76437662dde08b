"""An exact, independent event-driven reference solver for impact1d (docs/method.md sections 1-5).

Pure Python (numpy not even needed), written from the physics of docs/method.md and sharing
no code with the Fortran engine, so that the tests can compare the engine with it.

Scope: forces f_i(t) = constant + piecewise-linear table (held constant outside its
times); no sine.  Everything else of the model: Coulomb friction (stick, slip, stop),
any subset of the four unilateral constraints, Newton restitution by sequential
impulses, persistent contacts with contact forces from the small complementarity
problem, Zeno accumulation, a rigid link (d_min = d_max).

How it is exact.  Between two events the mode (active contacts, stuck bodies, sliding
directions) is fixed and the forces are linear in time, so the accelerations are
linear, the velocities quadratic and the gaps cubic in the time tau since the phase
start.  The solver never steps: it writes these polynomials down and finds the
earliest root of every watched function (gap of an open contact, velocity of a
sliding body, contact force / friction margin of the mode: linear) by isolating the
roots between the extrema of the polynomial (closed-form quadratic for the critical
points) and polishing them with safeguarded Newton to rounding.  Then it moves the
state to that instant with the same polynomials and handles the event point.

Bookkeeping that keeps the solution exact to rounding:
- A contact is "touching" only when the solver knows it: its root located the event
  (or fell on the same instant to rounding), or it was held/at rest and stayed so.
  Gaps of touching contacts are exactly 0 (positions snapped), so a bounce of height
  1e-25 m still has its flight time 2 u / a to full relative precision: a Zeno series
  is followed bounce by bounce until the rest of it lasts less than ZENO_TIME, then
  the contact is put to rest and `rest_<contact>` is logged at the accumulation time.
- Held motion is exact: a body on a wall or stuck has a = 0, bodies locked by the
  slot get the same acceleration, a perfectly inelastic impact leaves exactly zero
  normal velocity.

Event log conventions (those of the engine, README 'Inputs'):
- `left right slot_min slot_max`: one entry per impulse, velocities before/after.  A
  rigid link (d_min = d_max, closed) hitting a wall is one body of mass m1 + m2: one wall
  entry, v1' = v2' = -r v_cm, no slot impulse.
- `rest_<contact>`: the contact becomes persistent (active in the mode) and was not in
  contact before; at the accumulation time for a Zeno series.
- `release_<contact>`: a contact that was in contact opens (it leaves the mode and its
  gap starts to grow), logged at the instant it opens: where its force reaches zero, or a
  body on it breaks away from static friction at the bound, the separating acceleration
  is zero there and only its rate is positive (gap ~ s^3): that is still the release.  A contact that leaves the mode but stays closed because static
  friction now carries the load (acceleration along its normal zero) is still in
  contact: no release, and no new rest when it is held again.
- `stick<i>`: a sliding body with friction comes to rest and stays (not at t = 0).
- `slip<i>`: a body at rest breaks away without an impulse (not at t = 0).
- Mode choice when several are consistent (statically indeterminate cases): most
  bodies stuck, then most contacts held; the combination with dependent rows (a stuck
  body on its wall, both slot limits) is never used, its accelerations being those of
  another vertex.

Public API:
    solve(scene, t_end=None) -> Solution(events, final, phases, t_end); sol.state(t)
    read_table(path) -> (times, values)
and, for older tests, simulate_exact(scene) (impacts and free-flight segments) and
state_at(segments, a1, a2, times) for constant-force frictionless scenes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

EPS = 2.220446049250313e-16

# Contacts in the engine's order; normal on (x1, x2); gap = n . x + offset.
CONTACTS = ("left", "right", "slot_min", "slot_max")
NORMALS = {"left": (1.0, 0.0), "right": (0.0, -1.0),
           "slot_min": (-1.0, 1.0), "slot_max": (1.0, -1.0)}
LIMIT = {"left": "x_left", "right": "x_right", "slot_min": "d_min", "slot_max": "d_max"}
RESTITUTION = {"left": "r_left", "right": "r_right", "slot_min": "r_min", "slot_max": "r_max"}
IMPACT_KINDS = CONTACTS
DEFAULT_G = 9.80665

# A bounce series whose remaining flights last less than this (s) is put to rest at its
# accumulation time (docs/method.md 5); far below the 1e-9 s the tests ask for.
ZENO_TIME = 1e-13
# Normal velocities below this (m/s) are zero: a rounding level for velocities of
# order 1-10 m/s, and it ends the geometric impulse chains that a body pinned between
# two closed contacts (r < 1) would otherwise repeat forever at one instant.
VELOCITY_FLOOR = 1e-15
# Guards against a run that does not terminate.
MAX_EVENTS = 200_000
MAX_IMPULSES = 100_000
MAX_STALLS = 10_000


def _field(scene, name, default=None):
    value = scene.get(name, default) if isinstance(scene, dict) else getattr(scene, name, default)
    return default if value is None else value


def read_table(path):
    """A two-column `t f` file (comments after '#') -> (times, values)."""
    times, values = [], []
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            words = line.split("#", 1)[0].split()
            if words:
                times.append(float(words[0]))
                values.append(float(words[1]))
    return times, values


class Forcing:
    """f_i(t) = constant_i + table_i(t): value, right derivative and breakpoints."""

    def __init__(self, constants, tables):
        self.constants = constants
        self.tables = tables  # per body: None or (times, values)
        self.breaks = sorted({t for tab in tables if tab for t in tab[0]})

    @staticmethod
    def _segment(times, t):
        """Index k of the last corner with times[k] <= t (-1 before the first)."""
        lo, hi = -1, len(times)
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if times[mid] <= t:
                lo = mid
            else:
                hi = mid
        return lo

    def force(self, t):
        out = list(self.constants)
        for i, tab in enumerate(self.tables):
            if not tab:
                continue
            ts, fs = tab
            k = self._segment(ts, t)
            if k < 0:
                out[i] += fs[0]
            elif k >= len(ts) - 1:
                out[i] += fs[-1]
            else:
                s = (t - ts[k]) / (ts[k + 1] - ts[k])
                out[i] += fs[k] + s * (fs[k + 1] - fs[k])
        return out

    def rate(self, t):
        """Right derivative (the slope of the segment that starts at or before t)."""
        out = [0.0, 0.0]
        for i, tab in enumerate(self.tables):
            if not tab:
                continue
            ts, fs = tab
            k = self._segment(ts, t)
            if 0 <= k < len(ts) - 1:
                out[i] = (fs[k + 1] - fs[k]) / (ts[k + 1] - ts[k])
        return out

    def next_break(self, t):
        for tb in self.breaks:
            if tb > t:
                return tb
        return math.inf


# --- polynomials ----------------------------------------------------------------------

def _peval(c, s):
    """c[0] + c[1] s + c[2] s^2 + ... (Horner) and its derivative."""
    p, dp = 0.0, 0.0
    for coef in reversed(c):
        dp = dp * s + p
        p = p * s + coef
    return p, dp


def _quadratic_roots(a, b, c):
    """Real roots of a s^2 + b s + c (a, b may vanish), stable formulas."""
    if a == 0.0:
        return [] if b == 0.0 else [-c / b]
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return []
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    roots = [q / a]
    if q != 0.0:
        roots.append(c / q)
    return roots


def first_nonpositive(c, s_max):
    """Earliest s in (0, s_max] where the polynomial c (degree <= 3, low order first)
    reaches zero from above.  Exact zeros at s = 0 are divided out first (a gap that
    starts closed, a velocity that starts at zero), so c must be positive right after 0.
    Returns math.inf if it stays positive.

    The roots are isolated between the critical points (closed-form roots of the
    derivative) and polished by safeguarded Newton (bisection fallback) to rounding."""
    c = list(c)
    while c and c[0] == 0.0:
        c.pop(0)
    while c and c[-1] == 0.0:
        c.pop()
    if not c:
        return math.inf  # identically zero: nothing crosses
    if c[0] < 0.0:
        return 0.0  # already past: the caller's state is inconsistent by rounding
    if len(c) == 1:
        return math.inf
    deriv = [k * c[k] for k in range(1, len(c))] + [0.0, 0.0]
    crit = [s for s in _quadratic_roots(deriv[2], deriv[1], deriv[0]) if 0.0 < s < s_max]
    points = [0.0] + sorted(crit) + [s_max]
    lo = 0.0
    for hi in points[1:]:
        if hi <= lo:
            continue
        p_hi = _peval(c, hi)[0]
        if p_hi <= 0.0:
            return _polish(c, lo, hi)
        lo = hi
    return math.inf


def _polish(c, lo, hi):
    """Root of c in (lo, hi] with c(lo) > 0 >= c(hi), c monotone there."""
    s = hi
    for _ in range(200):
        p, dp = _peval(c, s)
        if p > 0.0:
            lo = s
        else:
            hi = s
        if hi - lo <= 2.0 * EPS * hi:
            break
        step = p / dp if dp != 0.0 else 0.0
        s_new = s - step
        if not (lo < s_new < hi) or dp == 0.0:
            s_new = 0.5 * (lo + hi)
        if s_new == s:
            break
        s = s_new
    return hi  # the function is <= 0 here and > 0 at lo, ulps below


# --- the model ------------------------------------------------------------------------

@dataclass
class Mode:
    active: tuple          # contact names held closed
    stuck: tuple           # (bool, bool)
    sgn: tuple             # sliding direction per body (0 at rest or without friction)
    gain: list             # 2x2: a = gain (f + f_slide)
    f_slide: tuple
    holds: list            # (w, c, label): w . (f + f_slide) + c >= 0


class Model:
    def __init__(self, scene):
        self.m = (float(_field(scene, "m1")), float(_field(scene, "m2")))
        g = float(_field(scene, "g", DEFAULT_G))
        self.c = tuple(float(_field(scene, f"mu{i}", 0.0)) * self.m[i - 1] * g for i in (1, 2))
        # Static friction (mus >= mu, default mu): the bound a body at rest holds to; c is
        # what a sliding body feels. A body has friction when s > 0.
        self.s = tuple(max(float(_field(scene, f"mus{i}", 0.0) or 0.0) * self.m[i - 1] * g, self.c[i - 1])
                       for i in (1, 2))
        # Two bodies on one line meet: without d_min the link's lower limit is at 0.
        self.contacts = [k for k in CONTACTS if _field(scene, LIMIT[k]) is not None or k == "slot_min"]
        self.limit = {k: float(_field(scene, LIMIT[k], 0.0)) for k in self.contacts}
        self.r = {k: float(_field(scene, RESTITUTION[k], 1.0)) for k in self.contacts}
        tables = []
        for i in (1, 2):
            if _field(scene, f"f{i}_amp") not in (None, 0.0):
                raise ValueError("exact_reference: sine forcing is out of scope")
            path = _field(scene, f"f{i}_table")
            tables.append(read_table(path) if path else None)
        self.forcing = Forcing([float(_field(scene, "f1", 0.0)), float(_field(scene, "f2", 0.0))],
                               tables)
        self.rigid = ("slot_min" in self.limit and "slot_max" in self.limit
                      and self.limit["slot_min"] == self.limit["slot_max"])

    def gap(self, k, x):
        if k == "left":
            return x[0] - self.limit[k]
        if k == "right":
            return self.limit[k] - x[1]
        if k == "slot_min":
            return (x[1] - x[0]) - self.limit[k]
        return self.limit[k] - (x[1] - x[0])

    @staticmethod
    def nv(k, v):
        n = NORMALS[k]
        return n[0] * v[0] + n[1] * v[1]

    def meff(self, k):
        n = NORMALS[k]
        return 1.0 / (n[0] ** 2 / self.m[0] + n[1] ** 2 / self.m[1])

    def restitution(self, k, touching):
        # A rigid link has no room to rebound: both slot limits closed -> r = 0.
        if k in ("slot_min", "slot_max") and "slot_min" in touching and "slot_max" in touching:
            return 0.0
        return self.r[k]

    def locked(self, touching):
        """A rigid link (d_min = d_max, both limits closed): the bodies are one body."""
        return self.rigid and "slot_min" in touching and "slot_max" in touching

    def impulse(self, k, r, v, touching=()):
        """Velocities after Newton's law on contact k: n.v' = -r n.v.

        A wall hit by a rigid link acts on one body of mass m1 + m2 moving with the
        centre-of-mass velocity (equal to v1 = v2 once the link is closed): Newton's law
        for that body gives v1' = v2' = -r v_cm, one impulse of (1 + r)(m1 + m2) |v_cm|
        shared by the wall; the link transmits it without any slot impact."""
        if k in ("left", "right") and self.locked(touching):
            total = self.m[0] + self.m[1]
            common = (self.m[0] * v[0] + self.m[1] * v[1]) / total
            after = 0.0 if r == 0.0 else -r * common
            return [after, after]
        n = NORMALS[k]
        if r == 0.0:
            # Exactly zero normal velocity after a perfectly inelastic impact.
            if k == "left":
                return [0.0, v[1]]
            if k == "right":
                return [v[0], 0.0]
            common = (self.m[0] * v[0] + self.m[1] * v[1]) / (self.m[0] + self.m[1])
            return [common, common]
        p = -(1.0 + r) * self.nv(k, v) * self.meff(k)
        out = [v[i] + n[i] * p / self.m[i] for i in range(2)]
        for i in range(2):
            if n[i] == 0.0:
                out[i] = v[i]
        return out

    def tolerances(self, f, df):
        tol = 1e3 * EPS * (abs(f[0]) + abs(f[1]) + 2.0 * (self.s[0] + self.s[1])) + 1e-300
        tol_rate = 1e3 * EPS * (abs(df[0]) + abs(df[1]))
        return tol, tol_rate

    # --- the complementarity problem by enumeration (docs/method.md 2) ---
    def solve_mode(self, f, df, candidate, resting, moving_sign):
        """candidate: touching contacts with zero normal velocity; resting[i]: body i at
        rest with friction; moving_sign[i]: sign of v_i for sliding bodies with friction.
        Conditions are judged on f and, where one sits at its bound, on its rate df."""
        cand = [k for k in self.contacts if k in candidate]
        for target_stuck in (2, 1, 0):
            for o1 in (0, 1, 2):
                for o2 in (0, 1, 2):
                    option = (o1, o2)
                    if any(not resting[i] and option[i] != 0 for i in range(2)):
                        continue
                    if sum(resting[i] and option[i] == 0 for i in range(2)) != target_stuck:
                        continue
                    for target_active in range(len(cand), -1, -1):
                        for mask in range(16):
                            active = tuple(k for j, k in enumerate(CONTACTS) if mask >> j & 1)
                            if any(k not in cand for k in active) or len(active) != target_active:
                                continue
                            mode = self._try(f, df, cand, resting, moving_sign, option, active)
                            if mode is not None:
                                return mode
        raise RuntimeError("no consistent contact/friction mode")

    def _try(self, f, df, cand, resting, moving_sign, option, active):
        m, c = self.m, self.c
        stuck = tuple(resting[i] and option[i] == 0 for i in range(2))
        sgn = list(moving_sign)
        for i in range(2):
            if resting[i] and option[i] == 1:
                sgn[i] = 1.0
            elif resting[i] and option[i] == 2:
                sgn[i] = -1.0
        f_slide = tuple(-c[i] * sgn[i] for i in range(2))
        rows, kinds = [], []
        for k in active:
            rows.append(NORMALS[k])
            kinds.append(("contact", k))
        for i in range(2):
            if stuck[i]:
                rows.append((1.0, 0.0) if i == 0 else (0.0, 1.0))
                kinds.append(("stuck", i))
        if len(rows) > 2:
            return None
        minv = (1.0 / m[0], 1.0 / m[1])
        gain = [[minv[0], 0.0], [0.0, minv[1]]]
        kgain = []
        if rows:
            jm = [[r[0] * minv[0], r[1] * minv[1]] for r in rows]
            s = [[sum(jm[p][i] * rows[q][i] for i in range(2)) for q in range(len(rows))]
                 for p in range(len(rows))]
            if len(rows) == 1:
                sinv = [[1.0 / s[0][0]]]
            else:
                det = s[0][0] * s[1][1] - s[0][1] * s[1][0]
                if abs(det) <= 1e-12 * s[0][0] * s[1][1]:
                    return None  # dependent rows: not a vertex
                sinv = [[s[1][1] / det, -s[0][1] / det], [-s[1][0] / det, s[0][0] / det]]
            # lambda = K load, K = -S^-1 J M^-1; a = M^-1 (I + J^T K) load.
            kgain = [[-sum(sinv[p][q] * jm[q][j] for q in range(len(rows))) for j in range(2)]
                     for p in range(len(rows))]
            for i in range(2):
                for j in range(2):
                    gain[i][j] += minv[i] * sum(rows[p][i] * kgain[p][j] for p in range(len(rows)))
            # Held motion exactly: two rows fix both bodies; a wall or a stuck row fixes
            # its body; a slot row moves both bodies alike.
            if len(rows) == 2:
                gain = [[0.0, 0.0], [0.0, 0.0]]
            for r in rows:
                for i in range(2):
                    if r[i] != 0.0 and r[1 - i] == 0.0:
                        gain[i] = [0.0, 0.0]
                if r[0] != 0.0 and r[1] != 0.0:
                    avg = [0.5 * (gain[0][j] + gain[1][j]) for j in range(2)]
                    gain = [list(avg), list(avg)]
        load = (f[0] + f_slide[0], f[1] + f_slide[1])
        tol, tol_rate = self.tolerances(f, df)

        def ok(w, const):
            value = w[0] * load[0] + w[1] * load[1] + const
            rate = w[0] * df[0] + w[1] * df[1]
            return value > tol or (value >= -tol and rate >= -tol_rate)

        holds = []
        for p, (what, who) in enumerate(kinds):
            if what == "contact":
                holds.append((tuple(kgain[p]), 0.0, f"force_{who}"))
            else:
                holds.append((tuple(-x for x in kgain[p]), self.s[who], f"friction+{who}"))
                holds.append((tuple(kgain[p]), self.s[who], f"friction-{who}"))
        for w, const, _ in holds:
            if not ok(w, const):
                return None
        # A closed contact left free must not close further; a body leaving rest must
        # move the way its friction assumes.
        for k in cand:
            if k in active:
                continue
            n, me = NORMALS[k], self.meff(k)
            w = [me * (n[0] * gain[0][j] + n[1] * gain[1][j]) for j in range(2)]
            if not ok(w, 0.0):
                return None
        for i in range(2):
            if resting[i] and not stuck[i]:
                w = [m[i] * sgn[i] * gain[i][j] for j in range(2)]
                if not ok(w, 0.0):
                    return None
        return Mode(active=active, stuck=stuck, sgn=tuple(sgn), gain=gain, f_slide=f_slide,
                    holds=holds)

    @staticmethod
    def acceleration(mode, f):
        load = (f[0] + mode.f_slide[0], f[1] + mode.f_slide[1])
        return [mode.gain[i][0] * load[0] + mode.gain[i][1] * load[1] for i in range(2)]

    @staticmethod
    def acceleration_rate(mode, df):
        return [mode.gain[i][0] * df[0] + mode.gain[i][1] * df[1] for i in range(2)]


@dataclass
class Phase:
    """Motion on [t0, t1]: x_i(t0 + s) = x + v s + a0 s^2/2 + a1 s^3/6."""
    t0: float
    t1: float
    x: tuple
    v: tuple
    a0: tuple
    a1: tuple

    def at(self, t):
        s = t - self.t0
        return tuple(v for i in range(2) for v in (
            self.x[i] + s * (self.v[i] + s * (0.5 * self.a0[i] + s * self.a1[i] / 6.0)),
            self.v[i] + s * (self.a0[i] + 0.5 * s * self.a1[i])))


@dataclass
class Solution:
    events: list = field(default_factory=list)   # (t, kind, v1b, v2b, v1a, v2a)
    phases: list = field(default_factory=list)
    final: tuple = ()                            # (x1, v1, x2, v2) at t_end
    t_end: float = 0.0

    def impacts(self):
        return [e for e in self.events if e[1] in IMPACT_KINDS]

    def state(self, t):
        """(x1, v1, x2, v2) at t; at an event instant the state after it."""
        if t >= self.t_end:
            return self.final
        chosen = self.phases[0]
        for ph in self.phases:
            if ph.t0 <= t:
                chosen = ph
            else:
                break
        return chosen.at(t)


def solve(scene, t_end=None):
    """Run a scene exactly from t = 0 to t_end (default: the scene's)."""
    return _Run(Model(scene), scene, t_end).run()


class _Run:
    def __init__(self, model, scene, t_end):
        self.M = model
        self.t_end = float(_field(scene, "t_end") if t_end is None else t_end)
        self.t = 0.0
        self.x = [float(_field(scene, "x1")), float(_field(scene, "x2"))]
        self.v = [float(_field(scene, "v1", 0.0)), float(_field(scene, "v2", 0.0))]
        self.sol = Solution(t_end=self.t_end)
        self.in_contact = set()
        self.at_rest = [False, False]
        self.mode = None
        self.touching = set()
        # Gaps are carried along as their own polynomials, not recomputed from positions:
        # a bounce 1e-20 m high near x = 10 m keeps its digits.
        self.gaps = {k: model.gap(k, self.x) for k in model.contacts}

    def log(self, t, kind, vb, va):
        self.sol.events.append((t, kind, vb[0], vb[1], va[0], va[1]))
        if len(self.sol.events) > MAX_EVENTS:
            raise RuntimeError(f"more than {MAX_EVENTS} events by t = {t}")

    def run(self):
        M = self.M
        # Initially only a rigid link is closed (scenes start strictly inside otherwise).
        self.touching = {k for k in M.contacts
                         if abs(M.gap(k, self.x)) <= 1e-12 * max(1.0, abs(M.limit[k]))}
        self.event_point(initial=True, stopped=())
        stalls, t_last = 0, -1.0
        while True:
            t_next, stopped, touching = self.next_event()
            self.t = t_next
            if t_next >= self.t_end:
                break
            stalls = stalls + 1 if t_next == t_last else 0
            if stalls > MAX_STALLS:
                raise RuntimeError(f"events do not advance at t = {t_next}")
            t_last = t_next
            self.touching = touching
            self.event_point(initial=False, stopped=stopped)
        self.sol.final = (self.x[0], self.v[0], self.x[1], self.v[1])
        self.sol.events.sort(key=lambda e: e[0])  # stable: order within an instant kept
        return self.sol

    # --- one phase: polynomials, earliest event, move the state there ---
    def next_event(self):
        M, t, mode = self.M, self.t, self.mode
        f, df = M.forcing.force(t), M.forcing.rate(t)
        a0 = M.acceleration(mode, f)
        a1 = M.acceleration_rate(mode, df)
        t_stop = min(M.forcing.next_break(t), self.t_end)
        s_max = t_stop - t
        tol, tol_rate = M.tolerances(f, df)
        x, v = self.x, self.v

        roots = {}  # ("contact", k) / ("stop", i) / ("hold", label) -> s
        for k in M.contacts:
            if k in mode.active:
                continue
            n = NORMALS[k]
            na0 = n[0] * a0[0] + n[1] * a0[1]
            na1 = n[0] * a1[0] + n[1] * a1[1]
            if k in self.touching:
                nv = M.nv(k, v)
                if nv == 0.0 and abs(na0) <= tol / M.meff(k):
                    na0 = 0.0  # rounding of a zero relative acceleration
                if nv == 0.0 and na0 == 0.0 and abs(na1) <= tol_rate / M.meff(k):
                    continue   # held closed by the other constraints: nothing moves it
                coeffs = [0.0, nv, 0.5 * na0, na1 / 6.0]
            else:
                coeffs = [self.gaps[k], M.nv(k, v), 0.5 * na0, na1 / 6.0]
            roots[("contact", k)] = first_nonpositive(coeffs, s_max)
        for i in range(2):
            if M.s[i] == 0.0 or mode.sgn[i] == 0.0:
                continue
            s = mode.sgn[i]
            acc0 = a0[i]
            if v[i] == 0.0 and abs(acc0) * M.m[i] <= tol:
                acc0 = 0.0
            roots[("stop", i)] = first_nonpositive([s * v[i], s * acc0, 0.5 * s * a1[i]], s_max)
        load = (f[0] + mode.f_slide[0], f[1] + mode.f_slide[1])
        for w, const, label in mode.holds:
            value = w[0] * load[0] + w[1] * load[1] + const
            rate = w[0] * df[0] + w[1] * df[1]
            if rate < -tol_rate:
                roots[("hold", label)] = max(-value / rate, 0.0)

        s_hit = min(list(roots.values()) + [math.inf])
        if s_hit > s_max:
            s_hit = s_max
            hits = []
        else:
            # Everything that happens at the same instant (to the rounding of t).
            same = 4.0 * EPS * max(abs(t + s_hit), 1e-3)
            hits = [key for key, s in roots.items() if s <= s_hit + same]
        t_new = t + s_hit if s_hit < s_max else t_stop
        ph = Phase(t, t_new, tuple(x), tuple(v), tuple(a0), tuple(a1))
        self.sol.phases.append(ph)
        x1, v1, x2, v2 = ph.at(t_new)
        self.x, self.v = [x1, x2], [v1, v2]
        s = t_new - t
        for k in M.contacts:
            if k in mode.active or (k in self.touching and ("contact", k) not in roots):
                self.gaps[k] = 0.0
                continue
            n = NORMALS[k]
            rate = [n[0] * v[0] + n[1] * v[1], n[0] * a0[0] + n[1] * a0[1], n[0] * a1[0] + n[1] * a1[1]]
            g0 = 0.0 if k in self.touching else self.gaps[k]
            self.gaps[k] = g0 + s * (rate[0] + s * (0.5 * rate[1] + s * rate[2] / 6.0))
        # Exactness of held motion: no drift of a body whose acceleration is zero and rate too.
        for i in range(2):
            if v[i] == 0.0 and a0[i] == 0.0 and a1[i] == 0.0:
                self.x[i], self.v[i] = x[i], 0.0
        # Contacts still touching: the ones hit now, and closed ones nothing opened.
        touching = {key[1] for key in hits if key[0] == "contact"}
        for k in self.touching:
            if ("contact", k) not in roots:
                touching.add(k)
        stopped = {key[1] for key in hits if key[0] == "stop"}
        if stopped and any(k in mode.active for k in ("slot_min", "slot_max")):
            stopped = {0, 1}  # bodies locked by the slot stop together
        stopped = tuple(sorted(stopped))
        return t_new, stopped, touching

    # --- everything that happens at one instant ---
    def event_point(self, initial, stopped):
        M, t = self.M, self.t
        f, df = M.forcing.force(t), M.forcing.rate(t)
        self.snap()
        for i in stopped:
            self.v[i] = 0.0
        # Sequential impulses, most approaching first (ties: the engine's contact order).
        for count in range(MAX_IMPULSES + 1):
            pick, worst = None, 0.0
            for k in M.contacts:
                if k in self.touching:
                    u = M.nv(k, self.v)
                    if u < worst and u < -self.vtol(k):
                        pick, worst = k, u
            if pick is None:
                break
            before = tuple(self.v)
            self.v = M.impulse(pick, M.restitution(pick, self.touching), self.v, self.touching)
            self.log(t, pick, before, self.v)
        else:
            raise RuntimeError(f"impacts at t = {t} do not settle")
        self.zero_small_normal_velocities()
        # Zeno: a rebound whose remaining series lasts less than ZENO_TIME ends in rest.
        for k in M.contacts:
            if k not in self.touching:
                continue
            u = M.nv(k, self.v)
            r = M.restitution(k, self.touching)
            if u <= 0.0 or r >= 1.0:
                continue
            free = self.new_mode(f, df)
            a = M.acceleration(free, f)
            a_gap = NORMALS[k][0] * a[0] + NORMALS[k][1] * a[1]
            if a_gap >= 0.0:
                continue
            remaining = 2.0 * u / (-a_gap) / (1.0 - r)
            if remaining >= ZENO_TIME:
                continue
            self.v = M.impulse(k, 0.0, self.v, self.touching)
            if k not in self.in_contact:
                # (A persistent contact kicked by an impulse chain through the other
                # body and settling again at once never opened: no second rest.)
                self.in_contact.add(k)
                self.log(t + remaining, "rest_" + k, self.v, self.v)
        mode = self.new_mode(f, df)

        acc = M.acceleration(mode, f)
        rate = M.acceleration_rate(mode, df)
        tol, tol_rate = M.tolerances(f, df)
        for k in M.contacts:
            if k in mode.active and k not in self.in_contact:
                self.in_contact.add(k)
                self.log(t, "rest_" + k, self.v, self.v)
            elif k in self.in_contact and k not in mode.active:
                # The contact left the mode.  It opens now if the gap starts to grow: a
                # positive separating acceleration, or (the contact force having just
                # reached zero, or a body on it breaking away from static friction at
                # the bound) a zero one whose time derivative is positive, the gap then
                # growing like s^3.  If nothing moves along its normal (static friction
                # carries the load) it stays closed and in contact.
                n = NORMALS[k]
                n_acc = n[0] * acc[0] + n[1] * acc[1]
                n_rate = n[0] * rate[0] + n[1] * rate[1]
                scale = abs(n[0]) / M.m[0] + abs(n[1]) / M.m[1]
                closed_still = k in self.touching and M.nv(k, self.v) == 0.0
                opening = n_acc > scale * tol or (n_acc >= -scale * tol
                                                  and n_rate > scale * tol_rate)
                if not closed_still or opening:
                    self.in_contact.discard(k)
                    self.log(t, "release_" + k, self.v, self.v)
        for i in range(2):
            if M.s[i] == 0.0:
                continue
            s = mode.sgn[i]
            tol_a = tol / M.m[i]
            leaving = s * acc[i] > tol_a or (s * acc[i] >= -tol_a and s * rate[i] > tol_rate / M.m[i])
            resting_now = self.v[i] == 0.0 and not leaving
            if resting_now and not self.at_rest[i] and not initial:
                self.log(t, f"stick{i + 1}", self.v, self.v)
            if not resting_now and self.at_rest[i] and self.v[i] == 0.0:
                self.log(t, f"slip{i + 1}", self.v, self.v)
            self.at_rest[i] = resting_now
        self.mode = mode

    def zero_small_normal_velocities(self):
        """Closed contacts left with a rounding-level normal velocity are still: the
        smallest (kinetic-energy metric) change of v that makes all of them exactly zero.
        One independent normal: a perfectly inelastic impulse; two: both bodies stop."""
        M = self.M
        small = [k for k in M.contacts if k in self.touching
                 and abs(M.nv(k, self.v)) <= self.vtol(k) and M.nv(k, self.v) != 0.0]
        if not small:
            return
        also = [k for k in M.contacts if k in self.touching and M.nv(k, self.v) == 0.0]
        rows = {k: NORMALS[k] for k in small + also}
        independent = []
        for k, n in rows.items():
            if not any(n[0] * o[1] - n[1] * o[0] == 0.0 for o in independent):
                independent.append(n)
        if len(independent) >= 2:
            self.v = [0.0, 0.0]
        else:
            self.v = M.impulse(small[0], 0.0, self.v)

    def new_mode(self, f, df):
        M = self.M
        candidate = {k for k in self.touching if M.nv(k, self.v) == 0.0}
        resting = tuple(M.s[i] > 0.0 and self.v[i] == 0.0 for i in range(2))
        moving = tuple(math.copysign(1.0, self.v[i]) if M.s[i] > 0.0 and self.v[i] != 0.0 else 0.0
                       for i in range(2))
        return M.solve_mode(f, df, candidate, resting, moving)

    def vtol(self, k):
        """Rounding level of a normal velocity: from the speeds of the bodies involved."""
        n = NORMALS[k]
        return 4.0 * EPS * (abs(n[0] * self.v[0]) + abs(n[1] * self.v[1])) + VELOCITY_FLOOR

    def snap(self):
        """Put touching contacts exactly on their constraints (walls first)."""
        M = self.M
        for k in self.touching:
            self.gaps[k] = 0.0
        on_wall = [False, False]
        if "left" in self.touching:
            self.x[0] = M.limit["left"]
            on_wall[0] = True
        if "right" in self.touching:
            self.x[1] = M.limit["right"]
            on_wall[1] = True
        for k in ("slot_min", "slot_max"):
            if k not in self.touching:
                continue
            d = M.limit[k]
            if on_wall[1] and not on_wall[0]:
                self.x[0] = self.x[1] - d
            else:
                self.x[1] = self.x[0] + d


# --- older API (constant-force frictionless scenes) -------------------------------------

def simulate_exact(scene, t_end=None):
    """Impacts and free-flight segments of a frictionless constant-force scene:
    events   -- list of (t, kind, v1_before, v2_before, v1_after, v2_after), impacts only
    segments -- list of (t0, x1, v1, x2, v2): the state at the start of each phase, then
                the state at t_end."""
    for name in ("mu1", "mu2"):
        if float(_field(scene, name, 0.0)) != 0.0:
            raise ValueError("simulate_exact handles frictionless scenes only")
    sol = solve(scene, t_end)
    segments = [(ph.t0, ph.x[0], ph.v[0], ph.x[1], ph.v[1]) for ph in sol.phases]
    segments.append((sol.t_end, sol.final[0], sol.final[1], sol.final[2], sol.final[3]))
    return sol.impacts(), segments


def state_at(segments, f1_over_m1, f2_over_m2, times):
    """Evaluate piecewise-quadratic free flight (constant accelerations) at the times.
    A time equal to an impact time gets the state after the impact."""
    starts = [seg[0] for seg in segments]
    out, k = [], 0
    for t in times:
        while k + 1 < len(segments) and starts[k + 1] <= t:
            k += 1
        t0, x1, v1, x2, v2 = segments[k]
        s = t - t0
        out.append((x1 + v1 * s + 0.5 * f1_over_m1 * s * s, v1 + f1_over_m1 * s,
                    x2 + v2 * s + 0.5 * f2_over_m2 * s * s, v2 + f2_over_m2 * s))
    return out
