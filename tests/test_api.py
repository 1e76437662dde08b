"""The Python API: Scene, load_scene, simulate, Result, errors (docs/formats.md, the Python API)."""

import dataclasses
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impact1d
from impact1d import InputError, SimulationError

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"

# Free flight is exact to rounding (x = x0 + v t over 2000 steps of 0.01 s).
FREE_FLIGHT_TOL = 1e-12
# Constant-force motion against its closed form: RK4 is exact for it, so only
# rounding over ~1500 steps remains (~1e-13); 1e-9 is the suite's event-level bound.
CLOSED_FORM_TOL = 1e-9

CASE3_NML = """\
&scene   title = 'api test scene' /
&bodies  m1 = 1.0, m2 = 2.0, mu1 = 0.0, mu2 = 0.0, g = 10.0 /
&walls   x_left = 0.0, r_left = 1.0, x_right = 10.0, r_right = 1.0 /
&link    d_min = 1.0, r_min = 1.0, d_max = 2.0, r_max = 1.0 /
&initial x1 = 1.0, v1 = -9.0, x2 = 2.5, v2 = 1.0 /
&forces  f1 = 0.0, f2 = 0.0 /
&run     t_end = 0.5, dt = 1.0e-3, dt_out = 1.0e-2 /
"""


def write_scene(tmp_path, text, name="scene.nml"):
    path = tmp_path / name
    path.write_text(text)
    return path


# --- package surface -----------------------------------------------------------

def test_public_names():
    for name in ("Scene", "Result", "InputError", "SimulationError", "load_scene",
                 "simulate", "read_output"):
        assert name in impact1d.__all__
        assert hasattr(impact1d, name)
    assert issubclass(InputError, ValueError)
    assert issubclass(SimulationError, RuntimeError)


def test_import_does_not_load_matplotlib():
    code = "import sys, impact1d; assert 'matplotlib' not in sys.modules, 'matplotlib loaded'"
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_plot_is_reexported_lazily():
    code = ("import sys, impact1d\n"
            "assert 'impact1d.plot' not in sys.modules\n"
            "from impact1d import plot\n"
            "assert plot.__name__ == 'impact1d.plot'\n"
            "assert impact1d.plot is plot\n")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT,
                   env={**__import__("os").environ, "MPLBACKEND": "Agg"})


def test_scene_fields_follow_the_core():
    reals, texts = impact1d._scene._api.field_names()
    names = [f.name for f in dataclasses.fields(impact1d.Scene)]
    # The tutorial's fields, source, then the N-body ones (arrays not already scalars,
    # r_meet, the records), each an input field of the core's.
    tutorial = impact1d._scene.decode(reals).split() + impact1d._scene.decode(texts).split()
    assert names[:len(tutorial) + 1] == tutorial + ["source"]
    inputs = impact1d._scene.decode(impact1d._scene._api.input_field_names()).split()
    assert inputs[:len(tutorial)] == tutorial and tuple(inputs) == impact1d._scene.INPUT_FIELDS
    assert set(names[len(tutorial) + 1:]) == (set(inputs[len(tutorial):]) - set(tutorial)
                                              - {n for n in inputs if "." in n}) | {"contacts", "springs", "sines", "frictions"}
    assert impact1d._scene.REAL_FIELDS[:28] == tuple(
        "m1 m2 mu1 mu2 g x_left r_left x_right r_right d_min r_min d_max r_max x1 v1 x2 v2 "
        "f1 f2 f1_amp f1_period f1_phase f2_amp f2_period f2_phase t_end dt dt_out".split())


# --- load_scene ------------------------------------------------------------------

def test_load_scene_case3():
    path = INPUT / "case3.nml"
    scene = impact1d.load_scene(path)
    assert isinstance(scene, impact1d.Scene)
    assert scene.title == "Test case 3: conservation of energy"
    assert scene.source == str(path)
    assert (scene.m1, scene.m2, scene.mu1, scene.mu2, scene.g) == (1.0, 2.0, 0.0, 0.0, 10.0)
    assert (scene.x_left, scene.x_right, scene.d_min, scene.d_max) == (0.0, 10.0, 1.0, 2.0)
    assert (scene.x1, scene.v1, scene.x2, scene.v2) == (1.0, -9.0, 2.5, 1.0)
    assert (scene.t_end, scene.dt, scene.dt_out, scene.method) == (6.0, 1e-3, 1e-3, "event")
    for absent in ("f1_amp", "f1_period", "f1_phase", "f2_amp", "f2_period", "f2_phase",
                   "f1_table", "f2_table"):
        assert getattr(scene, absent) is None, absent


def test_load_scene_resolves_table_path():
    scene = impact1d.load_scene(INPUT / "case6.nml")
    assert scene.f1 == 0.0
    assert Path(scene.f1_table).samefile(INPUT / "triangle.dat")
    assert scene.f2_table is None


def test_absent_variables_are_none(tmp_path):
    path = write_scene(tmp_path, "&bodies m1 = 1.0, m2 = 2.0 /\n"
                                 "&initial x1 = 1.0, x2 = 2.0 /\n"
                                 "&run t_end = 1.0, dt = 0.01 /\n")
    scene = impact1d.load_scene(path)
    assert (scene.m1, scene.m2, scene.x1, scene.x2, scene.t_end, scene.dt) == \
        (1.0, 2.0, 1.0, 2.0, 1.0, 0.01)
    for name in ("mu1", "g", "x_left", "r_left", "x_right", "d_min", "d_max", "v1", "f1",
                 "dt_out", "title", "method", "f1_table"):
        assert getattr(scene, name) is None, name


# --- simulate and Result -----------------------------------------------------------

def test_result_arrays_and_scene():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    res = impact1d.simulate(scene, t_end=0.5, dt_out=0.01)
    n = 51
    # A scene without springs, dampers or a moving ground has no pe, damping_loss and
    # drive_work columns.
    assert res.columns == tuple(c for c in impact1d.COLUMNS if c not in ("pe", "damping_loss", "drive_work"))
    assert res.pe is None and res.damping_loss is None and res.drive_work is None
    for name in res.columns:
        column = getattr(res, name)
        assert isinstance(column, np.ndarray) and column.dtype == np.float64, name
        assert column.shape == (n,), name
    assert res.samples.shape == (n, 10)
    assert res.events.dtype == np.dtype([("t", "f8"), ("kind", "U20"), ("v1_before", "f8"),
                                         ("v2_before", "f8"), ("v1_after", "f8"),
                                         ("v2_after", "f8")])
    assert list(res.events["kind"][:4]) == ["slot_max", "slot_min", "slot_max", "slot_min"]
    assert isinstance(res.steps, int) and res.steps >= 500
    assert isinstance(res.energy_residual, float)
    # The result carries the scene after the overrides; the caller's scene is untouched.
    assert (res.scene.t_end, res.scene.dt_out, res.scene.dt) == (0.5, 0.01, 1e-3)
    assert (scene.t_end, scene.dt_out) == (6.0, 1e-3)


def test_results_do_not_share_storage():
    """The core keeps one run in module storage: a Result must own copies."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    first = impact1d.simulate(scene, t_end=0.5)
    x1, kinds = first.x1.copy(), first.events.copy()
    impact1d.simulate(impact1d.load_scene(INPUT / "case5.nml"), t_end=0.5)
    assert np.array_equal(first.x1, x1)
    assert np.array_equal(first.events, kinds)


def test_scene_built_in_python_free_flight():
    """No walls, and a link whose lower limit is far beyond reach: the bodies fly through
    each other (without d_min they would meet, tests/test_model_widening.py)."""
    scene = impact1d.Scene(m1=1.0, m2=2.0, x1=0.0, v1=1.0, x2=5.0, v2=-0.5, d_min=-1.0e9,
                           t_end=20.0, dt=0.01, dt_out=0.5)
    res = impact1d.simulate(scene)
    assert res.t[-1] == pytest.approx(20.0, abs=FREE_FLIGHT_TOL)
    np.testing.assert_allclose(res.x1, res.t, rtol=0, atol=FREE_FLIGHT_TOL)
    np.testing.assert_allclose(res.x2, 5.0 - 0.5 * res.t, rtol=0, atol=FREE_FLIGHT_TOL)
    assert len(res.events) == 0
    np.testing.assert_allclose(res.ke, 0.5 + 0.25, rtol=0, atol=FREE_FLIGHT_TOL)


def test_override_makes_field_absent():
    """None as an override removes a component: without the left wall m1 flies on."""
    scene = impact1d.load_scene(INPUT / "case5.nml")
    res = impact1d.simulate(scene, x_left=None, r_left=None, t_end=1.5)
    assert "left" not in set(res.events["kind"])
    # x1 = 1 - t^2 with no wall.
    np.testing.assert_allclose(res.x1, 1.0 - res.t**2, rtol=0, atol=CLOSED_FORM_TOL)


# --- errors ---------------------------------------------------------------------

def test_unknown_override_names_it():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(InputError, match="t_stop"):
        impact1d.simulate(scene, t_stop=1.0)


def test_override_of_wrong_type_names_it():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(InputError, match="m1"):
        impact1d.simulate(scene, m1="heavy")


def test_simulate_needs_a_scene():
    with pytest.raises(InputError):
        impact1d.simulate({"m1": 1.0})


def test_missing_file_names_it(tmp_path):
    missing = tmp_path / "no_such_scene.nml"
    with pytest.raises(InputError, match="no_such_scene.nml"):
        impact1d.load_scene(missing)


@pytest.mark.parametrize("m1", ["0.0", "-1.0"])
def test_nonpositive_mass_in_file_names_it(tmp_path, m1):
    path = write_scene(tmp_path, CASE3_NML.replace("m1 = 1.0", f"m1 = {m1}"))
    with pytest.raises(InputError, match="m1"):
        impact1d.simulate(impact1d.load_scene(path))


@pytest.mark.parametrize("m1", [0.0, -1.0])
def test_nonpositive_mass_override_names_it(m1):
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(InputError, match="m1"):
        impact1d.simulate(scene, m1=m1)


def test_unknown_namelist_variable_names_it(tmp_path):
    path = write_scene(tmp_path, CASE3_NML.replace("m2 = 2.0,", "m2 = 2.0, mass3 = 4.0,"))
    with pytest.raises(InputError, match="mass3"):
        impact1d.simulate(impact1d.load_scene(path))


def test_missing_t_end_in_file_names_it(tmp_path):
    path = write_scene(tmp_path, CASE3_NML.replace("t_end = 0.5, ", ""))
    with pytest.raises(InputError, match="t_end"):
        impact1d.simulate(impact1d.load_scene(path))


def test_dat_file_needs_t_end():
    """A VisSim .dat file has no run settings: t_end must come as an override."""
    scene = impact1d.load_scene(INPUT / "input3.dat")
    with pytest.raises(InputError, match="t_end"):
        impact1d.simulate(scene, dt=1e-3)


@pytest.mark.parametrize("name", ["m1", "m2", "x1", "x2", "t_end", "dt"])
def test_missing_required_field_names_it(name):
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(InputError, match=name):
        impact1d.simulate(scene, **{name: None})


def test_unknown_method_names_it():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(InputError, match="method"):
        impact1d.simulate(scene, method="leapfrog")


def test_bad_dat_file(tmp_path):
    lines = (INPUT / "input3.dat").read_text().splitlines()
    short = [line for line in lines if not line.startswith("#")][:10]
    path = write_scene(tmp_path, "\n".join(short) + "\n", name="short.dat")
    with pytest.raises(InputError):
        impact1d.simulate(impact1d.load_scene(path), t_end=1.0, dt=1e-3)


# --- progress -------------------------------------------------------------

# A free flight under a sine force (every step evaluates it, so no shortcut applies) long
# enough (2e7 steps, about 3 s here; the line appears after 1 s) for the progress line to
# appear even on a machine twice as fast.
LONG_RUN = dict(t_end=2.0e4, dt=1.0e-3, dt_out=1.0e4)


def _free_flight():
    return impact1d.Scene(m1=1.0, m2=2.0, x1=0.0, x2=5.0, v1=1.0, v2=-0.5, f1=0.001, f2=-0.002,
                          f1_amp=0.1, f1_period=7.0)


def test_progress_only_when_asked(capfd):
    """progress=True shows a line on stderr (the Fortran side writes it) once a run has taken
    a second, and clears it; without it a long run says nothing."""
    impact1d.simulate(_free_flight(), **LONG_RUN)
    assert capfd.readouterr().err == ""
    res = impact1d.simulate(_free_flight(), progress=True, **LONG_RUN)
    err = capfd.readouterr().err
    assert "impact1d: " in err and "% (t = " in err
    assert re.search(r"of 20000\.0 s, \d+ events, about \d+ s left\)", err), err
    assert res.t[-1] == LONG_RUN["t_end"]


def _flat_run(core, rows, events, row_room, records=None):
    """One call of the flat API's simulate (core: to_core's fields, records: record_assignments';
    none by default) with arrays of the given room: its info array [status, n_samples,
    n_events, n_rows, steps, message length, warnings length, N] and the arrays it filled."""
    from impact1d._scene import _api, _NO_RECORDS
    from impact1d._simulate import COLUMNS
    texts = core[2:]
    out = dict(samples=np.zeros((rows, len(COLUMNS)), order="F"), has_column=np.zeros(len(COLUMNS), np.int32),
               event_real=np.zeros((events, 5), order="F"), event_int=np.zeros((events, 4), np.int32, order="F"),
               row_name_codes=np.zeros((32, row_room), np.int32, order="F"), info=np.zeros(8, np.int32),
               energy_residual=np.zeros(1), text_codes=np.zeros((16384, 2), np.int32, order="F"))
    _api.simulate(core[0], core[1], b"".join(texts) or b" ", np.cumsum([len(t) for t in texts], dtype=np.int32),
                  *(_NO_RECORDS if records is None else records), 0, *out.values())
    return out["info"], out


def test_flat_simulate_says_what_room_it_needs():
    """The flat API writes a run's rows straight into the caller's array; when that array
    (or the event arrays) is too small it says so with the sizes needed (status 3), and a
    call with those sizes gives the rows simulate() returns."""
    from impact1d._scene import to_core, record_assignments
    from impact1d._simulate import COLUMNS
    scene = impact1d.load_scene(INPUT / "case5.nml")
    expected = impact1d.simulate(scene)
    core, records = to_core(scene), record_assignments(scene)
    # (case 5 has the walls and both slot limits: four rows)
    for rows, events, contact_rows in ((3, 2000, 8), (len(expected.t) + 1, 2, 8), (len(expected.t) + 1, 2000, 1)):
        info, _ = _flat_run(core, rows, events, contact_rows, records)
        assert info[0] == 3
        assert tuple(info[1:4]) == (len(expected.t), len(expected.events), 4)
    n_samples, n_events, n_rows = info[1:4]
    info, out = _flat_run(core, n_samples, n_events, n_rows, records)
    assert info[0] == 0
    row_names = ["".join(map(chr, out["row_name_codes"][:, k])).strip() for k in range(n_rows)]
    assert row_names == ["left", "right", "slot_min", "slot_max"]
    # Events are (class, row or body) reporting bodies (1, 2); Python names them.
    event_class, event_index = out["event_int"][:, 0], out["event_int"][:, 1]
    assert set(event_class) <= {1, 2, 3, 4, 5} and (out["event_int"][:, 2:] == [1, 2]).all()
    assert list(expected.events["kind"][:3]) == [
        ("", "rest_", "release_")[c - 1] + row_names[i - 1] if c <= 3 else ("stick", "slip")[c - 4] + str(i)
        for c, i in zip(event_class[:3], event_index[:3])]
    np.testing.assert_array_equal(out["event_real"][:, 1], expected.events["v1_before"])
    present = [name for name, flag in zip(COLUMNS, out["has_column"]) if flag]
    assert present == list(expected.columns)
    for k, name in enumerate(present):
        np.testing.assert_array_equal(out["samples"][:, k], getattr(expected, name))


def test_flat_simulate_message_comes_in_its_codes():
    """A refused scene's status and whole message come back in the caller's buffers (info,
    text_codes), as simulate() raises them."""
    from impact1d._scene import to_core
    scene = dataclasses.replace(impact1d.load_scene(INPUT / "case3.nml"), dt=-1.0)
    with pytest.raises(impact1d.InputError) as raised:
        impact1d.simulate(scene)
    info, out = _flat_run(to_core(scene), 4, 4, 8)
    assert info[0] == 1
    assert bytes(out["text_codes"][:info[5], 0].astype(np.uint8)).decode() == str(raised.value)


def test_long_messages_come_whole(tmp_path):
    """A message naming a long path came cut at 512 characters (the flat API's buffer):
    its end, what went wrong, was lost. Whole from load_scene, simulate and a batch sweep
    (which keeps 512 characters per run and runs a run whose message filled them alone)."""
    folder = tmp_path
    for k in range(5):
        folder = folder / (f"{k}" * 200)
    folder.mkdir(parents=True)
    bad = write_scene(folder, CASE3_NML.replace("m2 = 2.0,", "m2 = 2.0, mass3 = 4.0,"))
    with pytest.raises(InputError) as caught:
        impact1d.load_scene(bad)
    assert len(str(caught.value)) > 1000 and str(bad) in str(caught.value)
    assert "unknown variable 'mass3'" in str(caught.value)
    table = folder / "force.dat"
    table.write_text("# no rows\n")
    scene = impact1d.load_scene(write_scene(folder, CASE3_NML.replace("f1 = 0.0,", "f1_table = 'force.dat',")))
    expected = f"{table}: the table has no rows"
    with pytest.raises(InputError) as caught:
        impact1d.simulate(scene)
    assert str(caught.value).endswith(expected)
    table_rows = impact1d.sweep(scene, {"r_left": [0.5, 0.9]}, workers=1)
    assert [error.endswith(expected) for error in table_rows["error"]] == [True, True]


def test_a_scene_changed_after_a_run_runs_as_changed():
    """simulate keeps a scene's core form between calls (by its field values): a field set
    after a call, an array changed in place, or a zero of the other sign, runs as it now is."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    first = impact1d.simulate(scene, dt=0.1, dt_out=scene.t_end)
    scene.v1 = -8.0
    changed = impact1d.simulate(scene, dt=0.1, dt_out=scene.t_end)
    assert changed.scene.v1 == -8.0 and changed.events["t"][0] != first.events["t"][0]
    scene.v1 = -9.0
    again = impact1d.simulate(scene, dt=0.1, dt_out=scene.t_end)
    np.testing.assert_array_equal(again.events["t"], first.events["t"])
    # (-0.0 == 0.0 in Python: the form must tell them apart all the same)
    assert math.copysign(1.0, impact1d.simulate(scene, t_end=0.1, f1=0.0).scene.f1) == 1.0
    assert math.copysign(1.0, impact1d.simulate(scene, t_end=0.1, f1=-0.0).scene.f1) == -1.0
    by_arrays = impact1d.Scene(m=[1.0, 2.0], x=[1.0, 2.5], v=[-9.0, 1.0], x_left=0.0, x_right=10.0,
                               t_end=1.0, dt=1e-3)
    before = impact1d.simulate(by_arrays)
    by_arrays.v[0] = -5.0
    after = impact1d.simulate(by_arrays)
    assert before.scene.v1 == -9.0 and after.scene.v1 == -5.0
    assert after.events["t"][0] != before.events["t"][0]


def test_results_do_not_share_arrays():
    """Each Result owns its arrays: a later run (into the thread's reused event buffers)
    and a change to one Result leave another as it was, and so does a change to its scene."""
    scene = impact1d.load_scene(INPUT / "case5.nml")
    first = impact1d.simulate(scene)
    kept = {name: getattr(first, name).copy() for name in first.columns + ("events",)}
    impact1d.simulate(scene, v1=1.0)
    second = impact1d.simulate(scene)
    for name, value in kept.items():
        np.testing.assert_array_equal(getattr(first, name), value)
    second.x1[:] = 0.0
    second.scene.m1 = 99.0
    np.testing.assert_array_equal(first.x1, kept["x1"])
    assert first.scene.m1 == scene.m1 and impact1d.simulate(scene).scene.m1 == scene.m1


TUTORIAL_KINDS = ("left", "right", "slot_min", "slot_max", "rest_left", "rest_right", "rest_slot_min",
                  "rest_slot_max", "release_left", "release_right", "release_slot_min", "release_slot_max",
                  "stick1", "stick2", "slip1", "slip2")


def test_event_kinds_without_a_scene_are_the_tutorials():
    assert impact1d.event_kinds() == TUTORIAL_KINDS
    assert impact1d.event_kinds(None) == TUTORIAL_KINDS


def test_event_kinds_of_a_scene_are_its_rows_and_bodies_in_the_engines_order():
    """A scene's kinds: impacts per row (the walls and slot it has, then its records'
    rows by name), rest_ and release_ per row, stick and slip per body; the same from a
    Result of it, from its output read back, and in the order the CLI counts them."""
    scene = impact1d.load_scene(INPUT / "inner_stop.nml")
    rows = ("left", "slot_max", "stop", "wall1")
    expected = rows + tuple("rest_" + r for r in rows) + tuple("release_" + r for r in rows) + \
        ("stick1", "stick2", "slip1", "slip2")
    assert impact1d.event_kinds(scene) == expected
    result = impact1d.simulate(scene)
    assert impact1d.event_kinds(result) == expected
    assert set(result.events["kind"]) <= set(expected)
    assert impact1d.event_kinds() == TUTORIAL_KINDS          # (no state left behind)
    one_body = impact1d.Scene(m1=1.0, x1=0.0, x_left=-1.0, t_end=1.0, dt=1e-3, f1=-1.0,
                              contacts=[dict(a=1, b=0, d_min=-0.5)])
    assert impact1d.event_kinds(one_body) == ("left", "contact1", "rest_left", "rest_contact1",
                                              "release_left", "release_contact1", "stick1", "slip1")
    # the CLI's summary counts the kinds in this order
    from tools import find_tool
    summary = subprocess.run([find_tool("impact1d"), str(INPUT / "inner_stop.nml"), "-o", "-"],
                             capture_output=True, text=True, check=True).stderr
    counted = re.search(r"^\s*events\s+(.*)$", summary, re.M).group(1).split()[::2]
    assert counted == [kind for kind in expected if kind in counted] and len(counted) > 4


def test_event_kinds_of_a_bad_scene_raise_as_simulate_does():
    scene = impact1d.load_scene(INPUT / "inner_stop.nml")
    with pytest.raises(InputError, match="m1"):
        impact1d.event_kinds(dataclasses.replace(scene, m1=-1.0))
    with pytest.raises(InputError, match="Scene or Result"):
        impact1d.event_kinds("input/inner_stop.nml")


def test_event_kinds_come_from_the_runs_rows_and_bodies():
    """Event (class, index) is named from the run's rows (1 impact, 2 rest, 3 release) and
    bodies (4 stick, 5 slip); anything outside them is 'unknown', never another's name."""
    from impact1d._simulate import _event_names
    codes = np.full((32, 2), ord(" "), dtype=np.int32, order="F")
    for k, name in enumerate(("left", "slot_max")):
        codes[:len(name), k] = [ord(c) for c in name]
    event_class = np.array([1, 2, 3, 1, 4, 5, 5, 0, 6, 1, 1, 4, -1], dtype=np.int32)
    event_index = np.array([1, 2, 1, 2, 1, 2, 1, 1, 1, 0, 3, 3, 1], dtype=np.int32)
    assert list(_event_names(event_class, event_index, codes, 2)) == [
        "left", "rest_slot_max", "release_left", "slot_max", "stick1", "slip2", "slip1",
        "unknown", "unknown", "unknown", "unknown", "unknown", "unknown"]


@pytest.mark.parametrize("overrides", [
    {"v1": -8.5}, {"v1": -0.0, "x2": 3.25}, {"t_end": 0.35, "dt": 0.01, "dt_out": 0.05},
    {"r_left": 0.5, "mu1": 0.2, "f2": -1.5}, {"v1": 1e300}, {"dt": float("nan")}, {"m1": -1.0},
    {"dt_out": np.float64(0.125)}, {"f1_amp": 2.0, "f1_period": 0.5}, {"k1": 50.0}])
def test_number_overrides_run_as_the_scene_with_those_values(overrides):
    """Float overrides of real fields go into the scene's kept core form (no conversion of
    the whole scene): the run, its Result.scene, or its error are those of a scene made with
    the values."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    impact1d.simulate(scene, t_end=0.1)                   # (its form kept)

    def outcome(run):
        try:
            result = run()
        except (InputError, SimulationError) as error:
            return type(error), str(error)
        fields = {name: value for name, value in vars(result.scene).items()}
        return result.samples.tobytes(), result.events.tobytes(), result.warnings, repr(fields)

    assert outcome(lambda: impact1d.simulate(scene, **overrides)) == \
        outcome(lambda: impact1d.simulate(dataclasses.replace(scene, **overrides)))
