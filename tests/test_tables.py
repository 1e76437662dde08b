"""Results as pandas tables (issue 22): Result.to_dataframe() and Result.events_frame(), and
the output files read by pandas with the call docs/formats.md and the README document: the
same doubles as the run, bit for bit."""

import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import impact1d
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
RUN_TIMEOUT = 120

# Two bodies and a force table; one body with a spring (pe); dampers (damping_loss).
SCENES = ("case6", "impact_oscillator", "mounted_stop")


def header_names(path):
    """The documented plain-pandas recipe's first half: the last '#' line names the columns."""
    with open(path) as handle:
        return [line for line in handle if line.startswith("#")][-1][1:].split()


def read_with_pandas(path):
    """The documented plain-pandas call (docs/formats.md, README)."""
    return pd.read_csv(path, sep=r"\s+", comment="#", header=None, names=header_names(path))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Each scene run by simulate() and by the CLI into a file."""
    folder = tmp_path_factory.mktemp("tables")
    out = {}
    for name in SCENES:
        path = folder / f"{name}.dat"
        done = subprocess.run([find_tool("impact1d"), str(INPUT / f"{name}.nml"), "-o", str(path)],
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
        assert done.returncode == 0, done.stderr
        out[name] = (impact1d.simulate(impact1d.load_scene(INPUT / f"{name}.nml")), path)
    return out


@pytest.mark.parametrize("name", SCENES)
def test_to_dataframe_is_the_result(runs, name):
    res, _ = runs[name]
    frame = res.to_dataframe()
    assert tuple(frame.columns) == res.columns
    assert len(frame) == len(res.t)
    for column in res.columns:
        assert frame[column].dtype == np.float64
        np.testing.assert_array_equal(frame[column].to_numpy(), getattr(res, column))
    np.testing.assert_array_equal(frame.to_numpy(), res.samples)


def test_columns_follow_the_scene(runs):
    assert "x2" not in runs["impact_oscillator"][0].to_dataframe()
    assert "pe" in runs["impact_oscillator"][0].to_dataframe()
    assert "damping_loss" in runs["mounted_stop"][0].to_dataframe()
    assert "pe" not in runs["case6"][0].to_dataframe()


@pytest.mark.parametrize("name", SCENES)
def test_events_frame_is_the_event_log(runs, name):
    res, _ = runs[name]
    frame = res.events_frame()
    assert list(frame.columns) == list(res.events.dtype.names)
    assert len(frame) == len(res.events) > 0
    for column in res.events.dtype.names:
        np.testing.assert_array_equal(frame[column].to_numpy(), res.events[column])


def test_empty_event_log_is_an_empty_frame():
    res = impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.0, v1=1.0, t_end=0.1, dt=0.01))
    frame = res.events_frame()
    assert len(frame) == 0 and list(frame.columns) == list(impact1d.ONE_BODY_EVENT_DTYPE.names)


@pytest.mark.parametrize("name", SCENES)
def test_output_file_round_trip(runs, name):
    """The file read back, by read_output().to_dataframe() and by plain pandas, equals the run."""
    res, path = runs[name]
    expected = res.to_dataframe()
    pd.testing.assert_frame_equal(impact1d.read_output(path).to_dataframe(), expected,
                                  check_exact=True)
    pd.testing.assert_frame_equal(read_with_pandas(path), expected, check_exact=True)
    pd.testing.assert_frame_equal(impact1d.read_output(path).events_frame(), res.events_frame(),
                                  check_exact=True)


def test_the_naive_call_loses_the_first_row(runs):
    """Why the docs give `names=`: the column names are on a '#' line, which comment='#'
    skips, so pandas takes the t = 0 row for the header (what the docs warn of)."""
    res, path = runs["case6"]
    naive = pd.read_csv(path, sep=r"\s+", comment="#")
    assert len(naive) == len(res.t) - 1 and "t" not in naive.columns


def test_the_documented_calls_are_these():
    call = 'pd.read_csv(path, sep=r"\\s+", comment="#", header=None, names=names)'
    for doc in (ROOT / "README.md", ROOT / "docs" / "formats.md"):
        text = doc.read_text()
        assert "impact1d.read_output(path).to_dataframe()" in text, doc
        assert call in text, doc
