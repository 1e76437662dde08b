"""read_output(): load a CLI output file (and its events file) back into a Result."""

from __future__ import annotations

import os

import numpy as np

from ._scene import REAL_FIELDS, TEXT_FIELDS, Scene, InputError
from ._files import check_input
from ._simulate import (COLUMNS, OPTIONAL_COLUMNS, EVENT_DTYPE, ONE_BODY_EVENT_DTYPE, Result,
                        result_from_columns)

__all__ = ["read_output", "events_path"]


def events_path(path) -> str:
    """The events file that goes with an output file, as the CLI names it: the output's
    extension, whatever it is, becomes .events.dat (res.dat, res.txt, res: res.events.dat)."""
    stem, _ = os.path.splitext(os.fspath(path))
    return stem + ".events.dat"


def _read_header(path):
    """The '# name = value' lines before the data, and the last comment line."""
    fields, last = {}, None
    with open(path, encoding="utf-8") as handle:
        for line in handle:
            if not line.startswith("#"):
                if line.strip():
                    break
                continue
            text = line[1:].strip()
            last = text
            name, sep, value = text.partition("=")
            if sep:
                fields[name.strip()] = value.strip()
    return fields, last


def _read_events(path, one_body=False) -> np.ndarray:
    rows = []
    dtype = ONE_BODY_EVENT_DTYPE if one_body else EVENT_DTYPE
    with open(path, encoding="utf-8") as handle:
        for number, line in enumerate(handle, 1):
            text = line.split("#", 1)[0].split()
            if not text:
                continue
            if len(text) != len(dtype.names):
                raise InputError(f"{path}:{number}: expected {len(dtype.names)} entries "
                                 f"({' '.join(dtype.names)})")
            t, kind, *velocities = text
            rows.append((float(t), kind, *map(float, velocities)))
    return np.array(rows, dtype=dtype)


def read_output(path) -> Result:
    """Load `impact1d` CLI output: the samples of OUT.dat, the events of OUT.events.dat
    when it exists, and the scene recorded in the header (`source` = the scene file).
    `steps` is None (the file does not record it); energy_residual is max |residual|."""
    path = os.fspath(path)
    check_input(path, "output file")
    header, columns = _read_header(path)
    names = tuple(columns.split()) if columns is not None else ()
    required = tuple(name for name in COLUMNS if name not in OPTIONAL_COLUMNS)
    if tuple(name for name in names if name not in OPTIONAL_COLUMNS) != required or \
            names != tuple(name for name in COLUMNS if name in names):
        raise InputError(f"{path}: the last header line must name the columns "
                         f"'{' '.join(required)}' (with pe after ke and damping_loss after "
                         f"impact_loss when the scene has them), got {columns!r}")
    samples = np.loadtxt(path, comments="#", ndmin=2)
    if samples.size == 0:
        samples = np.empty((0, len(names)))
    if samples.shape[1] != len(names):
        raise InputError(f"{path}: the header names {len(names)} columns, the rows have "
                         f"{samples.shape[1]}")

    kwargs = {}
    for name in REAL_FIELDS:
        if name in header:
            kwargs[name] = float(header[name])
    for name in TEXT_FIELDS:
        if name in header:
            kwargs[name] = header[name]
    scene = Scene(**kwargs, source=header.get("scene"))

    events_file = events_path(path)
    one_body = "x2" not in names
    if os.path.exists(events_file):
        check_input(events_file, "events file")     # a FIFO there would block the read
        events = _read_events(events_file, one_body)
    else:
        events = np.empty(0, dtype=ONE_BODY_EVENT_DTYPE if one_body else EVENT_DTYPE)
    residual = samples[:, names.index("residual")]
    energy_residual = float(np.max(np.abs(residual))) if residual.size else 0.0
    return result_from_columns(samples, events, names, energy_residual=energy_residual,
                               steps=None, scene=scene)
