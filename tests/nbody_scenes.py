"""N-body scenes with closed-form answers, and a random N-body scene generator.

Each builder returns a scene dict in the N-body format of /work/shared/DESIGN.md
("Mechanisms as data"), as tests/exact_nbody.py reads it:
    m, x, v, mu, mus, f (lists over the bodies 1..N), g, t_end, optional f_table (per body
    None or (times, values)), contacts: [{a, b, d_min, r_min, d_max, r_max, name}]
(a, b: body numbers, 0 the ground at x = 0; gap x_b - x_a - d_min >= 0 for a lower limit,
d_max - (x_b - x_a) >= 0 for an upper one), so that later tests can give it to the engine.
Its companion `*_answer` function gives the exact answer, derived in its docstring, as
mpf at exact_nbody.DPS digits:
    {"events": [(t, kind, before, after)], "final": (x, v)}
with `before`/`after` the velocity tuples of all bodies (None where the closed form does
not fix them), events in the log order of exact_nbody (impacts by contact name,
rest_<contact>, release_<contact>, stick<i>, slip<i>).  tests/test_exact_nbody.py checks
every one against exact_nbody.solve.  Numbers are chosen as short binary fractions, so a
float scene is exactly the scene the closed form is about.

Builders (each with its `<name>_answer(scene)`):
    newtons_cradle     a gapped cradle of equal elastic balls: the velocity is passed on
    galperin           Galperin's billiard (a light body between a wall and a heavy one):
                       floor(pi / atan(sqrt(m/M))) collisions, 31 for M/m = 100
                       (galperin_count(ratio) gives the count alone)
    equal_masses_wall  any number of equal elastic bodies and a wall (three, say): the
                       bodies are free quasi-particles folded at the wall
    falling_stack      three balls dropped in a column onto a floor under gravity
    friction_chain     eight touching blocks with static > sliding friction pushed on
                       block 1 by a constant force or a ramp: the load front and the
                       break-away
    bouncing_chain     five unequal bodies between two walls, free of forces, with gaps
                       and restitutions 1, 0.75, 0.5 (no closed form: exact_nbody's
                       events, nine impacts in four seconds; tests/test_vissim_nbody.py
                       and bench/nbody_accuracy.py measure vissim's order on it)
    random_scene       N = 3..12 bodies, friction, walls, gaps, restitutions 0..1 (no
                       answer: tests/test_exact_nbody.py checks the invariants that hold
                       exactly on any scene)
"""

from __future__ import annotations

import random

from mpmath import mp, mpf

import exact_nbody as nb

DPS = nb.DPS


def _mp(value):
    return value if isinstance(value, mpf) else mpf(value)


def _scene(m, x, v, contacts, t_end, f=None, mu=None, mus=None, g=nb.DEFAULT_G, f_table=None):
    n = len(m)
    return dict(m=list(m), x=list(x), v=list(v), mu=list(mu or [0.0] * n),
                mus=list(mus or mu or [0.0] * n), f=list(f or [0.0] * n), g=g,
                f_table=f_table, contacts=contacts, t_end=t_end)


# --- Newton's cradle -----------------------------------------------------------------------

def newtons_cradle(v=2.0, gaps=(0.25, 0.125, 0.5, 0.0625), diameter=1.0, m=1.0, t_end=1.0):
    """Five equal balls (len(gaps) + 1 in general) on a frictionless line, ball 1 at x = 0
    moving at v toward the others, at rest with the given gaps between neighbours:
    x_{i+1} = x_i + diameter + gap_i.  Contacts `b<i><i+1>` (d_min = diameter, r = 1)."""
    x = [0.0]
    for gap in gaps:
        x.append(x[-1] + diameter + gap)
    n = len(x)
    contacts = [dict(a=i, b=i + 1, d_min=diameter, r_min=1.0, name=f"b{i}{i + 1}") for i in range(1, n)]
    return _scene([m] * n, x, [v] + [0.0] * (n - 1), contacts, t_end)


def newtons_cradle_answer(scene):
    """Ball i moves alone at v and meets ball i+1 after crossing gap_i: an elastic impact of
    equal masses exchanges their velocities (P = m v: ball i stops, ball i+1 leaves at v).
    So impact k (contact b<k><k+1>) is at t_k = (gap_1 + ... + gap_k) / v, with only ball k
    moving at v before and only ball k+1 after; at the end ball i < n rests where it met ball
    i+1, x_i = x_{i+1}(0) - diameter, and ball n is at x_n(0) + v (t_end - t_{n-1})."""
    with mp.workdps(DPS):
        x0 = [_mp(a) for a in scene["x"]]
        v = _mp(scene["v"][0])
        d = _mp(scene["contacts"][0]["d_min"])
        n = len(x0)
        events, t = [], mpf(0)
        for k in range(1, n):
            t += (x0[k] - x0[k - 1] - d) / v
            before = tuple(v if i == k - 1 else mpf(0) for i in range(n))
            after = tuple(v if i == k else mpf(0) for i in range(n))
            events.append((t, f"b{k}{k + 1}", before, after))
        x = [x0[i + 1] - d for i in range(n - 1)] + [x0[-1] + v * (_mp(scene["t_end"]) - t)]
        return dict(events=events, final=(tuple(x), tuple(mpf(0) if i < n - 1 else v for i in range(n))))


# --- Galperin's billiard --------------------------------------------------------------------

def galperin(mass_ratio=100, speed=1.0, x1=1.0, x2=2.0, m=1.0, t_end=None):
    """A light body (m, at rest at x1 > 0) between a wall at 0 and a heavy one (M = mass_ratio
    m, at x2 > x1, moving at -speed), elastic, frictionless.  Contacts `wall` (x1 >= 0) and
    `meet` (x2 >= x1).  t_end: a while after the last collision."""
    contacts = [dict(a=0, b=1, d_min=0.0, r_min=1.0, name="wall"),
                dict(a=1, b=2, d_min=0.0, r_min=1.0, name="meet")]
    scene = _scene([m, m * mass_ratio], [x1, x2], [0.0, -speed], contacts, t_end or 1.0)
    if t_end is None:
        last = galperin_answer(scene)["events"][-1][0]
        scene["t_end"] = float(2 * last + 1)
    return scene


def galperin_answer(scene):
    """Unfolding (Galperin 2003).  In y = (sqrt(m) x1, sqrt(M) x2) the kinetic energy is
    |y'|^2 / 2, so the motion is straight at constant speed, the configuration space
    {0 <= x1 <= x2} is the wedge between the ray B (x1 = x2) at angle
    alpha = atan2(sqrt M, sqrt m) and the ray A (x1 = 0) at pi/2, of angle
    theta = atan(sqrt(m/M)), and an elastic collision is a mirror reflection in its side
    (the impulse is along M^-1 n, perpendicular to the side in this metric).  Unfold: the
    path is the straight line y(t) = y0 + u t, u = (0, -sqrt(M) speed), which turns from
    the angle of y0 to -pi/2 and crosses the images of the sides at the angles
    phi_j = alpha - j theta, j = 0, 1, ... while phi_j > -pi/2: even j is an image of B
    (collision `meet`), odd j of A (`wall`).  So there are N = #{j >= 0: (j + 1) theta < pi}
    collisions, floor(pi / theta) unless pi / theta is an integer (31 for M/m = 100:
    pi / atan(0.1) = 31.52), and collision j happens when the line crosses its ray:
        t_j = -cross(y0, e_j) / cross(u, e_j),  e_j = (cos phi_j, sin phi_j),
    cross(a, b) = a1 b2 - a2 b1.  Folding back: after 2p collisions the velocity is u
    rotated by 2 p theta, after 2p + 1 it is u reflected in the line at alpha - p theta
    (the composition of the reflections); positions likewise fold y0 + u t."""
    with mp.workdps(DPS):
        m, big = (_mp(a) for a in scene["m"])
        x1, x2 = (_mp(a) for a in scene["x"])
        speed = -_mp(scene["v"][1])
        if scene["v"][0] != 0 or speed <= 0:
            raise ValueError("galperin_answer: the light body starts at rest, the heavy one moving left")
        sm, sb = mp.sqrt(m), mp.sqrt(big)
        alpha, theta = mp.atan2(sb, sm), mp.atan(sm / sb)
        y0, u = (sm * x1, sb * x2), (mpf(0), -sb * speed)

        def cross(a, b):
            return a[0] * b[1] - a[1] * b[0]

        def fold(c, vec):
            """The folding map after c collisions applied to a vector of the unfolded plane."""
            p = c // 2
            if c % 2 == 0:
                ang = 2 * p * theta
                return (mp.cos(ang) * vec[0] - mp.sin(ang) * vec[1], mp.sin(ang) * vec[0] + mp.cos(ang) * vec[1])
            ang = 2 * (alpha - p * theta)
            return (mp.cos(ang) * vec[0] + mp.sin(ang) * vec[1], mp.sin(ang) * vec[0] - mp.cos(ang) * vec[1])

        def velocities(c):
            w = fold(c, u)
            return (w[0] / sm, w[1] / sb)

        events, j = [], 0
        while alpha - j * theta > -mp.pi / 2:
            phi = alpha - j * theta
            e = (mp.cos(phi), mp.sin(phi))
            t = -cross(y0, e) / cross(u, e)
            events.append((t, "meet" if j % 2 == 0 else "wall", velocities(j), velocities(j + 1)))
            j += 1
        t_end = _mp(scene["t_end"])
        y = fold(j, (y0[0] + u[0] * t_end, y0[1] + u[1] * t_end))
        return dict(events=events, final=((y[0] / sm, y[1] / sb), velocities(j)))


def galperin_count(mass_ratio):
    """N = #{j >= 0 : (j + 1) atan(sqrt(1/ratio)) < pi}."""
    with mp.workdps(DPS):
        theta = mp.atan(1 / mp.sqrt(_mp(mass_ratio)))
        return int(mp.ceil(mp.pi / theta)) - 1


# --- equal masses and a wall ------------------------------------------------------------------

def equal_masses_wall(x=(1.0, 2.5, 3.25), v=(0.5, -0.25, -1.5), m=1.0, t_end=6.0):
    """Equal elastic bodies (three by default) on a frictionless line right of a wall at 0,
    x_1 < x_2 < ...; contacts `wall` (x1 >= 0) and `meet<i><i+1>` (x_{i+1} >= x_i)."""
    n = len(x)
    contacts = [dict(a=0, b=1, d_min=0.0, r_min=1.0, name="wall")]
    contacts += [dict(a=i, b=i + 1, d_min=0.0, r_min=1.0, name=f"meet{i}{i + 1}") for i in range(1, n)]
    return _scene([m] * n, x, v, contacts, t_end)


def equal_masses_wall_answer(scene):
    """Equal masses, elastic: a collision of two bodies exchanges their velocities, so the
    bodies' trajectories are those of free quasi-particles p_i(t) = x_i + v_i t passing
    through one another; the wall reflects, so the positions are the folded values |p_i(t)|
    and the body k-th from the wall is at the k-th smallest of them, with the velocity
    sign(p_i) v_i of its quasi-particle.  Events: a wall impact when a quasi-particle
    crosses 0, t = -x_i / v_i > 0; a collision when two folded values meet,
    p_i = p_j at t = (x_j - x_i) / (v_i - v_j) or p_i = -p_j at t = -(x_i + x_j) / (v_i + v_j)
    (t > 0, value there != 0), between the bodies of ranks k, k+1 that carry them (contact
    meet<k><k+1>).  The count is the number of such roots: a closed form (the scene must
    not have two events at one instant)."""
    with mp.workdps(DPS):
        x = [_mp(a) for a in scene["x"]]
        v = [_mp(a) for a in scene["v"]]
        n, t_end = len(x), _mp(scene["t_end"])

        def state(t):
            folded = sorted((abs(xi + vi * t), (1 if xi + vi * t >= 0 else -1) * vi) for xi, vi in zip(x, v))
            return [p for p, _ in folded], [w for _, w in folded]

        times = []
        for i in range(n):
            if v[i] != 0 and 0 < -x[i] / v[i] < t_end:
                times.append((-x[i] / v[i], "wall"))
            for j in range(i + 1, n):
                for t in ([(x[j] - x[i]) / (v[i] - v[j])] if v[i] != v[j] else []) + \
                         ([-(x[i] + x[j]) / (v[i] + v[j])] if v[i] + v[j] != 0 else []):
                    if 0 < t < t_end and x[i] + v[i] * t != 0:
                        times.append((t, None))
        times.sort()
        for (ta, _), (tb, _) in zip(times, times[1:]):
            if tb - ta < mpf(10) ** -30:
                raise ValueError("equal_masses_wall_answer: two events at one instant")
        events = []
        for j, (t, kind) in enumerate(times):
            t_before = times[j - 1][0] if j else mpf(0)
            t_after = times[j + 1][0] if j + 1 < len(times) else t_end
            before, after = state((t_before + t) / 2)[1], state((t + t_after) / 2)[1]
            if kind is None:
                pos = state(t)[0]
                k = min(range(n - 1), key=lambda r: pos[r + 1] - pos[r])
                kind = f"meet{k + 1}{k + 2}"
            events.append((t, kind, tuple(before), tuple(after)))
        xs, vs = state(t_end)
        return dict(events=events, final=(tuple(xs), tuple(vs)))


# --- the falling stack -------------------------------------------------------------------------

def falling_stack(m=(4.0, 2.0, 1.0), heights=(1.0, 1.25, 1.375), diameter=0.0, g=8.0,
                  r_floor=1.0, r_balls=(1.0, 1.0), t_end=None):
    """Three balls dropped from rest, ball 1 lowest, under gravity (a constant force -m_i g
    on each: the line is vertical), floor `floor` under ball 1 (x1 >= diameter / 2, i.e. the
    centre's height), contacts `b12`, `b23` (x_{i+1} - x_i >= diameter), frictionless.
    t_end None: halfway between the third impact and the next event."""
    radius = diameter / 2
    contacts = [dict(a=0, b=1, d_min=radius, r_min=r_floor, name="floor"),
                dict(a=1, b=2, d_min=diameter, r_min=r_balls[0], name="b12"),
                dict(a=2, b=3, d_min=diameter, r_min=r_balls[1], name="b23")]
    scene = _scene(list(m), list(heights), [0.0] * 3, contacts, t_end, f=[-a * g for a in m], g=g)
    if t_end is None:
        scene["t_end"] = float(falling_stack_answer(scene)["t_safe"])
    return scene


def _impact(m1, m2, v1, v2, r):
    """Newton's law on a pair: v1', v2' with v2' - v1' = -r (v2 - v1), momentum kept."""
    total = m1 + m2
    return (((m1 - r * m2) * v1 + (1 + r) * m2 * v2) / total,
            ((m2 - r * m1) * v2 + (1 + r) * m1 * v1) / total)


def falling_stack_answer(scene):
    """Every ball falls with the same acceleration -g, so before the first impact the gaps
    G12 = h2 - h1 - D and G23 = h3 - h2 - D stay constant and ball 1 reaches the floor
    (centre at R = D/2) at t1 = sqrt(2 (h1 - R) / g), at speed u = g t1; it leaves with
    r_f u.  Between two balls in free fall the relative acceleration is zero, so a gap
    changes linearly: ball 1 meets ball 2 at
        t2 = t1 + G12 / ((1 + r_f) u)           (closing speed r_f u + g t1),
    and after Newton's law on the pair (velocities v1', v2', momentum kept, relative
    velocity times -r12) ball 2 meets ball 3, still falling at -g t2, at
        t3 = t2 + G23 / (v2' + g t2).
    The answer holds when nothing else comes first: ball 1 back on the floor (the root of
    its parabola) before t2 or t3 (checked: ValueError), and every restitution above 0 (a
    plastic pair would go on as one, a persistent contact: not this answer); the pairs
    separate after their impacts and their gaps then grow linearly.  t_next is the first
    event after t3 in closed form: ball 1 on the floor, the root of
    x1(t3) + v1 s - g s^2 / 2 = R, or balls 1 and 2 meeting again (their relative motion is
    linear); t_safe = (t3 + t_next) / 2 is a t_end the answer covers.  The final state is at
    the scene's t_end, which must lie in (t3, t_next) (t_end None: at t_safe)."""
    with mp.workdps(DPS):
        m = [_mp(a) for a in scene["m"]]
        h = [_mp(a) for a in scene["x"]]
        g = _mp(scene["g"])
        floor, c12, c23 = scene["contacts"]
        radius, d = _mp(floor["d_min"]), _mp(c12["d_min"])
        rf, r12, r23 = (_mp(c["r_min"]) for c in (floor, c12, c23))
        if min(rf, r12, r23) <= 0:
            raise ValueError("falling_stack: every restitution must be above 0")
        t1 = mp.sqrt(2 * (h[0] - radius) / g)
        u = g * t1
        v_t1 = (-u, -u, -u)
        a1 = (rf * u, -u, -u)
        t2 = t1 + (h[1] - h[0] - d) / ((1 + rf) * u)
        if t2 - t1 >= 2 * rf * u / g:
            raise ValueError("falling_stack: ball 1 is back on the floor before ball 2 arrives")
        v1 = rf * u - g * (t2 - t1)
        x1_t2 = radius + rf * u * (t2 - t1) - g * (t2 - t1) ** 2 / 2
        b2 = (v1, -g * t2, -g * t2)
        w1, w2 = _impact(m[0], m[1], v1, -g * t2, r12)
        a2 = (w1, w2, -g * t2)
        t3 = t2 + (h[2] - h[1] - d) / (w2 + g * t2)
        x1_t3 = x1_t2 + w1 * (t3 - t2) - g * (t3 - t2) ** 2 / 2
        floor_back = _floor_time(x1_t2 - radius, w1, g)
        if floor_back <= t3 - t2:
            raise ValueError("falling_stack: ball 1 is back on the floor before balls 2 and 3 meet")
        b3 = (w1 - g * (t3 - t2), w2 - g * (t3 - t2), -g * t3)
        y2, y3 = _impact(m[1], m[2], b3[1], b3[2], r23)
        a3 = (b3[0], y2, y3)
        # next: ball 1 on the floor, or balls 1 and 2 (closing at b3[0] - y2, if positive)
        x2_t3 = h[1] - g * t2 ** 2 / 2 + w2 * (t3 - t2) - g * (t3 - t2) ** 2 / 2
        candidates = [t3 + _floor_time(x1_t3 - radius, b3[0], g)]
        gap12 = x2_t3 - x1_t3 - d
        if y2 - b3[0] < 0:
            candidates.append(t3 + gap12 / (b3[0] - y2))
        t_next = min(candidates)
        t_safe = (t3 + t_next) / 2
        events = [(t1, "floor", v_t1, a1), (t2, "b12", b2, a2), (t3, "b23", b3, a3)]
        t_end = t_safe if scene["t_end"] is None else _mp(scene["t_end"])
        if not t3 < t_end < t_next:
            raise ValueError("falling_stack: t_end outside (t3, t_next): the answer does not cover it")
        s = t_end - t3
        x3_t3 = h[2] - g * t3 ** 2 / 2
        final_x = tuple(x + w * s - g * s * s / 2 for x, w in zip((x1_t3, x2_t3, x3_t3), a3))
        final_v = tuple(w - g * s for w in a3)
        return dict(events=events, final=(final_x, final_v), t_next=t_next, t_safe=t_safe)


def _floor_time(height, v, g):
    """The positive root s of height + v s - g s^2 / 2 = 0 (height >= 0, g > 0)."""
    return (v + mp.sqrt(v * v + 2 * g * height)) / g


# --- the friction chain ---------------------------------------------------------------------------

def friction_chain(n=8, push=None, ramp=8.0, m=1.0, mu=0.25, mus=(0.5, 0.375, 0.625, 0.5, 0.75, 0.5, 0.375, 0.5),
                   g=8.0, length=0.5, t_end=None):
    """n touching blocks (block i at (i - 1) length, contacts `c<i><i+1>`: x_{i+1} - x_i >=
    length, r = 0), kinetic mu, static mus_i > mu, pushed on block 1 toward the others by a
    constant force `push`, or (push None) by a ramp ramp * t (a two-corner table; t_end None:
    a second after the break-away).  mus is repeated to n values."""
    x = [i * length for i in range(n)]
    contacts = [dict(a=i, b=i + 1, d_min=length, r_min=0.0, name=f"c{i}{i + 1}") for i in range(1, n)]
    mus = [mus[i % len(mus)] for i in range(n)]
    if push is not None:
        scene = _scene([m] * n, x, [0.0] * n, contacts, t_end or 1.0, f=[push] + [0.0] * (n - 1),
                       mu=[mu] * n, mus=mus, g=g)
    else:
        horizon = 1024.0
        table = ([0.0, horizon], [0.0, ramp * horizon])
        scene = _scene([m] * n, x, [0.0] * n, contacts, 1.0, mu=[mu] * n, mus=mus, g=g,
                       f_table=[table] + [None] * (n - 1))
        if t_end is None:
            t_end = float(friction_chain_answer(scene)["t_break"] + 1)
        scene["t_end"] = t_end
    return scene


def friction_chain_answer(scene):
    """Blocks touching in a row with static bounds s_i = mus_i m_i g > sliding c_i = mu_i m_i g,
    pushed on block 1 by F(t) >= 0.  While all are at rest the contact forces are not fixed
    by the motion (statically indeterminate); the balance of blocks 1..k fixes
    lambda_k = F - (F_1 + ... + F_k) >= F - S_k, S_k = s_1 + ... + s_k, and the least-force
    distribution (the one exact_nbody holds to, module docstring) is
    lambda_k = max(0, F - S_k): the first blocks hold up to their static bound, the load
    goes on to the next.  So the chain holds as long as F <= S_n, whatever the order of the
    bounds, and contact c<k><k+1> carries load exactly while F > S_k.
    - Constant F <= S_n: nothing moves; the contacts with F > S_k are held from t = 0
      (rest_ at t = 0), no other event.
    - Constant F > S_n: every block breaks away at t = 0 (no slip is logged at t = 0) and
      the chain slides as one, a = (F - C) / M (C = sum c_i, M = sum m_i): each contact
      pushes the blocks ahead, lambda_k = sum_{i>k} (m_i a + c_i) > 0, so all are held from
      t = 0 and the chain never parts; x_i = x_i(0) + a t^2 / 2.
    - Ramp F = K t: the load front reaches contact k at t_k = S_k / K (rest_c<k><k+1>), and
      at t_n = S_n / K all blocks break away together (slip1 ... slip<n>), not one by one:
      the static bound of each is exhausted at that instant and the kinetic bounds are
      below; after it a(t) = (K t - C) / M > 0 (it jumps to (S_n - C) / M), and
      x_i = x_i(0) + ((S_n - C) s^2 / 2 + K s^3 / 6) / M, s = t - t_n."""
    with mp.workdps(DPS):
        m = [_mp(a) for a in scene["m"]]
        g = _mp(scene["g"])
        n = len(m)
        s = [_mp(b) * a * g for a, b in zip(m, scene["mus"])]
        c = [_mp(b) * a * g for a, b in zip(m, scene["mu"])]
        big_s = [sum(s[:k + 1]) for k in range(n)]
        total_m, total_c = sum(m), sum(c)
        x0 = [_mp(a) for a in scene["x"]]
        t_end = _mp(scene["t_end"])
        names = [f"c{k}{k + 1}" for k in range(1, n)]
        table = (scene.get("f_table") or [None])[0]
        if table is None:
            push = _mp(scene["f"][0])
            rest = tuple(mpf(0) for _ in range(n))
            if push <= big_s[-1]:
                events = [(mpf(0), "rest_" + names[k], rest, rest) for k in range(n - 1) if push > big_s[k]]
                return dict(events=events, final=(tuple(x0), rest), t_break=None)
            a = (push - total_c) / total_m
            events = [(mpf(0), "rest_" + name, rest, rest) for name in names]
            return dict(events=events, t_break=mpf(0),
                        final=(tuple(x + a * t_end ** 2 / 2 for x in x0), tuple(a * t_end for _ in x0)))
        times, values = table
        ramp = (_mp(values[1]) - _mp(values[0])) / (_mp(times[1]) - _mp(times[0]))
        rest = tuple(mpf(0) for _ in range(n))
        events = [(big_s[k] / ramp, "rest_" + names[k], rest, rest) for k in range(n - 1)]
        t_break = big_s[-1] / ramp
        events += [(t_break, f"slip{i + 1}", rest, rest) for i in range(n)]
        span = max(t_end - t_break, mpf(0))
        shift = ((big_s[-1] - total_c) * span ** 2 / 2 + ramp * span ** 3 / 6) / total_m
        speed = ((big_s[-1] - total_c) * span + ramp * span ** 2 / 2) / total_m
        return dict(events=events, t_break=t_break,
                    final=(tuple(x + shift for x in x0), tuple(speed for _ in x0)))


# --- random N-body scenes -----------------------------------------------------------------------------

# --- a chain of impacts ---------------------------------------------------------------------------

def bouncing_chain(t_end=4.0):
    """Five bodies (masses 1, 2, 0.5, 1.5, 1) a metre apart, diameter 0.25 (contacts n<i><i+1>,
    restitutions 1, 0.5, 0.75, 1), a wall `left` at x1 >= -1 (r = 1) and `right` at x5 <= 5
    (r = 0.5), no friction, no forces: a sequence of isolated impacts (two at once, on
    separate pairs, at t = 0.375), none of them pressed shut, so a fixed-step scheme that
    sees each impact a step late converges on it."""
    m = [1.0, 2.0, 0.5, 1.5, 1.0]
    r = [1.0, 0.5, 0.75, 1.0]
    contacts = [dict(a=i, b=i + 1, d_min=0.25, r_min=r[i - 1], name=f"n{i}{i + 1}") for i in range(1, 5)]
    contacts += [dict(a=0, b=1, d_min=-1.0, r_min=1.0, name="left"),
                 dict(a=0, b=5, d_max=5.0, r_max=0.5, name="right")]
    return _scene(m, [0.0, 1.0, 2.0, 3.0, 4.0], [2.0, 0.0, -1.0, 0.5, -1.5], contacts, t_end)


RESTITUTIONS = (0.0, 0.3, 0.7, 1.0)


def random_scene(seed, n=None):
    """A random N-body scene (N from 3 to 12 unless given): masses, friction on about half
    the bodies (static >= sliding, sometimes above), constant forces of both signs, gaps
    between neighbours (sometimes closed), neighbour contacts with lower limits and some
    with upper ones (slots), walls on the first and last bodies, a stop on a middle body,
    restitutions 0, 0.3, 0.7, 1 or random.  Numbers are rounded to binary fractions (1/64)
    so a closed gap is exactly closed.  Initial states lie inside every limit."""
    rng = random.Random(seed)

    def q(value, step=64):
        return round(value * step) / step

    n = n or rng.randint(3, 12)
    m = [q(rng.uniform(0.5, 3.0)) for _ in range(n)]
    mu = [q(rng.uniform(0.05, 0.4)) if rng.random() < 0.5 else 0.0 for _ in range(n)]
    mus = [a + (q(rng.uniform(0.0, 0.2)) if rng.random() < 0.5 else 0.0) for a in mu]
    g = 9.8125
    f = [q(rng.uniform(-12.0, 12.0)) if rng.random() < 0.7 else 0.0 for _ in range(n)]
    v = [q(rng.uniform(-3.0, 3.0)) for _ in range(n)]

    def restitution():
        return RESTITUTIONS[rng.randrange(4)] if rng.random() < 0.8 else q(rng.uniform(0.05, 0.95))

    x, contacts = [0.0], []
    for i in range(1, n):
        d = q(rng.uniform(0.1, 0.5))
        gap = 0.0 if rng.random() < 0.15 else q(rng.uniform(0.05, 0.6))
        x.append(x[-1] + d + gap)
        rec = dict(a=i, b=i + 1, d_min=d, r_min=restitution(), name=f"n{i}{i + 1}")
        if rng.random() < 0.3:
            rec.update(d_max=d + gap + q(rng.uniform(0.05, 0.5)), r_max=restitution())
        contacts.append(rec)
    if rng.random() < 0.7:
        contacts.append(dict(a=0, b=1, d_min=x[0] - q(rng.uniform(0.0625, 1.0)), r_min=restitution(),
                             name="left"))
    if rng.random() < 0.7:
        contacts.append(dict(a=0, b=n, d_max=x[-1] + q(rng.uniform(0.0625, 1.0)), r_max=restitution(),
                             name="right"))
    if rng.random() < 0.5:
        i = rng.randint(2, n - 1)
        contacts.append(dict(a=0, b=i, d_min=x[i - 1] - q(rng.uniform(0.1, 0.8)), r_min=restitution(),
                             name=f"stop{i}"))
    return _scene(m, x, v, contacts, q(rng.uniform(1.0, 2.5), 16), f=f, mu=mu, mus=mus, g=g)
