"""Parameter studies: many runs of one scene, one table row per run.

    table = impact1d.sweep(scene, {"r_left": np.linspace(0, 1, 21), "r_right": [0.5, 1.0]})

A row holds the varied fields, then the run's summary (SUMMARY_COLUMNS; past two bodies each
further body's end state, body_columns), then `error`: empty
when the run succeeded, else the message of its InputError or SimulationError (a failing run
is a row, never the end of the sweep). Runs go in chunks to threads of this machine (the
Fortran run releases the GIL) or to the workers of a dask.distributed Client.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Optional

import numpy as np

from ._scene import REAL_FIELDS, InputError, Scene, SimulationError
from ._simulate import _OVERRIDABLE, interrupt_epoch_now, is_impact_kind, run_summaries, simulate

__all__ = ["sweep", "SUMMARY_COLUMNS", "STEADY_COLUMNS", "summarize", "steady_state", "run_chunk"]

# Named so that they never clash with a varied field (x1 is a field, x1_end is not).
SUMMARY_COLUMNS = ("x1_end", "v1_end", "x2_end", "v2_end", "ke_end", "n_impacts",
                   "n_left", "n_right", "n_slot_min", "n_slot_max", "t_rest",
                   "impact_loss", "friction_loss", "energy_residual", "steps", "pe_end",
                   "damping_loss")
# With settle = T: the steady state over the window [T, t_end] (steady_state).
STEADY_COLUMNS = ("x1_p2p", "x1_rms", "v1_p2p", "v1_rms", "x2_p2p", "x2_rms", "v2_p2p", "v2_rms",
                  "impacts_per_period")
_IMPACT_KINDS = ("left", "right", "slot_min", "slot_max")
# Below this many runs a sweep stays on one thread unless asked: a pool costs more than
# it saves on a few milliseconds of work.
_PARALLEL_FROM = 200
# Runs per chunk: enough that a chunk's Python overhead (which holds the GIL) is small
# beside its Fortran runs, few enough that every thread gets about 8 chunks (a last chunk
# does not leave the others idle) and the progress bar moves.
_CHUNK_MIN, _CHUNK_MAX = 16, 512


def _bodies(scene: Scene) -> int:
    """How many bodies a scene has: the length of its mass array, else one or two by the
    tutorial's m2."""
    masses = vars(scene).get("m")
    if masses is not None and not isinstance(masses, (int, float)):
        return len(masses)
    return 2 if scene.m2 is not None else 1


def body_columns(n_bodies: int, words=("end",)) -> tuple:
    """The per-body columns past the second body's: x3_end v3_end .. xN_end vN_end (and
    with words ("p2p", "rms"): x3_p2p x3_rms v3_p2p v3_rms ..), after SUMMARY_COLUMNS
    (STEADY_COLUMNS), which name bodies 1 and 2."""
    return tuple(f"{q}{i}_{word}" for i in range(3, n_bodies + 1) for q in ("x", "v") for word in words)


def summary_columns(scene: Scene, settle: Optional[float] = None) -> tuple:
    """A sweep's measured columns for `scene`: SUMMARY_COLUMNS, each body's end state past
    the second, then with settle STEADY_COLUMNS and each body's past the second."""
    n = _bodies(scene)
    names = SUMMARY_COLUMNS + body_columns(n)
    return names + (STEADY_COLUMNS + body_columns(n, ("p2p", "rms")) if settle is not None else ())


def _chunk_size(n_runs: int, workers: int) -> int:
    return max(_CHUNK_MIN, min(_CHUNK_MAX, n_runs // (8 * workers)))


def summarize(result) -> dict:
    """The summary row of one Result (as the core's summary sink computes it).

    t_rest is when every body came to rest for good: the instant from which no sample and
    no event shows a velocity up to t_end: the event that stopped the last body (a stick,
    a rest at an accumulation time, an impact leaving both still), or without one (a stop
    by the vissim method's threshold) the first sample at rest; NaN if a body still moves
    at t_end."""
    events = result.events
    kinds = events["kind"]
    counts = {kind: int(np.count_nonzero(kinds == kind)) for kind in _IMPACT_KINDS}
    impacts = sum(1 for kind in kinds if is_impact_kind(kind))
    two_bodies = result.v2 is not None
    t_rest = _rest_time(result) if _bodies(result.scene) <= 2 else _rest_sample(result, np.any(result.v != 0.0, axis=1))
    row = {"x1_end": result.x1[-1], "v1_end": result.v1[-1], **_body_values(result, ("end",)),
           "x2_end": result.x2[-1] if two_bodies else math.nan,
           "v2_end": result.v2[-1] if two_bodies else math.nan, "ke_end": result.ke[-1],
           "n_impacts": impacts, **{f"n_{k}": counts[k] for k in _IMPACT_KINDS},
           "t_rest": t_rest, "impact_loss": result.impact_loss[-1],
           "friction_loss": result.friction_loss[-1],
           "energy_residual": result.energy_residual, "steps": result.steps,
           # The springs' energy and the dampers' loss at t_end: 0 without them.
           "pe_end": result.pe[-1] if result.pe is not None else 0.0,
           "damping_loss": result.damping_loss[-1] if result.damping_loss is not None else 0.0}
    return {name: row[name] for name in SUMMARY_COLUMNS + body_columns(_bodies(result.scene))}


def _rest_time(result) -> float:
    """summarize's t_rest of a one- or two-body run: its events carry both velocities."""
    events = result.events
    two_bodies = result.v2 is not None
    moving = (result.v1 != 0.0) | ((result.v2 != 0.0) if two_bodies else False)
    if moving[-1]:
        return math.nan
    # The core's order: events at a sample's time come before that sample, and events
    # at one instant in the order logged.
    t_sample_moved = result.t[np.flatnonzero(moving)[-1]] if moving.any() else -math.inf
    leaves_moving = (events["v1_after"] != 0.0) | (
        (events["v2_after"] != 0.0) if two_bodies else False)
    after = np.arange(len(events)) > (np.flatnonzero(leaves_moving)[-1] if leaves_moving.any() else -1)
    t_event_moved = events["t"][~after].max() if (~after).any() and leaves_moving.any() else -math.inf
    still = events["t"][after & (events["t"] > t_sample_moved)]
    at_rest = result.t[(result.t > t_sample_moved) & (result.t >= t_event_moved)]
    return float(min(still.min() if len(still) else math.inf, at_rest.min()))


def _rest_sample(result, moving) -> float:
    """summarize's t_rest of a run of more than two bodies (its events name only the pair
    they concern: the core's summary decides by the samples alone): the first sample from
    which no body moves, NaN if one moves at the last."""
    if moving[-1]:
        return math.nan
    return float(result.t[np.flatnonzero(moving)[-1] + 1] if moving.any() else result.t[0])


def _body_values(result, words, window=slice(None)) -> dict:
    """Each body's measures past the second (body_columns) from result.x and result.v:
    'end' the last sample, 'p2p' and 'rms' over the samples in window (NaN for a body the
    output does not have, &run bodies_out)."""
    row = {}
    # (a column per body written: a look-up, not a search of the tuple per body, O(N^2))
    column = {body: j for j, body in enumerate(result.bodies or ())}
    for i in range(3, _bodies(result.scene) + 1):
        for q in ("x", "v"):
            values = getattr(result, q)[window, column[i]] if i in column else None
            for word in words:
                row[f"{q}{i}_{word}"] = math.nan if values is None else _measure(values, word)
    return row


def _measure(values, word) -> float:
    """One column's measure: its last value, peak-to-peak, or RMS about its mean."""
    if word == "end":
        return float(values[-1])
    if word == "p2p":
        return float(values.max() - values.min())
    return float(np.sqrt(np.mean((values - values.mean()) ** 2)))


# The core's default &run max_events, and its largest (a summary reads the whole log).
_DEFAULT_MAX_EVENTS, _WHOLE_LOG = 10_000_000, 2**31 - 1


def _is_count(value) -> bool:
    """A max_events the core takes (else it is passed on, for the core's message)."""
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool)
                             and float(value).is_integer() and 1 <= value <= _WHOLE_LOG)


def _cut_log(result, cap: int):
    """A kept Result's log cut at max_events as the core cuts it, with its warning."""
    if len(result.events) <= cap:
        return result
    note = (f"the event log was cut at {cap} of {len(result.events)} events (max_events = {cap}); "
            "the run went on to its end and the counts are exact")
    return dataclasses.replace(result, events=result.events[:cap], warnings=result.warnings + (note,))


def steady_state(result, settle: float) -> dict:
    """The steady-state measures of one Result over the window [settle, t_end]: the samples
    with t >= settle and the events with t >= settle (NaN for a body the scene does not
    have, and for every measure when the window holds fewer than two samples).

    - xi_p2p, vi_p2p: peak-to-peak, max - min of body i's sampled position (velocity).
    - xi_rms, vi_rms: RMS about the window's mean, sqrt(mean((x - mean(x))^2)) (the
      oscillation's, not its offset's: a spring's rest position or a wall does not enter).
    - impacts_per_period: impacts (on any contact) in the window times the forcing period
      over the window's length; the period is f1_period when f1_amp is given and non-zero,
      else f2_period likewise, else the period of the first &sine record (Scene.sines) with
      a non-zero amplitude; NaN for a scene without a sine. (Several sines have no one
      period in general: the first one named is the period the count is per.)

    Sampling error, for x = A cos(w t + phi) sampled every h (dt_out) over a window of
    length L = N h (N samples), w h <= pi/2: the sums of exp(i w t_k) and exp(2 i w t_k)
    are at most 1 / sin(w h / 2) <= pi / (w h) and pi / (2 w h) in size, so the mean is
    within A pi / (w L) of 0 and the mean of x^2 within (A^2 / 2) pi / (2 w L) of A^2 / 2:
    with eps = pi / (4 w L) + (pi / (w L))^2, |rms^2 - A^2 / 2| <= A^2 eps and
    |rms - A / sqrt(2)| <= sqrt(2) A eps. A window of one period and h at least holds a
    sample within h / 2 of each extreme: 2 A (1 - (w h)^2 / 8) <= p2p <= 2 A. The same for
    v with A w for A."""
    t = result.t
    window = t >= settle
    scene = result.scene
    row = dict.fromkeys(STEADY_COLUMNS + body_columns(_bodies(scene), ("p2p", "rms")), math.nan)
    if np.count_nonzero(window) < 2:
        return row
    for name in ("x1", "v1", "x2", "v2"):
        values = getattr(result, name)
        if values is None:
            continue
        for word in ("p2p", "rms"):
            row[f"{name}_{word}"] = _measure(values[window], word)
    row.update(_body_values(result, ("p2p", "rms"), window))
    periods = [(getattr(scene, f"f{i}_amp"), getattr(scene, f"f{i}_period")) for i in (1, 2)]
    periods += [(record.get("amp"), record.get("period")) for record in scene.sines or ()]
    period = next((period for amp, period in periods if amp and period), None)
    if period is not None:
        events = result.events
        impacts = sum(1 for kind in events["kind"][events["t"] >= settle] if is_impact_kind(kind))
        row["impacts_per_period"] = impacts * float(period) / float(t[-1] - settle)
    return row


def _failed_row(names=SUMMARY_COLUMNS) -> dict:
    """A failed run's summary: nothing measured (its `error` says why)."""
    return {name: math.nan for name in names}


def _columns(rows: list, names=SUMMARY_COLUMNS) -> dict:
    """Summary rows as {column: float64 array} (how chunks travel: arrays, not rows)."""
    return {name: np.array([row[name] for row in rows], dtype=np.float64) for name in names}


def _batchable(overrides: list) -> bool:
    """Runs the core's batch entry can take: the same real fields, numbers only."""
    if not overrides or not overrides[0]:
        return False
    names = set(overrides[0])
    return all(set(run) == names and all(name in REAL_FIELDS and isinstance(value, (int, float))
                                         and not isinstance(value, bool)
                                         for name, value in run.items())
               for run in overrides)


def run_chunk(scene: Scene, overrides: list, keep_results: bool = False, settle: Optional[float] = None,
              interrupt_epoch: Optional[int] = None):
    """Run the scene once per override dict: ({column: array} of summaries, error
    messages[, Results]). A plain function of plain data, so that a Dask worker can run it
    and send back a few arrays. Without Results or steady-state measures (settle) wanted,
    runs that only change numbers go to the core in one call (no per-run glue); with
    settle, each run's Result is measured (steady_state) and dropped unless kept.
    interrupt_epoch: the interrupt count the sweep started with, in this process (its
    runs end at their first checkpoint when an interrupt came after it); None: each run's
    start."""
    names = summary_columns(scene, settle)
    if not keep_results and settle is None and _batchable(overrides):
        columns, errors = run_summaries(scene, overrides, body_columns(_bodies(scene)), interrupt_epoch)
        return {name: np.asarray(columns[name], dtype=np.float64) for name in names}, errors
    rows, errors, results = [], [], []
    for changes in overrides:
        # The summary reads the whole event log (its counts and t_rest are exact whatever
        # `events` and `max_events` keep); a kept Result then keeps what they asked for.
        events = changes.get("events", scene.events)
        cap = changes.get("max_events", scene.max_events)
        whole = {"events": None, "max_events": _WHOLE_LOG if _is_count(cap) else cap}
        try:
            result = simulate(scene, _interrupt_epoch=interrupt_epoch, **{**changes, **whole})
        except (InputError, SimulationError) as error:
            rows.append(_failed_row(names))
            errors.append(str(error))
            results.append(None)
            continue
        rows.append({**summarize(result), **(steady_state(result, settle) if settle is not None else {})})
        errors.append("")
        if keep_results and events is not None and str(events).lower() != "all":
            impacts_only = str(events).lower() == "impacts"
            keep = np.array([impacts_only and is_impact_kind(kind) for kind in result.events["kind"]], dtype=bool)
            result = dataclasses.replace(result, events=result.events[keep])
        if keep_results:
            result = _cut_log(result, _DEFAULT_MAX_EVENTS if cap is None else int(cap))
        results.append(result if keep_results else None)
    return (_columns(rows, names), errors, results) if keep_results else (_columns(rows, names), errors)


def _check_settle(settle, scene: Scene, runs: list) -> None:
    """settle, when given, is a time from 0 that every run's t_end lies beyond."""
    if settle is None:
        return
    if isinstance(settle, bool) or not isinstance(settle, (int, float, np.floating)) \
            or not math.isfinite(settle) or settle < 0:
        raise InputError(f"settle = {settle!r} must be a time of 0 s or more")
    for run in runs:
        t_end = run.get("t_end", scene.t_end)
        if isinstance(t_end, (int, float)) and t_end <= settle:
            raise InputError(f"settle = {settle} is not before t_end = {t_end}: "
                             "the window [settle, t_end] would be empty")


def _runs(params) -> tuple:
    """(varied field names, list of override dicts) from a grid dict or a list of dicts."""
    if isinstance(params, dict):
        names = list(params)
        values = [list(np.atleast_1d(params[name])) for name in names]
        runs = [dict(zip(names, combo)) for combo in itertools.product(*values)]
    else:
        runs = [dict(run) for run in params]
        names = list(dict.fromkeys(name for run in runs for name in run))
    unknown = [name for name in names if name not in _OVERRIDABLE]
    if unknown:
        raise InputError(f"unknown scene field(s) to vary: {', '.join(unknown)} "
                         f"(known: {', '.join(_OVERRIDABLE)})")
    # numpy scalars become plain floats: the row equals a simulate() call with those numbers.
    runs = [{k: (v.item() if isinstance(v, np.generic) else v) for k, v in run.items()}
            for run in runs]
    return names, runs


class _Progress:
    """A tqdm bar when tqdm is installed, else a counter line on stderr."""

    def __init__(self, total, show):
        self.total, self.done, self.bar = total, 0, None
        self.show = show
        if show:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit="run", desc="impact1d sweep", file=sys.stderr)
            except ImportError:
                pass

    def update(self, n):
        self.done += n
        if not self.show:
            return
        if self.bar is not None:
            self.bar.update(n)
        else:
            sys.stderr.write(f"\rimpact1d sweep: {self.done}/{self.total} runs")
            sys.stderr.flush()

    def close(self):
        if self.bar is not None:
            self.bar.close()
        elif self.show:
            sys.stderr.write("\n")


def sweep(scene: Scene, params, *, workers: Optional[int] = None, client=None,
          progress: Optional[bool] = None, keep: Optional[str] = None, settle: Optional[float] = None,
          _interrupt_epoch: Optional[int] = None):
    """Run `scene` over `params` and return a pandas DataFrame, one row per run in order.

    params: a dict field -> sequence (the Cartesian grid, the first field varying slowest)
    or a list of override dicts. workers: threads of this machine (default: all cores for
    sweeps of 200 runs or more, else 1). client: a dask.distributed Client to run the chunks
    on instead. progress: a progress bar (default: when stderr is a terminal).
    keep="results": return (table, list of Result or None for failed runs).
    settle=T: the table gains STEADY_COLUMNS, the steady state over [T, t_end] (peak-to-peak
    and RMS of each position and velocity, impacts per forcing period: steady_state). Each
    run's Result is measured and dropped (the batch path keeps no samples, so these runs
    go one by one). (_interrupt_epoch: the caller's interrupt_epoch_now, taken earlier than
    the sweep's start: impact1d-sweep's, from its main().)"""
    import pandas as pd

    if not isinstance(scene, Scene):
        raise InputError(f"sweep() needs an impact1d.Scene, got {type(scene).__name__}")
    if keep not in (None, "results"):
        raise InputError(f"keep must be None or 'results', got {keep!r}")
    names, runs = _runs(params)
    _check_settle(settle, scene, runs)
    if progress is None:
        progress = sys.stderr.isatty()
    if workers is None:
        workers = (os.cpu_count() or 1) if len(runs) >= _PARALLEL_FROM else 1
    if workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}")
    keep_results = keep == "results"
    size = _chunk_size(len(runs), workers)
    chunks = [runs[i:i + size] for i in range(0, len(runs), size)]
    bar = _Progress(len(runs), progress)
    # Every local run takes the interrupt count of the sweep's start: one that a worker
    # starts after an interrupt (it came while the worker took its chunk) ends at its first
    # checkpoint; with its own count it ran to its end, and the interpreter waited for it at
    # exit. (A Dask worker's process counts its own: its runs take theirs.)
    epoch = interrupt_epoch_now()
    if _interrupt_epoch is not None:
        epoch = _interrupt_epoch
    try:
        if client is not None:
            if keep_results:
                raise InputError("keep='results' is for local sweeps, not a Dask client")
            # Few, large tasks: a task costs the scheduler and the workers' processes
            # (on the same cores here) far more than a thread's chunk does.
            workers_there = max(1, len(client.scheduler_info().get("workers", {})))
            size = max(_CHUNK_MIN, -(-len(runs) // (4 * workers_there)))
            chunks = [runs[i:i + size] for i in range(0, len(runs), size)]
            futures = client.map(run_chunk, [scene] * len(chunks), chunks, [False] * len(chunks),
                                 [settle] * len(chunks), pure=False)
            outputs = []
            try:
                for future, chunk in zip(futures, chunks):
                    outputs.append(future.result())
                    bar.update(len(chunk))
            except KeyboardInterrupt:
                client.cancel(futures)      # the cluster does not go on with a sweep no one waits for
                raise
        elif workers == 1:
            outputs = []
            for chunk in chunks:
                outputs.append(run_chunk(scene, chunk, keep_results, settle, epoch))
                bar.update(len(chunk))
        else:
            with ThreadPoolExecutor(max_workers=workers) as pool:
                outputs = []
                try:
                    for chunk, output in zip(chunks, pool.map(
                            lambda c: run_chunk(scene, c, keep_results, settle, epoch), chunks)):
                        outputs.append(output)
                        bar.update(len(chunk))
                except KeyboardInterrupt:
                    # The runs in progress saw the interrupt too and end at their next
                    # checkpoint; the chunks not started are dropped.
                    pool.shutdown(wait=True, cancel_futures=True)
                    raise
    finally:
        bar.close()

    errors = [error for output in outputs for error in output[1]]
    table = pd.DataFrame({name: [run.get(name) for run in runs] for name in names})
    measured = summary_columns(scene, settle)
    summary = pd.DataFrame({name: (np.concatenate([output[0][name] for output in outputs])
                                   if outputs else np.empty(0)) for name in measured})
    table = pd.concat([table, summary], axis=1)
    table["error"] = errors
    # Counts are whole numbers; a failed run's are missing (pandas' nullable integers).
    for name in SUMMARY_COLUMNS:
        if name.startswith("n_") or name == "steps":
            table[name] = table[name].astype("Int64")
    if keep_results:
        return table, [result for output in outputs for result in output[2]]
    return table
