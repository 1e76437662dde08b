"""The fixed cost of `impact1d.simulate` (issue 20 item 1), stage by stage: a short run of
case 3 (t_end = dt = 1e-3: one step, two samples, no events) and case 3 as the CVODE
comparison runs it (dt = 0.1, dt_out = t_end: 41 events), each stage timed alone on the
same arguments, the minimum and the mean over batches of calls (time.perf_counter). The
Fortran stages (prepare_scene, the sink, run) are measured without Python by
build/bench/call_stages (bench/call_stages.f90, built as cvode_peer.py builds core_run).
The profile before the speed work (commit f118c72) is kept in
bench/results/call_profile_before.json: its stages no longer exist as separate code.
Measured, never asserted in tests."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import time

import numpy as np

import common
import cvode_peer
import impact1d
from impact1d import _scene, _simulate

BATCHES, CALLS = 15, 2000
SHORT = dict(t_end=1e-3, dt=1e-3)
EVENTS = dict(dt=0.1, dt_out=6.0)


def _timed(call) -> dict:
    per_call = []
    for _ in range(BATCHES):
        start = time.perf_counter()
        for _ in range(CALLS):
            call()
        per_call.append((time.perf_counter() - start) / CALLS)
    return {"min_us": min(per_call) * 1e6, "mean_us": float(np.mean(per_call)) * 1e6}


def _core_call(form):
    buffers = _simulate._buffers
    samples = np.empty((form.sample_capacity, len(_simulate.COLUMNS)), order="F")
    return lambda: _scene._api.simulate(
        form.core[0], form.core[1], form.blob, form.text_end, *form.records, 0, samples, *buffers.outputs)


def _prepared_call(form):
    """The core call of a form run before (simulate's: run_prepared on its handle)."""
    buffers = _simulate._buffers
    samples = np.empty((form.sample_capacity, len(_simulate.COLUMNS)), order="F")
    for _ in range(2):
        _simulate._prepared(form)
    return lambda: _scene._api.run_prepared(form.handle, 0, samples, *buffers.outputs, -1)


def _fortran_stages() -> dict:
    """prepare_scene, + the sink, + run of the short run, in Fortran alone (the best of 7
    batches of 20000)."""
    built = cvode_peer.build_core(source=common.BENCH / "call_stages.f90", name="call_stages")
    if not built["available"]:
        return {"available": False, "reason": built["reason"]}
    out = subprocess.run([built["exe"], str(common.SCENE_FILES["case3"])], capture_output=True, text=True, check=True)
    return {"available": True, **json.loads(out.stdout)}


def run() -> dict:
    scene = impact1d.load_scene(common.SCENE_FILES["case3"])
    short = _scene.core_form(scene, SHORT, _simulate._make_form)
    events = _scene.core_form(scene, EVENTS, _simulate._make_form)
    short_scene = dataclasses.replace(scene, **SHORT)
    fresh = iter(np.linspace(-9.0, -1.0, BATCHES * CALLS + 1).tolist())
    stages = {
        "short run, simulate() whole": _timed(lambda: impact1d.simulate(scene, **SHORT)),
        "short run with a new v1 each call (the cache misses: the value put into the scene's kept form)":
            _timed(lambda: impact1d.simulate(scene, **SHORT, v1=next(fresh))),
        "the core form from the cache (key and look-up)": _timed(lambda: _scene.core_form(scene, SHORT, _simulate._make_form)),
        "the core form made whole (a scene not run before: overrides, to_core)": _timed(lambda: _simulate._make_form(short_scene, {})),
        "the f2py call (arguments, validation, build_scene, sink, run)": _timed(_core_call(short)),
        "the prepared f2py call (run_prepared: arguments, sink, run)": _timed(_prepared_call(short)),
        "case 3 at dt = 0.1, simulate() whole": _timed(lambda: impact1d.simulate(scene, **EVENTS)),
        "case 3 at dt = 0.1, the f2py call": _timed(_core_call(events)),
    }
    _core_call(events)()
    log = np.empty(41, dtype=_simulate.EVENT_DTYPE)
    stages["case 3 at dt = 0.1, the event log rebuilt (41 events)"] = _timed(
        lambda: _simulate._fill_events(log, _simulate._buffers, 41, 4, False))
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=common.REPO, capture_output=True, text=True)
    res = {"stages": stages, "fortran": _fortran_stages(), "timed_at": commit.stdout.strip()}
    common.save_json("call_profile", res)
    return res


def _rows(stages) -> list:
    return [[name, f"{s['min_us']:.2f} us", f"{s['mean_us']:.2f} us"] for name, s in stages.items()]


def performance_section(res) -> str:
    before = common.load_json("call_profile_before")
    out = ["## The fixed cost of a call (issue 20 item 1)", "",
           "What `impact1d.simulate(case3, ...)` spends for a scene already loaded, stage by stage "
           "(bench/call_profile.py: each stage timed alone on the same arguments, the minimum and "
           f"the mean over {BATCHES} batches of {CALLS} calls; the machine is shared, so ratios within "
           "one table mean more than absolute times). The short run is t_end = dt = 1e-3 (one step, "
           "two samples, no events); the aim is at most 5 us. Before the speed work ("
           + before["commit"] + ", " + before["note"] + "):", "",
           common.markdown_table(_rows(before["stages"]), ["stage", "min", "mean"]), "",
           "Before and after side by side (" + before["side_by_side"]["how"] + "):", "",
           common.markdown_table([[name, f"{old:.2f} us", f"{new:.2f} us", f"{old / new:.1f}x"]
                                  for name, old, new in before["side_by_side"]["rows"]],
                                 ["run", "before", "after", "faster"]), ""]
    out += _instructions_section()
    if res is None:
        return "\n".join(out + ["After: not timed (run `make bench`)."])
    stages, fortran = res["stages"], res["fortran"]
    # (the short run's core call: the prepared one once simulate has it)
    core = stages.get("the prepared f2py call (run_prepared: arguments, sink, run)",
                      stages["the f2py call (arguments, validation, build_scene, sink, run)"])
    rest = (stages["short run, simulate() whole"]["min_us"]
            - stages["the core form from the cache (key and look-up)"]["min_us"] - core["min_us"])
    out += ["Timed (the scene's core form kept per scene and override set, keyed on the field "
            "values; the core's result arrays the caller's, the event and message buffers made once "
            "per thread; the event kinds' table made once per layout), at "
            + res.get("timed_at", "an unrecorded commit") + ":", "",
            common.markdown_table(_rows(stages), ["stage", "min", "mean"]), "",
            f"Of the short run's minimum, {rest:.2f} us is the Python around the call (the override "
            "check, the samples array, reading the counts, the Result with its column views, an "
            "empty event log and its copy of the scene run)."]
    if fortran.get("available"):
        out[-1] += (f" The Fortran share without Python (bench/call_stages.f90, best of 7 batches): "
                    f"prepare_scene (validation, build_scene with its stability eigen-solve) "
                    f"{fortran['prepare_us']:.2f} us, with the memory sink's reservation "
                    f"{fortran['reserve_us']:.2f} us, with the run itself (one step, two samples) "
                    f"{fortran['run_us']:.2f} us; most of it is about 90 small allocations a call "
                    "(validation messages, the scene's and the run's arrays: valgrind counts "
                    "them), not arithmetic.")
    return "\n".join(out)


def _instructions_section() -> list:
    """The instruction counts of bench/call_instructions.py, before and after, per stage, and
    what is left of the call besides its f2py call (the Python around it)."""
    if not (common.RESULTS / "call_instructions.json").exists():
        return []
    counts = common.load_json("call_instructions")
    before = counts.get("before", {}).get("stages")
    after = counts["after"]["stages"]
    columns = [before, after] if before else [after]

    def rest(stages):
        return stages["simulate() whole"] - stages["the f2py call (arguments, set-up, sink, run)"]

    rows = [[name, *(f"{stages[name]:,}" for stages in columns)] for name in after]
    rows.append(["the rest: Python around the call (the core form's look-up, the samples array, the Result)",
                 *(f"{rest(stages):,}" for stages in columns)])
    return ["Instructions per short call (bench/call_instructions.py: callgrind, which the machine's load "
            "does not move; a stage's inclusive count, its callees in it). "
            + (f"Before: {counts['before']['label']}, the scene set up whole at every call; after: " if before
               else "")
            + counts["after"].get("label", "") + ", the scene prepared once per core form (the api's prepare / run_prepared: validation, "
            "build_scene and the records made at the form's second run, not at every call), the Result "
            "built from a layout worked out once, the thread's buffers read as one tuple:", "",
            common.markdown_table(rows, ["stage", *(["before", "after"] if before else ["instructions"])]), ""] \
        + _estimate(counts)


def _estimate(counts) -> list:
    """The after's time at the instructions per microsecond of the last quiet timing: an
    estimate for a machine too loaded to time the change (not a measurement)."""
    quiet = counts.get("quiet_reference")
    if not quiet:
        return []
    rate = quiet["instructions"] / quiet["us"]
    after = counts["after"]["stages"]["simulate() whole"]
    return [f"At the rate of the last quiet timing ({quiet['label']}: {quiet['us']:.2f} us for about "
            f"{quiet['instructions']:,} instructions; {quiet['how']}), the after's {after:,} instructions "
            f"would take about {after / rate:.1f} us: an estimate, not a timing (the aim is 5 us; "
            "the machine was too loaded to time this change: the times below are of 7ae8c29).", ""]


if __name__ == "__main__":
    print(json.dumps(run(), indent=1))
