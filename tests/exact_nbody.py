"""An exact event-driven reference solver for N bodies on a line (METHOD sections 1-9).

Pure Python with mpmath at DPS = 50 digits, written from the physics of docs/method.md and
/work/shared/METHOD.md section 9 ("Any number of bodies"), sharing no code with the
Fortran engine and no physics with tests/exact_reference.py (the two-body reference it is
checked against, tests/test_exact_nbody.py; only its table reader and Horner's rule).  It is the yardstick for the engine's coming N-body
generalisation (issue 19, "Mechanisms as data").

Scope.  N >= 1 point bodies on a line, numbered 1..N (the ground is end 0, at x = 0).
Forces f_i(t) = constant + optional piecewise-linear table (held constant outside its
times); no sine, no springs or dampers (the motion would stop being a polynomial).
Coulomb friction of each body against the ground: sliding bound c_i = mu_i m_i g, static
bound s_i = mus_i m_i g >= c_i.  Contacts are records on two ends a, b (a body or the
ground): a lower limit x_b - x_a >= d_min and/or an upper limit x_b - x_a <= d_max, each
with its restitution; a wall is a contact with the ground.  A record with d_min = d_max
is a rigid link.  Out of scope: gear ratios, prescribed ground motion, body-body friction,
compliant stops (DESIGN "Laws added on the records").

Scenes are dicts in the N-body format of /work/shared/DESIGN.md:
    m, x, v, mu, mus, f: lists over the bodies (v, mu, f default 0, mus defaults to mu)
    g (default 9.80665), t_end, f_table: optional list over the bodies of None or
    (times, values) or a path to a two-column `t f` file
    contacts: list of records {a, b, d_min, r_min, d_max, r_max, name}; a missing limit is
    absent, a restitution missing beside its limit is 1.  Event names: a record with one
    limit uses `name` (default c<k>, k counting records from 1); a record with both uses
    `name`_min and `name`_max, or `name_min` / `name_max` when given.
from_two_body(scene) converts a tutorial two-body (or one-body) scene into this format.

How it is exact.  At an instant the mode is fixed by a linear complementarity problem;
within the mode the accelerations are linear in the forces, so linear in time between
table corners: velocities are quadratic and positions and gaps cubic in the time since
the phase start.  The solver writes these polynomials down and finds the earliest root of
every watched function (gap of an open contact, velocity of a body that slides with
friction, every basic variable of the mode's complementarity solution: linear) by
isolating roots between the extrema (closed-form critical points) and polishing them by
safeguarded Newton to the working precision; then it moves the state there with the same
polynomials and handles the event point.  Gaps are carried as their own polynomials, so a
bounce 1e-40 m high keeps its digits.

The mode at an instant (METHOD 9 "Clusters").  Bodies joined by closed contacts with zero
normal velocity (candidates) form clusters; each cluster with a candidate or a body at
rest with friction is one problem: accelerations a, contact forces lambda >= 0 with
n_k.a >= 0 and lambda_k n_k.a = 0, and for each body at rest a friction force F_i in
[-beta_i, beta_i], F_i = -beta_i sign(a_i) when a_i != 0.  Written in the forces it is
the LCP of the convex problem min 1/2 a.M a - b.a + sum beta_i |a_i| s.t. n_k.a >= 0
(Gauss's principle with friction), whose accelerations are unique; it is solved exactly
(no enumeration) by Lemke's complementary pivoting with the lexicographic rule, in 50
digits.  Conventions that make the answer unique:
- The mode that holds just AFTER the instant: the pivoting is done on the data at
  t + H_RIGHT (forces are linear in t), then every value is recomputed at t from the
  basis, with its time derivative.  So a holding force exactly at its bound with a rate
  outward breaks away now; one at its bound with zero rate holds.
- Static above sliding friction (METHOD 8): the problem is solved with the static bounds
  s_i for every body at rest; the bodies it moves break away and slide with c_i; the
  problem is solved again with their sliding bounds, until no more break away (a
  cascade; with mus = mu one solve).  A body at rest whose acceleration is zero on the
  coming phase is stuck (stick<i> / slip<i> are logged on the changes).
- Which closed contacts are held (`rest_<contact>` when one becomes held): among the
  force distributions (statically indeterminate clusters have many) the one of least
  total contact force sum lambda_k (a tie-breaking perturbation EPS_LABEL of the pivoting
  data): static friction carries what it can and the load goes through the contacts
  nearest its source.  Held = the closed contacts carrying force in it, plus the closed
  contacts with no force whose ends are not already joined to the ground or to each
  other (a frictionless body resting on a wall; one limit of a rigid link), taken in
  record order; a contact between two stuck bodies, or between a stuck body and a wall,
  is held only while friction cannot carry the load alone.  On two bodies these are the
  choices of tests/exact_reference.py ("most bodies stuck, then most contacts held, no
  dependent rows"): its 150 generated scenes give the same rest/release logs.  (Lemke's
  pivoting from zero forces already brings in contact forces only where needed in every
  case tried; the perturbation makes the rule independent of the pivoting order.)
Held contacts and the bodies joined to them move with one common acceleration, set
exactly (mass-weighted), so closed gaps stay exactly 0 and stuck bodies do not creep.

Impacts (METHOD 4, 8, 9).  While a closed contact approaches (n.v < -velocity
tolerance), the most approaching one (ties: record order) takes Newton's impulse
P = -(1+r) n.v / (n.M^-1 n) along M^-1 n.  A rigid link (d_min = d_max, both limits
closed) makes its bodies one body for every other contact (their masses add, they get one
velocity); its own limits have r = 0.  When the closed contacts connected to the
approaching one number two or more and every one is perfectly inelastic, the velocity
after is the projection of the velocity before, in the mass metric, onto
{w : n_k.w >= 0} (an LCP, solved by the same pivoting); each contact that took an impulse
is logged.  Normal velocities of closed contacts below the velocity tolerance are then
made exactly zero (bodies joined by such contacts get their mass-weighted velocity, or
zero when joined to the ground).

Zeno (METHOD 5).  A contact that separates after an impulse with r < 1 under an
acceleration that brings it back, u = n.v > 0, a = n.a < 0: its remaining bounce series
lasts 2 u / (|a| (1 - r)).  When that is below ZENO_TIME the contact takes an r = 0
impulse now and `rest_<contact>` is logged at the accumulation time t + 2 u/(|a|(1-r)).
Accumulations over several contacts (METHOD 9: a body rattling between a wall and a
heavier body pushed onto it, or between two bodies): the event points with impacts repeat
a pattern (the same set of contacts, period p <= CYCLE_POINTS) while the contacts' normal
velocities shrink by a ratio rho < 1 per period (the cycle map's dominant rate, measured on
the last two periods, consistent to CYCLE_FIT); when the rest of the series,
dt rho / (1 - rho) with dt the last period, lasts less than ZENO_TIME, all the cycle's
contacts are closed now (their gaps, of the order of the series' tiny flights, set to 0,
their normal velocities made zero in the mass metric) and their rests are logged at the
accumulation time.  Until then such a series is followed impact by impact, rest and release
of a contact inside each cycle included.

Event log (conventions of tests/exact_reference.py and the engine, README 'Inputs'):
- impacts: kind = the limit's name, one entry per impulse with the velocities before and
  after it (a joint projection: one entry per contact that took an impulse, each with the
  velocities before and after the projection, Event.joint set);
- `rest_<contact>`: a contact becomes held and was not in contact (also at t = 0, e.g. a
  rigid link); at the accumulation time for a Zeno series;
- `release_<contact>`: a contact in contact stops being held and its gap starts to grow
  (a positive separating acceleration, or a zero one with a positive rate); a contact
  that stops being held but stays closed (friction now carries its load) stays in
  contact: no release, no new rest later;
- `stick<i>`: a body with friction that slides (or leaves rest) comes to rest and stays
  (not at t = 0); `slip<i>`: a body at rest breaks away without an impulse (not at t = 0);
  a body that stops and slides back at once logs nothing.
Bodies are numbered from 1 in the names; velocities in events are tuples over the bodies.
Events at one instant are in the order they happen (impulses, rests at the instant,
releases, stick/slip); the list is sorted by time (stably).

Energy ledger: W = int sum f_i v_i dt (external forces), D = int sum c_i |v_i| dt
(sliding friction), Q = kinetic energy lost at impacts (and at a Zeno cut);
residual = KE - KE0 - W + D + Q, exact to the working precision.

Public API:
    solve(scene, t_end=None) -> Solution
        .events (list of Event(t, kind, subject, before, after, joint)), .final (x, v),
        .phases, .state(t) -> (x, v), .ledger (dict), .impacts(), .t_end, .model
    from_two_body(scene) -> the N-body scene dict of a tutorial one- or two-body scene
        (dict or impact1d.Scene), with f_table paths read
    two_body_events(solution) -> [(t, kind, v1b, v2b, v1a, v2a)] as floats (the log
        format of tests/exact_reference.py; v2 = 0.0 for one body)
    lemke(Q, q, tol), first_nonpositive(c, s_max) (earliest root of a cubic)
All numbers come back as mpf; float(...) them to compare with the engine.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field
from typing import NamedTuple

from mpmath import mp, mpf

from exact_reference import _peval, read_table   # (file reading, Horner: no physics shared)

DPS = 50
DEFAULT_G = 9.80665
RESERVED_PREFIXES = ("rest_", "release_", "stick", "slip")

with mp.workdps(DPS):
    # Relative size of a value that is zero (forces, accelerations, pivots): far above the
    # rounding of 50 digits after a few dozen pivots, far below anything physical.
    TOL = mpf(10) ** -38
    # Normal velocities below this fraction of the run's velocity scale are zero; it ends
    # the geometric impulse chains of a body pinned between two closed contacts (r < 1).
    TOL_V = mpf(10) ** -36
    # The mode "just after" an instant: pivoting data taken at t + H_RIGHT * t_scale.
    H_RIGHT = mpf(10) ** -22
    # The least-total-contact-force tie break, relative to the force scale: far below the
    # right-limit perturbation (so it never overrules the physics), far above TOL.
    EPS_LABEL = mpf(10) ** -31
    # Two event times closer than this (relative, floor 1e-3 s) are one instant.
    SAME_TIME = mpf(10) ** -36
    # A bounce series whose remaining flights last less than this (s) ends in rest.
    ZENO_TIME = mpf(10) ** -16
    # Initial gaps within this (relative to the limit, floor 1) are closed (a float scene
    # written in decimal, 0.6 - 0.3 - 0.3 != 0).
    INITIAL_TOUCH = mpf(10) ** -12

# A multi-contact bounce series: a cycle of at most CYCLE_POINTS event points, its normal
# velocities and durations geometric to CYCLE_FIT (relative) over the last two periods.
CYCLE_POINTS = 12
CYCLE_FIT = 1e-3
MAX_EVENTS = 100_000
MAX_IMPULSES = 100_000
MAX_STALLS = 1_000
MAX_PIVOTS = 10_000


def _mp(value):
    return value if isinstance(value, mpf) else mpf(value)


def _sign(value):
    return (value > 0) - (value < 0)


class Event(NamedTuple):
    t: mpf
    kind: str          # limit name (impact), rest_<name>, release_<name>, stick<i>, slip<i>
    subject: object    # the limit's name, or the body number (1-based)
    before: tuple      # velocities of all bodies before
    after: tuple       # and after
    joint: bool = False  # an impact of a joint inelastic projection (several contacts at once)


# --- forcing -------------------------------------------------------------------------

class Forcing:
    """f_i(t) = constant_i + table_i(t): value, right derivative, next corner."""

    def __init__(self, constants, tables):
        self.constants = [_mp(c) for c in constants]
        self.tables = [None if tab is None else ([_mp(t) for t in tab[0]], [_mp(f) for f in tab[1]])
                       for tab in tables]
        self.breaks = sorted({t for tab in self.tables if tab for t in tab[0]})

    @staticmethod
    def _table(tab, t):
        """(value, right slope) of a piecewise-linear table, constant outside its corners."""
        ts, fs = tab
        k = bisect.bisect_right(ts, t) - 1          # the last corner at or before t
        if k < 0 or k >= len(ts) - 1:
            return fs[max(k, 0)], mpf(0)
        slope = (fs[k + 1] - fs[k]) / (ts[k + 1] - ts[k])
        return fs[k] + (t - ts[k]) * slope, slope

    def force(self, t):
        return [c + (self._table(tab, t)[0] if tab else 0) for c, tab in zip(self.constants, self.tables)]

    def rate(self, t):
        return [self._table(tab, t)[1] if tab else mpf(0) for tab in self.tables]

    def next_break(self, t):
        k = bisect.bisect_right(self.breaks, t)
        return self.breaks[k] if k < len(self.breaks) else mp.inf

    def scale(self):
        """The largest |force| and |rate| any body sees (for tolerances)."""
        force = sum(abs(c) for c in self.constants)
        rate = mpf(0)
        for tab in self.tables:
            if tab is None:
                continue
            ts, fs = tab
            force += max(abs(f) for f in fs)
            rate = max([rate] + [abs((fs[k + 1] - fs[k]) / (ts[k + 1] - ts[k])) for k in range(len(ts) - 1)])
        return force, rate


# --- polynomials -----------------------------------------------------------------------

def _critical_points(c):
    """Real roots of the derivative of the cubic c (low order first): the roots of
    3 c3 s^2 + 2 c2 s + c1, by the formula without cancellation (q = -(b + sign(b) sqrt D)/2,
    roots q / a and c / q)."""
    a, b, c = 3 * c[3], 2 * c[2], c[1]
    if a == 0:
        return [] if b == 0 else [-c / b]
    disc = b * b - 4 * a * c
    if disc < 0:
        return []
    q = -(b + mp.sqrt(disc)) / 2 if b >= 0 else (mp.sqrt(disc) - b) / 2
    return [q / a] + ([c / q] if q != 0 else [])


def first_nonpositive(c, s_max):
    """Earliest s in (0, s_max] where the polynomial c (degree <= 3, low order first)
    reaches zero from above; mp.inf if it stays positive.  Exact zero coefficients at the
    low end (a gap that starts closed, a velocity that starts at zero) are divided out
    first, so c must be positive just after 0 (0 is returned if it is not)."""
    found = bracket(c, s_max)
    return found if not isinstance(found, tuple) else polish(*found)


def bracket(c, s_max):
    """The first root of c on (0, s_max] isolated: (c, lo, hi) with c(lo) > 0 >= c(hi) and c
    monotone between (polish() finds it), or mp.inf (none), or 0 (c <= 0 at once).  The
    roots are isolated between the critical points (closed-form roots of c')."""
    c = list(c)
    while c and c[0] == 0:
        c.pop(0)
    while c and c[-1] == 0:
        c.pop()
    if not c:
        return mp.inf
    if c[0] < 0:
        return mpf(0)
    if len(c) == 1:
        return mp.inf
    crit = sorted(s for s in _critical_points(c + [mpf(0)] * (4 - len(c))) if 0 < s < s_max)
    lo = mpf(0)
    for hi in crit + [s_max]:
        if hi <= lo:
            continue
        if _peval(c, hi)[0] <= 0:
            return c, lo, hi
        lo = hi
    return mp.inf


def polish(c, lo, hi):
    """The root of c in (lo, hi], c(lo) > 0 >= c(hi), c monotone there: safeguarded
    Newton; returns a point where c <= 0, a few ulps above the root."""
    s = hi
    resolution = mpf(2) ** (-mp.prec + 6)
    for _ in range(400):
        p, dp = _peval(c, s)
        if p > 0:
            lo = s
        else:
            hi = s
        if hi - lo <= resolution * hi:
            break
        step = p / dp if dp != 0 else None
        if step is not None and abs(step) <= resolution * hi:
            # Newton has converged to s - step: bracket it tightly (both sides checked).
            below, above = s - step - resolution * hi, s - step + resolution * hi
            if lo < below and _peval(c, below)[0] > 0:
                lo = below
            if above < hi and _peval(c, above)[0] <= 0:
                hi = above
            if hi - lo <= 4 * resolution * hi:
                break
            s = (lo + hi) / 2
            continue
        s_new = s - step if step is not None else lo
        if not lo < s_new < hi:
            s_new = (lo + hi) / 2
        s = s_new
    return hi


# --- linear complementarity -------------------------------------------------------------

def _lex_less(a, b, tol):
    """a < b lexicographically, entries equal within tol (relative) counting as ties."""
    for x, y in zip(a, b):
        if abs(x - y) > tol * (1 + abs(x) + abs(y)):
            return x < y
    return False


def lemke(Q, q, tol):
    """Solve the LCP w = q + Q z, w >= 0, z >= 0, w.z = 0 by Lemke's complementary pivoting
    (covering vector 1) with the lexicographic ratio test, so that degenerate problems (many
    zero forces) do not cycle.  Q is positive semidefinite here (a convex QP's LCP), so the
    pivoting ends with a solution.  Entries within tol (relative to the data) are zero.

    Returns (basic, binv): basic[i] is the variable basic in row i (j < n: w_j; n + j: z_j)
    and binv the inverse of the final basis, so the basic values for any right-hand side q'
    (the same data at another time, its rate) are binv q'; the others are zero."""
    n = len(q)
    identity = [[mpf(1) if i == j else mpf(0) for j in range(n)] for i in range(n)]
    scale = max([mpf(1)] + [abs(x) for x in q] + [abs(x) for row in Q for x in row])
    tol = tol * scale
    if all(x >= -tol for x in q):
        return list(range(n)), identity
    cols = 2 * n + 1
    table = [identity[i] + [-Q[i][j] for j in range(n)] + [mpf(-1)] for i in range(n)]
    rhs = list(q)
    basic = list(range(n))

    def key(i, col):
        return [rhs[i] / col] + [table[i][j] / col for j in range(n)]

    # z0 enters; the row leaving is the lexicographic minimum of (q_i, B^-1 row i).
    row = 0
    for i in range(1, n):
        if _lex_less([rhs[i]] + table[i][:n], [rhs[row]] + table[row][:n], TOL):
            row = i
    entering = 2 * n
    for _ in range(MAX_PIVOTS):
        pivot = table[row][entering]
        prow = [x / pivot for x in table[row]]
        prhs = rhs[row] / pivot
        for i in range(n):
            if i == row:
                continue
            factor = table[i][entering]
            if factor != 0:
                table[i] = [x - factor * y for x, y in zip(table[i], prow)]
                table[i][entering] = mpf(0)
                rhs[i] -= factor * prhs
        table[row], rhs[row] = prow, prhs
        leaving, basic[row] = basic[row], entering
        if leaving == 2 * n:
            return basic, [table[i][:n] for i in range(n)]
        entering = leaving + n if leaving < n else leaving - n
        best = None
        for i in range(n):
            col = table[i][entering]
            if col > tol:
                if best is None or _lex_less(key(i, col), key(best, table[best][entering]), TOL):
                    best = i
        if best is None:
            raise RuntimeError("lemke: ray termination (the complementarity problem has no solution)")
        row = best
    raise RuntimeError("lemke: no solution after MAX_PIVOTS pivots")


def _solve_values(basic, binv, q):
    """(w, z) of the basis for the right-hand side q."""
    n = len(q)
    w, z = [mpf(0)] * n, [mpf(0)] * n
    for i, var in enumerate(basic):
        value = sum(b * x for b, x in zip(binv[i], q))
        if var < n:
            w[var] = value
        else:
            z[var - n] = value
    return w, z


# --- the model ------------------------------------------------------------------------------

@dataclass
class Limit:
    """One unilateral constraint gap = sum_i coef_i x_i + offset >= 0 (ground dropped)."""
    index: int
    record: int
    name: str
    normal: tuple      # ((body, coef), ...), body 0-based, coef +-1
    offset: mpf
    r: mpf
    bodies: tuple

    def gap(self, x):
        return sum(c * x[i] for i, c in self.normal) + self.offset

    def rate(self, v):
        return sum(c * v[i] for i, c in self.normal)

    def grounded(self):
        return len(self.normal) == 1


def _get(scene, name, default=None):
    value = scene.get(name, default) if isinstance(scene, dict) else getattr(scene, name, default)
    return default if value is None else value


class Model:
    """Bodies, friction bounds, forcing and the contact limits of an N-body scene dict."""

    def __init__(self, scene):
        self.m = [_mp(a) for a in scene["m"]]
        n = self.n = len(self.m)
        if n == 0 or any(a <= 0 for a in self.m):
            raise ValueError("masses must be > 0")

        def per_body(name, default):
            values = scene.get(name)
            values = [default] * n if values is None else list(values)
            if len(values) != n:
                raise ValueError(f"{name} has {len(values)} values for {n} bodies")
            return values

        if scene.get("x") is None:
            raise ValueError("a scene needs the initial positions x")
        self.x0 = [_mp(a) for a in per_body("x", None)]
        self.v0 = [_mp(a) for a in per_body("v", 0.0)]
        mu = [_mp(a) for a in per_body("mu", 0.0)]
        mus = [_mp(b if b is not None else a) for a, b in zip(mu, per_body("mus", None))]
        if any(a < 0 for a in mu) or any(b < a for a, b in zip(mu, mus)):
            raise ValueError("friction: need 0 <= mu <= mus")
        g = _mp(DEFAULT_G if scene.get("g") is None else scene["g"])
        self.c = [a * m * g for a, m in zip(mu, self.m)]      # sliding bounds
        self.s = [b * m * g for b, m in zip(mus, self.m)]     # static bounds
        tables = []
        for tab in per_body("f_table", None):
            tables.append(read_table(tab) if isinstance(tab, str) else tab)
        self.forcing = Forcing(per_body("f", 0.0), tables)
        self.limits, self.rigid_records = [], set()
        names = set()
        for j, rec in enumerate(scene.get("contacts", ())):
            self._add_record(j, rec, names)
        force, rate = self.forcing.scale()
        self.f_scale = force + sum(self.s) + sum(self.m)      # + 1 m/s^2 per body: never 0
        self.rate_scale = rate + self.f_scale
        self.a_scale = self.f_scale / min(self.m)

    def _add_record(self, j, rec, names):
        a, b = int(rec.get("a", 0)), int(rec.get("b", 0))
        if not (0 <= a <= self.n and 0 <= b <= self.n) or a == b:
            raise ValueError(f"contact {j + 1}: ends a = {a}, b = {b} must be distinct, 0..{self.n}")
        lower, upper = rec.get("d_min"), rec.get("d_max")
        if lower is None and upper is None:
            raise ValueError(f"contact {j + 1}: no limit")
        name = rec.get("name", f"c{j + 1}")
        both = lower is not None and upper is not None
        if both and _mp(upper) < _mp(lower):
            raise ValueError(f"contact {name}: d_max < d_min")
        if both and _mp(upper) == _mp(lower):
            self.rigid_records.add(j)
        for side, d, r in (("min", lower, rec.get("r_min", 1.0)), ("max", upper, rec.get("r_max", 1.0))):
            if d is None:
                continue
            r = _mp(1.0 if r is None else r)
            if not 0 <= r <= 1:
                raise ValueError(f"contact {name}: restitution {r} outside [0, 1]")
            label = rec.get(f"name_{side}") or (f"{name}_{side}" if both else name)
            if label in names or label.startswith(RESERVED_PREFIXES):
                raise ValueError(f"contact name {label!r} repeated or reserved")
            names.add(label)
            sign = 1 if side == "min" else -1     # gap = sign (x_b - x_a - d)
            normal = tuple((i - 1, c) for i, c in ((b, sign), (a, -sign)) if i > 0)
            self.limits.append(Limit(index=len(self.limits), record=j, name=label, normal=normal,
                                     offset=-sign * _mp(d), r=r,
                                     bodies=tuple(i for i, _ in normal)))

    def restitution(self, k, touching):
        """A rigid link with both limits closed has no room to rebound: r = 0."""
        lim = self.limits[k]
        if lim.record in self.rigid_records and all(
                j in touching for j in self.record_limits(lim.record)):
            return mpf(0)
        return lim.r

    def record_limits(self, record):
        return [lim.index for lim in self.limits if lim.record == record]

    def ke(self, v):
        return sum(m * u * u for m, u in zip(self.m, v)) / 2


class _Union:
    """Union-find over bodies 0..n-1 and the ground (index n)."""

    def __init__(self, n):
        self.parent = list(range(n + 1))
        self.ground = n

    def find(self, i):
        while self.parent[i] != i:
            self.parent[i] = self.parent[self.parent[i]]
            i = self.parent[i]
        return i

    def union(self, i, j):
        ri, rj = self.find(i), self.find(j)
        if ri != rj:
            self.parent[ri] = rj
        return ri != rj

    def join_limit(self, lim):
        ends = list(lim.bodies) + ([self.ground] if lim.grounded() else [])
        return self.union(ends[0], ends[1])

    def groups(self, members):
        out = {}
        for i in members:
            out.setdefault(self.find(i), []).append(i)
        return list(out.values())


# --- the mode at an instant -----------------------------------------------------------------

@dataclass
class Mode:
    a0: list           # accelerations at the instant
    a1: list           # and their time derivatives (forces are linear in time)
    sgn: list          # sliding friction acts as -c_i sgn_i (0: stuck, or no friction)
    held: set          # limits held closed (persistent contacts)
    closed: set        # candidate limits that stay closed (held, or redundant: n.a = 0)
    stuck: set         # bodies at rest held by static friction
    holds: list        # (value, rate): the basic variables of the clusters' LCPs that decrease


@dataclass
class _ClusterSolution:
    a0: dict
    a1: dict
    lam: dict
    holds: list


class _ModeSolver:
    """The complementarity problem of each cluster at an instant (module docstring)."""

    def __init__(self, model, h):
        self.M = model
        self.h = h                                   # right-limit offset (s)
        self.tol_f = TOL * model.f_scale             # a zero force
        self.tol_fr = TOL * model.rate_scale         # a zero force rate
        self.tol_a = self.tol_f / min(model.m)
        self.tol_ar = self.tol_fr / min(model.m)

    def zero_acc(self, a, da):
        return abs(a) <= self.tol_a and abs(da) <= self.tol_ar

    def solve(self, t, v, touching):
        M = self.M
        n = M.n
        f, df = M.forcing.force(t), M.forcing.rate(t)
        cands = [k for k in sorted(touching) if M.limits[k].rate(v) == 0]
        resting = [i for i in range(n) if M.s[i] > 0 and v[i] == 0]
        fixed = [-M.c[i] * _sign(v[i]) for i in range(n)]     # sliding friction
        a0 = [(f[i] + fixed[i]) / M.m[i] for i in range(n)]
        a1 = [df[i] / M.m[i] for i in range(n)]
        sgn = [_sign(v[i]) if M.s[i] > 0 else 0 for i in range(n)]
        uf = _Union(n)
        for k in cands:
            if len(M.limits[k].bodies) == 2:
                uf.union(*M.limits[k].bodies)
        lam, holds, stuck = {}, [], set()
        for bodies in uf.groups(range(n)):
            members = set(bodies)
            cl_cands = [k for k in cands if M.limits[k].bodies[0] in members]
            cl_rest = [i for i in resting if i in members]
            if not cl_cands and not cl_rest:
                continue
            sol, moving = self._cascade(bodies, cl_cands, cl_rest, f, df, fixed)
            for i in bodies:
                a0[i], a1[i] = sol.a0[i], sol.a1[i]
            lam.update(sol.lam)
            holds += sol.holds
            for i in cl_rest:
                if i in moving:
                    sgn[i] = _sign(a0[i]) if abs(a0[i]) > self.tol_a else _sign(a1[i])
                else:
                    sgn[i] = 0
                    stuck.add(i)
            for i in bodies:
                if self.zero_acc(a0[i], a1[i]):
                    a0[i] = a1[i] = mpf(0)
        closed = {k for k in cands
                  if self.zero_acc(M.limits[k].rate(a0), M.limits[k].rate(a1))}
        self._equalise(closed, a0, a1)
        held = self._held(closed, lam, stuck)
        return Mode(a0=a0, a1=a1, sgn=sgn, held=held, closed=closed, stuck=stuck, holds=holds)

    def _cascade(self, bodies, cands, rest, f, df, fixed):
        """Static bounds for every body at rest; the ones that move break away and slide
        with their sliding bounds; again until no more break away (module docstring)."""
        M = self.M
        broken = set()
        while True:
            beta = {i: (M.c[i] if i in broken else M.s[i]) for i in rest}
            sol = self._lcp(bodies, cands, [i for i in rest if beta[i] > 0], beta, f, df, fixed)
            moving = {i for i in rest if not self.zero_acc(sol.a0[i], sol.a1[i])}
            if moving <= broken:
                return sol, moving
            broken |= moving

    def _lcp(self, bodies, cands, rest, beta, f, df, fixed):
        """z = (lambda_k, rho_i = F_i + beta_i, a_i^-), w = (n_k.a, a_i^+, 2 beta_i - rho_i)
        with a = M^-1 (b - beta + N^T lambda + rho) (rho, beta only on the bodies at rest)."""
        M = self.M
        nc, nr = len(cands), len(rest)
        size = nc + 2 * nr
        inv = {i: 1 / M.m[i] for i in bodies}
        slot = {i: r for r, i in enumerate(rest)}
        base = {i: f[i] + fixed[i] - (beta[i] if i in slot else 0) for i in bodies}
        normals = [dict(M.limits[k].normal) for k in cands]
        Q = [[mpf(0)] * size for _ in range(size)]
        q, dq = [mpf(0)] * size, [mpf(0)] * size
        for p, nk in enumerate(normals):
            for r, nl in enumerate(normals):
                Q[p][r] = sum(c * nl[i] * inv[i] for i, c in nk.items() if i in nl)
            for i, c in nk.items():
                q[p] += c * inv[i] * base[i]
                dq[p] += c * inv[i] * df[i]
                if i in slot:
                    Q[p][nc + slot[i]] = Q[nc + slot[i]][p] = c * inv[i]
        for i, r in slot.items():
            Q[nc + r][nc + r] = inv[i]
            Q[nc + r][nc + nr + r] = mpf(1)
            Q[nc + nr + r][nc + r] = mpf(-1)
            q[nc + r], dq[nc + r] = inv[i] * base[i], inv[i] * df[i]
            q[nc + nr + r] = 2 * beta[i]
        label = EPS_LABEL * M.a_scale
        q_right = [q[j] + self.h * dq[j] + (label if j < nc else 0) for j in range(size)]
        basic, binv = lemke(Q, q_right, TOL)
        _, z = _solve_values(basic, binv, q)
        _, dz = _solve_values(basic, binv, dq)
        a0, a1 = {}, {}
        for i in bodies:
            load, rate = base[i], df[i]
            if i in slot:
                load += z[nc + slot[i]]
                rate += dz[nc + slot[i]]
            for p, nk in enumerate(normals):
                if i in nk:
                    load += nk[i] * z[p]
                    rate += nk[i] * dz[p]
            a0[i], a1[i] = load * inv[i], rate * inv[i]
        lam = {k: (z[p], dz[p]) for p, k in enumerate(cands)}
        # Every basic variable stays >= 0 while the mode holds; rows are in acceleration or
        # force units: a rate below tol_hold is none (constant forces give exact zeros).
        tol_hold = mpf(10) ** -20 * M.rate_scale * max(1, max(inv.values()))
        holds = []
        for row in range(size):
            value = sum(b * x for b, x in zip(binv[row], q))
            rate = sum(b * x for b, x in zip(binv[row], dq))
            if rate < -tol_hold:
                holds.append((value, rate))
        return _ClusterSolution(a0=a0, a1=a1, lam=lam, holds=holds)

    def _equalise(self, closed, a0, a1):
        """Bodies joined by contacts that stay closed share one acceleration exactly: zero
        when joined to the ground or to a body that does not accelerate, else their
        mass-weighted mean (what the contact forces make it, to rounding)."""
        M = self.M
        uf = _Union(M.n)
        for k in closed:
            uf.join_limit(M.limits[k])
        touched = sorted({i for k in closed for i in M.limits[k].bodies})
        for group in uf.groups(touched):
            if uf.find(group[0]) == uf.find(uf.ground) or any(a0[i] == 0 and a1[i] == 0 for i in group):
                common0 = common1 = mpf(0)
            else:
                mass = sum(M.m[i] for i in group)
                common0 = sum(M.m[i] * a0[i] for i in group) / mass
                common1 = sum(M.m[i] * a1[i] for i in group) / mass
            for i in group:
                a0[i], a1[i] = common0, common1

    def _held(self, closed, lam, stuck):
        """Closed contacts carrying force in the least-force solution, then the force-free
        ones (record order) whose ends are not joined yet, the ground and stuck bodies
        counting as joined (module docstring)."""
        M = self.M
        uf = _Union(M.n)
        for i in stuck:
            uf.union(i, uf.ground)
        held = set()
        for k in sorted(closed):
            value, rate = lam.get(k, (mpf(0), mpf(0)))
            if value > self.tol_f or (value >= -self.tol_f and rate > self.tol_fr):
                held.add(k)
                uf.join_limit(M.limits[k])
        for k in sorted(closed - held):
            if uf.join_limit(M.limits[k]):
                held.add(k)
        return held


# --- the run ----------------------------------------------------------------------------------

@dataclass
class Phase:
    """Motion on [t0, t1]: x_i(t0 + s) = x + v s + a0 s^2/2 + a1 s^3/6."""
    t0: mpf
    t1: mpf
    x: tuple
    v: tuple
    a0: tuple
    a1: tuple

    def at(self, t):
        s = t - self.t0
        x = tuple(x + s * (v + s * (a0 / 2 + s * a1 / 6))
                  for x, v, a0, a1 in zip(self.x, self.v, self.a0, self.a1))
        v = tuple(v + s * (a0 + s * a1 / 2) for v, a0, a1 in zip(self.v, self.a0, self.a1))
        return x, v


@dataclass
class Solution:
    model: Model
    t_end: mpf
    events: list = field(default_factory=list)
    phases: list = field(default_factory=list)
    final: tuple = ()                  # (x, v) at t_end
    ledger: dict = field(default_factory=dict)

    def impacts(self):
        return [e for e in self.events if not e.kind.startswith(RESERVED_PREFIXES)]

    def state(self, t):
        """(x, v) at t; at an event instant the state after it."""
        t = _mp(t)
        if t >= self.t_end:
            return self.final
        k = bisect.bisect_right([ph.t0 for ph in self.phases], t) - 1   # the last phase begun by t
        return self.phases[max(k, 0)].at(t)


def solve(scene, t_end=None):
    """Run an N-body scene dict exactly from t = 0 to t_end (default: the scene's)."""
    t_end = scene.get("t_end") if t_end is None else t_end
    if t_end is None:
        raise ValueError("no t_end")
    with mp.workdps(DPS):
        return _Run(Model(scene), _mp(t_end)).run()


class _Run:
    def __init__(self, model, t_end):
        self.M = model
        self.t_end = t_end
        self.t = mpf(0)
        self.x, self.v = list(model.x0), list(model.v0)
        self.gaps = [lim.gap(self.x) for lim in model.limits]
        self.touching, self.in_contact = set(), set()
        self.at_rest = [False] * model.n
        self.mode = None
        self.solver = _ModeSolver(model, H_RIGHT * max(t_end, mpf(1)))
        v_scale = max([mpf(1), model.a_scale * t_end] + [abs(u) for u in self.v])
        self.vtol = TOL_V * v_scale
        self.sol = Solution(model=model, t_end=t_end)
        self.work = self.friction_loss = self.impact_loss = mpf(0)
        self.history = []      # event points with impacts: (t, kinds logged, v after)

    def log(self, t, kind, subject, before, after, joint=False):
        self.sol.events.append(Event(t, kind, subject, tuple(before), tuple(after), joint))
        if len(self.sol.events) > MAX_EVENTS:
            raise RuntimeError(f"more than {MAX_EVENTS} events by t = {float(t)}")

    def run(self):
        M = self.M
        for k, lim in enumerate(M.limits):
            if abs(self.gaps[k]) <= INITIAL_TOUCH * max(1, abs(lim.offset)):
                self.touching.add(k)
                self.gaps[k] = mpf(0)
            elif self.gaps[k] < 0:
                raise ValueError(f"contact {lim.name} starts violated (gap {float(self.gaps[k])})")
        ke0 = M.ke(self.v)
        self.event_point(initial=True, stopped=())
        stalls, t_last = 0, None
        while True:
            t_next, stopped, touching = self.next_event()
            self.t = t_next
            if t_next >= self.t_end:
                break
            stalls = stalls + 1 if t_next == t_last else 0
            if stalls > MAX_STALLS:
                raise RuntimeError(f"events do not advance at t = {float(t_next)}")
            t_last = t_next
            self.touching = touching
            self.event_point(initial=False, stopped=stopped)
        self.sol.final = (tuple(self.x), tuple(self.v))
        self.sol.events.sort(key=lambda e: e.t)
        ke = M.ke(self.v)
        self.sol.ledger = dict(ke0=ke0, ke=ke, work=self.work, friction_loss=self.friction_loss,
                               impact_loss=self.impact_loss,
                               residual=ke - ke0 - self.work + self.friction_loss + self.impact_loss)
        return self.sol

    # --- one phase ---
    def next_event(self):
        M, t, mode = self.M, self.t, self.mode
        t_stop = min(M.forcing.next_break(t), self.t_end)
        s_max = t_stop - t
        x, v, a0, a1 = self.x, self.v, mode.a0, mode.a1
        roots = {}
        for k, lim in enumerate(M.limits):
            if k in mode.held:
                continue
            nv, na0, na1 = lim.rate(v), lim.rate(a0), lim.rate(a1)
            if k in self.touching:
                if nv == 0 and self.solver.zero_acc(na0, 0):
                    na0 = mpf(0)   # the rounding of a zero relative acceleration
                if nv == 0 and na0 == 0 and self.solver.zero_acc(0, na1):
                    continue       # closed and kept closed by the other constraints
                coeffs = [mpf(0), nv, na0 / 2, na1 / 6]
            else:
                coeffs = [self.gaps[k], nv, na0 / 2, na1 / 6]
            roots[("contact", k)] = bracket(coeffs, s_max)
        for i in range(M.n):
            sg = mode.sgn[i]
            if M.s[i] > 0 and sg != 0:
                acc0 = 0 if v[i] == 0 and self.solver.zero_acc(a0[i], 0) else a0[i]
                roots[("stop", i)] = bracket([sg * v[i], sg * acc0, sg * a1[i] / 2], s_max)
        for j, (value, rate) in enumerate(mode.holds):
            roots[("hold", j)] = max(value, mpf(0)) / -rate

        # Polish the isolated roots in the order of their brackets, only those that can be
        # the earliest or at the same instant as it.
        s_hit = min([r for r in roots.values() if not isinstance(r, tuple)] + [mp.inf])
        for key, r in sorted(((k, r) for k, r in roots.items() if isinstance(r, tuple)),
                             key=lambda item: item[1][1]):
            if r[1] > s_hit + SAME_TIME * max(abs(t + s_hit), mpf("1e-3")):
                roots[key] = mp.inf   # (not needed: later than the earliest)
                continue
            roots[key] = polish(*r)
            s_hit = min(s_hit, roots[key])
        if s_hit >= s_max:
            s_hit, hits = s_max, []
            t_new = t_stop
        else:
            same = SAME_TIME * max(abs(t + s_hit), mpf("1e-3"))
            hits = [key for key, s in roots.items() if s <= s_hit + same]
            t_new = t + s_hit
        s = t_new - t
        ph = Phase(t, t_new, tuple(x), tuple(v), tuple(a0), tuple(a1))
        self.sol.phases.append(ph)
        self.account(s, mode)
        self.x, self.v = [list(u) for u in ph.at(t_new)]
        for k, lim in enumerate(M.limits):
            if k in self.touching and ("contact", k) not in roots:
                self.gaps[k] = mpf(0)
                continue
            g0 = mpf(0) if k in self.touching else self.gaps[k]
            self.gaps[k] = g0 + s * (lim.rate(v) + s * (lim.rate(a0) / 2 + s * lim.rate(a1) / 6))
        touching = {key[1] for key in hits if key[0] == "contact"}
        # A closed contact stays closed unless the phase opened it: a phase of zero length
        # (another contact hit at once) leaves its gap 0, whatever its own root.
        touching |= {k for k in self.touching if ("contact", k) not in roots or s == 0}
        stopped = tuple(sorted(key[1] for key in hits if key[0] == "stop"))
        return t_new, stopped, touching

    def account(self, s, mode):
        """Work of the external forces and loss to sliding friction over a phase of length s
        (exact integrals of the phase's polynomials)."""
        M = self.M
        f, df = M.forcing.force(self.t), M.forcing.rate(self.t)
        for i in range(M.n):
            v, a0, a1 = self.v[i], mode.a0[i], mode.a1[i]
            self.work += s * (f[i] * v + s * ((f[i] * a0 + df[i] * v) / 2
                                              + s * ((f[i] * a1 / 2 + df[i] * a0) / 3 + s * df[i] * a1 / 8)))
            if mode.sgn[i] != 0 and M.c[i] > 0:
                self.friction_loss += M.c[i] * mode.sgn[i] * s * (v + s * (a0 / 2 + s * a1 / 6))

    # --- an event point ---
    def event_point(self, initial, stopped):
        M, t = self.M, self.t
        for k in self.touching:
            self.gaps[k] = mpf(0)
        if stopped:
            # bodies moving with a stopped one (joined by closed contacts) stop with it
            uf = _Union(M.n)
            for k in self.mode.closed:
                if len(M.limits[k].bodies) == 2:
                    uf.union(*M.limits[k].bodies)
            roots = {uf.find(i) for i in stopped}
            for i in range(M.n):
                if uf.find(i) in roots:
                    self.v[i] = mpf(0)
        first = len(self.sol.events)
        self.impacts()
        self.zero_small_normal_velocities()
        mode = self.solver.solve(t, self.v, self.touching)
        mode = self.zeno(mode)
        if self.accumulation(first):
            mode = self.solver.solve(t, self.v, self.touching)
        self.mode = mode
        for k, lim in enumerate(M.limits):
            if k in mode.held and k not in self.in_contact:
                self.in_contact.add(k)
                self.log(t, "rest_" + lim.name, lim.name, self.v, self.v)
            elif k in self.in_contact and k not in mode.held:
                closed_still = k in self.touching and lim.rate(self.v) == 0
                if not closed_still or k not in mode.closed:
                    self.in_contact.discard(k)
                    self.log(t, "release_" + lim.name, lim.name, self.v, self.v)
        for i in range(M.n):
            if M.s[i] == 0:
                continue
            resting_now = self.v[i] == 0 and i in mode.stuck
            if resting_now and not self.at_rest[i] and not initial:
                self.log(t, f"stick{i + 1}", i + 1, self.v, self.v)
            if not resting_now and self.at_rest[i] and self.v[i] == 0:
                self.log(t, f"slip{i + 1}", i + 1, self.v, self.v)
            self.at_rest[i] = resting_now

    def zeno(self, mode):
        """A contact separating with a bounce series shorter than ZENO_TIME rests now; its
        rest is logged at the series' accumulation time."""
        M = self.M
        for k in sorted(self.touching):
            lim = M.limits[k]
            u, r = lim.rate(self.v), M.restitution(k, self.touching)
            if u <= 0 or r >= 1:
                continue
            a_gap = lim.rate(mode.a0)
            if a_gap >= 0:
                continue
            remaining = 2 * u / -a_gap / (1 - r)
            if remaining >= ZENO_TIME:
                continue
            ke = M.ke(self.v)
            self.impulse(k, mpf(0))
            self.zero_small_normal_velocities()
            self.impact_loss += ke - M.ke(self.v)
            if k not in self.in_contact:
                self.in_contact.add(k)
                self.log(self.t + remaining, "rest_" + lim.name, lim.name, self.v, self.v)
            mode = self.solver.solve(self.t, self.v, self.touching)
        return mode

    def accumulation(self, first):
        """A bounce series alternating between several contacts (METHOD 9): the event
        points with impacts repeat a pattern of p points whose contacts' normal velocities
        shrink by a ratio rho < 1 each period (the cycle map's dominant rate, measured on
        the last two periods).  When the rest of the series, dt rho / (1 - rho) with dt the
        last period's duration, lasts less than ZENO_TIME, every contact of the cycle is
        closed now (normal velocities made zero, gaps 0) and its rest is logged at the
        accumulation time.  Returns whether it cut."""
        # (a set: an impulse chain at one instant ends at the velocity floor, so its length
        # is not part of the pattern)
        kinds = tuple(sorted({e.kind for e in self.sol.events[first:]}))
        if not any(not k.startswith(RESERVED_PREFIXES) for k in kinds):
            return False
        names = {lim.name: lim.index for lim in self.M.limits}
        hist = self.history
        hist.append((self.t, kinds, tuple(self.v)))
        del hist[:-3 * CYCLE_POINTS]
        for p in range(1, CYCLE_POINTS + 1):
            if len(hist) < 2 * p + 1:
                break
            if any(hist[-1 - j][1] != hist[-1 - j - p][1] for j in range(p + 1)):
                continue
            cycle = sorted({names[k.split("_", 1)[1] if k.startswith(RESERVED_PREFIXES[:2]) else k]
                            for j in range(p) for k in hist[-1 - j][1] if not k.startswith(("stick", "slip"))})
            if len(cycle) < 2:
                continue   # one contact: zeno() sums its series exactly
            now = [self.M.limits[k].rate(hist[-1][2]) for k in cycle]
            then = [self.M.limits[k].rate(hist[-1 - p][2]) for k in cycle]
            norm = sum(u * u for u in then)
            if norm == 0:
                continue
            rho = sum(a * b for a, b in zip(now, then)) / norm
            dt, dt_before = hist[-1][0] - hist[-1 - p][0], hist[-1 - p][0] - hist[-1 - 2 * p][0]
            if not 0 < rho < 1 or dt <= 0 or \
                    sum((a - rho * b) ** 2 for a, b in zip(now, then)) > CYCLE_FIT ** 2 * norm * rho ** 2 or \
                    abs(dt - rho * dt_before) > CYCLE_FIT * dt:
                continue
            remaining = dt * rho / (1 - rho)
            if remaining >= ZENO_TIME:
                return False
            ke = self.M.ke(self.v)
            for k in cycle:
                self.touching.add(k)
                self.gaps[k] = mpf(0)
            self.common_velocities(cycle, cycle)
            self.impact_loss += ke - self.M.ke(self.v)
            for k in cycle:
                if k not in self.in_contact:
                    self.in_contact.add(k)
                    name = self.M.limits[k].name
                    self.log(self.t + remaining, "rest_" + name, name, self.v, self.v)
            hist.clear()
            return True
        return False

    # --- impacts ---
    def impacts(self):
        M = self.M
        for _ in range(MAX_IMPULSES):
            pick, worst = None, mpf(0)
            for k in sorted(self.touching):
                u = M.limits[k].rate(self.v)
                if u < worst and u < -self.vtol:
                    pick, worst = k, u
            if pick is None:
                return
            group = self.closed_group(pick)
            plastic = all(M.restitution(k, self.touching) == 0 for k in group)
            one_link = {M.limits[k].record for k in group} <= M.rigid_records and \
                len({M.limits[k].record for k in group}) == 1
            before, ke = tuple(self.v), M.ke(self.v)
            joint = len(group) > 1 and plastic and not one_link
            if joint:
                pushed = self.projection(group)
            else:
                self.impulse(pick, M.restitution(pick, self.touching))
                pushed = [pick]
            if joint or M.restitution(pick, self.touching) == 0:
                self.common_velocities(pushed, pushed)   # n.v = 0 exactly, not to rounding
            self.impact_loss += ke - M.ke(self.v)
            for k in pushed:
                self.log(self.t, M.limits[k].name, M.limits[k].name, before, self.v, joint)
        raise RuntimeError(f"impacts at t = {float(self.t)} do not settle")

    def closed_group(self, start):
        """The closed contacts joined to contact `start` through shared bodies."""
        M = self.M
        group, bodies, grew = {start}, set(M.limits[start].bodies), True
        while grew:
            grew = False
            for k in self.touching:
                if k not in group and bodies & set(M.limits[k].bodies):
                    group.add(k)
                    bodies |= set(M.limits[k].bodies)
                    grew = True
        return sorted(group)

    def rigid_groups(self, exclude_record):
        """Bodies made one by rigid links (both limits closed), but the excluded record's."""
        M = self.M
        uf = _Union(M.n)
        for rec in M.rigid_records:
            if rec != exclude_record and all(k in self.touching for k in M.record_limits(rec)):
                lim = M.limits[M.record_limits(rec)[0]]
                if len(lim.bodies) == 2:
                    uf.union(*lim.bodies)
        return uf

    def impulse(self, k, r):
        """Newton's law n.v' = -r n.v on limit k; bodies rigidly linked move as one."""
        M = self.M
        lim = M.limits[k]
        uf = self.rigid_groups(lim.record)
        weight = {}
        for i, c in lim.normal:
            weight[uf.find(i)] = weight.get(uf.find(i), 0) + c
        mass = {root: sum(M.m[j] for j in range(M.n) if uf.find(j) == root) for root in weight}
        denom = sum(w * w / mass[root] for root, w in weight.items())
        if denom == 0:
            return
        p = -(1 + r) * lim.rate(self.v) / denom
        for j in range(M.n):
            root = uf.find(j)
            if root in weight:
                self.v[j] += weight[root] * p / mass[root]

    def projection(self, group):
        """Perfectly inelastic contacts closed together: the velocity nearest the present one
        in the mass metric with no contact approaching (an LCP); the limits pushed."""
        M = self.M
        normals = [dict(M.limits[k].normal) for k in group]
        Q = [[sum(c * nl[i] / M.m[i] for i, c in nk.items() if i in nl) for nl in normals]
             for nk in normals]
        q = [M.limits[k].rate(self.v) for k in group]
        basic, binv = lemke(Q, q, TOL)
        _, z = _solve_values(basic, binv, q)
        tol = TOL * max([mpf(1)] + [abs(x) for x in q]) * max(M.m)
        for p, nk in enumerate(normals):
            for i, c in nk.items():
                self.v[i] += c * z[p] / M.m[i]
        return [k for p, k in enumerate(group) if z[p] > tol]

    def zero_small_normal_velocities(self):
        """Closed contacts left with a rounding-level normal velocity are still: bodies
        joined by them get one velocity, zero when the ground is among them."""
        M = self.M
        small = [k for k in self.touching if abs(M.limits[k].rate(self.v)) <= self.vtol]
        dirty = [k for k in small if M.limits[k].rate(self.v) != 0]
        if dirty:
            self.common_velocities(small, dirty)

    def common_velocities(self, limits, dirty):
        """The velocity nearest the present one (mass metric) with zero normal velocity on
        every given limit, changed only on the bodies joined to a `dirty` one."""
        M = self.M
        uf = _Union(M.n)
        for k in limits:
            uf.join_limit(M.limits[k])
        roots = {uf.find(M.limits[k].bodies[0]) for k in dirty}
        for group in uf.groups(range(M.n)):
            if uf.find(group[0]) not in roots:
                continue
            if uf.find(group[0]) == uf.find(uf.ground):
                common = mpf(0)
            else:
                common = sum(M.m[i] * self.v[i] for i in group) / sum(M.m[i] for i in group)
            for i in group:
                self.v[i] = common


# --- the tutorial's scenes --------------------------------------------------------------------

def from_two_body(scene):
    """The N-body scene dict of a tutorial one- or two-body scene (dict or impact1d.Scene,
    fields as README 'Inputs'): walls -> ground contacts `left` (x1 >= x_left) and `right`
    (x_last <= x_right), the link -> `slot_min` / `slot_max` on x2 - x1 (without d_min
    the bodies meet at x2 = x1, restitution r_min, default 1).  Tables are read."""
    two = _get(scene, "m2") is not None
    n = 2 if two else 1
    suffix = ("1", "2")[:n]

    def body(name, default=None):
        return [_get(scene, f"{name}{i}", default) for i in suffix]

    if any(_get(scene, f"f{i}_amp") not in (None, 0.0) for i in suffix):
        raise ValueError("exact_nbody: sine forcing is out of scope")
    if any(_get(scene, name) not in (None, 0.0) for name in
           ("k1", "k2", "k12", "c1", "c2", "c12")):
        raise ValueError("exact_nbody: springs and dampers are out of scope")
    tables = [read_table(p) if p else None for p in (_get(scene, f"f{i}_table") for i in suffix)]
    contacts = []
    if _get(scene, "x_left") is not None:
        contacts.append(dict(a=0, b=1, d_min=_get(scene, "x_left"), r_min=_get(scene, "r_left", 1.0),
                             name="left"))
    if _get(scene, "x_right") is not None:
        contacts.append(dict(a=0, b=n, d_max=_get(scene, "x_right"), r_max=_get(scene, "r_right", 1.0),
                             name="right"))
    if two:
        link = dict(a=1, b=2, d_min=_get(scene, "d_min", 0.0), r_min=_get(scene, "r_min", 1.0),
                    name_min="slot_min", name="slot")
        if _get(scene, "d_max") is not None:
            link.update(d_max=_get(scene, "d_max"), r_max=_get(scene, "r_max", 1.0), name_max="slot_max")
        contacts.append(link)
    mu = body("mu", 0.0)
    return dict(m=body("m"), x=body("x"), v=body("v", 0.0), mu=mu,
                mus=[a if b is None else b for a, b in zip(mu, body("mus"))],
                f=body("f", 0.0), f_table=tables, g=_get(scene, "g", DEFAULT_G),
                contacts=contacts, t_end=_get(scene, "t_end"))


def two_body_events(solution):
    """Events as tests/exact_reference.py logs them: (t, kind, v1b, v2b, v1a, v2a) floats."""
    out = []
    for e in solution.events:
        b, a = [float(u) for u in e.before], [float(u) for u in e.after]
        if len(b) == 1:
            b, a = b + [0.0], a + [0.0]
        out.append((float(e.t), e.kind, b[0], b[1], a[0], a[1]))
    return out
