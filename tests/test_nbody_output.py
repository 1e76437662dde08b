"""The N-body output format (docs/formats.md, "Scenes of more than two bodies"): read_output
reads a file of N bodies and its events back into a Result whose x and v are (samples, N)
with x1 ... views of their columns, its events in NBODY_EVENT_DTYPE; pandas reads the file
with the documented call. The engine for N > 2 is not merged yet: the files here are
written in the format the core's file sink writes (tests/fortran/test_output.f90 checks
that it does)."""

import io

import numpy as np
import pytest

import impact1d
from impact1d._simulate import Result, NBODY_EVENT_DTYPE

HEADER = """# impact1d output
# title = five
# method = event
# g = 9.80665
# dt = 0.001
# dt_out = 0.001
# m = 1.0 2.0 3.0 4.0 5.0
# x = 0.0 1.0 2.0 3.0 4.0
# d_min = 0.25 0.25 0.25 0.25
# bodies = 5
"""


def _write(tmp_path, columns, rows, events=None):
    path = tmp_path / "five.dat"
    lines = [HEADER + "# " + " ".join(columns)]
    lines += [" ".join(f"{value:25.16e}" for value in row) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    if events is not None:
        (tmp_path / "five.events.dat").write_text(
            "# impact1d events\n# t kind a b va_before vb_before va_after vb_after\n" + events)
    return path


def _rows(n_rows, n_columns):
    return np.arange(n_rows * n_columns, dtype=float).reshape(n_rows, n_columns) / 7.0


def test_read_output_of_five_bodies(tmp_path):
    columns = ["t"] + [f"{c}{i}" for i in range(1, 6) for c in "xv"] + \
        ["ke", "work", "friction_loss", "impact_loss", "residual"]
    rows = _rows(3, len(columns))
    events = ("  1.5 stop3 0 3  0.0 -2.0 0.0 1.0\n"
              "  2.0 link_2_5 2 5  1.0 2.0 3.0 4.0\n"
              "  2.5 stick4 4 0  0.5 0.0 0.0 0.0\n")
    res = impact1d.read_output(_write(tmp_path, columns, rows, events))
    assert res.bodies == (1, 2, 3, 4, 5)
    assert res.x.shape == (3, 5) and res.v.shape == (3, 5)
    np.testing.assert_array_equal(res.x, rows[:, 1:11:2])
    np.testing.assert_array_equal(res.v, rows[:, 2:12:2])
    for i in range(1, 6):
        assert np.shares_memory(getattr(res, f"x{i}"), res.x)
        np.testing.assert_array_equal(getattr(res, f"x{i}"), res.x[:, i - 1])
        np.testing.assert_array_equal(getattr(res, f"v{i}"), res.v[:, i - 1])
    np.testing.assert_array_equal(res.ke, rows[:, 11])
    assert res.pe is None and res.damping_loss is None
    assert res.columns == tuple(columns)
    np.testing.assert_array_equal(res.samples, rows)
    assert list(res.to_dataframe().columns) == columns
    assert res.energy_residual == np.max(np.abs(rows[:, -1]))
    # the scene's arrays from the header
    assert res.scene.m == [1.0, 2.0, 3.0, 4.0, 5.0] and res.scene.d_min == [0.25] * 4
    assert res.scene.title == "five" and res.scene.dt == 0.001
    # events: the pair and its velocities
    assert res.events.dtype == NBODY_EVENT_DTYPE
    assert list(res.events["kind"]) == ["stop3", "link_2_5", "stick4"]
    assert list(res.events["a"]) == [0, 2, 4] and list(res.events["b"]) == [3, 5, 0]
    np.testing.assert_array_equal(res.events["vb_after"], [1.0, 4.0, 0.0])
    assert list(res.events_frame().columns) == list(NBODY_EVENT_DTYPE.names)
    with pytest.raises(AttributeError):
        res.x6


def test_read_output_with_bodies_out(tmp_path):
    """&run bodies_out = 2, 5: the x and v of those bodies only (the ledger over every body);
    x1, x3 are None, x2 and x5 the columns of x."""
    columns = ["t", "x2", "v2", "x5", "v5", "ke", "pe", "work", "friction_loss", "impact_loss",
               "damping_loss", "residual"]
    rows = _rows(4, len(columns))
    res = impact1d.read_output(_write(tmp_path, columns, rows))
    assert res.bodies == (2, 5) and res.x.shape == (4, 2)
    assert res.x1 is None and res.v1 is None
    np.testing.assert_array_equal(res.x2, rows[:, 1])
    np.testing.assert_array_equal(res.v5, rows[:, 4])
    np.testing.assert_array_equal(res.pe, rows[:, 6])
    assert res.columns == tuple(columns)
    assert len(res.events) == 0 and res.events.dtype == NBODY_EVENT_DTYPE


def test_nbody_file_in_plain_pandas(tmp_path):
    """The documented plain-pandas call reads the samples and the events of an N-body output."""
    pd = pytest.importorskip("pandas")
    columns = ["t"] + [f"{c}{i}" for i in range(1, 4) for c in "xv"] + \
        ["ke", "work", "friction_loss", "impact_loss", "residual"]
    rows = _rows(2, len(columns))
    path = _write(tmp_path, columns, rows, "  1.5 link_1_3 1 3  1.0 2.0 3.0 4.0\n")
    with open(path) as handle:
        names = [line[1:].split() for line in handle if line.startswith("#")][-1]
    frame = pd.read_csv(path, sep=r"\s+", comment="#", header=None, names=names)
    assert list(frame.columns) == columns
    np.testing.assert_array_equal(frame.to_numpy(), rows)
    events = pd.read_csv(tmp_path / "five.events.dat", sep=r"\s+", comment="#", header=None,
                         names=list(NBODY_EVENT_DTYPE.names))
    assert events["b"].tolist() == [3] and events["kind"].tolist() == ["link_1_3"]


@pytest.mark.parametrize("columns", [
    ["t", "x1", "v1", "x3", "ke", "work", "friction_loss", "impact_loss", "residual"],   # x3 without v3
    ["t", "x3", "v3", "x1", "v1", "ke", "work", "friction_loss", "impact_loss", "residual"],   # out of order
    ["t", "x1", "v1", "x7", "v7", "ke", "work", "friction_loss", "impact_loss", "residual"],   # past N = 5
    ["t", "x1", "v1", "work", "ke", "friction_loss", "impact_loss", "residual"],   # ledger out of order
])
def test_read_output_refuses_bad_nbody_columns(tmp_path, columns):
    path = _write(tmp_path, columns, _rows(1, len(columns)))
    with pytest.raises(impact1d.InputError, match="the columns|names body"):
        impact1d.read_output(path)


def test_two_body_result_has_x_and_v_as_views():
    """One and two bodies keep every field; x and v are (samples, N) views beside them."""
    res = impact1d.simulate(impact1d.load_scene("input/case3.nml"), t_end=0.1)
    assert res.bodies == (1, 2) and res.x.shape == (len(res.t), 2)
    assert np.shares_memory(res.x, res.x1) and np.shares_memory(res.x, res.x2)
    np.testing.assert_array_equal(res.v[:, 1], res.v2)
    assert res.columns == ("t", "x1", "v1", "x2", "v2", "ke", "work", "friction_loss", "impact_loss",
                           "residual")
    one = impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.0, x_left=-1.0, t_end=0.1, dt=1e-3, f1=-1.0))
    assert one.bodies == (1,) and one.x.shape == (len(one.t), 1) and one.x2 is None
    made = Result(t=res.t, x1=res.x1, v1=res.v1, ke=res.ke)
    assert made.x.shape == (len(res.t), 1) and made.bodies == (1,)


def test_cli_bodies_out_limits_the_bodies_written(tmp_path):
    """--bodies-out 2 writes x2, v2 and not x1, v1 (the ledger unchanged); a list naming a
    body the scene does not have, out of order or not numbers, is bad input (status 1)."""
    import subprocess
    from pathlib import Path
    from tools import find_tool
    cli, case = find_tool("impact1d"), Path(__file__).parent.parent / "input" / "case3.nml"
    common = ("--t-end", "0.5", "--quiet")
    subprocess.run([cli, case, *common, "-o", tmp_path / "all.dat"], check=True, capture_output=True)
    subprocess.run([cli, case, *common, "--bodies-out", "2", "-o", tmp_path / "two.dat"], check=True,
                   capture_output=True)
    full, two = impact1d.read_output(tmp_path / "all.dat"), impact1d.read_output(tmp_path / "two.dat")
    assert two.bodies == (2,) and two.x1 is None and two.v1 is None
    assert two.columns == ("t", "x2", "v2", "ke", "work", "friction_loss", "impact_loss", "residual")
    np.testing.assert_array_equal(two.x2, full.x2)
    np.testing.assert_array_equal(two.residual, full.residual)
    np.testing.assert_array_equal(two.events["v1_after"], full.events["v1_after"])
    for bad in ("3", "2,1", "1,1", "x", ""):
        proc = subprocess.run([cli, case, *common, "--bodies-out", bad, "-o", tmp_path / "bad.dat"],
                              capture_output=True, text=True)
        assert proc.returncode == 1 and "bodies" in proc.stderr, (bad, proc.stderr)


NAMELIST = """&bodies m1 = 1.0, m2 = 2.0 /
&initial x1 = 0.0, v1 = 1.0, x2 = 5.0, v2 = -0.5 /
&run t_end = 0.1, dt = 1e-3, {} /
"""


def test_namelist_bodies_out(tmp_path):
    """&run bodies_out = ... in a namelist limits the CLI's columns as --bodies-out does (the
    list ends where the next variable starts); a bad list is bad input naming the line; Python's
    load_scene reads it as Scene.bodies_out and simulate writes the same columns."""
    import subprocess
    from tools import find_tool
    cli = find_tool("impact1d")
    scene = tmp_path / "two.nml"
    scene.write_text(NAMELIST.format("bodies_out = 2, dt_out = 0.01"))
    subprocess.run([cli, scene, "--quiet", "-o", tmp_path / "two.dat"], check=True, capture_output=True)
    res = impact1d.read_output(tmp_path / "two.dat")
    assert res.columns == ("t", "x2", "v2", "ke", "work", "friction_loss", "impact_loss", "residual")
    assert len(res.t) == 11 and res.x2[-1] == 5.0 - 0.05
    for bad, message in (("bodies_out = 1.5", "not a list of body numbers"), ("bodies_out = 3", "does not have"),
                         ("bodies_out = 2, 1", "increasing order"), ("bodies_out = 1, bodies_out = 2", "twice")):
        scene.write_text(NAMELIST.format(bad))
        proc = subprocess.run([cli, scene, "--quiet", "-o", tmp_path / "bad.dat"], capture_output=True, text=True)
        assert proc.returncode == 1 and message in proc.stderr, (bad, proc.stderr)
    # Python reads it as Scene.bodies_out (it used to refuse it) and runs it as the CLI does.
    scene.write_text(NAMELIST.format("bodies_out = 2, dt_out = 0.01"))
    loaded = impact1d.load_scene(scene)
    assert loaded.bodies_out == [2]
    res_py = impact1d.simulate(loaded)
    assert res_py.columns == res.columns and res_py.bodies == (2,) and res_py.x1 is None
    np.testing.assert_array_equal(res_py.samples, res.samples)


def test_python_bodies_out():
    """Scene(bodies_out=...) and simulate(scene, bodies_out=[...]): the x and v of those
    bodies only, the same numbers as a run of every body, the ledger unchanged; a bad list
    is InputError with the namelist's messages. The namelist's &run bodies_out of more than
    two bodies comes back in load_scene's Scene."""
    from pathlib import Path
    root = Path(__file__).parent.parent
    cradle = impact1d.load_scene(root / "input" / "newtons_cradle.nml")
    full = impact1d.simulate(cradle)
    some = impact1d.simulate(cradle, bodies_out=[1, 5])
    assert some.bodies == (1, 5) and some.x.shape == (len(full.t), 2) and some.x2 is None and some.x3 is None
    assert some.columns[:5] == ("t", "x1", "v1", "x5", "v5")
    np.testing.assert_array_equal(some.x5, full.x5)
    np.testing.assert_array_equal(some.v1, full.v1)
    np.testing.assert_array_equal(some.ke, full.ke)
    assert some.scene.bodies_out == [1, 5] and list(some.events["kind"]) == list(full.events["kind"])
    two = impact1d.simulate(impact1d.Scene(m1=1.0, m2=2.0, x1=0.0, v1=1.0, x2=5.0, t_end=0.1, dt=1e-3,
                                           bodies_out=[2]))
    assert two.columns == ("t", "x2", "v2", "ke", "work", "friction_loss", "impact_loss", "residual")
    for bad, message in (([3, 1], "increasing order"), ([7], "does not have"), ([0], "does not have"),
                         ([1.5], "list of body numbers"), ("1", "list of body numbers"), ([], "names no body")):
        with pytest.raises(impact1d.InputError, match=message):
            impact1d.simulate(cradle, bodies_out=bad)
    text = (root / "input" / "newtons_cradle.nml").read_text().replace("&run ", "&run bodies_out = 2, 4, ")
    import tempfile
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "cradle.nml"
        path.write_text(text)
        loaded = impact1d.load_scene(path)
    assert loaded.bodies_out == [2, 4] and impact1d.simulate(loaded).bodies == (2, 4)


def test_flat_api_output_of_five_bodies_becomes_a_result():
    """What simulate() does with the flat API's arrays of a run of five bodies (the engine
    is not merged: the arrays are made here as the core fills them, api.f90's simulate):
    has_column over the full row of 2 N + 9 columns, info(8) = N, events with their pair.
    The Result has x, v (samples, 5) with x1 .. x5 views, and NBODY_EVENT_DTYPE events
    named from the run's rows."""
    from types import SimpleNamespace
    from impact1d._simulate import _column_layout, _fill_result, _fill_events, row_length, row_names
    n, rows = 5, 4
    assert row_length(n) == 19 and row_names(n)[:3] == ("t", "x1", "v1") and row_names(n)[11:] == \
        ("ke", "pe", "work", "friction_loss", "impact_loss", "damping_loss", "drive_work", "residual")
    has_column = np.ones(row_length(n), dtype=np.int32)
    has_column[[12, 16, 17]] = 0                                # no pe, no damping_loss, no drive_work
    names = _column_layout(has_column.tobytes(), n)
    samples = np.asfortranarray(_rows(rows, row_length(n)))    # (the core's room: all columns)
    result = object.__new__(Result)
    _fill_result(vars(result), samples, names)
    vars(result).update(scene=None, events=None)
    assert result.columns == names and len(names) == 16
    assert result.x.shape == (rows, n) and result.bodies == (1, 2, 3, 4, 5)
    for i in range(1, n + 1):
        column = getattr(result, f"x{i}")
        assert np.shares_memory(column, result.x) and (column == samples[:, 2 * i - 1]).all()
        assert (getattr(result, f"v{i}") == samples[:, 2 * i]).all()
    assert (result.ke == samples[:, 11]).all() and (result.residual == samples[:, 15]).all()
    assert result.pe is None
    # events: (class, index, a, b) and [t, va-, vb-, va+, vb+]; rows 'stop3' and 'link_2_5'
    codes = np.full((32, 2), ord(" "), dtype=np.int32, order="F")
    for k, name in enumerate(("stop3", "link_2_5")):
        codes[:len(name), k] = [ord(c) for c in name]
    buffers = SimpleNamespace(
        event_real=np.asfortranarray([[1.5, 0.0, -2.0, 0.0, 1.0], [2.0, 1.0, 2.0, 3.0, 4.0],
                                      [2.5, 0.5, 0.0, 0.0, 0.0]]),
        event_int=np.asfortranarray(np.array([[1, 1, 0, 3], [2, 2, 2, 5], [4, 4, 4, 0]], dtype=np.int32)),
        row_name_codes=codes)
    events = np.empty(3, dtype=NBODY_EVENT_DTYPE)
    _fill_events(events, buffers, 3, 2, n)
    assert list(events["kind"]) == ["stop3", "rest_link_2_5", "stick4"]
    assert list(events["a"]) == [0, 2, 4] and list(events["b"]) == [3, 5, 0]
    assert list(events["va_after"]) == [0.0, 3.0, 0.0] and list(events["vb_before"]) == [-2.0, 2.0, 0.0]


def test_cli_writes_a_thousand_bodies(tmp_path):
    """A row of 1000 bodies is 2008 values (50 kB): the CLI measured its sample line in a
    buffer of 1024 characters and ended with a Fortran runtime error ('End of record',
    status 2, a backtrace). Now it writes the file, which reads back whole."""
    import subprocess
    from tools import find_tool
    n = 1000
    scene = tmp_path / "chain.nml"
    scene.write_text(f"&bodies m = {n}*1.0 /\n"
                     f"&initial x = {', '.join(f'{0.25 * i:g}' for i in range(n))}, v = 1.0, {n - 1}*0.0 /\n"
                     f"&link d_min = {n - 1}*0.1 /\n&run t_end = 0.2, dt = 0.01, dt_out = 0.1 /\n")
    done = subprocess.run([find_tool("impact1d"), scene, "--quiet", "-o", tmp_path / "chain.dat"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    res = impact1d.read_output(tmp_path / "chain.dat")
    assert res.x.shape == (3, n) and res.bodies == tuple(range(1, n + 1))
    np.testing.assert_allclose(res.x1, [0.0, 0.1, 0.15], atol=1e-12)    # ball 1 meets ball 2 at 0.15 s
    np.testing.assert_allclose(res.v[-1, :3], [0.0, 1.0, 0.0], atol=1e-12)


def test_cli_summary_counts_events_of_a_long_chain_by_kind(tmp_path):
    """A gapped cradle of 40 equal elastic balls passes ball 1's speed down the chain: 39
    impacts, one on each link. The summary named every row with its count (a line of 10,000
    names for a long chain); past 16 names it gives each kind's total and how many rows it
    is on. Two bodies still get names (case 3: its walls and slot)."""
    import subprocess
    from pathlib import Path
    from tools import find_tool
    n = 40
    scene = tmp_path / "cradle.nml"
    scene.write_text(f"&bodies m = {n}*1.0 /\n"
                     f"&initial x = {', '.join(f'{0.25 * i:g}' for i in range(n))}, v = 1.0, {n - 1}*0.0 /\n"
                     f"&link d_min = {n - 1}*0.1 /\n&run t_end = 6.5, dt = 0.01, dt_out = 0.5 /\n")
    done = subprocess.run([find_tool("impact1d"), scene, "-o", tmp_path / "cradle.dat"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    line = next(line for line in done.stdout.splitlines() if line.lstrip().startswith("events"))
    assert line.split() == ["events", "impacts", "39", "on", "39", "rows"], line
    case3 = Path(__file__).parent.parent / "input" / "case3.nml"
    done = subprocess.run([find_tool("impact1d"), case3, "-o", tmp_path / "case3.dat"],
                          capture_output=True, text=True)
    line = next(line for line in done.stdout.splitlines() if line.lstrip().startswith("events"))
    assert line.split() == ["events", "left", "3", "right", "1", "slot_min", "20", "slot_max", "17"], line
