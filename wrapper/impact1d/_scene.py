"""The Scene dataclass, the package's exceptions and the glue to the Fortran reader.

One parser and one validator, both in Fortran (impact1d._core): this module only
moves values between a Scene and the flat arrays of the api layer.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from typing import Optional

import numpy as np

from . import _core

# f2py wraps the routines of the Fortran module impact1d_api as _core.impact1d_api.
_api = getattr(_core, "impact1d_api", _core)

__all__ = ["Scene", "InputError", "SimulationError", "load_scene",
           "REAL_FIELDS", "TEXT_FIELDS"]


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
)
TEXT_FIELDS = ("title", "f1_table", "f2_table", "method", "substeps", "events")


@dataclass
class Scene:
    """A scene: fields named as the namelist variables; None means absent.

    Absent constraints do not exist; absent optional values take the engine's
    defaults (docs/formats.md).  `source` is the file the scene came from (for titles).
    Table paths from load_scene are already resolved against the scene's folder.
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
    title: Optional[str] = None
    f1_table: Optional[str] = None
    f2_table: Optional[str] = None
    method: Optional[str] = None
    substeps: Optional[str] = None     # 'auto': dt divided for springs coarse at dt
    events: Optional[str] = None       # 'all' (default), 'impacts' or 'none': what the log keeps
    source: Optional[str] = None


def decode(text) -> str:
    """Fortran text from f2py (bytes, numpy bytes or a char array) -> stripped str."""
    if isinstance(text, np.ndarray):
        text = text.tobytes()
    if isinstance(text, (bytes, np.bytes_)):
        text = bytes(text).decode("utf-8", errors="replace")
    return str(text).replace("\x00", " ").strip()


def _words(text) -> tuple:
    return tuple(decode(text).split())


def _check_field_order() -> None:
    reals, texts = _api.field_names()
    if _words(reals) != REAL_FIELDS or _words(texts) != TEXT_FIELDS:
        raise ImportError(
            "impact1d._core field names do not match impact1d.Scene: "
            f"core has {_words(reals)} / {_words(texts)}")


_check_field_order()
_SCENE_FIELDS = tuple(f.name for f in dataclasses.fields(Scene))
assert _SCENE_FIELDS == REAL_FIELDS + TEXT_FIELDS + ("source",)


def _fortran_text(value) -> bytes:
    # The api takes character(len=*), of any length, and keeps it whole. Text goes as
    # UTF-8 bytes (f2py accepts only ASCII str), as the CLI reads it from files.
    return b"" if value is None else os.fsencode(value) if isinstance(value, os.PathLike) \
        else str(value).encode("utf-8", errors="surrogateescape")


def to_core(scene: Scene):
    """Scene -> (values, given, *texts in TEXT_FIELDS order) for the api."""
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
    room = TEXT_ROOM
    while True:
        (values, given, codes, lengths,
         status, message) = _api.read_scene(os.fsencode(path), len(REAL_FIELDS), room)
        if int(status) != STATUS_TOO_SMALL or int(max(lengths)) <= room:
            break
        room = int(max(lengths))        # a text longer than the room: again, with its length
    raise_for_status(status, message)
    kwargs = {name: (float(values[i]) if given[i] else None)
              for i, name in enumerate(REAL_FIELDS)}
    for k, name in enumerate(TEXT_FIELDS):
        kwargs[name] = decode(np.asarray(codes[:lengths[k], k], dtype=np.uint8).tobytes()) or None
    return Scene(**kwargs, source=path)
