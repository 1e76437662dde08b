"""Closed-form event-driven references for springs, dampers and static friction.

The exact answers that the engine's tests for issue 10 (static friction, springs and
dampers, one-body scenes, bodies that meet) are checked against.  Pure Python with
mpmath at DPS = 50 digits; no engine code, no integrator: every phase is written down
in closed form (polynomials, harmonic arcs, damped exponentials) and every event time
is an explicit formula (quadratic roots, atan2/acos), evaluated to 50 digits.
tests/test_exact_springs.py checks each against an independent high-precision Taylor
integrator with generic event rules.

Inputs are floats (or anything mpmath.mpf accepts): a float is converted exactly, so a
reference built from the same binary numbers as an engine scene is exact for that scene.
Times and states come back as mpf; `float(...)` them for comparisons with the engine.

The event-driven functions (friction_block, impact_oscillator, stick_slip,
constant_force_bodies) return a `Reference`: `.events` (list of `Event`: t, kind, x, v_before,
v_after, as tuples over the bodies), `.phases` (list of `Phase`) and
`.state(t) -> (x, v)` tuples; `.times(kind)` lists event times.  Event kinds follow the
engine's log: `left`, `right`, `slot_min` (the bodies meet at x2 = x1), `rest_left`,
`rest_right`, `stick1` (a sliding body stops and holds), `slip1` (a body at rest
breaks away), with the engine's conventions (tests/exact_reference.py): nothing is
logged at t = 0, and a stop that does not hold is not a stick.  Two kinds the engine
does not log mark those stops here: `reverse1` (the velocity crosses zero and the body
slides back at once) and `graze1` (the velocity touches zero tangentially and the body
goes on the same way: mus = mu in the stick-slip cycle).  Filter by kind to compare.
damped_pair returns a `DampedPair` (state, ke, pe, damping_loss, energy_residual as
functions of t); stick_slip_cycle a dict of the cycle's closed-form numbers;
ramp_breakaway_time, equilibrium_wall_impact_times and rattle_time single formulas.

Physics (the model of issue 10, written out here).  Gravity g, normal force m g; kinetic bound c = mu m g,
static bound cs = mus m g >= c.  A sliding body feels -c sign(v).  A body at rest
with holding force H (every other force on it) stays while |H| <= cs; when |H| reaches
cs it breaks away (`slip1`) and slides in the direction of H.  A sliding body whose
velocity reaches zero holds (`stick1`) if |H| <= cs there, else it slides on in the
direction of H at once (`reverse1` / `graze1`).
A spring to the ground pulls with -k (x - x_rest).

1. friction_block: one body, force f(t) = f0 + rate t, no walls.  Phases are
   polynomials: sliding, m v' = f0 + rate t - sigma c, so v is quadratic and x cubic in
   the phase time; a stop is a root of that quadratic (numerically stable formula);
   at rest the holding force is f(t) itself, linear, and the break-away is
   t_b = (sign(rate) cs - f0) / rate exactly when f reaches the static bound.  Two
   scenes of issue 10: a ramp from rest (break-away, then the cubic), and a block
   sliding into a constant force with c < |f| <= cs: it stops at
   t = m v0 / (c + |f|) and stays.

2. impact_oscillator: mass m, spring k (rest x_rest), constant force f, left wall at
   x_left with restitution r.  With w = sqrt(k/m), x_eq = x_rest + f/k, u = x - x_eq and
   u_w = x_left - x_eq, an arc is u = A cos(w tau - alpha), A = hypot(u0, v0/w),
   alpha = atan2(v0/w, u0); the wall is reached, moving left, at
   w tau = (alpha + acos(u_w/A)) mod 2 pi (none if A < -u_w: the motion stays clear,
   A = -u_w is a grazing touch at zero speed: no impact).  After an impact the body
   leaves the wall at speed v+ and the next arc is exactly
   w tau = 2 atan2(v+/w, u_w)   (from u_w (cos th - 1) + (v+/w) sin th = 0),
   and it arrives with speed v+ (energy of the arc), so v+ falls by r per impact.
   "A spring-mass on a wall at its equilibrium" is u_w = 0 (x_rest + f/k = x_left):
   every arc is exactly half a period, pi sqrt(m/k), whatever r and the speed, so the
   impacts never accumulate: t_n = t_1 + (n - 1) pi sqrt(m/k), v_n = r^n v_1.
   With u_w > 0 (the spring presses the body into the wall) and r < 1 the arcs shrink
   like r^n and the impacts accumulate at t_1 + sum_n 2 atan(r^n v1/(w u_w))/w (summed
   to 50 digits with a rigorous tail bound); then `rest_left` and the body rests there.

3. stick_slip: the classic stick-slip oscillator, a block on a spring to the ground
   (k, x_rest) pulled by an anchor at speed V, written as the ramp force k V t (plus an
   optional constant f0): k (x_rest + V t - x) = -k (x - x_rest) + k V t.
   Holding force H(t, x) = f0 + k V t - k (x - x_rest).
   Slip (direction sigma): m x'' = H - sigma c.  q = x - x_rest - V t - f0/k
   + sigma c/k has q'' = x'' = -w^2 q: a harmonic arc about the moving equilibrium,
   q = q0 cos w tau + (p0/w) sin w tau, p0 = v0 - V, and v = V + q'.  With
   q' = P cos(w tau + psi), P = hypot(p0, w q0), psi = atan2(w q0, p0), the stop
   V + q' = 0 is at w tau + psi = sigma acos(-V/P) (mod 2 pi) (v decreasing through 0
   for sigma = +1, increasing for -1); none when P < |V| (steady sliding).
   Stick at x_s: H grows at the rate k V; break-away when it reaches
   sign(V) cs: t_b = t_s + (sign(V) cs - H(t_s)) / (k V).
   The limit cycle (V > 0).  Let Delta = (mus - mu) m g / k.  At break-away v = 0 and
   H = cs, i.e. q0 = -Delta, p0 = -V:
       v(tau) = V (1 - cos w tau) + Delta w sin w tau,
   zero again at tan(w tau/2) = -Delta w / V: the slip lasts
       T_slip = (2 pi - 2 atan(Delta w / V)) / w      (between half and one period),
   and there q = +Delta (the arc is symmetric about the moving equilibrium), so the
   block stops with H = c - k Delta = (2 mu - mus) m g, inside [-cs, cs]: it sticks.
   H must climb 2 k Delta at the rate k V:  T_stick = 2 Delta / V = 2 (mus - mu) m g / (k V).
   The block slips V T_slip + 2 Delta per cycle, which the anchor covers in a period
   T_slip + T_stick, so the next break-away is the same state shifted: every
   break-away from rest lies on the cycle.  The transient from an arbitrary (x0, v0) is
   at most a few arcs until the first stick; from then on the cycle is exact.
   mus = mu (Delta = 0): T_stick = 0 and the slip lasts a full period with v touching
   zero tangentially (v = V (1 - cos w tau) >= 0): a grazing stop, logged here as
   `graze1` (H = mu m g = cs there and growing: no hold); an engine sees no sign change
   of v and should log nothing: the motion is one smooth slide.

4. damped_pair: two bodies, no walls, spring k12 and damper c12 between them.  With
   d = x2 - x1, e = d - d_rest, reduced mass mr = m1 m2 / (m1 + m2):
   mr e'' + c12 e' + k12 e = 0 and the centre of mass moves uniformly.  e is a sum of
   exponentials exp(lambda t) (complex pair: under-damped; real pair: over-damped;
   double root (A + B t) exp(lambda t): critically damped, chosen when
   c12^2 == 4 mr k12 exactly).  KE = M vcm^2/2 + mr e'^2/2, PE = k12 e^2/2 and the
   damper's dissipation D_c = int c12 e'^2 dt, integrated term by term in closed
   form, so KE + PE - (KE0 + PE0) + D_c = 0.

5. constant_force_bodies: one or two bodies under constant forces, no friction, walls
   (left on body 1, right on the last body) and, for two bodies, the meeting contact
   x2 >= x1 (`slot_min` with d_min = 0, restitution r_meet).  Every gap is quadratic
   in time: each event is the earliest root of a quadratic.  Impacts by Newton's law
   (a meeting conserves momentum).  A single body pressed into a wall by its force
   with r < 1 rattles to rest at t + 2 u / (|a| (1 - r)) (geometric series of flights);
   other accumulations raise ValueError.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, List, Optional, Sequence, Tuple

import mpmath
from mpmath import mp, mpf

DEFAULT_G = 9.80665
# Working precision of every reference (decimal digits).
DPS = 50
# Relative size below which two 50-digit numbers are the same number (grazing tests,
# a stop at the start of a phase): far above the rounding of DPS digits, far below
# anything a double can resolve.
TOUCH = mpf(10) ** -40
# Impacts of an accumulating series closer than this (s) are not listed one by one: the
# series is summed to its accumulation time (rest_*) instead.
ZENO_GAP = mpf(10) ** -30
MAX_EVENTS = 100_000


def _mp(value):
    return value if isinstance(value, mpf) else mpf(value)


@dataclass
class Event:
    t: mpf
    kind: str
    x: tuple
    v_before: tuple
    v_after: tuple


@dataclass
class Phase:
    """One smooth phase on [t0, t1]; `motion(tau)` gives (x, v) tuples at t0 + tau.

    `label` says what the phase is (`stick`, `slide+`, `slide-`, `arc`, `rest`, `free`);
    `poly` (polynomial phases only) lists, per body, the coefficients of x in tau,
    lowest first, so that v is their derivative."""

    t0: mpf
    t1: mpf
    label: str
    motion: Callable
    poly: Optional[list] = None


@dataclass
class Reference:
    events: List[Event] = field(default_factory=list)
    phases: List[Phase] = field(default_factory=list)

    def state(self, t):
        """(x, v) tuples at time t (the phase that contains t; the later at a boundary)."""
        with mp.workdps(DPS):
            t = _mp(t)
            for phase in reversed(self.phases):
                if phase.t0 <= t:
                    if t > phase.t1 * (1 + TOUCH) + TOUCH:
                        raise ValueError(f"t = {t} beyond the reference's end {phase.t1}")
                    return phase.motion(t - phase.t0)
            raise ValueError(f"t = {t} before the reference's start")

    def times(self, kind=None):
        return [e.t for e in self.events if kind is None or e.kind == kind]


def _poly_eval(coeffs, tau):
    result = mpf(0)
    for c in reversed(coeffs):
        result = result * tau + c
    return result


def _poly_derivative(coeffs):
    return [i * c for i, c in enumerate(coeffs)][1:] or [mpf(0)]


def _smallest_positive_root(a, b, c, allow_zero=False):
    """Smallest tau > 0 (>= 0 with allow_zero) with a tau^2 + b tau + c = 0, else None.

    Stable roots (no cancellation): q = -(b + sign(b) sqrt(disc)) / 2, roots q/a, c/q."""
    roots = []
    if a == 0:
        if b != 0:
            roots = [-c / b]
    else:
        disc = b * b - 4 * a * c
        if disc < 0:
            if -disc > TOUCH * max(b * b, abs(4 * a * c)):
                return None
            disc = mpf(0)
        sq = mpmath.sqrt(disc)
        q = -(b + (sq if b >= 0 else -sq)) / 2
        if q != 0:
            roots = [q / a, c / q]
        else:
            roots = [mpf(0)]
    good = [tau for tau in roots if tau > 0 or (allow_zero and tau == 0)]
    return min(good) if good else None


def _sign(value):
    return 1 if value > 0 else (-1 if value < 0 else 0)


def _at_bound(h, cs):
    """|h| = cs to the working precision (a rounding either way must not decide)."""
    return abs(abs(h) - cs) <= TOUCH * cs


def _holds(h, rate, cs):
    """Static friction holds the holding force h (changing at `rate`): inside the bound,
    or on it and moving inward (or not moving)."""
    if _at_bound(h, cs):
        return _sign(rate) != _sign(h)
    return abs(h) < cs


# --------------------------------------------------------------------------------------
# 1. static friction, one body under a force ramp


def friction_block(m, mu, mus, f0, rate, t_end, x0=0.0, v0=0.0, g=DEFAULT_G):
    """One body with kinetic mu, static mus >= mu, force f(t) = f0 + rate t, from (x0, v0).

    Events `stick1`, `slip1`, `reverse1`, `graze1` (none at t = 0);
    phases carry `poly` = [x coefficients in tau] (cubic)."""
    with mp.workdps(DPS):
        m, mu, mus, f0, rate, g = map(_mp, (m, mu, mus, f0, rate, g))
        t_end, x, v = _mp(t_end), _mp(x0), _mp(v0)
        if mus < mu:
            raise ValueError("mus below mu")
        c, cs = mu * m * g, mus * m * g
        ref = Reference()
        t = mpf(0)

        def force(time):
            return f0 + rate * time

        def held(time):
            return _holds(force(time), rate, cs)

        sigma = _sign(v) if v != 0 else (0 if held(t) else _sign(force(t)))
        while t < t_end and len(ref.events) < MAX_EVENTS:
            if sigma == 0:
                poly = [x, mpf(0), mpf(0), mpf(0)]
                tau = None
                if rate != 0:
                    tau = (_sign(rate) * cs - force(t)) / rate
                t1 = t_end if tau is None or t + tau > t_end else t + tau
                ref.phases.append(_poly_phase(t, t1, "stick", poly))
                if t1 >= t_end:
                    break
                t = t1
                sigma = _sign(rate)
                ref.events.append(Event(t, "slip1", (x,), (mpf(0),), (mpf(0),)))
                continue
            # m a(tau) = f(t) - sigma c + rate tau
            a0 = (force(t) - sigma * c) / m
            a1 = rate / m
            poly = [x, v, a0 / 2, a1 / 6]
            tau = _smallest_positive_root(a1 / 2, a0, v)
            if v == 0 and tau is not None and tau <= TOUCH:
                tau = None
            t1 = t_end if tau is None or t + tau > t_end else t + tau
            ref.phases.append(_poly_phase(t, t1, "slide+" if sigma > 0 else "slide-", poly))
            if t1 >= t_end:
                break
            x = _poly_eval(poly, tau)
            v_before = _poly_eval(_poly_derivative(poly), tau)
            t = t1
            v = mpf(0)
            if held(t):
                ref.events.append(Event(t, "stick1", (x,), (v_before,), (mpf(0),)))
                sigma = 0
            else:
                kind = "graze1" if _sign(force(t)) == sigma else "reverse1"
                sigma = _sign(force(t))
                ref.events.append(Event(t, kind, (x,), (v_before,), (mpf(0),)))
        return ref


def _poly_phase(t0, t1, label, poly):
    def motion(tau):
        return (_poly_eval(poly, tau),), (_poly_eval(_poly_derivative(poly), tau),)

    return Phase(t0, t1, label, motion, [list(poly)])


def ramp_breakaway_time(m, mus, f0, rate, g=DEFAULT_G):
    """The instant a block at rest under f0 + rate t breaks away: |f| = mus m g."""
    with mp.workdps(DPS):
        m, mus, f0, rate, g = map(_mp, (m, mus, f0, rate, g))
        return (_sign(rate) * mus * m * g - f0) / rate


# --------------------------------------------------------------------------------------
# 2. the impact oscillator


def impact_oscillator(m, k, x_rest, x_left, r, x0, v0, t_end, force=0.0):
    """Mass m on a spring (k, x_rest) to the ground, constant force, left wall (r).

    Events `left` (one per impact) and `rest_left` (an accumulated series, u_w > 0)."""
    with mp.workdps(DPS):
        m, k, x_rest, x_left, r, force = map(_mp, (m, k, x_rest, x_left, r, force))
        t_end, x, v = _mp(t_end), _mp(x0), _mp(v0)
        if x < x_left:
            raise ValueError("start behind the wall")
        w = mpmath.sqrt(k / m)
        x_eq = x_rest + force / k
        u_w = x_left - x_eq
        ref = Reference()
        t = mpf(0)

        def arc(u0, p0):
            def motion(tau):
                cs, sn = mpmath.cos(w * tau), mpmath.sin(w * tau)
                return ((x_eq + u0 * cs + p0 / w * sn),), ((-u0 * w * sn + p0 * cs),)

            return motion

        # The first arc: from anywhere, the first time u reaches u_w moving left.
        u = x - x_eq
        amp = mpmath.hypot(u, v / w)
        tau = None
        arrival_sq = (u - u_w) * (u + u_w) + (v / w) ** 2
        if u == u_w and v < 0:
            tau = mpf(0)
        elif amp > 0 and u_w > -amp * (1 - TOUCH):
            alpha = mpmath.atan2(v / w, u)
            theta = (alpha + mpmath.acos(u_w / amp)) % (2 * mpmath.pi)
            if theta <= TOUCH:
                theta += 2 * mpmath.pi
            tau = theta / w
        while len(ref.events) < MAX_EVENTS:
            motion = arc(x - x_eq, v)
            if tau is None or t + tau > t_end:
                ref.phases.append(Phase(t, t_end, "arc", motion))
                return ref
            ref.phases.append(Phase(t, t + tau, "arc", motion))
            t = t + tau
            # Arrival speed from the arc's energy, without the cancellation of A^2 - u_w^2
            # (after an impact it is the departure speed itself: tiny Zeno arcs).
            speed = w * mpmath.sqrt(max(arrival_sq, mpf(0)))
            v_after = r * speed
            ref.events.append(Event(t, "left", (x_left,), (-speed,), (v_after,)))
            x, v = x_left, v_after
            if v_after == 0:
                break
            if u_w > 0 and r < 1:
                # The arcs 2 atan(v_n/(w u_w))/w shrink like r^n: list them while they
                # are resolvable, then sum the rest (atan y <= y bounds the tail).
                theta = 2 * mpmath.atan2(v / w, u_w) / w
                if theta < ZENO_GAP:
                    t_acc = t + _atan_series(v / (w * u_w), r) / w
                    ref.phases.append(Phase(t, t_acc, "arc", arc(u_w, v)))
                    t = t_acc
                    ref.events.append(Event(t, "rest_left", (x_left,), (mpf(0),), (mpf(0),)))
                    break
            tau = 2 * mpmath.atan2(v / w, u_w) / w
            arrival_sq = (v / w) ** 2
        # At rest on the wall (pressed there, or stopped there by r = 0 with u_w >= 0).
        if u_w < 0:
            raise ValueError("r = 0 with the wall inside the swing: the body grazes the wall")
        ref.phases.append(Phase(t, t_end, "rest", lambda tau: ((x_left,), (mpf(0),))))
        return ref


def _atan_series(y, r):
    """sum_{n >= 0} 2 atan(y r^n), to DPS digits (tail after N terms <= 2 y r^N / (1 - r))."""
    total, term_y = mpf(0), y
    limit = mpf(10) ** -(DPS + 2)
    while 2 * term_y / (1 - r) > limit:
        total += 2 * mpmath.atan(term_y)
        term_y *= r
    return total


def equilibrium_wall_impact_times(m, k, x_left, x0, v0, n):
    """Impact times of the spring-mass whose equilibrium is the wall (x_rest + f/k =
    x_left), from (x0, v0): the first arrival, then every half period pi sqrt(m/k)."""
    with mp.workdps(DPS):
        m, k, x_left, x0, v0 = map(_mp, (m, k, x_left, x0, v0))
        w = mpmath.sqrt(k / m)
        u, p = x0 - x_left, v0 / w
        if u == 0 and p == 0:
            raise ValueError("at rest at the equilibrium on the wall: no impact ever")
        # u = A cos(w t - alpha) reaches 0 moving left at w t - alpha = pi/2 (mod 2 pi)
        alpha = mpmath.atan2(p, u)
        theta = (alpha + mpmath.pi / 2) % (2 * mpmath.pi)
        if theta == 0 and not (u == 0 and v0 < 0):
            theta = 2 * mpmath.pi
        return [(theta + j * mpmath.pi) / w for j in range(n)]


# --------------------------------------------------------------------------------------
# 3. the stick-slip oscillator


def stick_slip(m, k, x_rest, pull_rate, mu, mus, x0, v0, t_end, f0=0.0, g=DEFAULT_G):
    """Block on a spring (k, x_rest) to the ground, force f0 + pull_rate t (the anchor's
    pull: pull_rate = k V, given as the engine's ramp table has it, so that both use the
    same binary number), kinetic mu, static mus, from (x0, v0) at t = 0, until t_end.
    Events `stick1`, `slip1`, `reverse1`, `graze1`."""
    with mp.workdps(DPS):
        m, k, x_rest, pull_rate, mu, mus, f0, g = map(
            _mp, (m, k, x_rest, pull_rate, mu, mus, f0, g))
        V = pull_rate / k
        t_end, x, v = _mp(t_end), _mp(x0), _mp(v0)
        if mus < mu:
            raise ValueError("mus below mu")
        w = mpmath.sqrt(k / m)
        c, cs = mu * m * g, mus * m * g
        delta = (cs - c) / k
        ref = Reference()
        t = mpf(0)

        def holding(time, pos):
            return f0 + pull_rate * time - k * (pos - x_rest)

        def held(time, pos):
            return _holds(holding(time, pos), pull_rate, cs)

        sigma = _sign(v) if v != 0 else (0 if held(t, x) else _sign(holding(t, x)))
        q0 = None  # exact q at a break-away (kept exact: the grazing case mus = mu)
        while len(ref.events) < MAX_EVENTS:
            if sigma == 0:
                rate = pull_rate
                tau = None if rate == 0 else (_sign(V) * cs - holding(t, x)) / rate
                x_s = x
                motion = lambda tau_, x_s=x_s: ((x_s,), (mpf(0),))
                if tau is None or t + tau >= t_end:
                    ref.phases.append(Phase(t, t_end, "stick", motion, [[x_s]]))
                    return ref
                ref.phases.append(Phase(t, t + tau, "stick", motion, [[x_s]]))
                t = t + tau
                sigma = _sign(V)
                q0 = -sigma * delta
                ref.events.append(Event(t, "slip1", (x,), (mpf(0),), (mpf(0),)))
                continue
            shift = x_rest + f0 / k - sigma * c / k  # x = q + shift + V t
            if q0 is None:
                q0 = x - shift - V * t
            p0 = v - V
            motion = _slip_arc(t, q0, p0, w, shift, V)
            tau = _slip_stop(q0, p0, w, V, sigma)
            label = "slide+" if sigma > 0 else "slide-"
            if tau is None or t + tau >= t_end:
                ref.phases.append(Phase(t, t_end, label, motion))
                return ref
            ref.phases.append(Phase(t, t + tau, label, motion))
            (x,), (v_before,) = motion(tau)
            t = t + tau
            v, q0 = mpf(0), None
            if held(t, x):
                ref.events.append(Event(t, "stick1", (x,), (v_before,), (v,)))
                sigma = 0
            else:
                kind = "graze1" if _sign(holding(t, x)) == sigma else "reverse1"
                sigma = _sign(holding(t, x))
                if _at_bound(holding(t, x), cs):
                    q0 = -sigma * delta  # exactly at the bound: keep the arc exact
                ref.events.append(Event(t, kind, (x,), (v_before,), (v,)))
        return ref


def _slip_arc(t0, q0, p0, w, shift, V):
    def motion(tau):
        cs, sn = mpmath.cos(w * tau), mpmath.sin(w * tau)
        q = q0 * cs + p0 / w * sn
        dq = -q0 * w * sn + p0 * cs
        return (q + shift + V * (t0 + tau),), (V + dq,)

    return motion


def _slip_stop(q0, p0, w, V, sigma):
    """First tau > 0 at which v = V + q' crosses zero against sigma, or None."""
    P = mpmath.hypot(p0, w * q0)
    if P == 0 or P < abs(V) * (1 - TOUCH):
        return None
    psi = mpmath.atan2(w * q0, p0)
    ratio = min(max(-V / P, mpf(-1)), mpf(1))
    target = sigma * mpmath.acos(ratio)
    theta = (target - psi) % (2 * mpmath.pi)
    if theta <= TOUCH * 2 * mpmath.pi:
        # the stop formula's root is the start itself: a phase that leaves v = 0 along
        # the tangent (mus = mu); the next touch is a full period later
        theta = 2 * mpmath.pi
    return theta / w


def stick_slip_cycle(m, k, pull_rate, mu, mus, g=DEFAULT_G):
    """The closed-form limit cycle (pull_rate = k V > 0): durations, slip distance, the
    holding force where the block stops, the peak speed."""
    with mp.workdps(DPS):
        m, k, pull_rate, mu, mus, g = map(_mp, (m, k, pull_rate, mu, mus, g))
        V = pull_rate / k
        w = mpmath.sqrt(k / m)
        delta = (mus - mu) * m * g / k
        t_slip = (2 * mpmath.pi - 2 * mpmath.atan(delta * w / V)) / w
        t_stick = 2 * delta / V
        return {
            "t_slip": t_slip,
            "t_stick": t_stick,
            "period": t_slip + t_stick,
            "slip_distance": V * t_slip + 2 * delta,
            "stop_force": (2 * mu - mus) * m * g,
            "peak_speed": V + mpmath.hypot(V, w * delta),
        }


# --------------------------------------------------------------------------------------
# 4. the damped spring pair


class DampedPair:
    """Two bodies, spring k12 and damper c12 between them, no walls, no friction.

    `state(t)`, `ke(t)`, `pe(t)`, `damping_loss(t)` (= int_0^t c12 (v2 - v1)^2) in
    closed form; `regime` is 'under', 'critical', 'over' or 'undamped'."""

    def __init__(self, m1, m2, k12, c12, d_rest, x1, v1, x2, v2):
        with mp.workdps(DPS):
            self.m1, self.m2, self.k, self.c, self.d_rest = map(_mp, (m1, m2, k12, c12, d_rest))
            x1, v1, x2, v2 = map(_mp, (x1, v1, x2, v2))
            self.M = self.m1 + self.m2
            self.mr = self.m1 * self.m2 / self.M
            self.xcm0 = (self.m1 * x1 + self.m2 * x2) / self.M
            self.vcm = (self.m1 * v1 + self.m2 * v2) / self.M
            e0, de0 = x2 - x1 - self.d_rest, v2 - v1
            disc = self.c**2 - 4 * self.mr * self.k
            if self.c == 0:
                self.regime = "undamped" if self.k > 0 else "free"
            else:
                self.regime = "over" if disc > 0 else ("critical" if disc == 0 else "under")
            # e(t) = sum_j (A_j + B_j t) exp(lam_j t), complex arithmetic throughout.
            if disc == 0:
                lam = -self.c / (2 * self.mr)
                self.terms = [(mpmath.mpc(e0), mpmath.mpc(de0 - lam * e0), mpmath.mpc(lam))]
            else:
                root = mpmath.sqrt(mpmath.mpc(disc))
                lam1 = (-self.c + root) / (2 * self.mr)
                lam2 = (-self.c - root) / (2 * self.mr)
                a1 = (de0 - lam2 * e0) / (lam1 - lam2)
                a2 = e0 - a1
                self.terms = [(a1, mpmath.mpc(0), lam1), (a2, mpmath.mpc(0), lam2)]
            self.e0, self.de0 = e0, de0

    def _e(self, t):
        e = de = mpmath.mpc(0)
        for a, b, lam in self.terms:
            ex = mpmath.exp(lam * t)
            e += (a + b * t) * ex
            de += (lam * (a + b * t) + b) * ex
        return e.real, de.real

    def state(self, t):
        with mp.workdps(DPS):
            t = _mp(t)
            e, de = self._e(t)
            xcm = self.xcm0 + self.vcm * t
            d = e + self.d_rest
            # x1 = xcm - m2 d / M, x2 = xcm + m1 d / M
            return ((xcm - self.m2 * d / self.M, xcm + self.m1 * d / self.M),
                    (self.vcm - self.m2 * de / self.M, self.vcm + self.m1 * de / self.M))

    def ke(self, t):
        with mp.workdps(DPS):
            _, de = self._e(_mp(t))
            return self.M * self.vcm**2 / 2 + self.mr * de**2 / 2

    def pe(self, t):
        with mp.workdps(DPS):
            e, _ = self._e(_mp(t))
            return self.k * e**2 / 2

    def damping_loss(self, t):
        """int_0^t c12 e'(s)^2 ds, term by term: e' = sum (alpha_j + beta_j s) exp(lam_j s)."""
        with mp.workdps(DPS):
            t = _mp(t)
            rates = [(lam * a + b, lam * b, lam) for a, b, lam in self.terms]
            total = mpmath.mpc(0)
            for al1, be1, l1 in rates:
                for al2, be2, l2 in rates:
                    # (al1 + be1 s)(al2 + be2 s) = p0 + p1 s + p2 s^2 times exp(L s)
                    p = (al1 * al2, al1 * be2 + be1 * al2, be1 * be2)
                    total += _poly_exp_integral(p, l1 + l2, t)
            return (self.c * total).real

    def energy_residual(self, t):
        """KE + PE - (KE0 + PE0) + D_c at t (zero in exact arithmetic)."""
        with mp.workdps(DPS):
            return self.ke(t) + self.pe(t) - self.ke(0) - self.pe(0) + self.damping_loss(t)


def _poly_exp_integral(p, lam, t):
    """int_0^t (p0 + p1 s + p2 s^2) exp(lam s) ds, closed form (lam = 0 allowed)."""
    if abs(lam) == 0:
        return p[0] * t + p[1] * t**2 / 2 + p[2] * t**3 / 3
    # antiderivative of s^n exp(lam s): exp(lam s) sum_j (-1)^j n!/(n-j)! s^(n-j) / lam^(j+1)
    def anti(s):
        ex = mpmath.exp(lam * s)
        total = mpmath.mpc(0)
        for n, coeff in enumerate(p):
            acc = mpmath.mpc(0)
            for j in range(n + 1):
                acc += (-1) ** j * mpmath.factorial(n) / mpmath.factorial(n - j) * s ** (n - j) / lam ** (j + 1)
            total += coeff * acc
        return ex * total

    return anti(t) - anti(mpf(0))


def damped_pair(m1, m2, k12, c12, d_rest, x1, v1, x2, v2):
    return DampedPair(m1, m2, k12, c12, d_rest, x1, v1, x2, v2)


# --------------------------------------------------------------------------------------
# 5. bodies under constant forces: one body between walls, two bodies that meet


def constant_force_bodies(masses, forces, x0, v0, t_end, x_left=None, x_right=None,
                          r_left=1.0, r_right=1.0, r_meet=1.0):
    """One or two frictionless bodies under constant forces; walls optional (left bounds
    body 1, right the last body); two bodies meet at x2 = x1 (`slot_min`, r_meet)."""
    with mp.workdps(DPS):
        n = len(masses)
        m = [_mp(a) for a in masses]
        acc = [_mp(f) / mm for f, mm in zip(forces, m)]
        x = [_mp(a) for a in x0]
        v = [_mp(a) for a in v0]
        t_end = _mp(t_end)
        r_left, r_right, r_meet = map(_mp, (r_left, r_right, r_meet))
        x_left = None if x_left is None else _mp(x_left)
        x_right = None if x_right is None else _mp(x_right)
        if n == 2 and x[1] < x[0]:
            raise ValueError("x2 < x1: the bodies cannot pass each other")
        # gap = sum_i n_i x_i + offset; normals on (x1[, x2])
        contacts = []
        if x_left is not None:
            contacts.append(("left", [1] + [0] * (n - 1), -x_left, r_left))
        if x_right is not None:
            contacts.append(("right", [0] * (n - 1) + [-1], x_right, r_right))
        if n == 2:
            contacts.append(("slot_min", [-1, 1], mpf(0), r_meet))
        ref = Reference()
        t = mpf(0)
        touching = set()
        while len(ref.events) < MAX_EVENTS:
            phase_x, phase_v = list(x), list(v)
            best, hit = None, []
            for name, normal, offset, _ in contacts:
                g0 = sum(a * b for a, b in zip(normal, phase_x)) + offset
                g1 = sum(a * b for a, b in zip(normal, phase_v))
                g2 = sum(a * b for a, b in zip(normal, acc)) / 2
                if name in touching and g0 == 0 and g1 == 0 and g2 <= 0:
                    raise ValueError(f"persistent contact {name}: not covered")
                tau = _smallest_positive_root(g2, g1, g0, allow_zero=(g0 == 0 and g1 < 0))
                if name in touching and tau is not None and tau == 0:
                    tau = None
                if tau is None:
                    continue
                if best is None or tau < best * (1 - TOUCH):
                    best, hit = tau, [name]
                elif tau <= best * (1 + TOUCH):
                    hit.append(name)
            ref.phases.append(_free_phase(t, phase_x, phase_v, acc))
            if best is None or t + best > t_end:
                ref.phases[-1].t1 = t_end
                return ref
            if len(hit) > 1:
                raise ValueError(f"simultaneous impacts {hit}: not covered")
            ref.phases[-1].t1 = t + best
            t = t + best
            x = [a + b * best + c * best**2 / 2 for a, b, c in zip(phase_x, phase_v, acc)]
            v = [b + c * best for b, c in zip(phase_v, acc)]
            name, normal, offset, r = next(c for c in contacts if c[0] == hit[0])
            # put the hit contact exactly on its constraint
            if name == "left":
                x[0] = x_left
            elif name == "right":
                x[-1] = x_right
            else:
                x[1] = x[0]
            before = tuple(v)
            vn = sum(a * b for a, b in zip(normal, v))
            impulse = -(1 + r) * vn / sum(a * a / mm for a, mm in zip(normal, m))
            v = [b + impulse * a / mm for a, b, mm in zip(normal, v, m)]
            ref.events.append(Event(t, name, tuple(x), before, tuple(v)))
            touching = {name}
            # a single body pressed into the wall it bounced off: geometric rattle
            if n == 1 and r < 1 and name in ("left", "right"):
                into = acc[0] if name == "right" else -acc[0]
                u = abs(v[0])
                if into > 0 and 2 * u / into < ZENO_GAP * (1 - r):
                    t_acc = t + 2 * u / (into * (1 - r))
                    ref.phases.append(Phase(t, t_acc, "rattle", _const_motion(x, [mpf(0)])))
                    t = t_acc
                    v = [mpf(0)]
                    ref.events.append(Event(t, "rest_" + name, tuple(x), (mpf(0),), (mpf(0),)))
                    ref.phases.append(Phase(t, t_end, "rest", _const_motion(x, v)))
                    return ref
        return ref


def _free_phase(t0, x, v, acc):
    poly = [[a, b, c / 2] for a, b, c in zip(x, v, acc)]

    def motion(tau):
        return (tuple(_poly_eval(p, tau) for p in poly),
                tuple(_poly_eval(_poly_derivative(p), tau) for p in poly))

    return Phase(t0, t0, "free", motion, poly)


def _const_motion(x, v):
    x, v = tuple(x), tuple(v)
    return lambda tau: (x, v)


def rattle_time(u, a_into, r):
    """Accumulation time after an impact leaving a wall at speed u, a body pushed back
    into it with acceleration a_into > 0, restitution r < 1: 2 u / (a_into (1 - r))."""
    with mp.workdps(DPS):
        u, a_into, r = map(_mp, (u, a_into, r))
        return 2 * u / (a_into * (1 - r))
