"""impact1d-sweep: run a scene over a grid of parameters and write the table.

    impact1d-sweep input/case5.nml --vary r_left=0:1:21 --vary r_right=0,0.5,1 -o table.csv

NAME=a:b:n is n values from a to b (both included); NAME=v1,v2,... lists them. The table
(CSV; Parquet for a .parquet name, with pyarrow installed) has one row per run: the
varied fields, the run's summary and its error message (empty when it ran).
Exit status: 0 done (rows with errors included), 1 bad input, 2 the table (or the line
saying where it went) could not be written, 130 interrupted (SIGINT, Ctrl-C): the previous
table is untouched. SIGTERM or SIGHUP: one line on stderr, the temporary table removed,
the previous one untouched, and the command ends by that signal (128 + signal in a shell).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

import numpy as np

from . import __version__
from ._scene import InputError, load_scene
from ._files import STANDARD_OUTPUT, Ended, die_of, ending_signals_raise, output_target, print_line, write_whole
from ._simulate import interrupt_epoch_now
from .sweep import sweep


def parse_values(spec: str) -> list:
    """'0:1:21' -> 21 values from 0 to 1; '0,0.1,0.2' -> those; a text value stays text."""
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise InputError(f"'{spec}': a range is start:stop:count")
        try:
            start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise InputError(f"'{spec}': a range is start:stop:count (numbers, count whole)") from None
        if count < 1:
            raise InputError(f"'{spec}': the count must be at least 1")
        return [float(v) for v in np.linspace(start, stop, count)]
    values = []
    for word in spec.split(","):
        word = word.strip()
        if not word:
            raise InputError(f"'{spec}': an empty value")
        try:
            values.append(float(word))
        except ValueError:
            values.append(word)      # a text field such as method
    return values


def parse_vary(items) -> dict:
    grid = {}
    for item in items:
        name, sep, spec = item.partition("=")
        if not sep or not name.strip():
            raise InputError(f"--vary '{item}': expected NAME=SPEC (e.g. r_left=0:1:21)")
        if name.strip() in grid:
            raise InputError(f"--vary {name.strip()} is given twice")
        grid[name.strip()] = parse_values(spec)
    return grid


def write_table(table, path: str) -> None:
    """CSV, or Parquet for a .parquet name; written whole (a failed write leaves none)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    if path.endswith(".parquet"):
        write_whole(path, table.to_parquet)
    else:
        write_whole(path, lambda temporary: table.to_csv(temporary, index=False))


def main(argv=None) -> int:
    # SIGINT counted from here on (the core's count, src/impact1d_interrupt.c), and the runs
    # ended by any interrupt since: one that comes while the scene is read, before the sweep
    # begins, ends them even if Python's KeyboardInterrupt for it is lost on the way (a
    # loaded machine once let one through: the sweep ran its 90 s and returned 0).
    state = {"interrupt_epoch": interrupt_epoch_now()}
    try:
        with ending_signals_raise():
            return _main(argv, state)
    except KeyboardInterrupt:
        # One line, as impact1d says it (a shell shows 130 for both): the table is written
        # whole or not at all, so the previous one is as it was.
        print("impact1d-sweep: interrupted; the table was not written", file=sys.stderr)
        return 130
    except Ended as ended:
        # SIGTERM, SIGHUP: the temporary file is gone; end by the signal, as impact1d does.
        table = f"the table {state['written']} is written" if "written" in state else "the table was not written"
        die_of(ended.signum, f"impact1d-sweep: ended by {signal.Signals(ended.signum).name}; {table}")
        raise


def _main(argv, state) -> int:
    parser = argparse.ArgumentParser(prog="impact1d-sweep", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="a namelist scene (.nml) or VisSim .dat file")
    parser.add_argument("--vary", action="append", default=[], metavar="NAME=SPEC",
                        help="a field and its values: a:b:n or v1,v2,... (repeat for a grid)")
    parser.add_argument("--workers", type=int, default=None,
                        help="threads to use (default: all cores for big sweeps)")
    parser.add_argument("--settle", type=float, default=None, metavar="T",
                        help="add the steady state over [T, t_end]: peak-to-peak and RMS of each "
                        "position and velocity, impacts per forcing period (docs/formats.md)")
    parser.add_argument("-o", "--output", default=None,
                        help="table to write (default output/<scene>_sweep.csv)")
    parser.add_argument("--version", action="version", version=f"impact1d-sweep {__version__}")
    args = parser.parse_args(argv)
    try:
        if not args.vary:
            raise InputError("nothing to vary: give at least one --vary NAME=SPEC")
        if args.output is not None and not args.output.strip():
            raise InputError("-o: an empty output name")
        if args.output in STANDARD_OUTPUT:
            raise InputError(f"-o {args.output}: the table is written to a file (.csv or .parquet), "
                             "not to standard output")
        if args.output and args.output.endswith(".parquet"):
            try:
                import pyarrow  # noqa: F401
            except ImportError:
                raise InputError("-o *.parquet needs pyarrow (pip install pyarrow); "
                                 "or write .csv") from None
        stem = os.path.splitext(os.path.basename(args.scene))[0]
        out = args.output or os.path.join("output", f"{stem}_sweep.csv")
        output_target(out)         # a FIFO or a folder there: refused before the runs
        scene = load_scene(args.scene)
        table = sweep(scene, parse_vary(args.vary), workers=args.workers, settle=args.settle,
                      _interrupt_epoch=state["interrupt_epoch"])
    except InputError as error:
        print(f"impact1d-sweep: {error}", file=sys.stderr)
        return 1
    try:
        write_table(table, out)
    except OSError as error:
        print(f"impact1d-sweep: cannot write {out}: {error.strerror or error}", file=sys.stderr)
        return 2
    state["written"] = out
    failed = int((table["error"] != "").sum())
    try:
        print_line(f"impact1d-sweep: {len(table)} runs ({failed} failed) -> {out}")
    except OSError as error:
        print(f"impact1d-sweep: cannot write to stdout: {error.strerror or error} "
              f"(the table {out} is written)", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
