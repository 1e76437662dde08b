"""bench/siconos_events.py: impacts and rests read from a Siconos run's rows.

The Siconos peer study (bench/siconos_peer.py, `make bench`) needs Siconos; these
functions do not, so they are checked here on hand-made rows whose answer is known.
"""

import importlib.util
from pathlib import Path

import numpy as np

# Loaded from its file: putting bench/ on sys.path would expose its other modules
# (common, performance, ...) to the whole test session.
_PATH = Path(__file__).resolve().parents[1] / "bench" / "siconos_events.py"
_SPEC = importlib.util.spec_from_file_location("siconos_events", _PATH)
se = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(se)

STEP, NS = se.STEP, se.NONSMOOTH
H = 1e-3


def row(t, impulses=(0.0, 0.0, 0.0, 0.0), flag=STEP):
    return [t, 0.0, 0.0, 0.0, 0.0, *impulses, flag]


def steps(active_by_step):
    """Time-stepping rows at t = (k + 1) H; each entry the impulses of that step."""
    return np.array([row((k + 1) * H, p) for k, p in enumerate(active_by_step)])


def test_event_driven_impacts_are_the_impulses_at_nonsmooth_events():
    rows = np.array([
        row(0.001),
        row(0.0015, (18.0, 0.0, 0.0, 0.0), NS),          # left impact between two steps
        row(0.002),
        row(0.0025, (0.0, 0.0, 0.0, 0.0), NS),           # a nonsmooth event without impulse
        row(0.003, (5.0, 0.0, 0.0, 0.0)),                # a step row: its impulse is no impact
        row(0.0031, (0.0, 2.0, 0.0, 3.0), NS),           # two contacts at one instant
    ])
    assert se.impacts_event_driven(rows) == [
        (0.0015, "left"), (0.0031, "right"), (0.0031, "slot_max")]


def test_time_stepping_impact_is_the_first_step_of_each_run_of_impulses():
    left = (1.0, 0.0, 0.0, 0.0)
    slot = (0.0, 0.0, 4.0, 0.0)
    both = (1.0, 0.0, 4.0, 0.0)
    rows = steps([left, left, (0.0,) * 4, slot, both, (0.0,) * 4, (0.0,) * 4])
    # left: runs starting at steps 0 and 4; slot_min: one run starting at step 3.
    assert se.impacts_time_stepping(rows) == [
        (1 * H, "left"), (4 * H, "slot_min"), (5 * H, "left")]
    assert se.rest_times(rows) == {}               # every contact open at the last step


def test_rest_starts_with_the_final_unbroken_run_of_impulses():
    press = (2e-3, 4e-3, 0.0, 0.0)
    rows = steps([(0.0,) * 4, (3.0, 0.0, 0.0, 0.0), (0.0,) * 4, (0.0, 6.0, 0.0, 0.0),
                  press, press, press])
    assert se.rest_times(rows) == {"left": 5 * H, "right": 4 * H}
    assert se.time_stepping_log(rows) == [
        (2 * H, "left"), (4 * H, "right"), (4 * H, "rest_right"), (5 * H, "left"),
        (5 * H, "rest_left")]


def test_a_contact_active_from_the_first_step_rests_from_it():
    rows = steps([(0.0, 1.0, 0.0, 0.0)] * 3)
    assert se.rest_times(rows) == {"right": 1 * H}


def test_impulses_at_rounding_level_are_no_contact():
    tiny = se.IMPULSE_FLOOR / 10
    rows = steps([(tiny, 0.0, 0.0, 0.0), (tiny, 0.0, 0.0, 0.0)])
    assert se.impacts_time_stepping(rows) == []
    assert se.rest_times(rows) == {}
    assert se.impacts_event_driven(np.array([row(0.5, (tiny, 0.0, 0.0, 0.0), NS)])) == []
