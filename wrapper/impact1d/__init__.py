"""impact1d: one-dimensional impacts with dry friction, solved as a hybrid system.

A thin Python layer over the Fortran engine (the f2py extension impact1d._core):

    import impact1d
    scene = impact1d.load_scene("input/case3.nml")
    res = impact1d.simulate(scene, dt=1e-3)
    res.t, res.x1, res.v1, res.x2, res.v2, res.ke     # float64 arrays
    res.events                                        # structured array of the event log
    res.energy_residual                               # the run's accuracy monitor

`impact1d.plot` (figures, needs matplotlib) is imported only when first used.
"""

from importlib import import_module as _import_module

from ._scene import Scene, InputError, SimulationError, load_scene
from ._simulate import Result, simulate, COLUMNS, EVENT_DTYPE, ONE_BODY_EVENT_DTYPE, NBODY_EVENT_DTYPE, event_kinds
from .sweep import sweep, SUMMARY_COLUMNS
from ._output import read_output

try:
    from importlib.metadata import version as _version, PackageNotFoundError as _NotFound
    try:
        __version__ = _version("impact1d")
    except _NotFound:
        __version__ = "0+unknown"
except ImportError:  # pragma: no cover
    __version__ = "0+unknown"

__all__ = [
    "Scene", "Result", "InputError", "SimulationError",
    "load_scene", "simulate", "sweep", "SUMMARY_COLUMNS", "read_output", "event_kinds",
    "COLUMNS", "EVENT_DTYPE", "ONE_BODY_EVENT_DTYPE", "NBODY_EVENT_DTYPE", "plot", "__version__",
]

# Submodules loaded on first attribute access, so that `import impact1d` stays free of
# matplotlib.
_LAZY = {"plot"}


def __getattr__(name):
    if name in _LAZY:
        module = _import_module(f".{name}", __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _LAZY)
