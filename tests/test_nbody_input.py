"""The scene formats for N bodies (issue 19, DESIGN "Mechanisms as data"), input side:
namelist arrays with repeat counts, repeatable &contact and &spring groups, and the checks
that need no engine."""
import dataclasses
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool

INPUT = Path(__file__).resolve().parent.parent / "input"
CASE3 = (INPUT / "case3.nml").read_text()
RUN = "&run t_end = 0.5, dt = 1e-3 /\n"
CHAIN = """&bodies  m = 5*1.0, mu = 5*0.1, mus = 5*0.15, g = 9.81 /
&initial x = 0.0, 0.3, 0.6, 0.9, 1.2,  v = -1.0, 4*0.0 /
&walls   x_left = -1.0, r_left = 1.0, x_right = 3.0, r_right = 1.0 /
&link    d_min = 4*0.25, r_min = 4*1.0, d_max = 4*0.5, r_max = 4*0.0 /
&contact a = 0, b = 3, d_min = -1.0, r_min = 0.8, name = 'stop3' /
&contact a = 2, b = 5, d_min = 0.1, r_min = 0.5, d_max = 1.0, r_max = 0.0 /
&spring  a = 1, b = 3, k = 40.0, d_rest = 0.5, c = 0.1 /
""" + RUN


def scene_file(tmp_path, text, name="scene.nml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def refused(tmp_path, text, match):
    """Refused when read, or when run."""
    with pytest.raises(impact1d.InputError, match=match) as caught:
        impact1d.simulate(impact1d.load_scene(scene_file(tmp_path, text)))
    assert "\n" not in str(caught.value)
    return str(caught.value)


# --- arrays for one and two bodies mean the tutorial's names --------------------------

TWO_BY_NAMES = """&bodies  m1 = 1.0, m2 = 2.0, mu1 = 0.1, mu2 = 0.2 /
&walls   x_left = 0.0, r_left = 0.5, x_right = 10.0 /
&link    d_min = 1.0, d_max = 2.0, r_max = 0.5 /
&initial x1 = 1.0, v1 = -9.0, x2 = 2.5, v2 = 1.0 /
&forces  f1 = 1.0, f2 = -1.0, f2_amp = 2.0, f2_period = 0.5 /
&springs k1 = 3.0, x1_rest = 1.0, c12 = 0.25 /
""" + RUN
TWO_BY_ARRAYS = """&bodies  m = 1.0, 2.0, mu = 0.1 0.2 /
&walls   x_left = 0.0, r_left = 0.5, x_right = 10.0 /
&link    d_min = 1.0, d_max = 2.0, r_max = 0.5 /
&initial x = 1.0, 2.5, v = -9.0, 1.0 /
&forces  f = 1.0, -1.0, f2_amp = 2.0, f2_period = 0.5 /
&springs k1 = 3.0, x1_rest = 1.0, c_link = 0.25 /
""" + RUN


def test_two_body_arrays_mean_the_tutorial_names(tmp_path):
    by_names = impact1d.load_scene(scene_file(tmp_path, TWO_BY_NAMES, "names.nml"))
    by_arrays = impact1d.load_scene(scene_file(tmp_path, TWO_BY_ARRAYS, "arrays.nml"))
    assert dataclasses.replace(by_arrays, source=by_names.source) == by_names
    a, b = impact1d.simulate(by_names), impact1d.simulate(by_arrays)
    assert np.array_equal(a.samples, b.samples) and np.array_equal(a.events, b.events)


def test_one_body_array_and_table_array(tmp_path):
    (tmp_path / "t.dat").write_text("0 1\n1 2\n")
    scene = impact1d.load_scene(scene_file(
        tmp_path, "&bodies m = 2*1.0 / &initial x = 0, 1 / &forces f_table = '', 't.dat' /\n" + RUN))
    assert scene.m1 == scene.m2 == 1.0 and scene.f1_table is None
    assert Path(scene.f2_table) == tmp_path / "t.dat"
    scene = impact1d.load_scene(scene_file(tmp_path, "&bodies m = 1*2.0 / &initial x = 0.5 /\n" + RUN))
    assert scene.m1 == 2.0 and scene.m2 is None and scene.x1 == 0.5


def test_array_element_errors_keep_the_spelling(tmp_path):
    refused(tmp_path, "&bodies m = 1.0, -1.0 / &initial x = 0, 1 /\n" + RUN, re.escape("m(2) = -1.0 must be positive"))
    refused(tmp_path, "&bodies m = 1.0, 1.0 / &initial x = 0, 1x /\n" + RUN, re.escape("x(2) = '1x' is not a number"))


@pytest.mark.parametrize("text, match", [
    ("&bodies m = 2*1.0 / &initial x = 0, 1, 2 /", "x has 3 values, but body arrays hold one per body, N = 2"),
    ("&bodies m = 2*1.0, m2 = 1 / &initial x = 0, 1 /", re.escape("m2 is given and so is m (m2 is m(2))")),
    ("&bodies m = 3*1.0 / &initial x = 0, , 2 /", "has a null"),
    ("&bodies m = 3*1.0 / &initial x = 0, 2*, 2 /", "has a null"),
    ("&bodies m = 3*1.0 / &initial x = 0, 1, 2, x1 = 0 /", "x1 is a name of a one- or two-body scene"),
    ("&bodies m = 3*1.0 / &initial x = 0, 1, 2 / &link d_min = 3*0.5 /",
     "d_min has 3 values, but &link arrays hold one per link, N - 1 = 2"),
    ("&bodies m = 3*1.0, mu = 3*0.2, mus = 0.3, 0.1, 0.3 / &initial x = 0, 1, 2 /",
     re.escape("mus(2) = 0.1 is below mu(2) = 0.2")),
    ("&bodies m = 3*1.0 / &initial x = 0, 1, 0.5 /",
     re.escape("the initial state violates the contact 'link2': x3 - x2 = -0.5 is below its lower limit 0.0")),
    ("&bodies m = 3*1.0 / &initial x = 0, 1, 2 / &link d_min = 0, 0, d_max = 2, -1 /",
     re.escape("d_min(2) = 0.0 must not exceed d_max(2) = -1.0")),
    ("&bodies m = 3*1.0 / &initial x = 0, 1, 2 / &link r_meet = 2 /", re.escape("r_meet = 2.0 is outside [0, 1]")),
])
def test_chain_faults(tmp_path, text, match):
    refused(tmp_path, text + "\n" + RUN, match)


# --- records ------------------------------------------------------------------------

@pytest.mark.parametrize("record, match", [
    ("&contact a = 1, b = 4, d_min = 0 /", re.escape("&contact (line 2): b = 4.0 is not a body: the ends are 1 to N = 3")),
    ("&contact a = 1.5, b = 2, d_min = 0 /", "a = 1.5 is not a body"),
    ("&contact a = 2, b = 2, d_min = 0 /", "a = b = 2: a record joins two different ends"),
    ("&contact b = 2, d_min = 0 /", "a is required but not given"),
    ("&contact a = 1, b = 3 /", "a contact needs d_min or d_max"),
    ("&contact a = 1, b = 3, d_min = 0, r_max = 0.5 /", "r_max is given but d_max is not"),
    ("&contact a = 1, b = 3, d_min = 0, r_min = 1.5 /", re.escape("r_min = 1.5 is outside [0, 1]")),
    ("&contact a = 1, b = 3, d_min = 1, d_max = 0.5 /", re.escape("d_min = 1.0 must not exceed d_max = 0.5")),
    ("&contact a = 1, b = 3, d_min = 0, a = 2 /", re.escape("a is given twice (lines 2 and 2)")),
    ("&contact a = 1, b = 3, d_min = 0, name = 'stick1' /", "'stick1' starts with 'stick'"),
    ("&contact a = 1, b = 3, d_min = 0, name = 'left' /\n&walls x_left = -1 /", "'left' is used twice"),
    ("&contact a = 1, b = 3, d_min = 3 /", re.escape("violates the contact 'contact1': x3 - x1 = 2.0 is below")),
    ("&contact a = 3, b = 0, d_min = -1 /", re.escape("violates the contact 'contact1': x3 = 2.0 is above its upper limit 1.0")),
    ("&spring a = 1, b = 3, k = 1 /", "k is given but d_rest is not"),
    ("&spring a = 1, b = 3, c = -1 /", re.escape("c = -1.0 must not be negative")),
    ("&spring a = 1, b = 3 /", "a spring needs k or c"),
    ("&contact a = 1, b = 3, d_min = 0, name = '" + "n" * 33 + "' /", "is longer than 32 characters"),
])
def test_record_faults(tmp_path, record, match):
    refused(tmp_path, "&bodies m = 3*1.0 / &initial x = 0, 1, 2 /\n" + record + "\n" + RUN, match)


def test_records_are_repeatable_and_given_twice_is_per_record(tmp_path):
    """Two &contact groups are two records (another group given twice is still refused)."""
    text = CHAIN.replace("&spring ", "&spring a = 2, b = 4, c = 1.0 /\n&spring ")
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    assert len(scene.springs) == 2 and len(scene.contacts) == 2
    refused(tmp_path, CHAIN + "&walls x_left = -2 /\n", r"&walls is given twice")


@pytest.mark.parametrize("extra", ["&contact a = 1, b = 2, d_min = -1 /", "&spring a = 0, b = 1, k = 1, d_rest = 1 /"])
def test_records_on_two_bodies_run(tmp_path, extra):
    """Records on one or two bodies run (tests/test_records_run.py checks what they give);
    the scene read back keeps them."""
    scene = impact1d.load_scene(scene_file(tmp_path, CASE3 + extra + "\n"))
    res = impact1d.simulate(scene)
    assert res.events.size > 0 and (res.scene.contacts or res.scene.springs)


def test_chain_is_read_checked_and_run_by_the_cli(tmp_path):
    """Five bodies run from the command line (the N-body engine), and with the tutorial's
    fixed-step method too (its N-body form, tests/test_vissim_nbody.py)."""
    cli = find_tool("impact1d")
    done = subprocess.run([cli, str(scene_file(tmp_path, CHAIN)), "-o", str(tmp_path / "out.dat")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.dat").exists() and (tmp_path / "out.events.dat").exists()
    done = subprocess.run([cli, str(scene_file(tmp_path, CHAIN)), "--method", "vissim", "-o",
                           str(tmp_path / "v.dat")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "v.dat").exists() and (tmp_path / "v.events.dat").exists()


def test_the_documented_examples_pass_every_check(tmp_path):
    """docs/formats.md's examples: the two-body scene with records runs (its events named
    by the records, as the text says), and so does the chain of five bodies with records."""
    doc = (Path(__file__).resolve().parent.parent / "docs" / "formats.md").read_text()
    section = doc[doc.index("### Scenes of N bodies"):doc.index("## VisSim-style parameter file")]
    blocks = [[line.strip() for line in block.splitlines() if line.startswith("    &")]
              for block in section.split("\n\n")]
    blocks = [block for block in blocks if block]
    two_body, chain = blocks[0], [line for block in blocks[1:] for line in block]
    assert len(two_body) == 7 and len(chain) == 9
    res = impact1d.simulate(impact1d.load_scene(scene_file(tmp_path, "\n".join(two_body) + "\n", "two.nml")))
    assert {"stop", "rest_stop", "wall1"} <= set(res.events["kind"])
    (tmp_path / "a.dat").write_text("0 0\n1 1\n")          # (the table the example names)
    res = impact1d.simulate(impact1d.load_scene(scene_file(tmp_path, "\n".join(chain) + "\n" + RUN, "chain.nml")))
    assert res.events.size > 0


# --- Python: Scene arrays and records, through the core's assignments ------------------

def test_scene_arrays_run_as_the_tutorial_names():
    by_arrays = impact1d.Scene(m=[1.0, 2.0], mu=[0.1, 0.2], x=[1.0, 2.5], v=[-9.0, 1.0], f=[1.0, -1.0],
                               x_left=0.0, r_left=0.5, x_right=10.0, d_min=1.0, d_max=2.0, r_max=0.5,
                               k=[3.0, 0.0], x_rest=[1.0, 0.0], c_link=[0.25], t_end=0.5, dt=1e-3)
    by_names = impact1d.Scene(m1=1.0, m2=2.0, mu1=0.1, mu2=0.2, x1=1.0, x2=2.5, v1=-9.0, v2=1.0, f1=1.0,
                              f2=-1.0, x_left=0.0, r_left=0.5, x_right=10.0, d_min=1.0, d_max=2.0, r_max=0.5,
                              k1=3.0, x1_rest=1.0, k2=0.0, x2_rest=0.0, c12=0.25, t_end=0.5, dt=1e-3)
    a, b = impact1d.simulate(by_arrays), impact1d.simulate(by_names)
    assert np.array_equal(a.samples, b.samples) and np.array_equal(a.events, b.events)
    assert a.columns == b.columns
    # sweeps and overrides by name work on it too
    table = impact1d.sweep(by_arrays, {"x_left": [0.0, -1.0]})
    assert list(table["error"]) == ["", ""] and table["x1_end"][0] == a.x1[-1]
    assert impact1d.simulate(dataclasses.replace(by_arrays, r_left=1.0)).events.size > 0


def test_load_scene_of_a_chain_gives_arrays_and_records(tmp_path):
    scene = impact1d.load_scene(scene_file(tmp_path, CHAIN))
    assert scene.m == [1.0] * 5 and scene.x == [0.0, 0.3, 0.6, 0.9, 1.2] and scene.d_min == [0.25] * 4
    assert scene.m1 is None and scene.g == 9.81 and scene.x_left == -1.0
    assert scene.contacts == [{"a": 0, "b": 3, "d_min": -1.0, "r_min": 0.8, "name": "stop3"},
                              {"a": 2, "b": 5, "d_min": 0.1, "r_min": 0.5, "d_max": 1.0, "r_max": 0.0}]
    assert scene.springs == [{"a": 1, "b": 3, "k": 40.0, "d_rest": 0.5, "c": 0.1}]
    assert impact1d.simulate(scene).events.size > 0
    assert impact1d.simulate(scene, method="vissim").x.shape[1] == 5
    # The same checks as a file's, on what Python changed.
    bad = dataclasses.replace(scene, contacts=scene.contacts + [{"a": 1, "b": 6, "d_min": 0.0}])
    with pytest.raises(impact1d.InputError, match=re.escape("&contact record 3: b = 6.0 is not a body")):
        impact1d.simulate(bad)
    with pytest.raises(impact1d.InputError, match=re.escape("m(4) = 0.0 must be positive")):
        impact1d.simulate(dataclasses.replace(scene, m=[1.0, 1.0, 1.0, 0.0, 1.0]))


@pytest.mark.parametrize("fields, match", [
    ({"m": 2.0}, "m must be a list"),
    ({"m": [1.0, "a"]}, re.escape("m[1] must be a number, got 'a'")),
    ({"contacts": [{"a": 1, "q": 2}]}, "contacts\\[0\\] has no field 'q'"),
    ({"contacts": {"a": 1}}, "contacts must be a list of dicts"),
    ({"contacts": [{"a": 1, "b": 2, "d_min": 0.0, "name": "n" * 33}]},
     re.escape("&contact record 1: name = '" + "n" * 33 + "' is longer than 32 characters")),
    ({"m": [1.0, 1.0], "m1": 2.0}, re.escape("m1 is given and so is m (m1 is m(1))")),
])
def test_scene_nbody_field_faults(fields, match):
    scene = impact1d.Scene(**{"m": [1.0, 1.0], "x": [0.0, 1.0], "t_end": 0.1, "dt": 1e-3, **fields})
    with pytest.raises(impact1d.InputError, match=match):
        impact1d.simulate(scene)


def test_load_scene_of_a_long_chain_takes_the_room_it_needs(tmp_path):
    """More numbers and texts than load_scene's first guess (64, 16): the core says how many."""
    n = 40
    text = (f"&bodies m = {n}*1.0 /\n&initial x = " + ", ".join(str(i) for i in range(n)) + " /\n"
            + f"&forces f_table = {n}*'' /\n"
            + "".join(f"&contact a = {i}, b = {i + 1}, d_max = 2, name = 'c{i}' /\n" for i in range(1, 20)) + RUN)
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    assert scene.m == [1.0] * n and scene.x == [float(i) for i in range(n)] and scene.f_table == [None] * n
    assert [c["name"] for c in scene.contacts] == [f"c{i}" for i in range(1, 20)]


def test_result_scene_of_arrays_is_the_scene_run():
    """The plots read the tutorial's names from Result.scene (a force f=[...] was drawn as 0)."""
    scene = impact1d.Scene(m=[1.0, 2.0], x=[0.0, 1.0], f=[1.0, -2.0], f_amp=[0.5, 0.0], f_period=[1.0, 1.0],
                           t_end=0.2, dt=1e-3)
    result = impact1d.simulate(scene)
    assert (result.scene.m1, result.scene.m2, result.scene.f1, result.scene.f2) == (1.0, 2.0, 1.0, -2.0)
    assert result.scene.m is None and scene.m == [1.0, 2.0]
    forces = impact1d.plot.applied_forces(result)
    assert np.allclose(forces["f1"], 1.0 + 0.5 * np.sin(2 * np.pi * result.t)) and np.all(forces["f2"] == -2.0)


def test_read_output_takes_the_forces_of_a_scene_written_with_arrays(tmp_path):
    (tmp_path / "t.dat").write_text("0 0\n1 3\n")
    text = ("&bodies m = 1.0, 2.0 / &initial x = 0.0, 1.0 / &forces f = 1.0, -2.0, f_table = 't.dat', '' /\n"
            "&run t_end = 0.2, dt = 1e-3 /\n")
    path = scene_file(tmp_path, text)
    subprocess.run([find_tool("impact1d"), str(path), "-o", str(tmp_path / "out.dat")], check=True,
                   capture_output=True, timeout=60)
    scene = impact1d.Scene(m=[1.0, 2.0], x=[0.0, 1.0], f=[1.0, -2.0], f_table=[str(tmp_path / "t.dat"), None])
    result = impact1d.read_output(tmp_path / "out.dat", scene=scene)
    assert result.forces_known and result.scene.f1_table == str(tmp_path / "t.dat")
