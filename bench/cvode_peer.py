"""SUNDIALS CVODE as a measured peer (docs/performance.md and docs/accuracy.md, 'CVODE'
sections).

CVODE with its root finding, in compiled C, is the strongest tool a user would pick
instead of impact1d for a short run: bench/cvode_peer.c is the event-restart loop (the
four gaps as root functions, Newton restitution by sequential impulses at a root,
CVodeReInit, on to t_end; Adams with fixed-point iteration), built here with `cc` against
Debian's libsundials-dev (`make bench` installs it with apt-get when missing) into
build/bench/. Both frictionless seed scenes under constant forces: case 3 (41 impacts in
6 s) and case 5 (pushed into both walls, r = 0.5: the impacts accumulate at t = 3).

Accuracy: every rtol of RTOLS (atol = rtol * 1e-3, as for SciPy and LSODAR in the other
studies) against the closed-form references of bench/common.py; the run compared is, of
the rtols whose event-time error is within TARGET_EVENT_ERROR with every impact of the
reference seen, the fastest (else the most accurate). Case 5 also: how much of the accumulating series
the plain loop resolves, what it does next and what that costs.

Timing at equal output (the events and the final state): impact1d's
`simulate(scene, dt=0.1, dt_out=t_end)` (event times exact to rounding at any dt on these
polynomial scenes) timed here, CVODE's run loop timed inside the C program (no process
start-up), and the same impact1d run without Python: bench/core_run.f90 linked against the
meson build's core library (build/py/libimpact1d_core.a, its module files in meson's
private folder beside it: the build does not install or export the library, the bench
reaches into the build folder). Each measure is the mean per run of a batch of RUNS runs,
the best of BATCHES batches; ROUNDS rounds interleave the three, rotating which goes first;
the doc gives the best of the rounds and the median of the per-round ratios.

    python bench/cvode_peer.py [--rounds N]      # -> bench/results/cvode.json
"""

from __future__ import annotations

import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import impact1d

import common

SOURCE = common.BENCH / "cvode_peer.c"
CORE_SOURCE = common.BENCH / "core_run.f90"
BUILD = common.REPO / "build" / "bench"
# The Makefile's BUILDDIR: the meson build that `make setup` installs the package from.
CORE_BUILD = Path(os.environ.get("IMPACT1D_BUILDDIR", common.REPO / "build" / "py"))
CVODE_HEADER = Path("/usr/include/cvode/cvode.h")
CC_FLAGS = ["-O2"]
CVODE_LIBS = ["-lsundials_cvode", "-lsundials_nvecserial", "-lm"]
# meson's flags for the core (buildtype=release, b_lto, meson.build's project arguments).
CORE_FLAGS = ["-O3", "-flto=auto", "-fno-semantic-interposition", "-frecursive", "-pthread"]

CASES = ("case3", "case5")
RTOLS = tuple(10.0 ** -k for k in range(6, 15))
TARGET_EVENT_ERROR = 1e-12          # the "event times within ~1e-12 s"
OUR_DT = 0.1                        # impact1d's step in the timed runs (exact at any dt here)
ROUNDS = 7
BATCHES = 5
RUNS = {"case3": 200, "case5": 20}  # runs per batch: a batch takes a few ms to tens of ms
SWEEP_TIMING = (3, 5)               # batches, runs per rtol in the tolerance sweep (rough)
WALLS = ("left", "right")
SCENE_FIELDS = ("m1", "m2", "x1", "x2", "x_left", "r_left", "x_right", "r_right",
                "d_min", "r_min", "d_max", "r_max", "t_end")


# ----------------------------------------------------------------------------- builds
def _compile(cmd, what):
    """Run a compiler; None when it worked, else why not (the last lines it printed)."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as exc:
        return f"{what}: {exc}"
    if proc.returncode != 0:
        tail = " ".join(proc.stderr.strip().splitlines()[-3:])
        return f"`{' '.join(cmd)}` failed: {tail}"
    return None


def build_cvode() -> dict:
    """build/bench/cvode_peer from bench/cvode_peer.c: {'available', 'exe' or 'reason'}."""
    if not CVODE_HEADER.exists():
        return {"available": False, "reason": f"{CVODE_HEADER} is missing (libsundials-dev "
                                              "is not installed)"}
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return {"available": False, "reason": "no C compiler (cc) on PATH"}
    BUILD.mkdir(parents=True, exist_ok=True)
    exe = BUILD / "cvode_peer"
    why = _compile([cc, *CC_FLAGS, "-o", str(exe), str(SOURCE), *CVODE_LIBS], "cc")
    if why:
        return {"available": False, "reason": why}
    info = {"available": True, "exe": str(exe), "compile": " ".join(
        ["cc", *CC_FLAGS, "bench/cvode_peer.c", *CVODE_LIBS])}
    try:
        info["package"] = subprocess.run(
            ["dpkg-query", "-W", "-f", "${Version}", "libsundials-dev"],
            capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        info["package"] = "not a Debian package"
    return info


def build_core(source=CORE_SOURCE, name="core_run") -> dict:
    """build/bench/<name> from `source` (bench/core_run.f90) and the meson build's core library."""
    lib = CORE_BUILD / "libimpact1d_core.a"
    mods = CORE_BUILD / "libimpact1d_core.a.p"
    if not lib.exists() or not (mods / "impact1d_solver.mod").exists():
        return {"available": False, "reason": f"{lib} or its module files are missing (run "
                                              "`make setup` first)"}
    BUILD.mkdir(parents=True, exist_ok=True)
    exe = BUILD / name
    why = _compile(["gfortran", *CORE_FLAGS, f"-I{mods}", f"-J{BUILD}", "-o", str(exe),
                    str(source), str(lib)], "gfortran")
    if why:
        return {"available": False, "reason": why}
    return {"available": True, "exe": str(exe)}


# ----------------------------------------------------------------------------- runs
def scene_args(scene) -> list:
    """The C program's name=value arguments; refuses what it does not model."""
    if (scene.mu1 or 0.0) or (scene.mu2 or 0.0):
        raise ValueError("the CVODE model here is frictionless")
    springs = (scene.k1, scene.k2, scene.k12, scene.c1, scene.c2, scene.c12)
    if (scene.f1_table or scene.f2_table or scene.f1_amp or scene.f2_amp
            or any(x is not None for x in springs)):
        raise ValueError("the CVODE model here has constant forces only")
    values = {name: float(getattr(scene, name)) for name in SCENE_FIELDS}
    values.update(v1=float(scene.v1 or 0.0), v2=float(scene.v2 or 0.0),
                  f1=float(scene.f1 or 0.0), f2=float(scene.f2 or 0.0))
    return [f"{k}={v!r}" for k, v in values.items()]


def run_cvode(exe, scene, rtol, batches=0, runs=0) -> dict:
    cmd = [exe, *scene_args(scene), f"rtol={rtol!r}", f"atol={rtol * 1e-3!r}",
           f"batches={batches}", f"runs={runs}"]
    out = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    out["events"] = [(float(t), k) for t, k in out["events"]]
    return out


def run_core(exe, name, scene, batches, runs) -> dict:
    cmd = [exe, str(common.SCENE_FILES[name]), repr(OUR_DT), repr(scene.t_end),
           str(batches), str(runs)]
    out = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    out["events"] = [(float(t), k) for t, k in out["events"]]
    return out


def ours(scene):
    return impact1d.simulate(scene, dt=OUR_DT, dt_out=scene.t_end)


def time_python(scene, batches, runs) -> float:
    """Best over batches of the mean time per call of `simulate(dt=0.1, dt_out=t_end)`."""
    best = math.inf
    for _ in range(batches):
        start = time.perf_counter()
        for _ in range(runs):
            ours(scene)
        best = min(best, (time.perf_counter() - start) / runs)
    return best


# ----------------------------------------------------------------------------- accuracy
def _accuracy(events, final, ref) -> dict:
    """Impacts logged, event-time error (ref's window), final-state error."""
    impacts = [e for e in events if e[1] in common.IMPACT_KINDS]
    err, shared = common.event_time_error(impacts, ref)
    return {"impacts": len(impacts), "event_error": err, "shared_events": shared,
            "final": [float(x) for x in final],
            "final_error": common.final_state_error(final, ref)}


def _series(events, scene) -> dict:
    """Case 5's accumulating series as the run saw it. Per wall: the impacts in a row from
    the first whose time is within 1 % of the time left to t = 3 (t_n = 3 - 2^(2-n): the
    series itself, not a neighbour of it), the time of the last of them, and the last impact
    logged at all. Then the state at t_end: each body's depth beyond its wall, and when it
    crossed it (t_end - |v| / |a|: it left the wall at rest to rounding, pushed at |a|)."""
    out = {}
    for i, wall in enumerate(WALLS):
        times = [t for t, k in events if k == wall]
        resolved = 0
        for n, t in enumerate(times, start=1):
            left = 2.0 ** (2 - n)
            if abs(t - (3.0 - left)) > 0.01 * left:
                break
            resolved = n
        out[wall] = {"impacts": len(times), "resolved": resolved,
                     "t_last_resolved": times[resolved - 1] if resolved else None,
                     "t_last": times[-1] if times else None}
    return out


def _beyond(final, scene) -> dict:
    """{wall: (depth beyond it at t_end, estimated crossing time)}; depth <= 0: not beyond."""
    x1, v1, x2, v2 = final
    a = (scene.f1 / scene.m1, scene.f2 / scene.m2)
    depth = (scene.x_left - x1, x2 - scene.x_right)
    speed = (abs(v1), abs(v2))
    return {w: {"depth": depth[i],
                "t_cross": scene.t_end - speed[i] / abs(a[i]) if depth[i] > 0 else None}
            for i, w in enumerate(WALLS)}


def tolerance_sweep(exe, name, scene, ref) -> list:
    rows = []
    for rtol in RTOLS:
        res = run_cvode(exe, scene, rtol, *SWEEP_TIMING)
        row = {"rtol": rtol, "atol": rtol * 1e-3, **_accuracy(res["events"], res["final"], ref)}
        row.update({k: res[k] for k in ("steps", "rhs_evals", "root_evals", "restarts",
                                        "empty_roots", "warnings", "stop_reason",
                                        "t_stopped")})
        row["seconds"] = res["reused_best_s"]
        if name == "case5":
            row["series"] = _series(res["events"], scene)
            row["beyond"] = _beyond(res["final"], scene)
        rows.append(row)
    return rows


def choose(rows, n_ref_impacts):
    """Of the rtols whose event-time error is within TARGET_EVENT_ERROR and which see every
    impact the reference has (within its window), the fastest in the sweep (not always the
    loosest: on case 5 a looser rtol finds more spurious roots); else the most accurate."""
    good = [r for r in rows if r["event_error"] <= TARGET_EVENT_ERROR
            and r["shared_events"] >= n_ref_impacts]
    if good:
        return min(good, key=lambda r: r["seconds"])
    return min(rows, key=lambda r: (r["event_error"], -r["rtol"]))


# ----------------------------------------------------------------------------- timing
def timing_rounds(cvode_exe, core_exe, name, scene, rtol, rounds) -> dict:
    """ROUNDS rounds of the three measures, rotating which goes first; each the best of
    BATCHES batches' mean per run."""
    runs = RUNS[name]

    def cvode():
        res = run_cvode(cvode_exe, scene, rtol, BATCHES, runs)
        return {"cvode": res["reused_best_s"], "cvode_fresh": res["fresh_best_s"]}

    def python():
        return {"impact1d": time_python(scene, BATCHES, runs)}

    def core():
        return {"core": run_core(core_exe, name, scene, BATCHES, runs)["best_s"]} if core_exe else {}

    measures = (cvode, python, core)
    python()                                           # warm-up
    per_round = []
    for i in range(rounds):
        row = {}
        for k in range(len(measures)):
            row.update(measures[(i + k) % len(measures)]())
        per_round.append(row)
    tools = per_round[0].keys()
    best = {tool: min(r[tool] for r in per_round) for tool in tools}
    ratios = {tool: statistics.median(r[tool] / r["impact1d"] for r in per_round)
              for tool in tools}
    return {"rounds": rounds, "batches": BATCHES, "runs": runs, "per_round": per_round,
            "best_s": best, "ratio_of_best": {t: best[t] / best["impact1d"] for t in tools},
            "median_ratio": ratios}


# ----------------------------------------------------------------------------- study
def study_case(cvode_exe, core_exe, name, rounds) -> dict:
    scene = common.load(name)
    ref = common.reference(name, scene)
    ref_impacts = [e for e in ref.events if e[1] in common.IMPACT_KINDS
                   and (ref.window is None or e[0] <= ref.window)]
    sweep = tolerance_sweep(cvode_exe, name, scene, ref)
    chosen = choose(sweep, len(ref_impacts))
    res = ours(scene)
    out = {"label": common.SCENE_SHORT[name], "reference": ref.how, "window": ref.window,
           "t_end": scene.t_end, "reference_impacts": len(ref_impacts), "sweep": sweep,
           "rtol": chosen["rtol"], "atol": chosen["atol"], "cvode": chosen,
           "impact1d": {**_accuracy(common.events_of(res), common.final_state(res), ref),
                        "steps": int(res.steps), "dt": OUR_DT,
                        "events": len(res.events["t"])}}
    if core_exe:
        core = run_core(core_exe, name, scene, 1, 1)
        out["core_same_output"] = (core["events"] == common.events_of(res)
                                   and core["final"] == list(common.final_state(res)))
    out["timing"] = timing_rounds(cvode_exe, core_exe, name, scene, chosen["rtol"], rounds)
    return out


def run(rounds=ROUNDS) -> dict:
    info = build_cvode()
    core = build_core()
    info["core"] = core
    if info["available"]:
        info["rounds"] = rounds
        info["sundials"] = run_cvode(info["exe"], common.load("case3"), RTOLS[0])["sundials"]
        for name in CASES:
            print(f"  cvode peer: {name} ...", flush=True)
            info[name] = study_case(info["exe"], core.get("exe"), name, rounds)
    else:
        print(f"  CVODE is not available: {info['reason']}", flush=True)
    # The executables' paths are this machine's: not kept in the results.
    common.save_json("cvode", {**info, "exe": None, "core": {**core, "exe": None}})
    return info


# ----------------------------------------------------------------------------- docs
def _unavailable(res) -> str:
    reason = res.get("reason", "bench/results/cvode.json is missing (the comparison was not "
                               "run)")
    return (f"CVODE was not compared in this run: {reason}. `make bench` installs it on "
            "Debian and Ubuntu (`apt-get install libsundials-dev`) and compiles "
            "bench/cvode_peer.c with `cc` into build/bench/.")


def _version_line(res) -> str:
    return (f"SUNDIALS CVODE {res['sundials']} from the package libsundials-dev "
            f"{res['package']}, compiled C (`{res['compile']}`)")


def _us(seconds) -> str:
    return f"{seconds * 1e6:.1f} us" if seconds < 1e-3 else f"{seconds * 1e3:.2f} ms"


def _accumulation(c5, tool) -> str:
    """What a tool does at case 5's accumulation point, in a table cell."""
    if tool in ("impact1d", "core"):
        return "resolves the series to rounding, both bodies at rest at t = 3, on to t_end"
    cv = c5["cvode"]
    s, b = cv["series"], cv["beyond"]
    crossed = [b[w]["t_cross"] for w in WALLS if b[w]["t_cross"] is not None]
    out = (f"follows the series for {s['left']['resolved']} impacts on the left wall and "
           f"{s['right']['resolved']} on the right (to t = "
           f"{min(s[w]['t_last_resolved'] for w in WALLS):.9f}), then finds "
           f"{cv['empty_roots']} roots with no impact")
    if crossed:
        depth = max(b[w]["depth"] for w in WALLS)
        out += (f"; the bodies pass through the walls (about t = {min(crossed):.9f}) and "
                f"end {depth:.3g} m beyond them")
    if cv["stop_reason"] == "t_end reached":
        return out + "; the loop runs on to t_end"
    return out + f"; the loop stops on its bound ({cv['stop_reason']})"


def performance_section(res, perf=None, siconos=None) -> str:
    out = ["## CVODE as a peer (the headline ratio; cases 3 and 5)", ""]
    if not res or not res.get("available"):
        return "\n".join(out + [_unavailable(res or {}), ""])
    c3, c5 = res["case3"], res["case5"]
    t3 = c3["timing"]
    core = res["core"]
    labels = {"impact1d": "impact1d `simulate(scene, dt=0.1, dt_out=t_end)` (Python)",
              "core": "impact1d core without Python (bench/core_run.f90)",
              "cvode": "CVODE loop, memory reused (CVodeReInit per run)",
              "cvode_fresh": "CVODE loop, memory made per run (CVodeCreate ... CVodeFree)"}
    rows = []
    for name, c in (("case 3", c3), ("case 5", c5)):
        tm = c["timing"]
        for tool in ("impact1d", "core", "cvode", "cvode_fresh"):
            if tool not in tm["best_s"]:
                continue
            acc = c["impact1d" if not tool.startswith("cvode") else "cvode"]
            rows.append([name, labels[tool], _us(tm["best_s"][tool]),
                         f"**{tm['ratio_of_best'][tool]:.2f}x**",
                         f"{tm['median_ratio'][tool]:.2f}x", common.fmt(acc["event_error"]),
                         common.fmt(acc["final_error"]),
                         _accumulation(c5, tool) if name == "case 5" else "-"])
    cv3, cv5 = c3["cvode"], c5["cvode"]
    out += [
        f"{_version_line(res)}: bench/cvode_peer.c, the event-restart loop a CVODE user "
        "writes. The state (x1, v1, x2, v2) under the scene's constant forces, Adams with "
        "fixed-point iteration (CVODE's choice for a nonstiff problem); the four gaps are "
        "its root functions (direction: closing); at a root, Newton restitution by "
        "sequential impulses (docs/method.md section 4: the most approaching closed contact "
        "first), then CVodeReInit from the state after the impacts, on to t_end. "
        f"Tolerances: of the rtols (atol = rtol * 1e-3) whose event times are within "
        f"{TARGET_EVENT_ERROR:g} s of the exact ones with every impact seen, the one that "
        "ran fastest in the tolerance sweep: case 3 rtol = "
        f"{c3['rtol']:g} ({cv3['steps']} steps, {cv3['rhs_evals']} right-hand-side and "
        f"{cv3['root_evals']} root-function evaluations, {cv3['restarts']} restarts), case 5 "
        f"rtol = {c5['rtol']:g} (within t <= {c5['window']} s). Every rtol from "
        f"{RTOLS[0]:g} to {RTOLS[-1]:g} is in docs/accuracy.md.",
        "",
        "How it was measured: equal output, the events and the final state (the CVODE "
        "program keeps its events in an array and its final state; impact1d returns them "
        "and its two samples, at 0 and t_end). Each time is the mean per run of a batch "
        f"({t3['runs']} runs on case 3, {c5['timing']['runs']} on case 5), the best of "
        f"{t3['batches']} batches: CVODE's run loop timed inside the C program "
        "(`clock_gettime`, after a first untimed run: no process start-up, no set-up but "
        "what a run does), `impact1d.simulate` timed here (`time.perf_counter`, scene "
        "already loaded), and the same impact1d run without Python, bench/core_run.f90: "
        "per run the flat API's work in Fortran (the checked scene built from the input, a "
        "memory sink, `run`), linked against the meson build's core library "
        "(build/py/libimpact1d_core.a, with the release build's flags; meson does not "
        "install or export that library, the bench compiles against its build folder"
        + ("" if core.get("available") else f"; not measured in this run: {core['reason']}")
        + "). The machine has 2 cores shared with other work, so the three measures are "
        f"interleaved: {res['rounds']} rounds, each running all three, rotating which goes "
        "first. The table gives the best of the rounds, the ratio of those bests (time / "
        "impact1d's `simulate`), and the median of the rounds' own ratios:",
        "",
        common.markdown_table(rows, ["scene", "tool", "time per run (best)",
                                     "ratio to impact1d simulate (of the bests)",
                                     "median of the rounds' ratios",
                                     f"max event-time error [s] (case 5: t <= {c5['window']} s)",
                                     "final-state error", "at case 5's accumulation"]),
        "",
        f"On case 3 CVODE takes **{t3['ratio_of_best']['cvode']:.1f} times** as long as "
        "`impact1d.simulate` for the same events and final state"
        + (f", and {t3['best_s']['cvode'] / t3['best_s']['core']:.1f} times as long as "
           "impact1d's core without Python" if "core" in t3["best_s"] else "")
        + f" (its event times {common.fmt(cv3['event_error'])} s off the exact ones, "
        f"impact1d's {common.fmt(c3['impact1d']['event_error'])} s)"
        + (f". The core runs the same case in {_us(t3['best_s']['core'])} of `simulate`'s "
           f"{_us(t3['best_s']['impact1d'])}: the rest is the call's Python and f2py layer "
           "and the event log's rebuild (\"The fixed cost of a call\" below)" if "core" in t3["best_s"] else "")
        + (". The core's events and final state are those of `simulate`, bit for bit"
           if c3.get("core_same_output") else "")
        + f". CVODE's {_us(t3['best_s']['cvode'])} are about "
        f"{t3['best_s']['cvode'] / cv3['restarts'] * 1e6:.1f} us per restart; making its "
        "memory afresh per run adds little. The issue's aim, 10 times CVODE at equal output, "
        f"is {'met' if t3['ratio_of_best']['cvode'] >= 10 else '**not met**'} by "
        "`simulate`.",
        "",
        "On case 5 the outputs are not equal and the ratio is only the cost of what each "
        f"did: CVODE at rtol = {c5['rtol']:g} follows the series and then fails at the "
        "accumulation point (last column; docs/accuracy.md has it for every rtol).",
    ]
    if perf or siconos:
        out += ["", "The other peers, for scale (measured differently, each in its own "
                "section): "
                + "; ".join(_other_peers(perf, siconos)) + "."]
    return "\n".join(out + [""])


def _other_peers(perf, siconos):
    out = []
    if perf:
        bt = perf["case3"]["batch"]
        out.append(f"SciPy's DOP853 event-restart loop (Python) {bt['ratio_median']:.0f} times "
                   "impact1d's time on case 3 with samples every 0.01 s")
    if siconos and siconos.get("available"):
        tm = siconos["case3"]["timing"]["kernel"]
        out.append(f"Siconos' event-driven LSODAR scheme {tm['ratio_median']:.0f} times on "
                   "case 3 with output at t_end (its C++ loop, model building included)")
    return out


def _sweep_table(c, with_series) -> str:
    rows = []
    for r in c["sweep"]:
        row = [f"{r['rtol']:g}", str(r["impacts"]), common.fmt(r["event_error"]),
               common.fmt(r["final_error"]), str(r["steps"]), str(r["rhs_evals"]),
               str(r["root_evals"]), str(r["restarts"]), _us(r["seconds"])]
        if with_series:
            s, b = r["series"], r["beyond"]
            crossed = [b[w]["t_cross"] for w in WALLS if b[w]["t_cross"] is not None]
            row += [", ".join(str(s[w]["resolved"]) for w in WALLS),
                    f"{min(s[w]['t_last_resolved'] for w in WALLS):.9f}",
                    f"{min(crossed):.9f}" if crossed else "no",
                    r["stop_reason"]]
        rows.append(row)
    header = ["rtol", "impacts logged", "event-time error", "final-state error", "steps",
              "rhs evals", "root evals", "restarts", "time per run (rough)"]
    if with_series:
        header += ["series followed (left, right)", "to t", "through a wall at t",
                   "loop ended"]
    return common.markdown_table(rows, header)


def _followed(row) -> str:
    return " and ".join(str(row["series"][w]["resolved"]) for w in WALLS)


def accuracy_section(res) -> str:
    out = ["## CVODE side by side (cases 3 and 5)", ""]
    if not res or not res.get("available"):
        return "\n".join(out + [_unavailable(res or {}), ""])
    c3, c5 = res["case3"], res["case5"]
    cv3, cv5, o3, o5 = c3["cvode"], c5["cvode"], c3["impact1d"], c5["impact1d"]
    s5, b5 = cv5["series"], cv5["beyond"]
    first, last = c5["sweep"][0], c5["sweep"][-1]
    out += [
        f"{_version_line(res)}; the loop and the timing are described in "
        "docs/performance.md. Every rtol (atol = rtol * 1e-3), the error measures above "
        f"(case 5: impacts before t = {c5['window']} s). 'restarts' counts root returns, "
        "each followed by CVodeReInit, with or without an impact; the times are the best of "
        f"{SWEEP_TIMING[0]} batches of {SWEEP_TIMING[1]} runs, not interleaved (rough). "
        f"impact1d at dt = {o3['dt']:g}: case 3 event-time error "
        f"{common.fmt(o3['event_error'])} s, final-state error {common.fmt(o3['final_error'])}; "
        f"case 5 {common.fmt(o5['event_error'])} s and {common.fmt(o5['final_error'])}.",
        "",
        f"**Case 3** ({c3['reference_impacts']} impacts; reference: {c3['reference']})",
        "",
        _sweep_table(c3, False),
        "",
        f"**Case 5** (reference: {c5['reference']}). 'Series followed': the impacts on "
        "each wall, from the first, whose time is within 1 % of the time left to t = 3; "
        "'through a wall at t': when a body crossed its wall, from its state at t_end "
        "(t_end - |v| / |a|: it left the wall at rest to rounding, pushed at |a|).",
        "",
        _sweep_table(c5, True),
        "",
        "### What the CVODE comparison shows",
        "",
        f"- **Case 3**: every rtol sees the {c3['reference_impacts']} impacts, with event "
        f"times {common.fmt(min(r['event_error'] for r in c3['sweep']))} to "
        f"{common.fmt(max(r['event_error'] for r in c3['sweep']))} s off the exact ones "
        f"(impact1d: {common.fmt(o3['event_error'])} s). The flights are straight lines, "
        "which Adams integrates exactly at any tolerance, so what is left is the root "
        "finding's own tolerance (CVODE locates a root to about 100 units of rounding of "
        "t and h) carried from impact to impact; no rtol improves it, and the work hardly "
        "changes with rtol.",
        f"- **Case 5, before the accumulation**: the first impacts on each wall agree with "
        f"t_n = 3 - 2^(2-n) to {common.fmt(cv5['event_error'])} s at rtol = {c5['rtol']:g}.",
        f"- **Case 5, at the accumulation point**: the plain loop follows the series for "
        f"{s5['left']['resolved']} impacts on the left wall and {s5['right']['resolved']} on "
        f"the right (to t = {min(s5[w]['t_last_resolved'] for w in WALLS):.9f} at rtol = "
        f"{c5['rtol']:g}; from {_followed(first)} at rtol = {first['rtol']:g} to "
        f"{_followed(last)} at {last['rtol']:g}). CVODE returns "
        "a root on the far side of the crossing (the gap a rounding-level negative), and "
        "once the rebounds are as small as its error on the restarted state, roots are "
        "reported where nothing approaches the wall: "
        f"{cv5['restarts']} restarts for {cv5['impacts']} impacts, {cv5['empty_roots']} of "
        "them with no impact at all. It does not stall; it "
        "passes the accumulation point wrongly. A body left just beyond its wall by a "
        "restart, with a rebound too weak to bring the gap back above zero before the "
        "force turns it round, leaves the root finder no sign change to find, and the "
        "force carries it through the wall"
        + (f" (at t = {min(b5[w]['t_cross'] for w in WALLS if b5[w]['t_cross']):.9f}), to "
           f"end {max(b5[w]['depth'] for w in WALLS):.3g} m beyond it at t_end, moving at "
           f"{max(abs(cv5['final'][1]), abs(cv5['final'][3])):.3g} m/s"
           if any(b5[w]["t_cross"] for w in WALLS) else "")
        + f" (final-state error {common.fmt(cv5['final_error'])}; impact1d: "
        f"{common.fmt(o5['final_error'])}, both bodies at rest on the walls from t = 3). "
        + ("No bound of the loop is reached; the run just ends wrong. "
           if cv5["stop_reason"] == "t_end reached" else
           f"The loop ended on its bound: {cv5['stop_reason']}. ")
        + f"Its cost: {_us(first['seconds'])} a run at rtol = {first['rtol']:g} "
        f"({first['restarts']} restarts), {_us(last['seconds'])} at {last['rtol']:g} "
        f"({last['restarts']}): the spurious roots, not the steps, set it.",
        "",
    ]
    return "\n".join(out)


if __name__ == "__main__":
    n = ROUNDS
    if "--rounds" in sys.argv:
        n = int(sys.argv[sys.argv.index("--rounds") + 1])
    print(json.dumps(run(n), indent=1, default=float)[:4000])
