"""simulate(): run a Scene in the Fortran engine and collect its output as numpy arrays."""

from __future__ import annotations

import dataclasses
import itertools
import threading
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Optional

import numpy as np

from ._scene import (REAL_FIELDS, Scene, InputError, SimulationError, decode, raise_for_status, to_core, _words, _api,
                     from_core, is_nbody_form, CoreForm, core_form, record_assignments, record_fields,
                     _STATUS_INTERRUPTED, to_assignments, _packed)
from ._scene import STATUS_TOO_SMALL as _STATUS_TOO_SMALL

__all__ = ["Result", "simulate", "COLUMNS", "EVENT_DTYPE", "ONE_BODY_EVENT_DTYPE", "NBODY_EVENT_DTYPE"]

# Every sample column the api (and the CLI output) can have, checked against the core
# below. A run has those its scene has: pe only with springs, damping_loss only with
# dampers, drive_work only with a moving ground (Result.columns); the others always.
COLUMNS = ("t", "x1", "v1", "x2", "v2", "ke", "pe", "work", "friction_loss",
           "impact_loss", "damping_loss", "drive_work", "residual")
OPTIONAL_COLUMNS = ("x2", "v2", "pe", "damping_loss", "drive_work")
# After the bodies' x and v, every run's row ends with these (pe, damping_loss and
# drive_work optional): an N-body run's columns are t x1 v1 .. xN vN, then LEDGER (the
# core's full row).
LEDGER = ("ke", "pe", "work", "friction_loss", "impact_loss", "damping_loss", "drive_work", "residual")

# Longest event kind is "release_slot_min" (16 characters).
EVENT_DTYPE = np.dtype([("t", "f8"), ("kind", "U20"), ("v1_before", "f8"),
                        ("v2_before", "f8"), ("v1_after", "f8"), ("v2_after", "f8")])
# A one-body scene's events (no m2: the scene has no body 2).
ONE_BODY_EVENT_DTYPE = np.dtype([("t", "f8"), ("kind", "U20"), ("v1_before", "f8"),
                                 ("v1_after", "f8")])
# The events of a scene of more than two bodies: each names the pair it reports, a and b (a
# contact row's ends, 0 the ground; a stick or slip: the body and 0), and their velocities
# (0 for the ground). Kinds are a prefix (8) and a row's name (32).
NBODY_EVENT_DTYPE = np.dtype([("t", "f8"), ("kind", "U40"), ("a", "i4"), ("b", "i4"),
                              ("va_before", "f8"), ("vb_before", "f8"), ("va_after", "f8"),
                              ("vb_after", "f8")])


def event_dtype(n_bodies: int) -> np.dtype:
    """The events' dtype of a run of n_bodies bodies."""
    return ONE_BODY_EVENT_DTYPE if n_bodies == 1 else EVENT_DTYPE if n_bodies == 2 else NBODY_EVENT_DTYPE


def row_length(n_bodies: int) -> int:
    """The core's full row of a run of n_bodies: t, x and v of max(N, 2) bodies, LEDGER."""
    return 2 * max(n_bodies, 2) + 1 + len(LEDGER)


@lru_cache(maxsize=64)
def row_names(n_bodies: int) -> tuple:
    """The names of the core's full row (impact1d_output's column_word): COLUMNS for N <= 2."""
    bodies = range(1, max(n_bodies, 2) + 1)
    return ("t", *(f"{c}{i}" for i in bodies for c in "xv"), *LEDGER)

if _words(_api.column_names()) != COLUMNS:
    raise ImportError("impact1d._core sample columns do not match impact1d.COLUMNS: "
                      f"core has {_words(_api.column_names())}")

_OVERRIDABLE = tuple(f.name for f in dataclasses.fields(Scene))
_OVERRIDABLE_SET = frozenset(_OVERRIDABLE)

# Room for events a run starts with (most runs log fewer); a thread's buffers grown past the
# most kept go back to this after the run (their memory is kept between calls).
_EVENT_CAPACITY = 256
_EVENT_CAPACITY_KEPT = 1 << 16
# Rows a scene starts with room for (the flat API says when it has more, and the buffer
# grows): the tutorial's four and a few records.
_ROW_CAPACITY = 8
# Room for the message and the warnings (the api's message_length).
_TEXT_ROOM = 16384


class _Buffers(threading.local):
    """What simulate's core call fills besides the samples, made once per thread and reused
    (read out into the Result before the next call: no run keeps them)."""

    def __init__(self):
        self.make(_EVENT_CAPACITY, _ROW_CAPACITY)

    def make(self, events: int, rows: int) -> None:
        self.event_real = np.zeros((events, 5), dtype=np.float64, order="F")
        self.event_int = np.zeros((events, 4), dtype=np.int32, order="F")
        self.row_name_codes = np.zeros((32, rows), dtype=np.int32, order="F")
        self.info = np.zeros(8, dtype=np.int32)
        self.energy_residual = np.zeros(1, dtype=np.float64)
        self.text_codes = np.zeros((_TEXT_ROOM, 2), dtype=np.int32, order="F")
        self.columns(len(COLUMNS))

    def columns(self, n_columns: int) -> None:
        """has_column n_columns long, and `outputs`: the arrays the core call fills after the
        samples, in its order (one attribute of the thread's read per call, not seven)."""
        self.has_column = np.zeros(n_columns, dtype=np.int32)
        self.outputs = (self.has_column, self.event_real, self.event_int, self.row_name_codes, self.info,
                        self.energy_residual, self.text_codes)


_buffers = _Buffers()


def _with_overrides(scene: Scene, overrides: dict) -> Scene:
    """A copy with the overrides, as dataclasses.replace but without re-running __init__
    (it only assigns the fields): a tenth of the time, which counts when a run is 0.1 ms."""
    changed = object.__new__(Scene)
    vars(changed).update(vars(scene), **overrides)
    for name in ("method", "substeps", "events"):        # keywords: as the CLI and namelists
        if isinstance(getattr(changed, name), str):
            setattr(changed, name, getattr(changed, name).lower())
    return changed


def interrupt_epoch_now() -> int:
    """Catch SIGINT from now on and return the interrupts counted so far (src/impact1d_interrupt.c):
    runs given this epoch end at their next checkpoint once an interrupt came after it, even
    one that came before they started (a sweep's worker starting a chunk)."""
    return int(_api.interrupt_epoch_now())


def run_summaries(scene: Scene, overrides: list, body_columns: tuple = (), interrupt_epoch: Optional[int] = None):
    """Run `scene` once per override dict in one core call, keeping each run's summary only
    (no samples: O(1) memory per run). The dicts must override the same real fields with
    numbers. Returns ({column: float64 array}, [error message or '' per run]).
    body_columns: the names of x3_end v3_end .. xN_end vN_end for a scene of N > 2 bodies
    (the core writes them after its named columns). interrupt_epoch: the caller's
    (interrupt_epoch_now); None: taken now."""
    epoch = interrupt_epoch_now() if interrupt_epoch is None else interrupt_epoch
    names = list(overrides[0]) if overrides else []
    index = np.array([REAL_FIELDS.index(name) + 1 for name in names], dtype=np.int32)
    matrix = np.array([[run[name] for name in names] for run in overrides],
                      dtype=np.float64).reshape(len(overrides), len(names)).T
    form = core_form(scene, {}, _make_form)
    columns = _summary_names() + tuple(body_columns)
    summary, status, codes = _api.simulate_summaries(*form.core, *form.records, index, matrix, len(columns),
                                                     interrupt_epoch=epoch)
    errors = [""] * len(overrides)
    for j in np.flatnonzero(status):
        errors[j] = decode(np.asarray(codes[:, j], dtype=np.uint8).tobytes())
        if status[j] == _STATUS_INTERRUPTED:
            raise KeyboardInterrupt(errors[j])     # Ctrl-C ended the batch
        if codes[-1, j] != ord(" "):               # filled its room: maybe cut, run it alone
            errors[j] = _whole_message(scene, overrides[j]) or errors[j]
    return dict(zip(columns, summary)), errors


def _whole_message(scene: Scene, overrides: dict) -> str:
    """A failing run's whole message: the batch keeps 512 characters per run (its memory
    is per run), simulate's message has room for any (a long path name)."""
    try:
        simulate(scene, **overrides)
    except (InputError, SimulationError) as error:
        return str(error)
    return ""


@lru_cache(maxsize=None)
def _summary_names() -> tuple:
    return _words(_api.summary_column_names())


_ABSENT = {name: None for name in ("x1", "v1", *OPTIONAL_COLUMNS)}


@lru_cache(maxsize=64)
def _column_layout(has_column: bytes, n_bodies: int):
    """The core's has_column flags (as bytes: a few layouts recur) of a run of n_bodies ->
    the present columns' names in order."""
    flags = np.frombuffer(has_column, dtype=np.int32)
    return tuple(name for name, flag in zip(row_names(n_bodies), flags) if flag)


def _sample_capacity(scene) -> int:
    """Rows a run will emit: t = 0, dt_out, ..., t_end (the core's exact count may be one
    less; a scene the core refuses needs none)."""
    try:
        step = scene.dt_out if scene.dt_out is not None else scene.dt
        rows = float(scene.t_end) / float(step)
        return int(min(rows, 1e7)) + 2 if rows >= 0 else 1
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return 1


def event_kinds(scene=None) -> tuple:
    """The event kinds a run can log, in the order the engine counts them: each contact
    row's impacts ('<row>'), each row's 'rest_<row>', each row's 'release_<row>', each
    body's 'stick<i>', each body's 'slip<i>'. Without an argument, those of the tutorial's
    scenes (two bodies, its walls and slot: 16, whichever of them a scene has); with a
    Scene, or a Result (its scene's), that scene's: its rows as the engine builds them (the
    walls and slot it has, then its &contact records' rows, by name) and its bodies. The
    scene is set up by the engine (a run of no length): one it refuses raises InputError
    as simulate does."""
    if scene is None:
        return _tutorial_event_kinds()
    if isinstance(scene, Result):
        if scene.scene is None:
            raise InputError("the result has no scene to take its event kinds from")
        scene = scene.scene
    if not isinstance(scene, Scene):
        raise InputError(f"event_kinds() takes an impact1d.Scene or Result, got {type(scene).__name__}")
    simulate(scene, t_end=_NO_TIME, dt_out=None)
    # simulate leaves the run's rows in this thread's buffers until the next call
    rows, n_rows = _buffers.row_name_codes, int(_buffers.info[3])
    table, _ = _kind_table(np.ascontiguousarray(rows[:, :n_rows].T).tobytes(), n_rows,
                           int(_buffers.info[7]))
    return tuple(str(kind) for kind in table[:-1])      # (without 'unknown')


# The run event_kinds(scene) makes to have the engine build the scene's rows: the shortest
# (one sample each end), whatever the scene's own t_end.
_NO_TIME = 1e-300


@lru_cache(maxsize=None)
def _tutorial_event_kinds() -> tuple:
    return _words(_api.event_kind_names())


# Event classes of the core (1 impact, 2 rest, 3 release of a row; 4 stick, 5 slip of a body)
# and the words their names start with.
_ROW_PREFIXES = ("", "rest_", "release_")
_BODY_PREFIXES = ("stick", "slip")
# A kind is an impact unless it starts so (DESIGN: no contact name may start so).
_NOT_IMPACTS = tuple(p for p in _ROW_PREFIXES if p) + _BODY_PREFIXES


def is_impact_kind(kind) -> bool:
    """Whether an event kind is an impact (not a rest_, release_, stick or slip)."""
    return not str(kind).startswith(_NOT_IMPACTS)


@lru_cache(maxsize=64)
def _kind_table(row_name_codes: bytes, n_rows: int, n_bodies: int):
    """A run's 3 n_rows + 2 N event kinds, '<row>', 'rest_<row>', 'release_<row>',
    'stick<i>', 'slip<i>', then 'unknown', and where event (class, index) finds its kind
    (class 1 to 3 a row's, 4 and 5 a body's; rows' names as the core's codes, 32 a row): made
    once per layout (scenes come in series), not per call."""
    codes = np.frombuffer(row_name_codes, dtype=np.int32).reshape(n_rows, 32)
    row_names = [decode(row.astype(np.uint8).tobytes()) for row in codes]
    table = np.array([p + name for p in _ROW_PREFIXES for name in row_names]
                     + [f"{p}{i}" for p in _BODY_PREFIXES for i in range(1, n_bodies + 1)]
                     + ["unknown"], dtype=NBODY_EVENT_DTYPE["kind"])
    position = np.full((6, max(n_rows, n_bodies) + 1), len(table) - 1)
    for c in (1, 2, 3):
        position[c, 1:n_rows + 1] = (c - 1) * n_rows + np.arange(n_rows)
    for c in (4, 5):
        position[c, 1:n_bodies + 1] = 3 * n_rows + (c - 4) * n_bodies + np.arange(n_bodies)
    return table, position


def _event_names(event_class, event_index, row_name_codes, n_bodies) -> np.ndarray:
    """Each event's kind (_kind_table's names), one lookup per event; an event outside the
    run's rows and bodies is 'unknown'."""
    n_rows = row_name_codes.shape[1]
    table, position = _kind_table(np.ascontiguousarray(row_name_codes.T).tobytes(), n_rows, n_bodies)
    # (as unsigned, a negative class or index is out of range too: two comparisons, not four)
    known = (event_class.view(np.uint32) < 6) & (event_index.view(np.uint32) < position.shape[1])
    return table[np.where(known, position[event_class * known, event_index * known], len(table) - 1)]


def _empty():
    return np.empty(0, dtype=np.float64)


@dataclass
class Result:
    """One run: the samples as float64 arrays (one entry per output time), the event
    log, the run's accuracy monitor and the scene actually run. pe (the springs' potential
    energy) and damping_loss (what the dampers dissipated) are None for a scene without
    springs or dampers, drive_work (what a moving ground's prescribed motion did on the
    bodies) for a scene without one, and x2 and v2 for a one-body scene (no m2; its events then have no
    v2 fields either): `columns` names the columns the run has.

    `x` and `v` are (samples, len(bodies)) arrays of the positions and velocities of the
    bodies written (`bodies`: every body, or those of &run bodies_out), and `x1`, `v1`, ...
    `xN`, `vN` views of their columns (None for a body not written; beyond the second they
    are attributes, not fields). A scene of more than two bodies has events of
    NBODY_EVENT_DTYPE: t, kind, a, b, va_before, vb_before, va_after, vb_after."""

    t: np.ndarray = field(default_factory=_empty)
    x1: np.ndarray = field(default_factory=_empty)
    v1: np.ndarray = field(default_factory=_empty)
    x2: Optional[np.ndarray] = field(default_factory=_empty)
    v2: Optional[np.ndarray] = field(default_factory=_empty)
    ke: np.ndarray = field(default_factory=_empty)
    pe: Optional[np.ndarray] = None
    work: np.ndarray = field(default_factory=_empty)
    friction_loss: np.ndarray = field(default_factory=_empty)
    impact_loss: np.ndarray = field(default_factory=_empty)
    damping_loss: Optional[np.ndarray] = None
    drive_work: Optional[np.ndarray] = None
    residual: np.ndarray = field(default_factory=_empty)
    events: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=EVENT_DTYPE))
    energy_residual: float = 0.0       # max |residual| over the samples
    steps: Optional[int] = None        # integrator steps taken (None: read from a file)
    scene: Optional[Scene] = None
    # What the run should know but did not stop it, one sentence each (a step that is
    # coarse for the springs' fastest mode, with the error RK4 makes on it).
    warnings: tuple = ()
    # Whether `scene` holds the run's applied forces whole: False for an output file read
    # back without its scene (its header records every force value but not the force
    # tables' names); read_output(path, scene=...) makes it True.
    forces_known: bool = True
    # The bodies' positions and velocities, (samples, len(bodies)) (x1 ... are views of
    # their columns), and the body numbers of their columns; () for a Result made from the
    # tutorial's columns alone (x and v are then made from x1, x2 when asked for).
    x: Optional[np.ndarray] = None
    v: Optional[np.ndarray] = None
    bodies: tuple = ()

    def __post_init__(self):
        if self.x is None and self.x1 is not None:
            # (x2, v2 default to empty arrays: a body of no samples is not written)
            written = [i for i in (1, 2) if getattr(self, f"x{i}") is not None and
                       len(getattr(self, f"x{i}")) == len(self.x1)]
            self.x = np.column_stack([getattr(self, f"x{i}") for i in written])
            self.v = np.column_stack([getattr(self, f"v{i}") for i in written])
            self.bodies = tuple(written)

    def __getattr__(self, name):
        # x3, v3, ...: the columns of x and v of a body past the second (x1 .. v2 are fields)
        if name[:1] in ("x", "v") and name[1:].isdigit() and name[1:2] != "0":
            bodies = vars(self).get("bodies", ())
            body = int(name[1:])
            if body in bodies:
                return vars(self)[name[0]][:, bodies.index(body)]
            if body > 2 and body <= _body_count(vars(self).get("scene")):
                return None
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def columns(self) -> tuple:
        """The names of the columns this run has, in the core's order: t, x and v of each
        body written, then ke, [pe,] work, friction_loss, impact_loss, [damping_loss,]
        [drive_work,] residual (COLUMNS' order for one or two bodies)."""
        if not self.bodies:
            return tuple(name for name in COLUMNS if getattr(self, name) is not None)
        return ("t", *(f"{c}{i}" for i in self.bodies for c in "xv"),
                *(name for name in LEDGER if getattr(self, name) is not None))

    @property
    def samples(self) -> np.ndarray:
        """The run's sample columns as one (n, len(columns)) array, in `columns` order."""
        return np.column_stack([getattr(self, name) for name in self.columns])

    def to_dataframe(self):
        """The samples as a pandas DataFrame: one column per name in `columns`, in that
        order, one row per sample (the same float64 values)."""
        import pandas as pd

        return pd.DataFrame({name: getattr(self, name) for name in self.columns},
                            columns=list(self.columns))

    def events_frame(self):
        """The event log as a pandas DataFrame: one row per event, in order, with the
        columns of `events` (t, kind, v1_before, [v2_before,] v1_after[, v2_after])."""
        import pandas as pd

        return pd.DataFrame(self.events, columns=list(self.events.dtype.names))

    def __repr__(self) -> str:
        title = self.scene.title if self.scene is not None else None
        return (f"Result({title!r}: {len(self.t)} samples, {len(self.events)} events, "
                f"steps={self.steps}, energy_residual={self.energy_residual:.3g})")


def _lines(text) -> tuple:
    """The core's newline-separated texts as a tuple of sentences (none: ())."""
    return tuple(line for line in decode(text).split("\n") if line.strip())


def result_from_columns(samples: np.ndarray, events: np.ndarray, names=COLUMNS, **extra) -> Result:
    """Build a Result from an (n, len(names)) sample array whose columns are `names`
    (the core's order: t, x and v of each body written, the ledger; the optional ones may
    be missing)."""
    names = tuple(names)
    samples = np.asarray(samples, dtype=np.float64).reshape(-1, len(names))
    # Each column a contiguous view: as the core's column-major arrays already are (no
    # copy), a copy of a row-major table (np.loadtxt) otherwise. Absent columns are None.
    if samples.shape[0] > 1 and samples.strides[0] != samples.itemsize:
        samples = np.asfortranarray(samples)
    result = object.__new__(Result)
    _fill_result(vars(result), samples, names)
    vars(result).update(events=events, **{"energy_residual": 0.0, "steps": None, "scene": None,
                                          "warnings": (), "forces_known": True, **extra})
    return result


def _fill_result(columns: dict, samples: np.ndarray, names: tuple) -> None:
    """A Result's sample fields from the (rows, >= len(names)) column-major samples whose
    first columns are `names`: each a view of its column, x and v views of every other
    column from the first x (the core writes x1 v1 x2 v2 ...), x1 ... views of theirs."""
    fields, head, tail, tail_start, x, v = _result_layout(names)
    columns.update(fields)
    # (zip stops at the last name)
    columns.update(zip(head, samples.T))
    if tail:
        columns.update(zip(tail, samples.T[tail_start:]))
    columns["x"] = samples[:, x]
    columns["v"] = samples[:, v]


@lru_cache(maxsize=64)
def _result_layout(names: tuple):
    """What _fill_result does for the columns `names`, worked out once per layout: the
    fields that are no column's view (the absent columns None, `bodies`), the names of the
    columns that are fields (head: t, and x1 .. v2 of the bodies written, the columns they
    open with; tail: the ledger's, from column tail_start; () when head has them all), and
    the slices of x and v (x3 ...: __getattr__'s views of them)."""
    n_written = sum(1 for name in names if name[0] == "x")
    bodies = tuple(int(name[1:]) for name in names[1:2 * n_written:2])
    fields = {**_ABSENT, "bodies": bodies}
    head = names[:1 + 2 * sum(1 for body in bodies if body <= 2)]
    tail_start = 1 + 2 * n_written
    tail = names[tail_start:] if len(head) < tail_start else ()
    if not tail:
        head = names
    return fields, head, tail, tail_start, slice(1, 2 * n_written, 2), slice(2, 2 * n_written + 1, 2)


def _body_count(scene) -> int:
    """The bodies of a scene (a Scene, or its fields as a dict): its arrays' length; 2 if
    it has none (one body or two: the same full row)."""
    fields = scene if isinstance(scene, dict) else vars(scene) if scene is not None else {}
    m = fields.get("m")
    return len(m) if isinstance(m, (list, tuple)) else 2


_REAL_INDEX = {name: k for k, name in enumerate(REAL_FIELDS)}


def _make_form(scene: Scene, overrides: dict) -> CoreForm:
    """A scene with overrides in the core's form (core_form keeps it for the next call).
    Numbers for the tutorial's real fields of a flat scene (a fit's or a sweep's calls, each
    with new values) are put into the scene's own form; anything else is converted whole."""
    if overrides and overrides.keys() <= _REAL_INDEX.keys() and \
            all(isinstance(value, float) for value in overrides.values()):
        base = core_form(scene, {}, _make_form)
        if base.flat:
            return _with_reals(base, overrides)
    scene = _with_overrides(scene, overrides)
    form = CoreForm()
    form.core = to_core(scene)
    form.flat = not is_nbody_form(scene)
    form.records = record_assignments(scene) if form.flat or not _more_than_two(scene) else \
        _packed(*to_assignments(scene))
    if not form.flat and not _more_than_two(scene):
        # (one or two bodies written with arrays: the Result's scene is the one run, in the
        # tutorial's names, with its records; more bodies keep their arrays, which the
        # tutorial's names cannot hold and the N-body plots read: the links, the springs)
        scene = dataclasses.replace(from_core(*form.core, source=scene.source), **record_fields(scene))
    texts = form.core[2:]
    form.blob = b"".join(texts) or b" "           # (f2py refuses an empty string)
    form.text_end = np.array(list(itertools.accumulate(map(len, texts))), dtype=np.int32)
    form.fields = vars(scene)
    form.sample_capacity = _sample_capacity(scene)
    form.row_length = row_length(_body_count(form.fields))
    return form


def _more_than_two(scene: Scene) -> bool:
    """A scene written with arrays of more than two bodies: it goes to the core whole, as
    assignments (one or two bodies go as the tutorial's fields)."""
    masses = vars(scene).get("m")
    return masses is not None and not isinstance(masses, (int, float)) and len(masses) > 2


def _with_reals(base: CoreForm, overrides: dict) -> CoreForm:
    """`base` with real fields set to the overrides' floats (to_core's values: a float is
    stored as the same double)."""
    form = CoreForm()
    values, given = base.core[0].copy(), base.core[1].copy()
    for name, value in overrides.items():
        values[_REAL_INDEX[name]] = value
        given[_REAL_INDEX[name]] = 1
    form.core = (values, given, *base.core[2:])
    form.blob, form.text_end, form.flat, form.records = base.blob, base.text_end, True, base.records
    form.row_length = base.row_length
    form.fields = {**base.fields, **overrides}
    run_scene = object.__new__(Scene)
    vars(run_scene).update(form.fields)
    form.sample_capacity = _sample_capacity(run_scene)
    return form


def simulate(scene: Scene, *, progress: bool = False, _interrupt_epoch: Optional[int] = None,
             **overrides) -> Result:
    """Run `scene` with keyword overrides of any Scene field (typically dt, t_end,
    dt_out, method; None makes a field absent).  Raises InputError for a bad scene
    and SimulationError for a run that cannot go on.  With progress=True a run that
    takes more than a second shows a progress line on stderr, as the CLI does.
    (_interrupt_epoch: a sweep's, for the runs its workers start: interrupt_epoch_now.)"""
    # Taken before the core call: an interrupt after this line ends the run (one in the
    # call's own set-up, before the run took the count, did not).
    epoch = interrupt_epoch_now() if _interrupt_epoch is None else _interrupt_epoch
    if not isinstance(scene, Scene):
        raise InputError(f"simulate() needs an impact1d.Scene, got {type(scene).__name__}")
    if not overrides.keys() <= _OVERRIDABLE_SET:
        unknown = [name for name in overrides if name not in _OVERRIDABLE]
        raise InputError(f"unknown scene field(s) in overrides: {', '.join(unknown)} "
                         f"(known: {', '.join(_OVERRIDABLE)})")
    form = core_form(scene, overrides, _make_form)
    handle = _prepared(form)
    progress = 1 if progress else 0
    # The samples are made for this call (the Result's columns are views of them); the rest
    # is the thread's buffers, read out below (so threads may run at once).
    buffers = _buffers
    outputs = buffers.outputs
    # (columns: the full row of the scene's bodies, has_column as long; N is the core's)
    samples = np.empty((form.sample_capacity, form.row_length), dtype=np.float64, order="F")
    while True:
        if len(outputs[0]) != samples.shape[1]:
            buffers.columns(samples.shape[1])
            outputs = buffers.outputs
        if handle:
            _api.run_prepared(handle, progress, samples, *outputs, epoch)
        else:
            _api.simulate(form.core[0], form.core[1], form.blob, form.text_end, *form.records, progress,
                          samples, *outputs, interrupt_epoch=epoch)
        status, n_samples, n_events, n_rows, steps, message_length, warnings_length, n_bodies = \
            outputs[4].tolist()
        if status != _STATUS_TOO_SMALL:
            break
        n_columns = max(row_length(n_bodies), samples.shape[1])
        if n_samples > samples.shape[0] or n_columns > samples.shape[1]:
            samples = np.empty((max(n_samples, samples.shape[0]), n_columns), dtype=np.float64, order="F")
        buffers.make(max(n_events, buffers.event_int.shape[0]), max(n_rows, buffers.row_name_codes.shape[1]))
        outputs = buffers.outputs
    has_column, _, event_int, row_name_codes, _, energy_residual, text_codes = outputs
    if status:
        raise_for_status(status, _codes_text(text_codes[:message_length, 0]))
    # (a form's columns are its scene's: the core's has_column read once per form)
    names = form.names
    if names is None:
        names = form.names = _column_layout(has_column[:row_length(n_bodies)].tobytes(), n_bodies)
    events = np.empty(n_events, dtype=event_dtype(n_bodies))
    if n_events > 0:
        _fill_events(events, buffers, n_events, n_rows, n_bodies)
        if form.fields.get("frictions"):
            _name_pair_events(events, buffers.event_int[:n_events], n_rows, form.fields["frictions"])
    if event_int.shape[0] > _EVENT_CAPACITY_KEPT:
        buffers.make(_EVENT_CAPACITY, row_name_codes.shape[1])
    # The Result and its scene made without their dataclass __init__ (every field set here,
    # the scene's copied whole): a short run's time.
    columns = {}
    _fill_result(columns, samples if n_samples == len(samples) else samples[:n_samples], names)
    run_scene = object.__new__(Scene)
    run_scene.__dict__ = form.fields.copy()
    columns.update(events=events, energy_residual=float(energy_residual[0]), steps=steps,
                   scene=run_scene, forces_known=True,
                   warnings=_lines(_codes_text(text_codes[:warnings_length, 1])) if warnings_length else ())
    result = object.__new__(Result)
    result.__dict__ = columns
    return result


# Guards a form's handle while it changes (a form two threads run at once keeps one prepared
# scene).
_PREPARING = threading.Lock()


def _prepared(form: CoreForm) -> int:
    """The core's prepared scene to run `form` with, or 0 to set it up whole: a form's first
    run sets it up whole (most forms of a fit or a sweep run once), its second prepares it
    (the core validates and builds it once: impact1d_prepared), and later runs use that."""
    handle = form.handle
    if handle >= 0:
        return handle
    with _PREPARING:
        if form.handle == CoreForm.FRESH:
            form.handle = CoreForm.RUN_ONCE
            return 0
        if form.handle != CoreForm.RUN_ONCE:
            return form.handle
    # (the set-up releases the GIL, as a run's does: a large scene's takes a while)
    handle = int(_api.prepare(form.core[0], form.core[1], form.blob, form.text_end, *form.records))
    with _PREPARING:
        if form.handle == CoreForm.RUN_ONCE:
            form.handle = handle
            return handle
    if handle > 0:
        form._release(handle)       # (another thread prepared the form meanwhile)
    return form.handle


def _codes_text(codes) -> bytes:
    """The api's character codes (int32) as bytes."""
    return codes.astype(np.uint8).tobytes()


# The core's classes of a friction contact's stick and slip (&friction j: index n_rows + j).
_PAIR_CLASSES = ((6, "stick_"), (7, "slip_"))


def _name_pair_events(events, event_int, n_rows, frictions) -> None:
    """The kinds of the friction contacts' events, 'stick_<name>' and 'slip_<name>' (the
    record's name, else 'friction<j>')."""
    names = [record.get("name") or f"friction{j}" for j, record in enumerate(frictions, 1)]
    for event_class, prefix in _PAIR_CLASSES:
        for k in np.flatnonzero(event_int[:, 0] == event_class):
            events["kind"][k] = prefix + names[event_int[k, 1] - n_rows - 1]


def _fill_events(events, buffers, n_events, n_rows, n_bodies) -> None:
    """The event log from the core's event arrays (the kinds named by _event_names): one or
    two bodies' velocities (the pair is (1, 2), or (1, 0)), or the pair and theirs."""
    event_real, event_int = buffers.event_real, buffers.event_int
    events["t"] = event_real[:n_events, 0]
    events["kind"] = _event_names(event_int[:n_events, 0], event_int[:n_events, 1],
                                  buffers.row_name_codes[:, :n_rows], n_bodies)
    if n_bodies > 2:
        events["a"], events["b"] = event_int[:n_events, 2], event_int[:n_events, 3]
        for k, name in enumerate(("va_before", "vb_before", "va_after", "vb_after"), 1):
            events[name] = event_real[:n_events, k]
        return
    events["v1_before"], events["v1_after"] = event_real[:n_events, 1], event_real[:n_events, 3]
    if n_bodies == 2:
        events["v2_before"], events["v2_after"] = event_real[:n_events, 2], event_real[:n_events, 4]
