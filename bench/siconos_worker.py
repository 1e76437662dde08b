"""The Siconos side of the Siconos peer study (bench/siconos_peer.py).

Runs under the system interpreter that has Debian's python3-siconos (/usr/bin/python3),
never inside the project's venv, and imports nothing from the project. The study starts
it once and keeps it running, so that neither interpreter start-up nor `import siconos`
is counted, and sends it one run at a time, alternating with impact1d's runs.

Protocol (one JSON object per line, on the worker's stdout; whatever Siconos itself prints
goes to stderr): the worker first prints
    {"ready": true, "siconos": "<version>"}
then answers each request line
    {"scene": {m1, m2, f1, f2, x1, v1, x2, v2, x_left, r_left, x_right, r_right,
               d_min, r_min, d_max, r_max, t_end},
     "scheme": "event_driven" | "moreau_jean", "dt": h,
     "rtol": .., "atol": .. (LsodarOSI), "theta": .. (MoreauJeanOSI),
     "loop": "rows" | "kernel", "rows": true|false}
with
    {"seconds": wall time of the run, "final": [x1, v1, x2, v2], "steps": steps taken,
     "rows": [[t, x1, v1, x2, v2, p_left, p_right, p_slot_min, p_slot_max, flag], ...]}
("steps" for the "rows" loop, "rows" only when asked), or {"error": message}.

A run is what a Siconos user writes: build the model (one 2-dof LagrangianLinearTIDS,
four LagrangianLinearTIR + NewtonImpactNSL interactions), then either the Python loop of
the Siconos tutorials, storing one row per step into a numpy array (time, state and each
contact's impulse lambda(1); flag 1 for a step, a time-discretisation event, and 2 for a
nonsmooth event of the event-driven scheme, its row holding the post-impact state), or
Siconos' own C++ loop, simulation.run(), which stores nothing.
"""

import json
import os
import sys
import time

import numpy as np

import siconos.kernel as sk

# Contact name, gap y = H q + b with q = (x1, x2): H and the sign of the limit in b;
# the restitution field. The same four constraints as impact1d (README 'Inputs').
CONTACTS = (("left", (1.0, 0.0), -1.0, "x_left", "r_left"),
            ("right", (0.0, -1.0), 1.0, "x_right", "r_right"),
            ("slot_min", (-1.0, 1.0), -1.0, "d_min", "r_min"),
            ("slot_max", (1.0, -1.0), 1.0, "d_max", "r_max"))

STEP, NONSMOOTH = 1.0, 2.0           # row flags
NS_EVENT_TYPE = 2                     # EventsManager: 1 time-discretisation, 2 nonsmooth
COLUMNS = 10


def build(scene):
    """The scene as a Siconos nonsmooth dynamical system: (ds, nsds, interactions)."""
    ds = sk.LagrangianLinearTIDS([scene["x1"], scene["x2"]], [scene["v1"], scene["v2"]],
                                 np.diag([scene["m1"], scene["m2"]]))
    ds.setFExtPtr([scene["f1"], scene["f2"]])
    nsds = sk.NonSmoothDynamicalSystem(0.0, scene["t_end"])
    nsds.insertDynamicalSystem(ds)
    interactions = []
    for _, normal, sign, limit, restitution in CONTACTS:
        relation = sk.LagrangianLinearTIR(np.array([normal]), np.array([sign * scene[limit]]))
        inter = sk.Interaction(sk.NewtonImpactNSL(scene[restitution]), relation)
        nsds.link(inter, ds)
        interactions.append(inter)
    return ds, nsds, interactions


def _impulses(interactions):
    out = []
    for inter in interactions:
        lam = inter.lambda_(1)
        out.append(0.0 if lam is None else float(lam[0]))
    return out


def event_driven(scene, dt, rtol, atol):
    """Siconos' event-driven scheme: LSODAR between events, LCPs at impacts and for the
    contact accelerations; it stops at every multiple of dt (and at each event)."""
    ds, nsds, interactions = build(scene)
    osi = sk.LsodarOSI()
    osi.setTol(1, rtol, atol)                 # itol = 1: scalar rtol and atol
    simulation = sk.EventDriven(nsds, sk.TimeDiscretisation(0.0, dt))
    simulation.insertIntegrator(osi)
    simulation.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_IMPACT)
    simulation.insertNonSmoothProblem(sk.LCP(), sk.SICONOS_OSNSP_ED_SMOOTH_ACC)
    return ds, interactions, simulation


def moreau_jean(scene, dt, theta):
    """Moreau-Jean time stepping: one velocity-level LCP per step of dt."""
    ds, nsds, interactions = build(scene)
    simulation = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, dt),
                                 sk.MoreauJeanOSI(theta), sk.LCP())
    return ds, interactions, simulation


def event_driven_rows(ds, interactions, simulation, capacity):
    events = simulation.eventsManager()
    q, v = ds.q(), ds.velocity()
    rows = np.empty((capacity, COLUMNS))
    k = 0
    while simulation.hasNextEvent():
        simulation.advanceToEvent()
        nonsmooth = events.nextEvent().getType() == NS_EVENT_TYPE
        simulation.processEvents()
        if k == len(rows):
            rows = np.concatenate([rows, np.empty_like(rows)])
        rows[k, :5] = simulation.startingTime(), q[0], v[0], q[1], v[1]
        rows[k, 5:9] = _impulses(interactions) if nonsmooth else 0.0
        rows[k, 9] = NONSMOOTH if nonsmooth else STEP
        k += 1
    return rows[:k]


def time_stepping_rows(ds, interactions, simulation, capacity):
    q, v = ds.q(), ds.velocity()
    rows = np.empty((capacity, COLUMNS))
    k = 0
    while simulation.hasNextEvent():
        simulation.computeOneStep()
        if k == len(rows):
            rows = np.concatenate([rows, np.empty_like(rows)])
        rows[k, :5] = simulation.nextTime(), q[0], v[0], q[1], v[1]
        rows[k, 5:9] = _impulses(interactions)
        rows[k, 9] = STEP
        k += 1
        simulation.nextStep()
    return rows[:k]


def run(request):
    """One timed run. loop "rows": the Python loop storing a row per step (and event);
    loop "kernel": Siconos' own C++ loop, simulation.run(), nothing stored but the final
    state."""
    scene, dt = request["scene"], float(request["dt"])
    scheme, loop = request["scheme"], request.get("loop", "rows")
    start = time.perf_counter()
    if scheme == "event_driven":
        ds, interactions, simulation = event_driven(scene, dt, float(request["rtol"]),
                                                    float(request["atol"]))
        stepper = event_driven_rows
    elif scheme == "moreau_jean":
        ds, interactions, simulation = moreau_jean(scene, dt, float(request["theta"]))
        stepper = time_stepping_rows
    else:
        raise ValueError(f"unknown scheme {scheme!r}")
    rows = None
    if loop == "kernel":
        simulation.run()
    else:
        rows = stepper(ds, interactions, simulation, 2 * int(scene["t_end"] / dt) + 16)
    seconds = time.perf_counter() - start
    q, v = ds.q(), ds.velocity()
    answer = {"seconds": seconds,
              "final": [float(q[0]), float(v[0]), float(q[1]), float(v[1])]}
    if rows is not None:
        answer["steps"] = int(np.count_nonzero(rows[:, 9] == STEP))
        if request.get("rows"):
            answer["rows"] = rows.tolist()
    return answer


def _version():
    import siconos
    return str(getattr(siconos, "version", "unknown"))


def main():
    # The protocol gets its own descriptor; the kernel's own messages (simulation.run()
    # prints a banner on C++ std::cout) go to stderr with everything else on fd 1.
    protocol = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    protocol.write(json.dumps({"ready": True, "siconos": _version()}) + "\n")
    protocol.flush()
    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            answer = run(json.loads(line))
        except Exception as exc:          # report it to the study, keep serving
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        protocol.write(json.dumps(answer) + "\n")
        protocol.flush()


if __name__ == "__main__":
    main()
