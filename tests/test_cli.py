"""The `impact1d` command line: same numbers as the Python API, files numpy can read."""

import os
import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool, mounted_tmpfs

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"

# The CLI and the f2py module run the same compiled Fortran, and the CLI prints 17
# significant digits (ES24.16), which round-trip a double exactly: anything beyond
# rounding of the last printed digit is a real difference.
SAME_RTOL = 1e-12
# Entries that are rounding noise around zero (the ledger residual, ~1e-15 J).
SAME_ATOL = 1e-13
# Generous bound on a CLI run of a seed case on a 2-core machine.
CLI_TIMEOUT = 120

COLUMNS = "t x1 v1 x2 v2 ke work friction_loss impact_loss residual"


@pytest.fixture(scope="module")
def cli():
    """The installed executable. A missing CLI is a failure, never a skip."""
    return find_tool("impact1d")


def run_cli(cli, *args, cwd, check=True):
    proc = subprocess.run([cli, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=CLI_TIMEOUT, stdin=subprocess.DEVNULL)
    if check:
        assert proc.returncode == 0, f"impact1d {args} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc


def comment_lines(path):
    lines = []
    with open(path) as handle:
        for line in handle:
            if not line.startswith("#"):
                break
            lines.append(line.rstrip("\n"))
    return lines


def assert_same_run(got, want):
    """`got` (read from CLI files) and `want` (a Python run) hold the same numbers."""
    assert got.columns == want.columns
    for name in want.columns:
        np.testing.assert_allclose(getattr(got, name), getattr(want, name),
                                   rtol=SAME_RTOL, atol=SAME_ATOL, err_msg=name)
    assert list(got.events["kind"]) == list(want.events["kind"])
    for name in ("t", "v1_before", "v2_before", "v1_after", "v2_after"):
        np.testing.assert_allclose(got.events[name], want.events[name],
                                   rtol=SAME_RTOL, atol=SAME_ATOL, err_msg=name)


@pytest.mark.parametrize("case", [1, 2, 3, 4, 5, 6])
def test_cli_matches_python(cli, tmp_path, case):
    scene_path = INPUT / f"case{case}.nml"
    out = tmp_path / f"case{case}.dat"
    run_cli(cli, scene_path, "-o", out, cwd=tmp_path)
    data = np.loadtxt(out)
    assert data.ndim == 2 and data.shape[1] == 10
    res = impact1d.simulate(impact1d.load_scene(scene_path))
    assert data.shape[0] == len(res.t)
    np.testing.assert_allclose(data, res.samples, rtol=SAME_RTOL, atol=SAME_ATOL)
    assert (tmp_path / f"case{case}.events.dat").is_file()
    assert_same_run(impact1d.read_output(out), res)


def test_cli_output_header(cli, tmp_path):
    scene_path = INPUT / "case3.nml"
    out = tmp_path / "case3.dat"
    run_cli(cli, scene_path, "-o", out, cwd=tmp_path)
    header = comment_lines(out)
    assert header[0] == "# impact1d output"
    assert header[1] == "# title = Test case 3: conservation of energy"
    assert header[2].startswith("# scene = ") and header[2].endswith("case3.nml")
    assert header[3] == "# method = event"
    assert header[-1] == "# " + COLUMNS
    # One "# name = value" line per real field the scene has; they parse back.
    scene = impact1d.load_scene(scene_path)
    recorded = impact1d.read_output(out).scene
    assert recorded.title == scene.title and recorded.method == "event"
    for name in ("m1", "m2", "mu1", "mu2", "g", "x_left", "r_left", "x_right", "r_right",
                 "d_min", "r_min", "d_max", "r_max", "x1", "v1", "x2", "v2", "f1", "f2",
                 "t_end", "dt", "dt_out"):
        assert getattr(recorded, name) == pytest.approx(getattr(scene, name),
                                                        rel=SAME_RTOL), name
    events = comment_lines(tmp_path / "case3.events.dat")
    assert events == ["# impact1d events", "# t kind v1_before v2_before v1_after v2_after"]


def test_cli_dat_input_with_overrides(cli, tmp_path):
    """The tutorial's way: parameters from input5.dat, t_end and dt on the command line."""
    out = tmp_path / "input5.dat"
    run_cli(cli, INPUT / "input5.dat", "--t-end", "3.2", "--dt", "1e-3", "-o", out,
            cwd=tmp_path)
    got = impact1d.read_output(out)
    want = impact1d.simulate(impact1d.load_scene(INPUT / "input5.dat"), t_end=3.2, dt=1e-3)
    assert_same_run(got, want)
    nml = impact1d.simulate(impact1d.load_scene(INPUT / "case5.nml"))
    assert_same_run(got, nml)


def test_cli_run_overrides(cli, tmp_path):
    out = tmp_path / "short.dat"
    run_cli(cli, INPUT / "case3.nml", "--t-end", "0.5", "--dt", "0.01", "--dt-out", "0.05",
            "--method", "event", "-o", out, cwd=tmp_path)
    data = np.loadtxt(out)
    assert data.shape == (11, 10)
    want = impact1d.simulate(impact1d.load_scene(INPUT / "case3.nml"), t_end=0.5, dt=0.01,
                             dt_out=0.05, method="event")
    assert_same_run(impact1d.read_output(out), want)


def test_cli_default_output_path(cli, tmp_path):
    (tmp_path / "output").mkdir()
    proc = run_cli(cli, INPUT / "case1.nml", cwd=tmp_path)
    assert (tmp_path / "output" / "case1.dat").is_file()
    assert (tmp_path / "output" / "case1.events.dat").is_file()
    assert proc.stdout.strip(), "the CLI prints a summary"
    assert np.loadtxt(tmp_path / "output" / "case1.dat").shape == (5001, 10)


def _assert_fails_naming(proc, word):
    assert proc.returncode != 0
    text = (proc.stdout + proc.stderr).strip()
    assert word in text, text
    assert len(text.splitlines()) == 1, f"not a one-line reason:\n{text}"


def test_cli_missing_scene_fails(cli, tmp_path):
    proc = run_cli(cli, tmp_path / "no_such_scene.nml", "-o", tmp_path / "x.dat",
                   cwd=tmp_path, check=False)
    _assert_fails_naming(proc, "no_such_scene.nml")
    assert not (tmp_path / "x.dat").exists()


def test_cli_bad_mass_fails(cli, tmp_path):
    text = (INPUT / "case3.nml").read_text().replace("m1 = 1.0", "m1 = -1.0")
    path = tmp_path / "bad.nml"
    path.write_text(text)
    proc = run_cli(cli, path, "-o", tmp_path / "bad.dat", cwd=tmp_path, check=False)
    _assert_fails_naming(proc, "m1")


def test_cli_dat_without_t_end_fails(cli, tmp_path):
    proc = run_cli(cli, INPUT / "input3.dat", "--dt", "1e-3", "-o", tmp_path / "x.dat",
                   cwd=tmp_path, check=False)
    _assert_fails_naming(proc, "t_end")


def test_cli_bad_option_fails(cli, tmp_path):
    proc = run_cli(cli, INPUT / "case3.nml", "--dt", "fast", "-o", tmp_path / "x.dat",
                   cwd=tmp_path, check=False)
    assert proc.returncode != 0
    assert (proc.stdout + proc.stderr).strip()


def test_read_output_missing_file(tmp_path):
    with pytest.raises(impact1d.InputError, match="nothing.dat"):
        impact1d.read_output(tmp_path / "nothing.dat")


# A run of a few seconds (about 3 s in 2026: a sine force, which every step evaluates), so
# that a progress line is due (after 1 s) however fast the machine and the step: at
# t_end = 1.5e4 it took 1.0 s and the terminal test failed whenever it took less.
LONG_SCENE = ("&bodies m1 = 1.0, m2 = 2.0 /\n&initial x1 = 0.0, v1 = 1.0, x2 = 5.0 /\n"
              "&forces f1 = 0.001, f1_amp = 0.1, f1_period = 7.0 /\n"
              "&run t_end = 4.5e4, dt = 1.0e-3, dt_out = 1.0e4 /\n")


def test_no_progress_line_when_stderr_is_not_a_terminal(cli, tmp_path):
    """The progress line is for a person at a terminal: a long run (LONG_SCENE) with stderr
    piped, as here and in scripts, writes nothing there."""
    scene = tmp_path / "long.nml"
    scene.write_text(LONG_SCENE)
    done = run_cli(cli, scene, "-o", tmp_path / "long.dat", cwd=tmp_path)
    assert done.stderr == ""


def _run_on_a_terminal(cli, tmp_path, *options):
    """The long run above with stderr (and stdout) on a pseudo-terminal, as a person runs it:
    everything the terminal received."""
    import pty
    scene = tmp_path / "long.nml"
    scene.write_text(LONG_SCENE)
    main, terminal = pty.openpty()
    process = subprocess.Popen([cli, str(scene), "-o", str(tmp_path / "long.dat"), *options],
                               stdin=subprocess.DEVNULL, stdout=terminal, stderr=terminal, cwd=tmp_path)
    os.close(terminal)
    received = b""
    while True:
        try:
            chunk = os.read(main, 4096)
        except OSError:          # the terminal closed: the process is done
            break
        if not chunk:
            break
        received += chunk
    os.close(main)
    assert process.wait(timeout=120) == 0
    return received.decode()


def test_progress_line_on_a_terminal_and_quiet(cli, tmp_path):
    """On a terminal a run of over a second shows its progress on stderr (simulated time,
    events so far, the time left), then clears it; --quiet shows none. (In a pipe nothing:
    the test above.)"""
    shown = _run_on_a_terminal(cli, tmp_path)
    assert re.search(r"\d+% \(t = [0-9.]+ of 45000\.0 s, \d+ events, about \d+ s left\)", shown), shown
    assert "impact1d: " in shown and "steps" in shown          # the summary follows
    quiet = _run_on_a_terminal(cli, tmp_path, "--quiet")
    assert "% (t = " not in quiet and "steps" in quiet


# --- what a new user meets first (issue 12) ----------------------------------------------

# Case 3's motion between events is a polynomial RK4 reproduces exactly, so its event
# times do not depend on dt: only the rounding of the located roots separates two steps
# (measured 9e-16 s at dt = 0.1 against 1e-3; the clock is kept as a compensated sum).
EVENT_TIME_ROUNDING = 1e-13


def test_version_from_the_package_metadata(cli):
    """One version: meson.build's project version, which the package metadata carries."""
    want = metadata.version("impact1d")
    assert run_cli(cli, "--version", cwd=ROOT).stdout.strip() == f"impact1d {want}"
    plot = run_cli(find_tool("impact1d-plot"), "--version", cwd=ROOT)
    assert plot.stdout.strip() == f"impact1d-plot {want}"
    assert impact1d.__version__ == want


def test_help_names_methods_dat_needs_and_exit_codes(cli):
    text = run_cli(cli, "--help", cwd=ROOT).stdout
    for word in ("event", "vissim", "--t-end", "--dt", "--dt-out", "--method", "-o",
                 "--version", ".dat", "Exit status: 0", "1 bad input", "2 the run"):
        assert word in text, word
    dat_line = next(line for line in text.splitlines() if ".dat scenes" in line)
    assert "--t-end" in dat_line and "--dt" in dat_line


def test_gnu_style_option_values(cli, tmp_path):
    """--dt=0.01 is --dt 0.01 (and so for every option with a value)."""
    run_cli(cli, INPUT / "case3.nml", "--t-end", "0.5", "--dt", "0.01", "--method", "event",
            "-o", tmp_path / "spaced.dat", cwd=tmp_path)
    run_cli(cli, INPUT / "case3.nml", "--t-end=0.5", "--dt=0.01", "--method=event",
            "-o", tmp_path / "joined.dat", cwd=tmp_path)
    assert np.array_equal(np.loadtxt(tmp_path / "spaced.dat"), np.loadtxt(tmp_path / "joined.dat"))
    assert (tmp_path / "joined.events.dat").read_text() == (tmp_path / "spaced.events.dat").read_text()


def test_method_names_in_any_case(cli, tmp_path):
    """'VisSim' on the command line, 'VISSIM' in a namelist, 'Vissim' from Python: all vissim."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    want = impact1d.simulate(scene, method="vissim", t_end=0.5)
    assert_same_run(impact1d.simulate(scene, method="Vissim", t_end=0.5), want)
    upper = tmp_path / "upper.nml"
    upper.write_text((INPUT / "case3.nml").read_text().replace("'event'", "'VISSIM'"))
    assert impact1d.load_scene(upper).method == "vissim"
    run_cli(cli, INPUT / "case3.nml", "--method", "VisSim", "--t-end", "0.5",
            "-o", tmp_path / "cli.dat", cwd=tmp_path)
    got = impact1d.read_output(tmp_path / "cli.dat")
    assert got.scene.method == "vissim"
    assert_same_run(got, want)


@pytest.mark.parametrize("value", ["1e-3 junk", "1e-3,2", "2*0.1", "", "0.1/"])
def test_option_value_must_be_one_number(cli, tmp_path, value):
    proc = run_cli(cli, INPUT / "case3.nml", "--dt", value, "-o", tmp_path / "x.dat",
                   cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "--dt")
    assert not (tmp_path / "x.dat").exists()


@pytest.mark.parametrize("spelling", [("--method", ""), ("--method=",)])
def test_empty_method_is_refused(cli, tmp_path, spelling):
    proc = run_cli(cli, INPUT / "case1.nml", *spelling, "-o", tmp_path / "x.dat", cwd=tmp_path,
                   check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "--method")
    assert list(tmp_path.iterdir()) == []


def test_empty_output_name_is_refused(cli, tmp_path):
    """-o '' (an unset shell variable) is a mistake, not a request for the default."""
    proc = run_cli(cli, INPUT / "case1.nml", "-o", "", cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "-o")
    assert list(tmp_path.iterdir()) == []


def test_output_folders_are_created(cli, tmp_path):
    out = tmp_path / "runs" / "today" / "case3.dat"
    run_cli(cli, INPUT / "case3.nml", "--t-end", "0.5", "-o", out, cwd=tmp_path)
    assert out.is_file() and out.with_name("case3.events.dat").is_file()
    # relative to the working folder, as a user types it
    run_cli(cli, INPUT / "case3.nml", "--t-end", "0.5", "-o", "rel/x.dat", cwd=tmp_path)
    assert (tmp_path / "rel" / "x.dat").is_file()


def test_messages_never_show_the_temporary_name(cli, tmp_path):
    (tmp_path / "a_file").write_text("a file, not a folder\n")
    proc = run_cli(cli, INPUT / "case3.nml", "-o", tmp_path / "a_file" / "x.dat",
                   cwd=tmp_path, check=False)
    _assert_fails_naming(proc, "a_file/x.dat")
    assert ".part" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


@pytest.mark.parametrize("name", ["res.txt", "res", "res.dat"])
def test_events_file_name_rule(cli, tmp_path, name):
    """The output's extension, whatever it is, becomes .events.dat; read_output agrees."""
    run_cli(cli, INPUT / "case3.nml", "--t-end", "0.5", "-o", tmp_path / name, cwd=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, "res.events.dat"])
    assert len(impact1d.read_output(tmp_path / name).events) > 0


def _copy_of(path, folder, name):
    copy = folder / name
    copy.write_bytes(path.read_bytes())
    return copy


@pytest.mark.parametrize("how", ["same", "dot-slash", "link"])
def test_output_that_is_the_scene_is_refused(cli, tmp_path, how):
    scene = _copy_of(INPUT / "input5.dat", tmp_path, "copy5.dat")
    before = scene.read_bytes()
    if how == "link":
        (tmp_path / "link.dat").symlink_to(scene)
    out = {"same": "copy5.dat", "dot-slash": "./copy5.dat", "link": "link.dat"}[how]
    proc = run_cli(cli, "copy5.dat", "--t-end", "3.2", "--dt", "1e-3", "-o", out,
                   cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "scene")
    assert scene.read_bytes() == before
    assert not (tmp_path / "copy5.events.dat").exists()


def test_output_that_is_a_force_table_or_the_scene_as_events_file_is_refused(cli, tmp_path):
    scene = _copy_of(INPUT / "case6.nml", tmp_path, "case6.nml")
    table = _copy_of(INPUT / "triangle.dat", tmp_path, "triangle.dat")
    before = table.read_bytes()
    proc = run_cli(cli, scene, "-o", table, cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "force table")
    assert table.read_bytes() == before
    # The events file the run would write is checked too: run.events.dat as the scene
    # (a .dat parameter file) and -o run.txt, whose events file is run.events.dat.
    dat = _copy_of(INPUT / "input3.dat", tmp_path, "run.events.dat")
    proc = run_cli(cli, dat, "--t-end", "1", "--dt", "1e-3", "-o", "run.txt", cwd=tmp_path,
                   check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "scene")
    assert dat.read_bytes() == (INPUT / "input3.dat").read_bytes()
    assert not (tmp_path / "run.txt").exists()


def test_coarse_step_alone_is_accepted(cli, tmp_path):
    """--dt 0.1 with the scene's dt_out = 1e-3: samples every 1e-3 s as the scene asks."""
    proc = run_cli(cli, INPUT / "case3.nml", "--dt", "0.1", "-o", tmp_path / "c.dat", cwd=tmp_path)
    assert "dt = 0.1 s" in proc.stdout
    assert np.loadtxt(tmp_path / "c.dat").shape == (6001, 10)


def test_event_times_do_not_depend_on_the_step():
    """The README's claim: case 3's 41 events at dt = 0.1 (steps really 0.1 s: dt_out too)
    are those at dt = 1e-3, to rounding."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    fine = impact1d.simulate(scene)
    coarse = impact1d.simulate(scene, dt=0.1, dt_out=0.1)
    assert coarse.steps < fine.steps / 50
    assert list(coarse.events["kind"]) == list(fine.events["kind"]) and len(fine.events) == 41
    np.testing.assert_allclose(coarse.events["t"], fine.events["t"], rtol=0,
                               atol=EVENT_TIME_ROUNDING)


def test_readme_step_independence_command_runs():
    """The README shows the claim above as one command: it runs and prints a rounding-level
    difference."""
    readme = (ROOT / "README.md").read_text()
    command = next(line.strip() for line in readme.splitlines()
                   if line.strip().startswith("python -c") and "dt=0.1" in line)
    code = command[len("python -c "):].strip().strip('"')
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=CLI_TIMEOUT, check=True)
    assert float(done.stdout.split()[-1]) <= EVENT_TIME_ROUNDING


@pytest.mark.parametrize("method", ["event", "vissim"])
def test_samples_finer_than_the_step(method):
    """dt_out < dt: both methods stop at every sample time (their step is then at most
    dt_out), so the samples are exactly where dt_out puts them."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    res = impact1d.simulate(scene, method=method, t_end=1.0, dt=0.1, dt_out=0.01)
    np.testing.assert_array_equal(res.t, np.arange(101) * 0.01)
    assert res.steps >= 100


def test_dat_scene_title_is_its_first_comment(cli, tmp_path):
    title = "Test case 5: wall collisions with rattling stop"
    assert impact1d.load_scene(INPUT / "input5.dat").title == title
    proc = run_cli(cli, INPUT / "input5.dat", "--t-end", "0.5", "--dt", "1e-3",
                   "-o", tmp_path / "i5.dat", cwd=tmp_path)
    assert proc.stdout.splitlines()[0] == f"impact1d: {title}"
    assert f"# title = {title}" in comment_lines(tmp_path / "i5.dat")


def test_summary_values_line_up(cli, tmp_path):
    """Every summary line after the title has its values from one column."""
    proc = run_cli(cli, INPUT / "case3.nml", "-o", tmp_path / "c.dat", cwd=tmp_path)
    lines = proc.stdout.splitlines()[1:]
    assert [line.split()[0] for line in lines] == ["scene", "output", "events", "final",
                                                   "energy", "ledger", "steps"]
    column = len("  scene     ")
    for line in lines:
        assert line[column - 1] == " " and line[column] != " ", line


def summary_numbers(text):
    """Every 'name = number' of the summary's final, energy and ledger lines, as floats."""
    import re
    numbers = {}
    for line in text.splitlines():
        if line.split()[:1] in (["final"], ["energy"], ["ledger"]):
            for name, value in re.findall(r"([\w |]+?) (?:=|<=)\s*(\S+)", line):
                numbers[name.split()[-1]] = float(value)      # a lost E would not parse
    return numbers


def test_summary_numbers_keep_their_exponent(cli, tmp_path):
    """KE = 5e155 J was printed '5.00000+155' (ES12.5 drops the E of a three-digit
    exponent), which reads as no number."""
    scene = tmp_path / "fast.nml"
    scene.write_text("&bodies m1 = 1.0, mu1 = 0.0 /\n&initial x1 = 0.0, v1 = 1e78 /\n"
                     "&run t_end = 1e-80, dt = 1e-81 /\n")
    proc = run_cli(cli, scene, "-o", tmp_path / "fast.dat", cwd=tmp_path)
    numbers = summary_numbers(proc.stdout)
    assert numbers["KE"] == pytest.approx(5e155, rel=1e-5)
    assert numbers["t"] == pytest.approx(1e-80, rel=1e-5) and numbers["v1"] == pytest.approx(1e78)
    assert set(numbers) >= {"t", "x1", "v1", "KE", "work", "loss", "|residual|"}


def test_a_file_where_a_folder_should_be_is_named(cli, tmp_path):
    """-o a_file/x.dat said only 'Not a directory' (or 'File exists')."""
    (tmp_path / "a_file").write_text("a file\n")
    for out in ("a_file/x.dat", "a_file/sub/x.dat"):
        proc = run_cli(cli, INPUT / "case3.nml", "-o", out, cwd=tmp_path, check=False)
        assert proc.returncode == 1
        _assert_fails_naming(proc, f"cannot write output {out}: a_file is not a folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


@pytest.fixture
def read_only_folder(tmp_path):
    """A read-only tmpfs, always unmounted afterwards (skipped where mount is not allowed)."""
    with mounted_tmpfs(tmp_path / "ro", "ro,size=64k") as folder:
        yield folder


def test_read_only_file_system_is_named(cli, tmp_path, read_only_folder):
    """-o ro/sub/x.dat said 'No such file or directory': the folder ro/sub could not be
    made, and why is the message."""
    proc = run_cli(cli, INPUT / "case3.nml", "-o", "ro/sub/x.dat", cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "cannot make the folder ro/sub: Read-only file system")
    proc = run_cli(cli, INPUT / "case3.nml", "-o", "ro/x.dat", cwd=tmp_path, check=False)
    assert proc.returncode == 1
    _assert_fails_naming(proc, "ro/x.dat: Read-only file system")
    assert list(read_only_folder.iterdir()) == []


# --- -o -: the samples to standard output (issue 22, item 3) -----------------------------

def _documented_read(text):
    """docs/formats.md's plain-pandas call, on a text instead of a path."""
    import io

    import pandas as pd

    names = [line for line in text.splitlines(keepends=True) if line.startswith("#")][-1][1:].split()
    return pd.read_csv(io.StringIO(text), sep=r"\s+", comment="#", header=None, names=names)


def test_dash_streams_the_samples_to_stdout(cli, tmp_path):
    """`-o -` wrote a file named `-` (and `-.events.dat`). Now the header and rows of the
    file go to stdout as they come, piped into a reader; the summary goes to stderr; no
    event log without --events-file (and none is written anywhere)."""
    case = INPUT / "case5.nml"
    run_cli(cli, case, "-o", tmp_path / "file.dat", cwd=tmp_path)
    written = (tmp_path / "file.dat").read_text()
    streaming = tmp_path / "streaming"
    streaming.mkdir()
    writer = subprocess.Popen([cli, str(case), "-o", "-"], cwd=streaming, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)
    text = writer.stdout.read()            # read while it runs: the pipe's buffer is small
    summary = writer.stderr.read()
    assert writer.wait(timeout=CLI_TIMEOUT) == 0, summary
    assert text == written
    assert list(streaming.iterdir()) == []
    assert "output    standard output (" in summary and "no event log (-o - writes the samples" in summary
    assert "left 47 right 47" in summary              # the counts stay exact
    frame = _documented_read(text)
    np.testing.assert_array_equal(frame.to_numpy(), np.loadtxt(tmp_path / "file.dat"))
    # With --events-file the log is the file run's.
    proc = run_cli(cli, case, "-o", "-", "--events-file", "logs/run.events.dat", cwd=streaming)
    assert proc.stdout == written
    assert (streaming / "logs" / "run.events.dat").read_text() == (tmp_path / "file.events.dat").read_text()
    assert "and logs/run.events.dat (96 events)" in proc.stderr
    # A reader that stops early (head) ends the writer by SIGPIPE, leaving no temporary file.
    pipeline = subprocess.run(f"'{cli}' '{case}' -o - --events-file logs/x.dat | head -n 2", shell=True,
                              cwd=streaming, capture_output=True, text=True, timeout=CLI_TIMEOUT)
    assert pipeline.stdout.splitlines() == written.splitlines()[:2]
    assert sorted(p.name for p in (streaming / "logs").iterdir()) == ["run.events.dat"]


def test_dev_stdout_streams_too(cli, tmp_path):
    """`-o /dev/stdout > file` used to replace the file stdout was redirected to through
    the link (the summary then went to the replaced file and was lost) and write
    /dev/stdout.events.dat; into a pipe it was refused as a FIFO. It is standard output:
    a stream, into a redirected file or a pipe."""
    case = INPUT / "case3.nml"
    run_cli(cli, case, "-o", tmp_path / "file.dat", cwd=tmp_path)
    written = (tmp_path / "file.dat").read_text()
    redirected = tmp_path / "redirected.dat"
    with open(redirected, "w") as stdout:
        proc = subprocess.run([cli, str(case), "-o", "/dev/stdout"], cwd=tmp_path, stdout=stdout,
                              stderr=subprocess.PIPE, text=True, timeout=CLI_TIMEOUT)
    assert proc.returncode == 0, proc.stderr
    assert redirected.read_text() == written and "standard output" in proc.stderr
    assert not os.path.exists("/dev/stdout.events.dat")
    piped = run_cli(cli, case, "-o", "/dev/stdout", cwd=tmp_path)
    assert piped.stdout == written


@pytest.mark.parametrize("args, message", [
    (["-o", "-", "--events", "none", "--events-file", "e.dat"], "the scene keeps no event log"),
    (["-o", "x.dat", "--events-file", "-"], "the event log cannot go to standard output"),
    (["-o", "-", "--events-file", ""], "--events-file needs a file name"),
    # Not yet there, the two names were one file: the samples replaced the log.
    (["-o", "x.dat", "--events-file", "x.dat"], "are the same file"),
])
def test_dash_refusals(cli, tmp_path, args, message):
    proc = run_cli(cli, INPUT / "case3.nml", *args, cwd=tmp_path, check=False)
    assert proc.returncode == 1 and message in proc.stderr and proc.stdout == ""
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("tool, args", [
    ("impact1d-plot", ["{run}", "-o", "-"]),
    ("impact1d-sweep", [str(INPUT / "case3.nml"), "--vary", "r_left=0.5", "-o", "-"]),
])
def test_tools_that_write_files_refuse_dash(cli, tmp_path, tool, args):
    """impact1d-plot wrote `-.png`, impact1d-sweep a table named `-`: refused, naming why."""
    run_cli(cli, INPUT / "case3.nml", "-o", tmp_path / "run.dat", cwd=tmp_path)
    before = sorted(tmp_path.iterdir())
    proc = subprocess.run([find_tool(tool), *(a.format(run=tmp_path / "run.dat") for a in args)],
                          cwd=tmp_path, capture_output=True, text=True, timeout=CLI_TIMEOUT)
    assert proc.returncode == 1 and "not to standard output" in proc.stderr
    assert sorted(tmp_path.iterdir()) == before


def test_dash_to_a_full_disk_fails(cli, tmp_path):
    """The Fortran runtime drops the errors of its writes to stdout: `-o - > /dev/full`
    lost every row with exit status 0. The stream goes out through write(2): status 2."""
    with open("/dev/full", "w") as full:
        proc = subprocess.run([cli, str(INPUT / "case3.nml"), "-o", "-"], cwd=tmp_path, stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=CLI_TIMEOUT)
    assert proc.returncode == 2
    assert "cannot write output standard output: No space left on device" in proc.stderr
