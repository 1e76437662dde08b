"""A tiny independent event-driven reference for frictionless constant-force scenes.

Pure Python (math only), written from the physics of METHOD.md, sharing no code
with the Fortran engine, so the tests can compare the engine with it.

Scope: both friction coefficients zero (or absent), constant forces f1 and f2, any
subset of the four unilateral constraints.  Between events each body moves with
constant acceleration a_i = f_i / m_i, so every gap is a quadratic in time and its
earliest root has a closed form.  At an impact Newton's restitution law is applied by
sequential impulses (METHOD.md section 4), which also covers simultaneous impacts
(both walls at once).  Persistent contact and Zeno accumulation (r < 1 under a
pressing force) are out of scope: the reference raises instead of guessing.
"""

import math

# A gap this close to zero counts as touching: rounding of the closed-form
# positions near 10 m is ~1e-15, so 1e-12 never mixes a real gap up with a touch.
TOUCH_TOL = 1e-12

# Stop rather than loop forever when impacts accumulate (rattling, out of scope).
MAX_EVENTS = 100_000

# name: (normal on (x1, x2), restitution field); gap = n . x + offset (see _gap).
CONTACTS = {
    "left": ((1.0, 0.0), "r_left"),
    "right": ((0.0, -1.0), "r_right"),
    "slot_min": ((-1.0, 1.0), "r_min"),
    "slot_max": ((1.0, -1.0), "r_max"),
}
_LIMIT = {"left": "x_left", "right": "x_right", "slot_min": "d_min", "slot_max": "d_max"}


def _field(scene, name, default=None):
    if isinstance(scene, dict):
        value = scene.get(name, default)
    else:
        value = getattr(scene, name, default)
    return default if value is None else float(value)


def _gap(name, limit, x1, x2):
    if name == "left":
        return x1 - limit
    if name == "right":
        return limit - x2
    if name == "slot_min":
        return (x2 - x1) - limit
    return limit - (x2 - x1)


def earliest_impact(c, b, a):
    """Earliest s >= 0 where gap(s) = c + b s + a s^2 / 2 reaches zero while decreasing.

    c >= 0 is the gap now, b its rate, a its (constant) second derivative.  A touch
    with zero rate (grazing) is not an impact.  Returns math.inf if there is none.
    """
    if a == 0.0:
        return c / -b if b < 0.0 else math.inf
    A = 0.5 * a
    disc = b * b - 4.0 * A * c
    if disc < 0.0:
        return math.inf
    # Stable quadratic roots (no cancellation): q/A and c/q.
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
    roots = []
    if q != 0.0:
        roots += [q / A, c / q]
    else:  # b == 0 and disc == 0 -> c == 0: a double root at 0
        roots += [0.0]
    best = math.inf
    for s in roots:
        if s >= 0.0 and b + a * s < 0.0:
            best = min(best, s)
    return best


def simulate_exact(scene, t_end=None):
    """Run a frictionless constant-force scene exactly.

    scene: anything with the Scene field names as attributes (impact1d.Scene) or a
    dict; None or missing means absent.  Returns (events, segments):
    events   -- list of (t, kind, v1_before, v2_before, v1_after, v2_after)
    segments -- list of (t0, x1, v1, x2, v2): the state at the start of each free flight
    """
    for name in ("mu1", "mu2"):
        if _field(scene, name, 0.0) != 0.0:
            raise ValueError("exact_reference handles frictionless scenes only")
    m = (_field(scene, "m1"), _field(scene, "m2"))
    acc = (_field(scene, "f1", 0.0) / m[0], _field(scene, "f2", 0.0) / m[1])
    t_end = _field(scene, "t_end") if t_end is None else float(t_end)
    contacts = []
    for name, (normal, r_name) in CONTACTS.items():
        limit = _field(scene, _LIMIT[name])
        if limit is not None:
            contacts.append((name, normal, limit, _field(scene, r_name, 1.0)))

    t = 0.0
    x = [_field(scene, "x1"), _field(scene, "x2")]
    v = [_field(scene, "v1", 0.0), _field(scene, "v2", 0.0)]
    events, segments = [], []
    while True:
        segments.append((t, x[0], v[0], x[1], v[1]))
        # Earliest impact of every constraint during free flight from now.
        s_hit, hit = math.inf, None
        for name, n, limit, _ in contacts:
            c = max(_gap(name, limit, *x), 0.0)
            if c < TOUCH_TOL:
                c = 0.0
            b = n[0] * v[0] + n[1] * v[1]
            a = n[0] * acc[0] + n[1] * acc[1]
            if c == 0.0 and b == 0.0 and a < 0.0:
                raise RuntimeError(f"persistent contact {name} at t = {t} is out of scope")
            s = earliest_impact(c, b, a)
            if s < s_hit:
                s_hit, hit = s, name
        if t + s_hit >= t_end:
            s = t_end - t
            x = [x[i] + v[i] * s + 0.5 * acc[i] * s * s for i in range(2)]
            v = [v[i] + acc[i] * s for i in range(2)]
            segments.append((t_end, x[0], v[0], x[1], v[1]))
            return events, segments
        s = s_hit
        t = t + s
        x = [x[i] + v[i] * s + 0.5 * acc[i] * s * s for i in range(2)]
        v = [v[i] + acc[i] * s for i in range(2)]
        _resolve(t, x, v, m, contacts, events)
        if len(events) > MAX_EVENTS:
            raise RuntimeError("impacts accumulate (rattling): out of scope")


def _resolve(t, x, v, m, contacts, events):
    """Sequential impulses: hit the most approaching touching contact until none approaches."""
    for _ in range(1000):
        worst, pick = 0.0, None
        for name, n, limit, r in contacts:
            if abs(_gap(name, limit, *x)) < TOUCH_TOL:
                vn = n[0] * v[0] + n[1] * v[1]
                if vn < worst:
                    worst, pick = vn, (name, n, r)
        if pick is None:
            return
        name, n, r = pick
        before = tuple(v)
        p = -(1.0 + r) * worst / (n[0] ** 2 / m[0] + n[1] ** 2 / m[1])
        v[0] += n[0] * p / m[0]
        v[1] += n[1] * p / m[1]
        events.append((t, name, before[0], before[1], v[0], v[1]))
    raise RuntimeError(f"impacts at t = {t} do not settle")


def state_at(segments, f1_over_m1, f2_over_m2, times):
    """Evaluate the exact piecewise-quadratic motion at the given times.

    Returns a list of (x1, v1, x2, v2).  A time equal to an impact time gets the state
    after the impact.
    """
    starts = [seg[0] for seg in segments]
    out = []
    k = 0
    for t in times:
        while k + 1 < len(segments) and starts[k + 1] <= t:
            k += 1
        t0, x1, v1, x2, v2 = segments[k]
        s = t - t0
        out.append((x1 + v1 * s + 0.5 * f1_over_m1 * s * s, v1 + f1_over_m1 * s,
                    x2 + v2 * s + 0.5 * f2_over_m2 * s * s, v2 + f2_over_m2 * s))
    return out
