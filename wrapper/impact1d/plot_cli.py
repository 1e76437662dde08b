"""``impact1d-plot OUTPUT.dat [-o PNG] [--separate] [--show] [--forces | --no-forces]
[--scene SCENE] [--t-from T] [--t-to T]``: plot a run written by the CLI.
``impact1d-plot --animate OUTPUT.dat [-o GIF] [--fps N] [--max-frames N] [--t-from T] [--t-to T]``:
the mechanism moving (impact1d.plot.animate), written as OUTPUT.gif (or -o NAME.gif, NAME.mp4
with ffmpeg).
``impact1d-plot TABLE.csv --x NAME [--y NAME] [--value COLUMN ...]``: plot a sweep's table
(impact1d-sweep): lines over one varied field, a heatmap over two.

Reads OUTPUT.dat (and OUTPUT.events.dat next to it, if present: the output's
extension replaced by .events.dat) and writes OUTPUT.png next to it, or one PNG per panel with ``--separate``
(OUTPUT_positions.png, ...).  ``--show`` also opens the figures in a window.
The force panel needs the scene's force tables, which the output's header does not name:
they come from --scene, else from the scene file the header names (`# scene = ...`, as
given to impact1d: relative to the folder impact1d ran in) when its force values are the
header's; else a note on stderr says why there is no force panel.
Any error (one that writing the report on stdout meets too) gives a one-line message on
stderr and exit status 1. SIGTERM or SIGHUP removes the image being written (the previous
one stays) and ends the command by that signal. Only regular files are read (a FIFO or a device is refused).
"""

from __future__ import annotations

import argparse
import os
import sys

PROG = "impact1d-plot"


def _parser():
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Plot an impact1d output file: positions with walls and slot, "
        "velocities, applied forces, kinetic and potential energy, impacts per constraint, "
        "energy ledger (three bodies or more: a space-time plot and the energies); or "
        "animate it (--animate); or plot a sweep's table.",
        epilog="exit status: 0 done; 1 the output could not be read or drawn (a time window "
        "that misses the run, a --scene it was not run from) or the image written; "
        "2 a bad command line.",
    )
    p.add_argument("output", metavar="OUTPUT.dat", help="output file written by impact1d "
                   "(its OUTPUT.events.dat is read too when present)")
    p.add_argument("-o", dest="png", metavar="PNG",
                   help="image to write (default: OUTPUT with .png instead of .dat)")
    p.add_argument("--separate", action="store_true",
                   help="one PNG per panel: PNG stem + _positions, _velocities, ...")
    p.add_argument("--show", action="store_true", help="also open the figures in a window")
    p.add_argument("--forces", action=argparse.BooleanOptionalAction, default=None,
                   help="the applied-force panel (default: when a force changes in time)")
    p.add_argument("--scene", metavar="SCENE", help="the scene OUTPUT was run from, for its "
                   "force tables (default: the scene file named in OUTPUT's header)")
    p.add_argument("--t-from", type=float, metavar="T", help="draw from time T (s)")
    p.add_argument("--t-to", type=float, metavar="T", help="draw up to time T (s)")
    p.add_argument("--animate", action="store_true",
                   help="write an animation of the mechanism instead (-o NAME.gif, or NAME.mp4 "
                   "with ffmpeg; default OUTPUT with .gif)")
    p.add_argument("--fps", type=int, default=20, metavar="N", help="animation frames per second")
    p.add_argument("--max-frames", type=int, default=300, metavar="N",
                   help="at most N frames: the samples evenly thinned (default 300)")
    p.add_argument("--x", help="a sweep table's varied field for the x axis")
    p.add_argument("--y", help="a second varied field: a heatmap of --value")
    p.add_argument("--value", action="append", default=None,
                   help="summary column(s) to show (default t_rest)")
    p.add_argument("--version", action="version", version=f"{PROG} {_version()}")
    return p


def _version():
    # From the installed package's metadata (meson.build's project version), without
    # importing impact1d and its compiled core.
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("impact1d")
    except PackageNotFoundError:
        return "(not installed)"


def _default_png(output):
    # The CLI's rule for its events file: the extension, whatever it is, is replaced.
    return os.path.splitext(output)[0] + ".png"


def _read(path):
    # Imported here so `impact1d-plot --help` works even if the package's
    # compiled core cannot load.
    from impact1d import read_output

    return read_output(path)


def _fail(message):
    print(f"{PROG}: error: {message}", file=sys.stderr)
    return 1


def _note(message):
    print(f"{PROG}: note: {message}", file=sys.stderr)


def _with_forces(result, output, scene):
    """(the result with its force tables, None), or (the result, why they are unknown). From
    `scene` when given (its errors raised), else from the scene file the header names."""
    from impact1d import InputError
    from impact1d._output import with_forces_of

    if scene is not None:
        return with_forces_of(result, scene, output), None
    source = result.scene.source if result.scene is not None else None
    if not source:
        return result, f"{output} names neither its force tables nor its scene (give --scene SCENE)"
    try:
        return with_forces_of(result, source, output), None
    except InputError as error:
        return result, (f"the header of {output} does not name force tables, and its scene "
                        f"file is of no use ({_one_line(error)}): give --scene SCENE")


def _one_line(exc):
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror         # the caller names the file
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _say(line):
    """A line on stdout; False (and the one-line error) when it cannot be written."""
    from impact1d._files import print_line

    try:
        print_line(line)
        return True
    except OSError as error:
        _fail(f"cannot write to stdout: {error.strerror or error}")
        return False


def main(argv=None):
    from impact1d._files import Ended, die_of, ending_signals_raise
    import signal

    try:
        with ending_signals_raise():
            return _main(argv)
    except Ended as ended:
        # SIGTERM, SIGHUP: the temporary image is gone; end by the signal, as impact1d does.
        die_of(ended.signum, f"{PROG}: ended by {signal.Signals(ended.signum).name}")
        raise


def _main(argv):
    args = _parser().parse_args(argv)
    output = args.output
    from impact1d import InputError
    from impact1d._files import STANDARD_OUTPUT, check_input

    if args.png in STANDARD_OUTPUT:
        return _fail(f"-o {args.png}: a figure is written to a file (give a PNG name), "
                     "not to standard output")
    try:
        check_input(output)         # a FIFO or /dev/zero would never end
    except InputError as error:
        return _fail(str(error))
    if output.endswith((".csv", ".parquet")):
        return _plot_table(args)
    try:
        result = _read(output)
    except Exception as exc:  # noqa: BLE001 - any read failure is reported the same way
        text = _one_line(exc)
        return _fail(text if output in text else f"cannot read {output}: {text}")
    if len(getattr(result, "t", ())) == 0:
        return _fail(f"no samples in {output}")

    import matplotlib

    if not args.show or args.animate:
        matplotlib.use("Agg")
    from impact1d import plot

    if args.animate:
        return _animate(args, result)
    factory = None
    if args.show:
        import matplotlib.pyplot as plt

        factory = plt.figure
    forces, why_not = args.forces, None
    if forces is not False:
        try:
            result, why_not = _with_forces(result, output, args.scene)
        except Exception as exc:  # noqa: BLE001 - --scene unreadable or not this output's
            return _fail(_one_line(exc))
        if why_not:
            forces = False
    try:
        figs = plot.figure(result, separate=args.separate, forces=forces, t_from=args.t_from,
                           t_to=args.t_to, figure_factory=factory)
    except Exception as exc:  # noqa: BLE001
        return _fail(f"cannot plot {output}: {_one_line(exc)}")
    paths = plot._paths(args.png or _default_png(output), figs)
    for fig, path in zip(figs if args.separate else [figs], paths):
        try:
            plot._write(fig, path)
        except Exception as exc:  # noqa: BLE001
            return _fail(f"cannot write {path}: {_one_line(exc)}")
        if not _say(f"wrote {path}"):
            return 1
    if why_not:         # after the figure: a failure is then one line, as every error
        _note(f"no force panel: {why_not}")
    if args.show:
        plt.show()
    return 0


def _animate(args, result):
    """The animation of the run (impact1d.plot.animate), written whole."""
    from impact1d import plot

    path = args.png or os.path.splitext(args.output)[0] + ".gif"
    if args.fps < 1 or args.max_frames < 1:
        return _fail("--fps and --max-frames must be at least 1")
    if args.separate or args.show or args.forces is not None:
        return _fail("--animate writes one animation: --separate, --show and --forces are "
                     "for figures")
    try:
        plot.animate(result, path, fps=args.fps, max_frames=args.max_frames,
                     t_from=args.t_from, t_to=args.t_to)
    except Exception as exc:  # noqa: BLE001 - one line, whatever went wrong
        return _fail(f"cannot write {path}: {_one_line(exc)}")
    return 0 if _say(f"wrote {path}") else 1


def _plot_table(args):
    """A sweep's table: lines or a heatmap (impact1d.plot.sweep)."""
    if not args.x:
        return _fail("a sweep table needs --x NAME (and --y NAME for a heatmap)")
    import matplotlib

    matplotlib.use("Agg")
    import pandas as pd
    from impact1d import plot

    png = args.png or _default_png(args.output)
    try:
        table = (pd.read_parquet if args.output.endswith(".parquet") else pd.read_csv)(args.output)
    except Exception as exc:  # noqa: BLE001 - one line, whatever went wrong
        return _fail(f"cannot read {args.output}: {_one_line(exc)}")
    try:
        figure = plot.sweep(table, args.x, args.y, args.value or ["t_rest"])
    except Exception as exc:  # noqa: BLE001
        return _fail(f"cannot plot {args.output}: {_one_line(exc)}")
    try:
        plot._write(figure, png)
    except Exception as exc:  # noqa: BLE001
        return _fail(f"cannot write {png}: {_one_line(exc)}")
    return 0 if _say(f"wrote {png}") else 1


if __name__ == "__main__":
    sys.exit(main())
