"""A clear error for every bad input (issue 4).

Python: impact1d.InputError naming the variable and the value.  CLI: a non-zero exit
(1 for bad input, 2 for a run that cannot go on) with a one-line message on stderr,
and no output file created or overwritten (outputs go to a temporary name and are
renamed at the end).
"""

import math
import re
import subprocess
from pathlib import Path

import pytest

import impact1d
from impact1d import InputError, SimulationError
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"

# Generous bound on a CLI run that fails at once, on a 2-core machine.
CLI_TIMEOUT = 60
# Old content placed under the output names: a failed run must leave it as it is.
OLD_OUTPUT = "# an earlier run's output\n0 1 2\n"
OLD_EVENTS = "# an earlier run's events\n"

# A complete valid scene with every group; cases below edit one value in it.
GOOD = {
    "scene": "title = 'bad input base'",
    "bodies": "m1 = 1.0, m2 = 2.0, mu1 = 0.1, mu2 = 0.1, g = 10.0",
    "walls": "x_left = 0.0, r_left = 1.0, x_right = 10.0, r_right = 1.0",
    "link": "d_min = 1.0, r_min = 1.0, d_max = 2.0, r_max = 1.0",
    "initial": "x1 = 1.0, v1 = -9.0, x2 = 2.5, v2 = 1.0",
    "forces": "f1 = 0.0, f2 = 0.0",
    "run": "t_end = 0.5, dt = 1.0e-3, dt_out = 1.0e-2, method = 'event'",
}


def scene_text(**groups):
    """The namelist text of GOOD with some groups replaced (None drops a group)."""
    merged = {**GOOD, **groups}
    return "".join(f"&{name} {body} /\n" for name, body in merged.items() if body is not None)


def edit(group, old, new):
    """GOOD with `old` replaced by `new` inside one group."""
    assert old in GOOD[group], (group, old)
    return scene_text(**{group: GOOD[group].replace(old, new)})


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?|[-+]?(?:nan|inf(?:inity)?)",
                     re.IGNORECASE)


def mentions_value(message, value):
    """True if one of the numbers written in `message` equals `value` (NaN and +-Inf
    included; any formatting: 1.0, 1, 1.0E+00, 1.0d0)."""
    for text in _NUMBER.findall(message):
        try:
            number = float(text.lower().replace("d", "e").replace("infinity", "inf"))
        except ValueError:
            continue
        if math.isnan(value) and math.isnan(number):
            return True
        if number == value:
            return True
    return False


def assert_names(message, name, value=None):
    assert name in message, f"{name!r} not named in: {message}"
    if value is not None:
        assert mentions_value(message, value), f"value {value!r} not in: {message}"


@pytest.fixture(scope="module")
def cli():
    return find_tool("impact1d")


def run_cli(cli, *args, cwd):
    return subprocess.run([cli, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=CLI_TIMEOUT, stdin=subprocess.DEVNULL)


def check_cli_failure(cli, tmp_path, scene_path, words, status=1, extra=()):
    """The CLI fails with `status` and one line on stderr naming every word; an existing
    output pair is untouched, a new name is not created, and no temporary file is left."""
    old = tmp_path / "old.dat"
    old.write_text(OLD_OUTPUT)
    (tmp_path / "old.events.dat").write_text(OLD_EVENTS)
    before = set(tmp_path.iterdir())
    for out in (old, tmp_path / "new.dat"):
        proc = run_cli(cli, scene_path, *extra, "-o", out, cwd=tmp_path)
        assert proc.returncode == status, (proc.returncode, proc.stdout, proc.stderr)
        err = proc.stderr.strip()
        assert len(err.splitlines()) == 1, f"not one line on stderr:\n{proc.stderr}"
        for word in words:
            assert word in err, f"{word!r} not in: {err}"
    assert old.read_text() == OLD_OUTPUT
    assert (tmp_path / "old.events.dat").read_text() == OLD_EVENTS
    assert set(tmp_path.iterdir()) == before, sorted(p.name for p in set(tmp_path.iterdir()) - before)
    return err


# --- bad values: (case id, namelist text, variable named, value named) ------------------

NAN, INF = float("nan"), float("inf")

VALUE_CASES = [
    ("m1-zero", edit("bodies", "m1 = 1.0", "m1 = 0.0"), "m1", 0.0),
    ("m2-zero", edit("bodies", "m2 = 2.0", "m2 = 0.0"), "m2", 0.0),
    ("m1-negative", edit("bodies", "m1 = 1.0", "m1 = -1.0"), "m1", -1.0),
    ("m2-negative", edit("bodies", "m2 = 2.0", "m2 = -2.5"), "m2", -2.5),
    ("mu1-negative", edit("bodies", "mu1 = 0.1", "mu1 = -0.1"), "mu1", -0.1),
    ("mu2-negative", edit("bodies", "mu2 = 0.1", "mu2 = -0.25"), "mu2", -0.25),
    ("g-negative-with-friction", edit("bodies", "g = 10.0", "g = -10.0"), "g", -10.0),
    ("r_left-negative", edit("walls", "r_left = 1.0", "r_left = -0.1"), "r_left", -0.1),
    ("r_right-above-one", edit("walls", "r_right = 1.0", "r_right = 1.5"), "r_right", 1.5),
    ("r_min-just-below-zero", edit("link", "r_min = 1.0", "r_min = -1.0e-9"), "r_min", -1e-9),
    ("r_max-just-above-one", edit("link", "r_max = 1.0", "r_max = 1.000001"), "r_max",
     1.000001),
    ("walls-equal", edit("walls", "x_right = 10.0", "x_right = 0.0"), "x_left", 0.0),
    ("walls-crossed", edit("walls", "x_left = 0.0", "x_left = 11.0"), "x_left", 11.0),
    ("slot-crossed", edit("link", "d_min = 1.0", "d_min = 2.5"), "d_min", 2.5),
    ("x1-behind-left-wall", edit("initial", "x1 = 1.0", "x1 = -0.5"), "x1", -0.5),
    ("x2-behind-right-wall", edit("initial", "x2 = 2.5", "x2 = 10.5"), "x2", 10.5),
    ("slot-below-d_min", edit("initial", "x2 = 2.5", "x2 = 1.5"), "d_min", 1.0),
    ("slot-above-d_max", edit("initial", "x2 = 2.5", "x2 = 3.5"), "d_max", 2.0),
    ("dt-zero", edit("run", "dt = 1.0e-3", "dt = 0.0"), "dt", 0.0),
    ("dt-negative", edit("run", "dt = 1.0e-3", "dt = -1.0e-3"), "dt", -1e-3),
    ("t_end-zero", edit("run", "t_end = 0.5", "t_end = 0.0"), "t_end", 0.0),
    ("t_end-negative", edit("run", "t_end = 0.5", "t_end = -1.0"), "t_end", -1.0),
    ("dt_out-zero", edit("run", "dt_out = 1.0e-2", "dt_out = 0.0"), "dt_out", 0.0),
    ("nan-mass", edit("bodies", "m1 = 1.0", "m1 = NaN"), "m1", NAN),
    ("inf-position", edit("initial", "x2 = 2.5", "x2 = Infinity"), "x2", INF),
    ("minus-inf-force", edit("forces", "f1 = 0.0", "f1 = -Inf"), "f1", -INF),
    ("nan-restitution", edit("link", "r_min = 1.0", "r_min = NaN"), "r_min", NAN),
    ("inf-t_end", edit("run", "t_end = 0.5", "t_end = Inf"), "t_end", INF),
    ("unknown-method", edit("run", "method = 'event'", "method = 'no_such_method'"),
     "method", None),
    ("output-too-large", edit("run", "t_end = 0.5", "t_end = 1.0e9"), "dt_out", None),
]


def _write(tmp_path, text, name="scene.nml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, name, value", [c[1:] for c in VALUE_CASES],
                         ids=[c[0] for c in VALUE_CASES])
def test_bad_value_python(tmp_path, text, name, value):
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as info:
        impact1d.simulate(impact1d.load_scene(path))
    assert_names(str(info.value), name, value)


@pytest.mark.parametrize("text, name, value", [c[1:] for c in VALUE_CASES],
                         ids=[c[0] for c in VALUE_CASES])
def test_bad_value_cli(cli, tmp_path, text, name, value):
    path = _write(tmp_path, text)
    err = check_cli_failure(cli, tmp_path, path, [name])
    if value is not None:
        assert mentions_value(err, value), err


def test_negative_gravity_without_friction_is_allowed(tmp_path):
    """g only sets the friction bound mu m g: with mu = 0 a negative g means nothing."""
    text = edit("bodies", "mu1 = 0.1, mu2 = 0.1, g = 10.0", "mu1 = 0.0, mu2 = 0.0, g = -10.0")
    impact1d.simulate(impact1d.load_scene(_write(tmp_path, text)))


def test_output_too_large_suggests_dt_out(tmp_path):
    path = _write(tmp_path, edit("run", "t_end = 0.5", "t_end = 1.0e9"))
    with pytest.raises(InputError, match="dt_out") as info:
        impact1d.simulate(impact1d.load_scene(path))
    assert "limit" in str(info.value) or "too" in str(info.value)


# --- NaN and infinity in any value, through the Python API ----------------------------

FULL = impact1d.Scene(m1=1.0, m2=2.0, mu1=0.1, mu2=0.1, g=10.0, x_left=0.0, r_left=1.0,
                      x_right=10.0, r_right=1.0, d_min=1.0, r_min=1.0, d_max=2.0, r_max=1.0,
                      x1=1.0, v1=-9.0, x2=2.5, v2=1.0, f1=0.0, f2=0.0, f1_amp=1.0,
                      f1_period=1.0, f1_phase=0.0, f2_amp=1.0, f2_period=1.0, f2_phase=0.0,
                      t_end=0.5, dt=1e-3, dt_out=1e-2)


def test_full_scene_is_valid():
    impact1d.simulate(FULL)


@pytest.mark.parametrize("value", [NAN, INF, -INF], ids=["nan", "inf", "-inf"])
@pytest.mark.parametrize("name", impact1d._scene.REAL_FIELDS)
def test_non_finite_value_python(name, value):
    with pytest.raises(InputError) as info:
        impact1d.simulate(FULL, **{name: value})
    assert_names(str(info.value), name, value)


# --- files: missing, empty, unreadable, malformed ------------------------------------------

def test_missing_file(cli, tmp_path):
    missing = tmp_path / "no_such_scene.nml"
    with pytest.raises(InputError, match="no_such_scene.nml"):
        impact1d.load_scene(missing)
    check_cli_failure(cli, tmp_path, missing, ["no_such_scene.nml"])


def test_empty_file(cli, tmp_path):
    path = _write(tmp_path, "", name="empty.nml")
    with pytest.raises(InputError, match="empty.nml"):
        impact1d.load_scene(path)
    check_cli_failure(cli, tmp_path, path, ["empty.nml"])


def test_blank_file(cli, tmp_path):
    path = _write(tmp_path, "\n   \n! only a comment\n", name="blank.nml")
    with pytest.raises(InputError, match="blank.nml"):
        impact1d.simulate(impact1d.load_scene(path))
    check_cli_failure(cli, tmp_path, path, ["blank.nml"])


def test_directory_instead_of_file(cli, tmp_path):
    """A path that exists but cannot be read as a file (running as root, permission bits
    do not stop reading, so a directory stands for 'unreadable')."""
    folder = tmp_path / "folder.nml"
    folder.mkdir()
    with pytest.raises(InputError, match="folder.nml"):
        impact1d.load_scene(folder)
    check_cli_failure(cli, tmp_path, folder, ["folder.nml"])


def test_binary_garbage_file(cli, tmp_path):
    path = tmp_path / "garbage.nml"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(InputError, match="garbage.nml"):
        impact1d.simulate(impact1d.load_scene(path))
    check_cli_failure(cli, tmp_path, path, ["garbage.nml"])


# (case id, text, words the message must contain)
FILE_CASES = [
    ("misspelt-group", scene_text().replace("&bodies", "&bodys"), ["bodys"]),
    ("bad-number", edit("bodies", "m1 = 1.0", "m1 = 1.0.0"), ["bodies"]),
    ("word-for-number", edit("bodies", "m1 = 1.0", "m1 = heavy"), ["bodies"]),
    ("missing-slash", scene_text().replace("g = 10.0 /", "g = 10.0 ", 1), ["bodies"]),
    ("unknown-variable", edit("bodies", "m2 = 2.0,", "m2 = 2.0, m3 = 4.0,"), ["m3"]),
    ("unknown-group", scene_text() + "&extras a = 1.0 /\n", ["extras"]),
    ("missing-bodies", scene_text(bodies=None), ["bodies"]),
    ("missing-initial", scene_text(initial=None), ["initial"]),
    ("missing-run", scene_text(run=None), ["run"]),
    ("missing-m1", edit("bodies", "m1 = 1.0, ", ""), ["m1"]),
    ("missing-x2", edit("initial", ", x2 = 2.5", ""), ["x2"]),
    ("missing-dt", edit("run", "dt = 1.0e-3, ", ""), ["dt"]),
]


@pytest.mark.parametrize("text, words", [c[1:] for c in FILE_CASES],
                         ids=[c[0] for c in FILE_CASES])
def test_malformed_scene(cli, tmp_path, text, words):
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as info:
        impact1d.simulate(impact1d.load_scene(path))
    for word in words:
        assert word in str(info.value), str(info.value)
    check_cli_failure(cli, tmp_path, path, words)


# --- force tables -------------------------------------------------------------------------

# (case id, table text or None for a missing file, words the message must contain)
TABLE_CASES = [
    ("missing", None, ["f1_table", "table.dat"]),
    ("empty", "", ["f1_table", "table.dat"]),
    ("comments-only", "# t f\n\n", ["f1_table", "table.dat"]),
    ("not-a-number", "0 1\n1 x\n", ["f1_table", "table.dat"]),
    ("one-column", "0\n1\n", ["f1_table", "table.dat"]),
    ("three-columns", "0 1 5\n1 2 5\n", ["f1_table", "table.dat"]),
    ("time-repeats", "0 1\n1 2\n1 3\n", ["f1_table", "table.dat"]),
    ("time-decreases", "0 1\n2 2\n1 3\n", ["f1_table", "table.dat"]),
    ("nan-value", "0 1\n1 nan\n", ["f1_table", "table.dat"]),
]


@pytest.mark.parametrize("table, words", [c[1:] for c in TABLE_CASES],
                         ids=[c[0] for c in TABLE_CASES])
def test_bad_force_table(cli, tmp_path, table, words):
    if table is not None:
        (tmp_path / "table.dat").write_text(table)
    path = _write(tmp_path, scene_text(forces="f1 = 0.0, f2 = 0.0, f1_table = 'table.dat'"))
    with pytest.raises(InputError) as info:
        impact1d.simulate(impact1d.load_scene(path))
    for word in words:
        assert word in str(info.value), str(info.value)
    check_cli_failure(cli, tmp_path, path, words)


def test_good_force_table_is_accepted(tmp_path):
    (tmp_path / "table.dat").write_text("# t f\n0 0\n1 10\n2 0\n")
    path = _write(tmp_path, scene_text(forces="f1 = 0.0, f2 = 0.0, f1_table = 'table.dat'"))
    impact1d.simulate(impact1d.load_scene(path))


# --- the output -------------------------------------------------------------------------

@pytest.mark.parametrize("target", ["a_file/out.dat", "a_folder", "a_folder/"])
def test_output_path_that_cannot_be_written(cli, tmp_path, target):
    (tmp_path / "a_folder").mkdir()
    (tmp_path / "a_file").write_text("a file, so no folder of that name can be made\n")
    scene = _write(tmp_path, scene_text())
    before = sorted(p.name for p in tmp_path.rglob("*"))
    proc = run_cli(cli, scene, "-o", tmp_path / target, cwd=tmp_path)
    assert proc.returncode == 1, (proc.stdout, proc.stderr)
    err = proc.stderr.strip()
    assert len(err.splitlines()) == 1, proc.stderr
    assert target.rstrip("/").split("/")[0] in err, err
    # Nothing written anywhere: no output, no temporary file left behind.
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_cli_option_override_is_validated(cli, tmp_path):
    scene = _write(tmp_path, scene_text())
    check_cli_failure(cli, tmp_path, scene, ["dt_out"], extra=("--dt-out", "-1e-5"))
    check_cli_failure(cli, tmp_path, scene, ["method"], extra=("--method", "no_such_method"))
    check_cli_failure(cli, tmp_path, scene, ["dt"], extra=("--dt", "-1"))


# --- runtime failures -----------------------------------------------------------------

# x2 = 1e308 moving at 1e308 m/s: after one step of 0.5 s the position overflows.
OVERFLOW = """\
&bodies  m1 = 1.0, m2 = 2.0 /
&initial x1 = 2.0, x2 = 1.0e308, v2 = 1.0e308 /
&run     t_end = 10.0, dt = 0.5 /
"""


def test_non_finite_state_python(tmp_path):
    path = _write(tmp_path, OVERFLOW)
    with pytest.raises(SimulationError) as info:
        impact1d.simulate(impact1d.load_scene(path))
    message = str(info.value)
    assert "t =" in message and "finite" in message, message
    assert not isinstance(info.value, InputError)


def test_non_finite_state_cli(cli, tmp_path):
    """Exit status 2, one line, and the earlier output is left whole (temporary name)."""
    path = _write(tmp_path, OVERFLOW)
    err = check_cli_failure(cli, tmp_path, path, ["t =", "finite"], status=2)
    assert "overflow.nml" in err or "scene.nml" in err
