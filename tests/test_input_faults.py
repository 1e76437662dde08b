"""Hostile and unlucky input (issue 13 items 4, 5, 6, 8, 10; issue 12 item 5): every
mistake is an InputError naming what is wrong, never a silently different scene."""

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
CASE3 = (INPUT / "case3.nml").read_text()
RUN_TIMEOUT = 120


def scene_file(tmp_path, text, name="scene.nml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def refused(tmp_path, text, match, name="scene.nml"):
    with pytest.raises(impact1d.InputError, match=match) as caught:
        impact1d.load_scene(scene_file(tmp_path, text, name))
    assert "\n" not in str(caught.value)
    return str(caught.value)


# --- item 4: lines of any length ---------------------------------------------------

def test_long_indented_group_is_read(tmp_path):
    """A &walls group indented by 5000 blanks was dropped (case 3 then ran off to x1 = -13)."""
    scene = impact1d.load_scene(scene_file(tmp_path, CASE3.replace("&walls", " " * 5000 + "&walls")))
    assert scene.x_left == 0.0 and scene.x_right == 10.0
    res = impact1d.simulate(scene)
    assert res.x1.min() >= 0.0


def test_long_line_in_a_dat_file_keeps_the_order(tmp_path):
    text = (INPUT / "input3.dat").read_text().splitlines()
    numbers = [i for i, line in enumerate(text) if line.strip() and not line.startswith("#")]
    text[numbers[1]] = " " * 5000 + text[numbers[1]]
    path = tmp_path / "long.dat"
    path.write_text("\n".join(text) + "\n")
    assert impact1d.load_scene(path) == impact1d.load_scene(INPUT / "input3.dat").__class__(
        **{**vars(impact1d.load_scene(INPUT / "input3.dat")), "source": str(path)})


def test_big_force_table_reads_in_linear_time(tmp_path):
    """10^6 rows took 5.9 s (every row scanned a 4096-byte buffer twice)."""
    def table_of(rows):
        path = tmp_path / f"t{rows}.dat"
        path.write_text("".join(f"{i * 1e-3} {i % 7}\n" for i in range(rows)))
        return path

    def seconds(rows):
        text = (INPUT / "case6.nml").read_text().replace("'triangle.dat'", f"'{table_of(rows)}'")
        scene = impact1d.load_scene(scene_file(tmp_path, text, f"s{rows}.nml"))
        start = time.perf_counter()
        impact1d.simulate(scene, t_end=1e-3)
        return time.perf_counter() - start

    # Linear reading: 10x the rows cost about 10x (quadratic would be 100x); the ratio,
    # not a time, is asserted, with room for a noisy machine.
    assert seconds(200_000) < 30 * seconds(20_000) + 0.05


# --- item 5: given-ness does not depend on the value; syntax the reader passed over -----

@pytest.mark.parametrize("field, old", [("r_right", "r_right = 1.0"), ("mu1", "mu1 = 0.0")])
def test_largest_double_is_a_given_value(tmp_path, field, old):
    text = CASE3.replace(old, f"{field} = 1.7976931348623157e308")
    refused(tmp_path, text, field)


def test_largest_double_velocity_is_given(tmp_path):
    scene = impact1d.load_scene(scene_file(tmp_path, CASE3.replace("v1 = -9.0", "v1 = 1.7976931348623157e308")))
    assert scene.v1 == 1.7976931348623157e308
    with pytest.raises(impact1d.SimulationError, match="no longer finite"):
        impact1d.simulate(scene)


@pytest.mark.parametrize("old, new", [("v1 = -9.0", "v1 = +"), ("r_left = 1.0", "r_left = -")])
def test_lone_sign_is_refused(tmp_path, old, new):
    message = refused(tmp_path, CASE3.replace(old, new), "no number after its sign")
    assert ":" + str(CASE3.splitlines().index(next(l for l in CASE3.splitlines() if old in l)) + 1) in message


def test_second_group_is_refused(tmp_path):
    refused(tmp_path, CASE3 + "&run t_end = nan /\n", r"&run is given twice \(lines 8 and 9\)")


def test_stray_text_is_refused(tmp_path):
    refused(tmp_path, CASE3.replace("&walls", "oops\n&walls"), r":4: text outside any group: 'oops'")


def test_misspelt_variable_lists_the_group(tmp_path):
    refused(tmp_path, CASE3.replace("mu1 =", "mu_1 ="),
            r"unknown variable 'mu_1' \(&bodies has: m1, m2, mu1, mu2, mus1, mus2, g\)")


def test_missing_slash_says_so(tmp_path):
    refused(tmp_path, CASE3.replace("r_max = 1.0 /", "r_max = 1.0"),
            r"the group &link \(line 5\) has no closing '/'")
    refused(tmp_path, CASE3.rstrip().rstrip("/") + "\n", r"&run has no closing '/'")


def test_slash_inside_a_title_is_text(tmp_path):
    scene = impact1d.load_scene(scene_file(tmp_path, CASE3.replace(
        "conservation of energy", "energy / momentum")))
    assert scene.title.endswith("energy / momentum")


# --- item 6 (input part): overflow is an input error ---------------------------------

def test_friction_bound_that_overflows(tmp_path):
    refused(tmp_path, CASE3.replace("mu1 = 0.0", "mu1 = 1e308"), "mu1 = 1e\\+?308: the friction bound")


def test_int_too_large_for_a_double():
    with pytest.raises(impact1d.InputError, match="m1 = .* too large for a double"):
        impact1d.simulate(impact1d.load_scene(INPUT / "case3.nml"), m1=10 ** 400)


# --- item 8: coordinates beyond their resolution -------------------------------------

def test_scene_far_from_the_origin_is_refused():
    """Case 3 moved by 2e14 m: its 1 m slot and 0.5 m gaps are a few dozen ulps of the
    coordinates (a phantom impact at t = 0 took KE from 41.5 J to 8.17 J)."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    shift = 2e14
    with pytest.raises(impact1d.InputError, match="below the resolution"):
        impact1d.simulate(scene, x_left=shift, x_right=shift + 10, x1=shift + 1, x2=shift + 2.5)
    # Moved by 1e6 m it is resolved, and runs as at the origin (to the rounding of 1e6).
    res = impact1d.simulate(scene, x_left=1e6, x_right=1e6 + 10, x1=1e6 + 1, x2=1e6 + 2.5)
    base = impact1d.simulate(scene)
    assert len(res.events) == len(base.events)
    np.testing.assert_allclose(res.events["t"], base.events["t"], rtol=0, atol=1e-8)


def test_tiny_limit_is_refused():
    with pytest.raises(impact1d.InputError, match="d_min = 1e-100 is below the resolution"):
        impact1d.simulate(impact1d.load_scene(INPUT / "case3.nml"), d_min=1e-100, x2=1.5)


# --- item 10: folders, control bytes ---------------------------------------------------

def test_folder_as_scene(tmp_path):
    with pytest.raises(impact1d.InputError, match="is a folder"):
        impact1d.load_scene(tmp_path)
    done = subprocess.run([find_tool("impact1d"), str(tmp_path)], capture_output=True,
                          text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 1 and "is a folder" in done.stderr


def test_folder_as_force_table(tmp_path):
    (tmp_path / "table").mkdir()
    text = (INPUT / "case6.nml").read_text().replace("'triangle.dat'", "'table'")
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    with pytest.raises(impact1d.InputError, match="f1_table: .*table: is a folder"):
        impact1d.simulate(scene)


def test_control_bytes_are_escaped(tmp_path):
    path = tmp_path / "ctl.dat"
    path.write_bytes(b"# ctl\n1.0\n\x1b[31mred\x07\n")
    with pytest.raises(impact1d.InputError) as caught:
        impact1d.load_scene(path)
    assert "\\x1b[31mred\\x07" in str(caught.value)
    assert not any(ord(c) < 32 for c in str(caught.value))


def test_last_line_without_newline(tmp_path):
    """An editor that ends the file without a newline: the namelist read hit the end of
    the file inside &run ("in &run: End of file")."""
    scene = impact1d.load_scene(scene_file(tmp_path, CASE3.rstrip("\n")))
    assert scene == impact1d.load_scene(INPUT / "case3.nml").__class__(
        **{**vars(impact1d.load_scene(INPUT / "case3.nml")), "source": str(tmp_path / "scene.nml")})


# --- issue 18, item 4: only regular files are read; outputs go through links ----------

# The Python calls run in a child Python with a timeout: before the fix a FIFO blocked the
# open for ever and /dev/zero was read without end (a line of zeros, growing).
CHILD_TIMEOUT = 60


def child_python(tmp_path, code):
    """Run code in a fresh Python (cwd tmp_path); its stdout, stripped."""
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=CHILD_TIMEOUT)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def input_error_of(tmp_path, call):
    """The InputError message of an impact1d call made in a child Python ('' if none)."""
    return child_python(tmp_path, "import impact1d\n"
                                  "try:\n"
                                  f"    {call}\n"
                                  "except impact1d.InputError as error:\n"
                                  "    print(error)\n")


@pytest.mark.parametrize("path, kind", [("fifo", "FIFO"), ("/dev/zero", "character device"),
                                        (".", "folder")])
def test_special_file_as_scene(tmp_path, path, kind):
    os.mkfifo(tmp_path / "fifo")
    message = input_error_of(tmp_path, f"impact1d.load_scene({path!r})")
    assert path in message and kind in message, message
    assert "no such file" not in message


@pytest.mark.parametrize("table, kind", [("fifo", "FIFO"), ("/dev/zero", "character device")])
def test_special_file_as_force_table(tmp_path, table, kind):
    os.mkfifo(tmp_path / "fifo")
    scene = f"impact1d.load_scene({str(INPUT / 'case6.nml')!r})"
    message = input_error_of(tmp_path, f"impact1d.simulate({scene}, f1_table={table!r}, t_end=0.1)")
    assert message.startswith("f1_table: ") and table in message and kind in message, message


def test_links_to_regular_inputs_are_read(tmp_path):
    (tmp_path / "scene.nml").symlink_to(INPUT / "case6.nml")
    (tmp_path / "triangle.dat").symlink_to(INPUT / "triangle.dat")
    res = impact1d.simulate(impact1d.load_scene(tmp_path / "scene.nml"), t_end=1.0)
    base = impact1d.simulate(impact1d.load_scene(INPUT / "case6.nml"), t_end=1.0)
    np.testing.assert_array_equal(res.samples, base.samples)


def test_special_output_file_is_not_read(tmp_path):
    """read_output and impact1d-plot on a FIFO or a device: refused, not blocked."""
    os.mkfifo(tmp_path / "fifo.dat")
    for path, kind in (("fifo.dat", "FIFO"), ("/dev/zero", "character device")):
        message = input_error_of(tmp_path, f"impact1d.read_output({path!r})")
        assert path in message and kind in message, message
        done = subprocess.run([find_tool("impact1d-plot"), path], cwd=tmp_path, capture_output=True,
                              text=True, timeout=CHILD_TIMEOUT)
        assert done.returncode == 1 and done.stderr.count("\n") == 1 and kind in done.stderr


def test_outputs_are_written_through_links(tmp_path):
    """A link to a regular file at the output's name stays a link; the file it leads to
    gets the output (the CLI's samples and events, a plot's image, a sweep's table). Before,
    the link was replaced by a new file."""
    real = tmp_path / "real"
    real.mkdir()
    names = ["o.dat", "o.events.dat", "o.png", "t.csv"]
    for name in names:
        (real / name).write_text("an earlier file\n")
        (tmp_path / name).symlink_to(Path("real") / name)
    done = subprocess.run([find_tool("impact1d"), str(INPUT / "case3.nml"), "--dt-out", "0.5",
                           "-o", "o.dat"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    from impact1d import plot
    plot.save(impact1d.read_output(tmp_path / "o.dat"), tmp_path / "o.png")
    done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "case5.nml"), "--vary",
                           "r_left=0,1", "--vary", "t_end=1", "-o", "t.csv"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    for name in names:
        assert (tmp_path / name).is_symlink(), name
        assert (real / name).read_bytes() != b"an earlier file\n", name
    assert sorted(p.name for p in real.iterdir()) == sorted(names)       # no temporaries
    assert (real / "o.dat").read_text().startswith("# impact1d output")
    assert (real / "t.csv").read_text().startswith("r_left,")


def test_special_outputs_are_refused(tmp_path):
    """A FIFO (replaced by a file before), the standard output's descriptor link (as
    /dev/stdout, which root replaced, writing /dev/stdout.events.dat beside it) and a link
    to nothing: refused, untouched, nothing written."""
    os.mkfifo(tmp_path / "fifo.dat")
    (tmp_path / "stdout.dat").symlink_to("/proc/self/fd/1")
    (tmp_path / "dangling.dat").symlink_to("nowhere.dat")
    before = sorted(p.name for p in tmp_path.iterdir())
    for name, kind in (("fifo.dat", "FIFO"), ("stdout.dat", "FIFO"),
                       ("dangling.dat", "symbolic link to a missing file")):
        done = subprocess.run([find_tool("impact1d"), str(INPUT / "case3.nml"), "-o", name],
                              cwd=tmp_path, capture_output=True, text=True, timeout=RUN_TIMEOUT)
        assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
        assert name in done.stderr and kind in done.stderr, done.stderr
        done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "case5.nml"), "--vary",
                               "r_left=0,1", "-o", name], cwd=tmp_path, capture_output=True,
                              text=True, timeout=RUN_TIMEOUT)
        assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
        assert name in done.stderr and kind in done.stderr, done.stderr
    from impact1d import plot
    with pytest.raises(impact1d.InputError, match="fifo.png: it is a FIFO"):
        os.mkfifo(tmp_path / "fifo.png")
        plot.save(impact1d.simulate(impact1d.load_scene(INPUT / "case3.nml"), t_end=1.0),
                  tmp_path / "fifo.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(before + ["fifo.png"])
    assert (tmp_path / "fifo.dat").is_fifo() and (tmp_path / "fifo.png").is_fifo()
    assert os.readlink(tmp_path / "stdout.dat") == "/proc/self/fd/1"


# --- issue 18 item 6: parsing holes that changed the scene silently --------------------

def line_of(text, needle):
    """1-based number of the first line of `text` holding `needle`."""
    return next(n for n, line in enumerate(text.splitlines(), 1) if needle in line)


def case3_values():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    return {k: v for k, v in vars(scene).items() if k not in ("title", "source")}


@pytest.mark.parametrize("title", [
    "x &initial x1 = 5.0, x2 = 7.0 /",      # replaced the real &initial group
    "Table 1 &initial conditions",           # refused as "unknown variable 'conditions''"
    "&run t_end = 1 / $end &end",
    "a, b = c; d ! not a comment",
])
def test_group_marks_inside_a_quoted_title_are_text(tmp_path, title):
    text = CASE3.replace("'Test case 3: conservation of energy'", "'" + title + "'")
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    assert scene.title == title
    assert {k: v for k, v in vars(scene).items() if k not in ("title", "source")} == case3_values()


def test_double_quotes_and_doubled_quotes_in_a_title(tmp_path):
    for written, meant in [('"say ""&initial x1 = 5 /"" now"', 'say "&initial x1 = 5 /" now'),
                           ("'it''s &run / done'", "it's &run / done")]:
        text = CASE3.replace("'Test case 3: conservation of energy'", written)
        scene = impact1d.load_scene(scene_file(tmp_path, text))
        assert scene.title == meant and scene.x1 == 1.0 and scene.v1 == -9.0


@pytest.mark.parametrize("old, new, name", [
    ("v1 = -9.0", "v1 = ", "v1"),             # 'v1 = ,': v1 was absent (0)
    ("v2 = 1.0", "v2 = 1*", "v2"),            # a null: v2 was absent
    ("f2 = 0.0 /", "f2 /", "f2"),             # no '=' at all
    ("x2 = 2.5, v2 = 1.0", "x2 = 2.5, v2 =", "v2"),
])
def test_variable_without_a_value_is_refused(tmp_path, old, new, name):
    message = refused(tmp_path, CASE3.replace(old, new), f"{name}.* has no value")
    assert f"scene.nml:{line_of(CASE3, old)}:" in message


def test_variable_given_twice_is_refused(tmp_path):
    """m1 = 1.0, m1 = 7.0 ran with m1 = 7 without a word."""
    message = refused(tmp_path, CASE3.replace("m1 = 1.0,", "m1 = 1.0, m1 = 7.0,"),
                      r"m1 is given twice \(lines 3 and 3\)")
    assert "scene.nml:3:" in message
    text = CASE3.replace("g = 10.0 /", "g = 10.0,\n         m1 = 7.0 /")
    refused(tmp_path, text, r":4: in &bodies: m1 is given twice \(lines 3 and 4\)")


def dat_lines():
    """input3.dat's lines, and the index of each line that holds a number."""
    lines = (INPUT / "input3.dat").read_text().splitlines()
    return lines, [i for i, line in enumerate(lines) if line.strip() and not line.startswith("#")]


@pytest.mark.parametrize("null", [",", "1*", ", # m1"])
def test_null_dat_line_is_refused_and_nothing_survives_a_read(tmp_path, null):
    """A null as the first number left m1 uninitialised: the CLI saw 0.0, Python the value
    the previous read left on the stack (4.0 after a file whose last number was 4.0)."""
    lines, numbers = dat_lines()
    good = list(lines)
    good[numbers[0]] = "4.0  # m1"
    good[numbers[-1]] = "4.0  # f2"
    (tmp_path / "good.dat").write_text("\n".join(good) + "\n")
    assert impact1d.load_scene(tmp_path / "good.dat").m1 == 4.0
    bad = list(lines)
    bad[numbers[0]] = null
    (tmp_path / "bad.dat").write_text("\n".join(bad) + "\n")
    with pytest.raises(impact1d.InputError, match=f"bad.dat:{numbers[0] + 1}: .* holds no number "
                                                  r"\(expected m1\)"):
        impact1d.load_scene(tmp_path / "bad.dat")
    done = subprocess.run([find_tool("impact1d"), str(tmp_path / "bad.dat"), "--t-end", "1",
                           "--dt", "1e-3", "-o", str(tmp_path / "out.dat")],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 1 and f"bad.dat:{numbers[0] + 1}:" in done.stderr


def test_null_dat_line_later_does_not_repeat_the_one_before(tmp_path):
    """'1*' as x2 reused x1's 1.0 (the scene then failed on a slot it had not asked for)."""
    lines, numbers = dat_lines()
    lines[numbers[12]] = "1*  # x2(0)"
    (tmp_path / "x2.dat").write_text("\n".join(lines) + "\n")
    with pytest.raises(impact1d.InputError, match=rf"x2.dat:{numbers[12] + 1}: '1\*' holds no number "
                                                  r"\(expected x2\)"):
        impact1d.load_scene(tmp_path / "x2.dat")


def test_core_keeps_no_input_state_between_calls():
    """No module variable, SAVEd local or initialised local (which Fortran SAVEs) in the
    core's sources: a read or a run may only leave state in what it returns."""
    declaration = re.compile(r"^\s*(real|integer|logical|character|complex|type\s*\(|class\s*\()[^:]*::(.*)$",
                             re.I)
    block_start = re.compile(r"^\s*(abstract\s+interface|interface|type\s*(,|::|\s+\w))", re.I)
    block_end = re.compile(r"^\s*end\s*(interface|type)\b", re.I)
    found = []
    for path in sorted((ROOT / "src").glob("*.f90")):
        in_procedures = in_block = False
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("!")[0]
            in_procedures = in_procedures or re.match(r"^contains\s*$", code) is not None
            if not in_procedures and block_start.match(code):
                in_block = True
            if block_end.match(code):
                in_block = False
            if re.match(r"^\s*(save|common|data)\b(?!\s*=)", code, re.I):
                found.append(f"{path.name}:{number}: {line.strip()}")
            match = declaration.match(code)
            if not match or in_block or re.search(r"\bparameter\b", code.split("::")[0], re.I):
                continue
            if not in_procedures:
                found.append(f"{path.name}:{number}: module variable: {line.strip()}")
            elif re.search(r"\bsave\b", code.split("::")[0], re.I) or \
                    re.search(r"(?<![=<>/])=(?!=)", match.group(2)):
                found.append(f"{path.name}:{number}: saved local: {line.strip()}")
    assert not found, found


# --- issue 18 item 9: messages that named the wrong thing -------------------------------

@pytest.mark.parametrize("value", ["(1.0, 2.0)", ".true.", "1.0_8", "0x1p0", "1.0 2.0", "--1", "1.5$"])
def test_bad_value_is_named_as_a_bad_value(tmp_path, value):
    """All were 'unknown variable' ('1.5$': "no closing '/' before &")."""
    message = refused(tmp_path, CASE3.replace("m1 = 1.0", "m1 = " + value),
                      re.escape(f"scene.nml:3: in &bodies: m1 = '{value}' is not a number"))
    assert "unknown variable" not in message and "closing" not in message


def test_decimal_comma_is_suggested(tmp_path):
    """m2 = 0,5 gave "unknown variable '5'"."""
    refused(tmp_path, CASE3.replace("m2 = 2.0", "m2 = 0,5"),
            re.escape("in &bodies: m2 = '0,5' is not a number (a decimal comma?"))


# --- numbers list-directed input took wrongly -------------------------------------------

@pytest.mark.parametrize("value", ["1+1", "1.0.0", "2e", "1.5d", "1e+", "1-2"])
def test_malformed_number_is_refused(tmp_path, value):
    """'1+1' was read as 1e+1 = 10.0 (list-directed input takes a sign as the exponent)."""
    refused(tmp_path, CASE3.replace("m1 = 1.0", "m1 = " + value),
            re.escape(f"in &bodies: m1 = '{value}' is not a number"))


def test_decimal_comma_in_a_scalar_is_still_suggested(tmp_path):
    refused(tmp_path, CASE3.replace("m1 = 1.0", "m1 = 1,5"), re.escape("m1 = '1,5' is not a number (a decimal comma?"))


def test_malformed_number_in_a_table_row(tmp_path):
    """A table row '1+1 2' was the corner t = 10."""
    (tmp_path / "t.dat").write_text("0 1\n1+1 2\n")
    text = CASE3.replace("&forces  f1 = 0.0", "&forces  f1_table = 't.dat', f1 = 0.0")
    with pytest.raises(impact1d.InputError, match=r"t\.dat:2: malformed row '1\+1 2'"):
        impact1d.simulate(impact1d.load_scene(scene_file(tmp_path, text)), t_end=0.1, dt=1e-3)


@pytest.mark.parametrize("value", ["1.0", "-9", "1.0e-3", "1.0d-3", "+.5", "5.", "1E+03", "NaN", "-Inf"])
def test_well_formed_numbers_are_read(tmp_path, value):
    text = CASE3.replace("&forces  f1 = 0.0", "&forces  f1 = " + value)
    scene = impact1d.load_scene(scene_file(tmp_path, text)) if value[-1] not in "Nf" else None
    if scene is not None:
        assert scene.f1 == float(value.replace("d", "e"))
    else:
        refused(tmp_path, text, "is not a finite number")


@pytest.mark.parametrize("row", [", 5", "0.5 ,", "1*", "0.5 /"])
def test_malformed_table_row_is_named(tmp_path, row):
    """', 5' took the row before's time: "time 0.0 does not increase"."""
    (tmp_path / "table.dat").write_text(f"# t f\n0 1\n{row}\n1 2\n")
    text = (INPUT / "case6.nml").read_text().replace("'triangle.dat'", "'table.dat'")
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    with pytest.raises(impact1d.InputError, match=re.escape(f"table.dat:3: malformed row '{row}'")):
        impact1d.simulate(scene, t_end=0.1)


def long_folder(tmp_path, pieces=6):
    """A folder whose path from tmp_path is over 1,200 characters (names of 200)."""
    folder = tmp_path
    for k in range(pieces):
        folder = folder / (chr(ord("a") + k) * 200)
    folder.mkdir(parents=True)
    return folder


def test_table_path_of_any_length(tmp_path):
    """A path over 1,024 characters was cut there and refused as 'is a folder'."""
    folder = long_folder(tmp_path)
    shutil.copy(INPUT / "triangle.dat", folder / "triangle.dat")
    relative = str((folder / "triangle.dat").relative_to(tmp_path))
    assert len(relative) > 1024
    text = (INPUT / "case6.nml").read_text().replace("'triangle.dat'", f"'{relative}'")
    scene = impact1d.load_scene(scene_file(tmp_path, text))
    assert scene.f1_table == str(folder / "triangle.dat")
    expected = impact1d.simulate(impact1d.load_scene(INPUT / "case6.nml"), t_end=1.0)
    assert np.array_equal(impact1d.simulate(scene, t_end=1.0).x1, expected.x1)
    out = tmp_path / "out.dat"
    done = subprocess.run([find_tool("impact1d"), str(tmp_path / "scene.nml"), "--t-end", "1",
                           "-o", str(out)], capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert np.array_equal(np.loadtxt(out)[:, 1], expected.x1)


def test_batch_runs_keep_every_text(tmp_path):
    """A batch (simulate_summaries, sweep's engine) copies the scene for each run: with the
    texts as one array of deferred-length strings gfortran 12 copied them wrongly (the
    table path came out as garbage)."""
    folder = long_folder(tmp_path, pieces=2)
    shutil.copy(INPUT / "triangle.dat", folder / "triangle.dat")
    scene = impact1d.load_scene(INPUT / "case6.nml")
    scene.f1_table = str(folder / "triangle.dat")
    scene.title = "t" * 2000
    scene.t_end = 1.0
    table = impact1d.sweep(scene, {"r_left": [0.5, 1.0]})
    assert (table["error"] == "").all(), list(table["error"])
    for r_left, x1_end in zip(table["r_left"], table["x1_end"]):
        assert x1_end == impact1d.simulate(scene, r_left=r_left).x1[-1]


def test_long_title_is_kept_whole(tmp_path):
    """A title was cut at 1,024 characters (the namelist's buffer), in Python as at the CLI."""
    title = "A long title " + "x" * 3000 + " end"
    text = CASE3.replace("'Test case 3: conservation of energy'", f"'{title}'")
    path = scene_file(tmp_path, text)
    assert impact1d.load_scene(path).title == title
    dat = (INPUT / "input3.dat").read_text().replace("# Test case 3: conservation of energy", "# " + title)
    assert impact1d.load_scene(scene_file(tmp_path, dat, "long.dat")).title == title
    res = impact1d.simulate(impact1d.load_scene(INPUT / "case3.nml"), title=title, t_end=0.01)
    assert res.scene.title == title
    out = tmp_path / "out.dat"
    done = subprocess.run([find_tool("impact1d"), str(path), "--t-end", "0.01", "-o", str(out)],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert f"# title = {title}\n" in out.read_text()
    assert impact1d.read_output(out).scene.title == title


def test_row_limit_message_counts_the_rows(tmp_path):
    """'10000000.0 output rows is over the limit of 10000000.0': the run would have written
    10^7 + 1 rows (t = 0 included), and counts are integers."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    with pytest.raises(impact1d.InputError) as caught:
        impact1d.simulate(scene, t_end=1.0e7, dt=1.0, dt_out=1.0)
    assert "10000001 output rows" in str(caught.value) and "limit of 10000000:" in str(caught.value)
    assert "10000000.0" not in str(caught.value).split("makes")[1]
    # At the limit the run writes exactly max_rows rows; one more row is refused.
    assert len(impact1d.simulate(scene, t_end=1.0, dt_out=0.1, max_rows=11).t) == 11
    with pytest.raises(impact1d.InputError, match="makes 11 output rows .* limit of 10:"):
        impact1d.simulate(scene, t_end=1.0, dt_out=0.1, max_rows=10)
    # t_end within rounding of the grid: 11 rows, not refused as 12.
    assert len(impact1d.simulate(scene, t_end=1.0 + 1e-12, dt_out=0.1, max_rows=11).t) == 11
