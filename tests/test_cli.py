"""The `impact1d` command line: same numbers as the Python API, files numpy can read."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import impact1d

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
    exe = shutil.which("impact1d")
    assert exe is not None, ("the impact1d CLI is not on PATH: install the package "
                             "(pip install --no-build-isolation .) with its bin/ on PATH")
    return exe


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
    for name in impact1d.COLUMNS:
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


def test_no_progress_line_when_stderr_is_not_a_terminal(cli, tmp_path):
    """The progress line is for a person at a terminal: a long run (about 2 s here: a sine
    force, which every step evaluates) with stderr piped, as here and in scripts, writes
    nothing there."""
    scene = tmp_path / "long.nml"
    scene.write_text("&bodies m1 = 1.0, m2 = 2.0 /\n&initial x1 = 0.0, v1 = 1.0, x2 = 5.0 /\n"
                     "&forces f1 = 0.001, f1_amp = 0.1, f1_period = 7.0 /\n"
                     "&run t_end = 1.5e4, dt = 1.0e-3, dt_out = 1.0e4 /\n")
    done = run_cli(cli, scene, "-o", tmp_path / "long.dat", cwd=tmp_path)
    assert done.stderr == ""
