"""read_output(): load a CLI output file (and its events file) back into a Result."""

from __future__ import annotations

import dataclasses
import os

import numpy as np

from ._scene import (REAL_FIELDS, TEXT_FIELDS, ARRAY_FIELDS, LAW_FIELDS, _RECORD_TEXT_FIELDS, Scene, InputError, load_scene, is_nbody_form, from_core, to_core,
                     _put)
from ._files import check_input
from ._simulate import LEDGER, Result, event_dtype, result_from_columns

__all__ = ["read_output", "events_path"]

# The scene fields that make the applied forces, besides the tables (which the output's
# header does not name).
FORCE_FIELDS = ("f1", "f2", "f1_amp", "f1_period", "f1_phase", "f2_amp", "f2_period", "f2_phase", "sines")


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


# The events file's last line when the log was cut at &run max_events (the core's words).
_CUT_NOTE = "the event log was cut at "


def _read_events(path, n_bodies=2):
    """The events of an events file, and its notes (a log cut at max_events says so in a
    comment line: it becomes a warning of the Result)."""
    rows, notes = [], []
    dtype = event_dtype(n_bodies)
    with open(path, encoding="utf-8") as handle:
        for number, line in enumerate(handle, 1):
            if line.startswith("# " + _CUT_NOTE):
                notes.append(line[2:].strip())
            text = line.split("#", 1)[0].split()
            if not text:
                continue
            if len(text) != len(dtype.names):
                raise InputError(f"{path}:{number}: expected {len(dtype.names)} entries "
                                 f"({' '.join(dtype.names)})")
            t, kind, *numbers = text
            if n_bodies > 2:      # t kind a b va_before vb_before va_after vb_after
                rows.append((float(t), kind, int(numbers[0]), int(numbers[1]), *map(float, numbers[2:])))
            else:
                rows.append((float(t), kind, *map(float, numbers)))
    return np.array(rows, dtype=dtype), tuple(notes)


def read_output(path, scene=None) -> Result:
    """Load `impact1d` CLI output: the samples of OUT.dat, the events of OUT.events.dat
    when it exists, and the scene recorded in the header (`source` = the scene file).
    `steps` is None (the file does not record it); energy_residual is max |residual|.

    The header records every value of the scene but not the force tables' names, so the
    Result's `forces_known` is False, unless `scene` (a Scene or a scene file: the one
    the output was run from) is given: its force tables then complete the Result's scene
    (InputError if its force values differ from the header's)."""
    path = os.fspath(path)
    check_input(path, "output file")
    header, columns = _read_header(path)
    names = tuple(columns.split()) if columns is not None else ()
    n_bodies = _check_names(path, names, header)
    samples = np.loadtxt(path, comments="#", ndmin=2)
    if samples.size == 0:
        samples = np.empty((0, len(names)))
    if samples.shape[1] != len(names):
        raise InputError(f"{path}: the header names {len(names)} columns, the rows have "
                         f"{samples.shape[1]}")

    kwargs = {}
    for name in REAL_FIELDS:
        if name in header and not (n_bodies > 2 and name in ARRAY_FIELDS):
            kwargs[name] = float(header[name])
    for name in TEXT_FIELDS:
        if name in header:
            kwargs[name] = header[name]
    if n_bodies > 2:
        # The arrays of more than two bodies: '# m = 1.0 2.0 5.0' (the force tables' names,
        # texts, are not written).
        for name in ARRAY_FIELDS:
            if name in header and name != "f_table":
                kwargs[name] = [float(value) for value in header[name].split()]
    else:
        # (the friction laws' arrays, which one or two bodies keep as arrays)
        for name in LAW_FIELDS:
            if name in header:
                kwargs[name] = [float(value) for value in header[name].split()]
    # The records: '# contact.2.d_min = 0.5', '# spring.1.k = 40.0', '# sine.1.amp = 2.0',
    # '# friction.1.normal = 9.81' (in record order).
    for key, value in header.items():
        group, _, rest = key.partition(".")
        number, _, field = rest.partition(".")
        if group in ("contact", "spring", "sine", "friction") and number.isdigit() and field:
            _put(kwargs, f"{group}.{field}", int(number), value if field in _RECORD_TEXT_FIELDS else float(value))
    header_scene = Scene(**kwargs, source=header.get("scene"))

    events_file = events_path(path)
    if os.path.exists(events_file):
        check_input(events_file, "events file")     # a FIFO there would block the read
        events, notes = _read_events(events_file, n_bodies)
    else:
        events, notes = np.empty(0, dtype=event_dtype(n_bodies)), ()
    residual = samples[:, names.index("residual")]
    energy_residual = float(np.max(np.abs(residual))) if residual.size else 0.0
    result = result_from_columns(samples, events, names, energy_residual=energy_residual,
                                 steps=None, scene=header_scene, forces_known=False, warnings=notes)
    return result if scene is None else with_forces_of(result, scene, path)


def _check_names(path, names, header) -> int:
    """The number of bodies of an output whose last header line names `names`: t, x<i> v<i>
    of bodies in increasing order, then ke, [pe,] work, friction_loss, impact_loss,
    [damping_loss,] residual (InputError otherwise). N is the header's `bodies` (written for
    more than two), else 2 with an m2 or an x2 column, else 1."""
    bodies = []
    k = 1
    while k + 1 < len(names) and names[k][:1] == "x" and names[k][1:].isdigit() and \
            names[k + 1] == "v" + names[k][1:]:
        bodies.append(int(names[k][1:]))
        k += 2
    ledger = names[k:]
    if not names or names[0] != "t" or not bodies or bodies != sorted(set(bodies)) or bodies[0] < 1 or \
            ledger != tuple(name for name in LEDGER if name in ledger) or \
            not {"ke", "work", "friction_loss", "impact_loss", "residual"} <= set(ledger):
        raise InputError(f"{path}: the last header line must name the columns 't x1 v1 [x2 v2 ...] ke "
                         f"work friction_loss impact_loss residual' (with pe after ke, damping_loss "
                         f"after impact_loss and drive_work before residual when the scene has them), got {' '.join(names)!r}")
    n_bodies = int(header["bodies"]) if header.get("bodies", "").isdigit() else \
        2 if "m2" in header or 2 in bodies else 1
    if bodies[-1] > max(n_bodies, 1):
        raise InputError(f"{path}: the columns name body {bodies[-1]} of a scene of {n_bodies}")
    return n_bodies


def with_forces_of(result: Result, scene, path) -> Result:
    """`result` (read from the output file `path`) with the force tables of `scene` (a Scene
    or a scene file), whose force values must be the header's."""
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    if is_nbody_form(scene):
        # (written with arrays of one or two bodies: compared in the tutorial's names)
        scene = dataclasses.replace(from_core(*to_core(scene), source=scene.source), sines=scene.sines)
    for name in FORCE_FIELDS:
        mine, theirs = getattr(result.scene, name), getattr(scene, name)
        if mine != theirs:
            where = f"the scene {scene.source}" if scene.source else "the scene"
            raise InputError(f"{path} was not run from {where}: its header has "
                             f"{name} = {mine}, the scene {name} = {theirs}")
    tables = {"f1_table": scene.f1_table, "f2_table": scene.f2_table}
    return dataclasses.replace(result, scene=dataclasses.replace(result.scene, **tables),
                               forces_known=True)
