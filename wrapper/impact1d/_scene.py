"""The Scene dataclass, the package's exceptions and the glue to the Fortran reader.

One parser and one validator, both in Fortran (impact1d._core): this module only
moves values between a Scene and the flat arrays of the api layer.
"""

from __future__ import annotations

import dataclasses
import marshal
import os
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from . import _core

# f2py wraps the routines of the Fortran module impact1d_api as _core.impact1d_api.
_api = getattr(_core, "impact1d_api", _core)

__all__ = ["Scene", "InputError", "SimulationError", "load_scene",
           "REAL_FIELDS", "TEXT_FIELDS", "ARRAY_FIELDS", "CONTACT_FIELDS", "SPRING_FIELDS"]


class InputError(ValueError):
    """A scene or an argument is invalid (api status 1)."""


class SimulationError(RuntimeError):
    """A run could not go on (api status 2)."""


# Room load_scene first gives the core for each text (title, table paths, method); a
# longer one makes the core say how long, and the call is repeated with that room.
TEXT_ROOM = 1024
# The api's status for "the arrays given were too small" (it returns the sizes needed).
STATUS_TOO_SMALL = 3

# The api's field order, written out so that the dataclass below is static and
# readable; checked against _api.field_names() at import (one source of truth).
REAL_FIELDS = (
    "m1", "m2", "mu1", "mu2", "g",
    "x_left", "r_left", "x_right", "r_right",
    "d_min", "r_min", "d_max", "r_max",
    "x1", "v1", "x2", "v2",
    "f1", "f2", "f1_amp", "f1_period", "f1_phase", "f2_amp", "f2_period", "f2_phase",
    "t_end", "dt", "dt_out", "zero_vel", "max_rows", "max_impulses", "max_step_events",
    "mus1", "mus2", "k1", "x1_rest", "c1", "k2", "x2_rest", "c2", "k12", "d_rest", "c12",
    "max_events",
    "x_left_v", "x_left_amp", "x_left_period", "x_left_phase",
    "x_right_v", "x_right_amp", "x_right_period", "x_right_phase",
)
TEXT_FIELDS = ("title", "f1_table", "f2_table", "method", "substeps", "events", "x_left_table", "x_right_table")
# The N-body scene (DESIGN "Mechanisms as data"): arrays (body i's value at i; the &link
# ones and k_link, d_rest, c_link one per neighbour pair), &link r_meet, and the fields of
# the &contact, &spring, &sine and &friction records. Checked against _api.input_field_names() at import.
ARRAY_FIELDS = ("m", "mu", "mus", "x", "v", "f", "f_amp", "f_period", "f_phase", "k", "x_rest", "c",
                "d_min", "r_min", "d_max", "r_max", "k_link", "d_rest", "c_link", "f_table",
                "belt_v", "v_s", "c_v", "belt_amp", "belt_period", "belt_phase")
# The friction laws' arrays (DESIGN "Laws added on the records"; belt_amp, belt_period,
# belt_phase, a belt's sine speed, are an addition named as the ground's motion is): arrays
# for any N, with no tutorial name; they go to the core with the records (record_fields).
LAW_FIELDS = ("belt_v", "v_s", "c_v", "belt_amp", "belt_period", "belt_phase")
# A record with a ground end (a or b = 0) may move it: GROUND_FIELDS (DESIGN "Laws added");
# ground_table is the path of a (t, w) table, read as a force table is.
GROUND_FIELDS = ("ground_v", "ground_amp", "ground_period", "ground_phase", "ground_table")
# A gear ratio n on a contact or spring (DESIGN "Laws added"): it acts on x_b - n x_a.
CONTACT_FIELDS = ("a", "b", "d_min", "r_min", "d_max", "r_max", "name", "k", "c") + GROUND_FIELDS + ("ratio",)
SPRING_FIELDS = ("a", "b", "k", "d_rest", "c") + GROUND_FIELDS + ("ratio",)
# The records' fields that are texts.
_RECORD_TEXT_FIELDS = ("name", "ground_table")
SINE_FIELDS = ("body", "amp", "period", "phase")
# A friction contact between bodies a and b under a constant normal load (DESIGN "Laws added").
FRICTION_FIELDS = ("a", "b", "mu", "mus", "normal", "name")
# The record groups: Scene field, the core's prefix of its fields, the fields.
_RECORD_GROUPS = (("contacts", "contact.", CONTACT_FIELDS), ("springs", "spring.", SPRING_FIELDS),
                  ("sines", "sine.", SINE_FIELDS), ("frictions", "friction.", FRICTION_FIELDS))
_RECORD_NAMES = tuple(group for group, _, _ in _RECORD_GROUPS)
# Record fields that are body numbers (whole numbers, as ints in a Scene).
_BODY_NUMBER_FIELDS = ("a", "b", "body")
# Array fields that are also the tutorial's scalars (d_min is d_min(1)): a sequence given
# for one of these is the array.
_SHARED_FIELDS = ("d_min", "r_min", "d_max", "r_max", "d_rest")


@dataclass
class Scene:
    """A scene: fields named as the namelist variables; None means absent.

    Absent constraints do not exist; absent optional values take the engine's
    defaults (docs/formats.md).  `source` is the file the scene came from (for titles).
    Table paths from load_scene are already resolved against the scene's folder.

    N bodies (docs/formats.md, "Scenes of N bodies"): the arrays (`m=[...]`, `x=[...]`,
    ..., and `d_min`, `r_min`, `d_max`, `r_max`, `d_rest` given as sequences), `r_meet`,
    and `contacts` / `springs` / `sines` / `frictions`: lists of dicts with the &contact /
    &spring / &sine / &friction fields (`{"a": 0, "b": 3, "d_min": -1.0, "name": "stop3"}`,
    `{"body": 1, "amp": 2.0, "period": 0.5}`, `{"a": 1, "b": 2, "mu": 0.3, "normal": 9.81}`; a gear
    ratio on a contact or spring, `{"a": 1, "b": 2, "d_min": -0.01, "d_max": 0.01, "ratio": 3.0}`,
    acts on x_b - ratio x_a). One or two bodies given so run as the tutorial's names, with
    their records; more wait for the N-body engine (InputError).
    """

    m1: Optional[float] = None
    m2: Optional[float] = None
    mu1: Optional[float] = None
    mu2: Optional[float] = None
    g: Optional[float] = None
    x_left: Optional[float] = None
    r_left: Optional[float] = None
    x_right: Optional[float] = None
    r_right: Optional[float] = None
    d_min: Optional[float] = None
    r_min: Optional[float] = None
    d_max: Optional[float] = None
    r_max: Optional[float] = None
    x1: Optional[float] = None
    v1: Optional[float] = None
    x2: Optional[float] = None
    v2: Optional[float] = None
    f1: Optional[float] = None
    f2: Optional[float] = None
    f1_amp: Optional[float] = None
    f1_period: Optional[float] = None
    f1_phase: Optional[float] = None
    f2_amp: Optional[float] = None
    f2_period: Optional[float] = None
    f2_phase: Optional[float] = None
    t_end: Optional[float] = None
    dt: Optional[float] = None
    dt_out: Optional[float] = None
    zero_vel: Optional[float] = None
    max_rows: Optional[float] = None
    max_impulses: Optional[float] = None
    max_step_events: Optional[float] = None
    mus1: Optional[float] = None
    mus2: Optional[float] = None
    k1: Optional[float] = None
    x1_rest: Optional[float] = None
    c1: Optional[float] = None
    k2: Optional[float] = None
    x2_rest: Optional[float] = None
    c2: Optional[float] = None
    k12: Optional[float] = None
    d_rest: Optional[float] = None
    c12: Optional[float] = None
    max_events: Optional[float] = None   # events the log keeps (default 10^7); counts stay exact
    # The walls' prescribed motion, added to x_left / x_right (docs/formats.md): v t +
    # amp sin(2 pi t / period + phase).
    x_left_v: Optional[float] = None
    x_left_amp: Optional[float] = None
    x_left_period: Optional[float] = None
    x_left_phase: Optional[float] = None
    x_right_v: Optional[float] = None
    x_right_amp: Optional[float] = None
    x_right_period: Optional[float] = None
    x_right_phase: Optional[float] = None
    title: Optional[str] = None
    f1_table: Optional[str] = None
    f2_table: Optional[str] = None
    method: Optional[str] = None
    substeps: Optional[str] = None     # 'auto': dt divided for springs coarse at dt
    events: Optional[str] = None       # 'all' (default), 'impacts' or 'none': what the log keeps
    # The walls' tables (paths, read as force tables are), added to x_left / x_right.
    x_left_table: Optional[str] = None
    x_right_table: Optional[str] = None
    source: Optional[str] = None
    m: Optional[Sequence[float]] = None
    mu: Optional[Sequence[float]] = None
    mus: Optional[Sequence[float]] = None
    x: Optional[Sequence[float]] = None
    v: Optional[Sequence[float]] = None
    f: Optional[Sequence[float]] = None
    f_amp: Optional[Sequence[float]] = None
    f_period: Optional[Sequence[float]] = None
    f_phase: Optional[Sequence[float]] = None
    k: Optional[Sequence[float]] = None
    x_rest: Optional[Sequence[float]] = None
    c: Optional[Sequence[float]] = None
    k_link: Optional[Sequence[float]] = None
    c_link: Optional[Sequence[float]] = None
    f_table: Optional[Sequence[Optional[str]]] = None
    belt_v: Optional[Sequence[float]] = None  # each body's friction surface velocity (m/s; any N)
    v_s: Optional[Sequence[float]] = None     # Stribeck velocity (m/s): mu(u) = mu + (mus - mu) exp(-(u/v_s)^2) + c_v |u|
    c_v: Optional[Sequence[float]] = None     # viscous friction coefficient (s/m)
    # a belt's sine speed: V(t) = belt_v + belt_amp sin(2 pi t / belt_period + belt_phase)
    belt_amp: Optional[Sequence[float]] = None     # m/s
    belt_period: Optional[Sequence[float]] = None  # s
    belt_phase: Optional[Sequence[float]] = None   # rad
    r_meet: Optional[float] = None
    contacts: Optional[Sequence[dict]] = None
    springs: Optional[Sequence[dict]] = None
    sines: Optional[Sequence[dict]] = None     # &sine records: {"body", "amp", "period", "phase"}
    frictions: Optional[Sequence[dict]] = None  # &friction records: {"a", "b", "mu", "mus", "normal", "name"}
    bodies_out: Optional[Sequence[int]] = None  # &run bodies_out: the bodies whose x, v a run keeps


def decode(text) -> str:
    """Fortran text from f2py (bytes, numpy bytes or a char array) -> stripped str."""
    if isinstance(text, np.ndarray):
        text = text.tobytes()
    if isinstance(text, (bytes, np.bytes_)):
        text = bytes(text).decode("utf-8", errors="replace")
    return str(text).replace("\x00", " ").strip()


def _words(text) -> tuple:
    return tuple(decode(text).split())


# Every input field as the core numbers them (id k: the k-th name).
INPUT_FIELDS = REAL_FIELDS + TEXT_FIELDS + ARRAY_FIELDS + ("r_meet",) + \
    tuple(prefix + name for _, prefix, fields in _RECORD_GROUPS for name in fields) + ("bodies_out",)


def _check_field_order() -> None:
    reals, texts = _api.field_names()
    if _words(reals) != REAL_FIELDS or _words(texts) != TEXT_FIELDS or \
            _words(_api.input_field_names()) != INPUT_FIELDS:
        raise ImportError(
            "impact1d._core field names do not match impact1d.Scene: "
            f"core has {_words(reals)} / {_words(texts)} / {_words(_api.input_field_names())}")


_check_field_order()
_SCENE_FIELDS = tuple(f.name for f in dataclasses.fields(Scene))
# (the N-body fields after source: positional Scene(...) calls keep their meaning)
_NBODY_FIELDS = tuple(name for name in ARRAY_FIELDS if name not in _SHARED_FIELDS) + \
    ("r_meet", "contacts", "springs", "sines", "frictions")
# (what a run writes, whatever the scene's form; it goes to the core with the records)
_OUTPUT_FIELDS = ("bodies_out",)
assert _SCENE_FIELDS == REAL_FIELDS + TEXT_FIELDS + ("source",) + _NBODY_FIELDS + _OUTPUT_FIELDS
# Field ids: the scalars' and texts' by name, the arrays' apart (d_min is both).
_ID = {name: k + 1 for k, name in reversed(list(enumerate(INPUT_FIELDS)))}
_ARRAY_ID = {name: len(REAL_FIELDS + TEXT_FIELDS) + k + 1 for k, name in enumerate(ARRAY_FIELDS)}


def _fortran_text(value) -> bytes:
    # The api takes character(len=*), of any length, and keeps it whole. Text goes as
    # UTF-8 bytes (f2py accepts only ASCII str), as the CLI reads it from files.
    return b"" if value is None else os.fsencode(value) if isinstance(value, os.PathLike) \
        else str(value).encode("utf-8", errors="surrogateescape")


def _is_sequence(value) -> bool:
    return isinstance(value, (list, tuple, np.ndarray))


def is_nbody_form(scene: Scene) -> bool:
    """Whether the scene is written with arrays or records (DESIGN's N-body form)."""
    fields = vars(scene)
    return any(fields.get(name) is not None for name in _NBODY_FIELDS) or \
        any(_is_sequence(fields.get(name)) for name in _SHARED_FIELDS)


def to_core(scene: Scene):
    """Scene -> (values, given, *texts in TEXT_FIELDS order) for the api. A scene written
    with arrays or records is settled by the core first (settle_scene): one or two bodies
    come back in the tutorial's fields, anything else is its InputError."""
    if is_nbody_form(scene):
        return _settled(scene)
    fields = vars(scene)
    reals = [fields[name] for name in REAL_FIELDS]
    given = np.array([value is not None for value in reals], dtype=np.int32)
    try:
        values = np.array([0.0 if value is None else value for value in reals], dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        values = None
    if values is None or values.shape != (len(REAL_FIELDS),):
        # Name the field that is not a number (or an int beyond any double: 10**400).
        for name, value in zip(REAL_FIELDS, reals):
            try:
                float(value if value is not None else 0.0)
            except OverflowError:
                raise InputError(f"{name} = {value!r:.40} is too large for a double "
                                 "(largest 1.8e308)") from None
            except (TypeError, ValueError):
                raise InputError(f"{name} must be a number, got {value!r}") from None
        raise InputError("scene fields must be numbers")
    texts = []
    for name in TEXT_FIELDS:
        value = fields[name]
        if value is not None and not isinstance(value, (str, os.PathLike)):
            raise InputError(f"{name} must be text, got {value!r}")
        texts.append(_fortran_text(value))
    return (values, given, *texts)


class CoreForm:
    """A scene (with its overrides) as the core takes it, made once: `core` is to_core's
    (values, given, *texts), `blob` and `text_end` the texts as simulate takes them,
    `fields` the Scene fields of the scene run (Result.scene), `sample_capacity` the rows
    its run will emit, `flat` whether the scene is in the tutorial's fields (not settled
    from arrays or records), `records` its &contact and &spring records as simulate takes
    them (record_assignments), `row_length` the core's full row of its bodies, `names` the
    columns its runs have (once one ran). `handle`:
    the core's prepared scene (impact1d_prepared) once the form runs a second time, freed
    with the form (FRESH before its first run, RUN_ONCE after it, 0 when the core does not
    prepare it: simulate sets it up whole each run)."""

    __slots__ = ("core", "blob", "text_end", "fields", "sample_capacity", "flat", "records", "row_length",
                 "handle", "names")

    # (a handle is the entry's address: positive, as user-space addresses are)
    FRESH, RUN_ONCE = -2, -1
    _release = staticmethod(_api.release_prepared)

    def __init__(self):
        self.handle = CoreForm.FRESH
        self.names = None          # (the run's column names: simulate's, after its first run)

    def __del__(self):
        # (the form goes when the cache drops it and no run holds it: a run in another
        # thread keeps its form, so the core never frees a scene while it runs)
        if self.handle > 0:
            self._release(self.handle)


# Core forms by the scene's field values and the overrides (marshal's bytes, version 2: each
# value's type and bits, so -0.0 is not 0.0, and a list's items as they are now, mutated or
# not): a scene run again with the same values is not converted again. A value marshal
# cannot write (a path object, a numpy scalar) makes the form afresh each call.
_CORE_FORMS: dict = {}
_CORE_FORMS_MAX = 256


def core_form(scene: Scene, overrides: dict, make) -> CoreForm:
    """The CoreForm of `scene` with `overrides` (known Scene fields): from the cache when a
    scene had these values before, else make(scene, overrides) (not kept when it raises)."""
    try:
        key = marshal.dumps((tuple(vars(scene).values()), overrides), 2)
    except ValueError:
        return make(scene, overrides)
    form = _CORE_FORMS.get(key)
    if form is None:
        form = make(scene, overrides)
        if len(_CORE_FORMS) >= _CORE_FORMS_MAX:
            _CORE_FORMS.clear()        # (a sweep of many variants: start again)
        _CORE_FORMS[key] = form
    return form


def _number(name, value) -> float:
    try:
        number = float(value)
    except OverflowError:
        raise InputError(f"{name} = {value!r:.40} is too large for a double (largest 1.8e308)") from None
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    return number


def _text(name, value) -> bytes:
    if value is not None and not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{name} must be text, got {value!r}")
    return _fortran_text(value)


def _records(name, records, fields):
    if not _is_sequence(records) or not all(isinstance(r, dict) for r in records):
        raise InputError(f"{name} must be a list of dicts with the fields {', '.join(fields)}, got {records!r:.80}")
    for j, record in enumerate(records, start=1):
        unknown = [key for key in record if key not in fields]
        if unknown:
            raise InputError(f"{name}[{j - 1}] has no field {unknown[0]!r} (fields: {', '.join(fields)})")
        yield j, record


def to_assignments(scene: Scene):
    """Scene -> the core's assignments: (field ids, indices, values), (text ids, indices,
    texts) in the numbering of INPUT_FIELDS (index 0 a scalar, else the element or record)."""
    numbers, texts = [], []
    for name, value in vars(scene).items():
        if value is None or name in ("source",) + _RECORD_NAMES:
            continue
        if name in _OUTPUT_FIELDS:
            numbers += _body_list(name, value)
            continue
        if name in ARRAY_FIELDS and (_is_sequence(value) or name not in _SHARED_FIELDS):
            if not _is_sequence(value):
                raise InputError(f"{name} must be a list (one value per body or link), got {value!r:.80}")
            for i, item in enumerate(value, start=1):
                if name == "f_table":
                    texts.append((_ARRAY_ID[name], i, _text(f"{name}[{i - 1}]", item)))
                else:
                    numbers.append((_ARRAY_ID[name], i, _number(f"{name}[{i - 1}]", item)))
        elif name in TEXT_FIELDS:
            texts.append((_ID[name], 0, _text(name, value)))
        else:
            numbers.append((_ID[name], 0, _number(name, value)))
    for group, prefix, fields in _RECORD_GROUPS:
        for j, record in _records(group, getattr(scene, group) or [], fields):
            for key, value in record.items():
                if value is None:
                    continue
                if key in _RECORD_TEXT_FIELDS:
                    texts.append((_ID[prefix + key], j, _text(f"{group}[{j - 1}].name", value)))
                else:
                    numbers.append((_ID[prefix + key], j, _number(f"{group}[{j - 1}].{key}", value)))
    return numbers, texts


def _body_list(name, value):
    """bodies_out = [1, 10, 20] as assignments (element i: a body number; the core checks
    them against the scene, as the namelist's)."""
    if not _is_sequence(value) or any(isinstance(item, bool) or float(_number(name, item)) != int(_number(name, item))
                                      for item in value):
        raise InputError(f"{name} must be a list of body numbers (bodies_out=[1, 10, 20]), got {value!r:.80}")
    if len(value) == 0:
        raise InputError(f"{name} names no body (None: every body)")      # (the core's words)
    return [(_ID[name], i, float(item)) for i, item in enumerate(value, start=1)]


def _packed(numbers, texts):
    """Assignments as the api takes them: (n_numbers, n_texts, ids, indices, values, text
    ids, text indices, text ends, text blob)."""
    # (one unused row at the end: f2py refuses arrays of no element)
    ids, index, values = (np.array(column + (0,), dtype=dtype) for column, dtype in
                          zip(tuple(zip(*numbers)) or ((), (), ()), (np.int32, np.int32, np.float64)))
    text_ids, text_index, blobs = tuple(zip(*texts)) or ((), (), ())
    ends = np.array(np.cumsum([len(b) for b in blobs], dtype=np.int64).tolist() + [0], dtype=np.int32)
    return (len(numbers), len(texts), ids, index, values, np.array(text_ids + (0,), dtype=np.int32),
            np.array(text_index + (0,), dtype=np.int32), ends, b"".join(blobs) or b" ")


def record_assignments(scene: Scene):
    """The scene's &contact, &spring and &sine records as the api's simulate takes them
    (_packed; none: counts 0). The rest of the scene goes as to_core's flat fields."""
    records = record_fields(scene)
    if not records:
        return _NO_RECORDS      # (a run of 50 us spent 9 us packing nothing)
    numbers, texts = to_assignments(Scene(**records))
    return _packed(numbers, texts)


_NO_RECORDS = _packed([], [])


def record_fields(scene: Scene) -> dict:
    """The scene's record lists that are given ({"contacts": [...], ...}; {} for none), its
    bodies_out, and the friction laws' arrays (which go to the core with them, whatever the
    scene's form: they have no tutorial name)."""
    fields = vars(scene)
    return {name: fields[name] for name in _RECORD_NAMES + _OUTPUT_FIELDS + LAW_FIELDS if fields[name] is not None}


def _settled(scene: Scene):
    """The core's settle_scene: the scene as the tutorial's flat fields, or its InputError
    (its records are checked, and go to simulate apart: record_assignments)."""
    numbers, texts = to_assignments(scene)
    room = max([len(text) for _, _, text in texts] + [1])
    values_out, given, codes, lengths, status, message = _api.settle_scene(
        *_packed(numbers, texts), len(REAL_FIELDS), room)
    raise_for_status(status, message)
    out = [bytes(np.asarray(codes[:lengths[k], k], dtype=np.uint8)) for k in range(len(TEXT_FIELDS))]
    return (np.asarray(values_out, dtype=np.float64), np.asarray(given, dtype=np.int32), *out)


def from_core(values, given, *texts, source=None) -> Scene:
    """to_core's flat fields -> the Scene in the tutorial's names (how a scene written with
    arrays of one or two bodies runs: the Result's scene, which the plots read)."""
    fields = {name: (float(values[i]) if given[i] else None) for i, name in enumerate(REAL_FIELDS)}
    fields.update((name, text.decode("utf-8", errors="surrogateescape") or None)
                  for name, text in zip(TEXT_FIELDS, texts))
    return Scene(**fields, source=source)


# The api's status for a run that an interrupt (SIGINT) ended.
_STATUS_INTERRUPTED = 4


def raise_for_status(status, message) -> None:
    """Turn an api status and message into the package's exceptions."""
    status = int(status)
    if status == 0:
        return
    text = decode(message) or f"impact1d core returned status {status}"
    if status == _STATUS_INTERRUPTED:
        # Ctrl-C ended the run (the core saw SIGINT at a checkpoint); Python's own handler
        # has usually raised already by the time this line runs.
        raise KeyboardInterrupt(text)
    if status == 1:
        raise InputError(text)
    raise SimulationError(text)


def load_scene(path) -> Scene:
    """Read a scene file: a namelist (.nml, or any other name) or a VisSim .dat file."""
    from ._files import check_input      # here: _files needs this module's InputError

    path = os.fspath(path)
    check_input(path, "scene file")
    room, numbers, texts = TEXT_ROOM, 64, 16
    while True:
        (ids, index, values, text_ids, text_index, codes, lengths, n_numbers, n_texts,
         status, message) = _api.read_scene(os.fsencode(path), numbers, texts, room)
        if int(status) != STATUS_TOO_SMALL or (n_numbers <= numbers and n_texts <= texts
                                               and int(max(lengths, default=0)) <= room):
            break
        # More than the room given: again, with what the core says it needs.
        numbers, texts = max(numbers, int(n_numbers)), max(texts, int(n_texts))
        room = max(room, int(max(lengths, default=0)))
    raise_for_status(status, message)
    kwargs = {}
    for k in range(int(n_numbers)):
        _put(kwargs, INPUT_FIELDS[ids[k] - 1], int(index[k]), float(values[k]))
    for k in range(int(n_texts)):
        text = decode(np.asarray(codes[:lengths[k], k], dtype=np.uint8).tobytes())
        _put(kwargs, INPUT_FIELDS[text_ids[k] - 1], int(text_index[k]), text or None)
    return Scene(**kwargs, source=path)


def _put(kwargs: dict, name: str, index: int, value) -> None:
    """One assignment from the core into Scene keyword arguments."""
    if index == 0:
        kwargs[name] = value
    elif "." in name:
        group, key = name.split(".")
        records = kwargs.setdefault(group + "s", [])
        records.extend({} for _ in range(index - len(records)))
        records[index - 1][key] = int(value) if key in _BODY_NUMBER_FIELDS else value
    else:
        array = kwargs.setdefault(name, [])
        array.extend(None for _ in range(index - len(array)))
        array[index - 1] = int(value) if name in _OUTPUT_FIELDS else value
