"""Parameter sweeps (issue 11): a table with a row per run, equal to single runs, on threads
and on a real Dask LocalCluster with worker processes; a failing run is a row."""

import dataclasses
import math
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import impact1d
from impact1d.sweep import SUMMARY_COLUMNS, summarize
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
RUN_TIMEOUT = 300
GRID = {"r_left": [0.0, 0.5, 1.0], "r_right": [0.25, 0.75]}


@pytest.fixture(scope="module")
def case5():
    return impact1d.load_scene(INPUT / "case5.nml")


@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def assert_rows_equal_single_runs(table, scene, runs):
    assert len(table) == len(runs)
    for (_, row), overrides in zip(table.iterrows(), runs):
        for name, value in overrides.items():
            assert row[name] == value
        alone = summarize(impact1d.simulate(scene, **overrides))
        for name in SUMMARY_COLUMNS:
            want, got = alone[name], row[name]
            assert (math.isnan(want) and math.isnan(got)) if isinstance(want, float) and math.isnan(want) \
                else got == want, (overrides, name, got, want)
        assert row["error"] == ""


def grid_runs():
    return [{"r_left": a, "r_right": b} for a in GRID["r_left"] for b in GRID["r_right"]]


def test_columns_and_grid_order(case5):
    table = impact1d.sweep(case5, GRID)
    assert list(table.columns) == ["r_left", "r_right", *SUMMARY_COLUMNS, "error"]
    assert_rows_equal_single_runs(table, case5, grid_runs())


@pytest.mark.parametrize("workers", [1, 2, 3])
def test_workers_give_the_same_rows(case5, workers):
    runs = [{"r_left": a, "dt": dt} for a in np.linspace(0, 1, 9) for dt in (1e-3, 2e-3)]
    table = impact1d.sweep(case5, runs, workers=workers)
    assert_rows_equal_single_runs(table, case5, [{k: float(v) for k, v in r.items()} for r in runs])


def test_dask_local_cluster_gives_the_same_rows(case5, dask_client):
    runs = [{"r_left": float(a)} for a in np.linspace(0, 1, 150)]
    table = impact1d.sweep(case5, runs, client=dask_client)
    assert_rows_equal_single_runs(table, case5, runs)


def test_a_bad_run_is_one_row(case5):
    runs = [{"r_left": 0.5}] * 1000
    runs[417] = {"r_left": 0.5, "dt": -1.0}
    table = impact1d.sweep(case5, runs)
    errors = table["error"] != ""
    assert errors.sum() == 1 and errors[417]
    assert "dt = -1" in table.loc[417, "error"]
    assert math.isnan(table.loc[417, "x1_end"])
    assert table.loc[~errors, "t_rest"].eq(3.0).all()


def test_t_rest(case5):
    table = impact1d.sweep(case5, [{"r_left": 0.5, "r_right": 0.5}, {"r_right": 1.0}])
    assert table.loc[0, "t_rest"] == 3.0               # both rest at the accumulation time
    assert math.isnan(table.loc[1, "t_rest"])          # an elastic wall never lets it rest


def test_keep_results(case5):
    table, results = impact1d.sweep(case5, [{"r_left": 0.5}, {"dt": 0.0}], keep="results")
    assert results[1] is None and table.loc[1, "error"]
    np.testing.assert_array_equal(results[0].x1, impact1d.simulate(case5, r_left=0.5).x1)


def test_unknown_field_is_refused(case5):
    with pytest.raises(impact1d.InputError, match="unknown scene field.*r_lft"):
        impact1d.sweep(case5, {"r_lft": [0.1]})


def test_cli_writes_the_table_and_the_plot_draws_it(case5, tmp_path):
    out = tmp_path / "table.csv"
    done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "case5.nml"),
                           "--vary", "r_left=0:1:3", "--vary", "r_right=0.25,0.75",
                           "--workers", "2", "-o", str(out)],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(out, keep_default_na=False, na_values=[""])
    expected = impact1d.sweep(case5, GRID)
    np.testing.assert_array_equal(table["t_rest"].to_numpy(float), expected["t_rest"].to_numpy(float))
    np.testing.assert_array_equal(table["x2_end"], expected["x2_end"])
    png = tmp_path / "map.png"
    done = subprocess.run([find_tool("impact1d-plot"), str(out), "--x", "r_left", "--y", "r_right",
                           "--value", "t_rest", "-o", str(png)],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_writes_parquet_with_the_same_rows(case5, tmp_path):
    """-o NAME.parquet: the same table as CSV, column types kept (counts stay integers)."""
    csv, parquet = tmp_path / "table.csv", tmp_path / "table.parquet"
    for out in (csv, parquet):
        done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "case5.nml"),
                               "--vary", "r_left=0:1:3", "--vary", "r_right=0.25,0.75", "-o", str(out)],
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
        assert done.returncode == 0, done.stderr
    from_parquet = pd.read_parquet(parquet)
    from_csv = pd.read_csv(csv, keep_default_na=False, na_values=[""])
    assert list(from_parquet.columns) == list(from_csv.columns) == ["r_left", "r_right", *SUMMARY_COLUMNS, "error"]
    assert str(from_parquet["n_impacts"].dtype) == "Int64"
    for name in ("t_rest", "x1_end", "energy_residual"):
        np.testing.assert_array_equal(from_parquet[name].to_numpy(float), from_csv[name].to_numpy(float))
    assert parquet.read_bytes()[:4] == b"PAR1"


def test_cli_bad_vary_is_one_line(tmp_path):
    done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "case5.nml"),
                           "--vary", "r_left=0:1"], capture_output=True, text=True,
                          timeout=RUN_TIMEOUT)
    assert done.returncode == 1
    assert done.stderr.strip().count("\n") == 0 and "start:stop:count" in done.stderr


def test_plot_axes(case5):
    from impact1d import plot
    fig = plot.sweep(impact1d.sweep(case5, GRID), "r_left", "r_right", "t_rest")
    ax = fig.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("r_left", "r_right")
    fig = plot.sweep(impact1d.sweep(case5, {"r_left": [0.1, 0.5, 0.9]}), "r_left",
                     value=["t_rest", "impact_loss"])
    # quantities of different units on axes of their own, each labelled with its name
    axes = {ax.get_label(): ax for ax in fig.axes}
    assert list(axes) == ["t_rest", "impact_loss"]
    assert [axes[n].get_ylabel() for n in axes] == ["t_rest (s)", "impact_loss (J)"]
    assert all(len(ax.lines) == 1 for ax in fig.axes)


# A third varied field: r_right (three values) beside x = r_left; t_end has one value (as in
# make study), so it is no group.
THREE_FIELDS = {"r_left": [0.9, 0.0, 0.3, 0.6], "r_right": [0.2, 0.5, 0.8], "t_end": [4.0]}


def test_plot_lines_grouped_by_the_other_field(case5):
    """A line per r_right, each along r_left in order (it was one line zig-zagging through
    every row), and an axes per quantity; counts tick at whole numbers."""
    from impact1d import plot
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    table = impact1d.sweep(case5, THREE_FIELDS)
    fig = plot.sweep(table, "r_left", value=["n_impacts", "impact_loss"])
    FigureCanvasAgg(fig).draw()
    axes = {ax.get_label(): ax for ax in fig.axes}
    assert list(axes) == ["n_impacts", "impact_loss"]
    assert axes["n_impacts"].get_ylabel() == "n_impacts"
    for name, ax in axes.items():
        assert [line.get_label() for line in ax.lines] == [f"r_right = {r:g}" for r in (0.2, 0.5, 0.8)]
        for line, r in zip(ax.lines, (0.2, 0.5, 0.8)):
            rows = table[table["r_right"] == r].sort_values("r_left")
            np.testing.assert_array_equal(line.get_xdata(), [0.0, 0.3, 0.6, 0.9])
            np.testing.assert_array_equal(line.get_ydata(), rows[name].to_numpy(float))
    ticks = axes["n_impacts"].get_yticks()
    assert np.all(ticks == np.round(ticks))
    assert "a line per r_right" in fig._suptitle.get_text()


def test_plot_maps_one_per_value_of_the_other_field(case5):
    from impact1d import plot

    table = impact1d.sweep(case5, {"r_left": [0.0, 0.5], "r_right": [0.25, 0.75], "t_end": [2.0, 4.0]})
    fig = plot.sweep(table, "r_left", "r_right", "impact_loss")
    maps = [ax for ax in fig.axes if ax.collections and ax.get_label() != "<colorbar>"]
    assert [ax.get_title() for ax in maps] == ["t_end = 2", "t_end = 4"]
    limits = {ax.collections[0].get_clim() for ax in maps}
    assert len(limits) == 1          # one colour scale
    for ax, t_end in zip(maps, (2.0, 4.0)):
        rows = table[table["t_end"] == t_end].sort_values(["r_right", "r_left"])
        np.testing.assert_array_equal(np.asarray(ax.collections[0].get_array()).ravel(),
                                      rows["impact_loss"].to_numpy(float))


def test_plot_failed_runs_are_gaps(case5):
    from impact1d import plot

    table = impact1d.sweep(case5, {"r_left": [0.2, 1.5, 0.8]})      # r_left = 1.5 is refused
    assert table["n_impacts"].isna().sum() == 1
    line = plot.sweep(table, "r_left", value="n_impacts").axes[0].lines[0]
    np.testing.assert_array_equal(line.get_xdata(), [0.2, 0.8, 1.5])
    assert np.isnan(line.get_ydata()[2]) and not np.isnan(line.get_ydata()[:2]).any()


def test_rest_time_map_matches_the_closed_form(case5):
    """The README's study: each wall's impacts accumulate at 1 + 2 r / (1 - r) s (the first
    impact at t = 1, flights shrinking by r), and the pair rests at the later of the two."""
    r = np.linspace(0.0, 0.9, 7)
    table = impact1d.sweep(case5, {"r_left": r, "r_right": r, "t_end": [10.0]}, workers=2)
    accumulation = lambda x: 1.0 + 2.0 * x / (1.0 - x)
    expected = np.maximum(accumulation(table["r_left"]), accumulation(table["r_right"]))
    rested = table["t_rest"].notna()
    np.testing.assert_allclose(table.loc[rested, "t_rest"], expected[rested], rtol=0, atol=1e-12)
    assert (expected[~rested] > 10.0 - 1e-9).all()


def test_runs_the_batch_entry_cannot_take(case5):
    """No override at all, a text field, a field made absent: each run goes on its own."""
    plain = impact1d.sweep(case5, [{}] * 2)
    assert_rows_equal_single_runs(plain, case5, [{}] * 2)
    methods = impact1d.sweep(case5, {"method": ["event", "vissim"]})
    assert list(methods["method"]) == ["event", "vissim"] and (methods["error"] == "").all()
    assert methods.loc[0, "x2_end"] == impact1d.simulate(case5).x2[-1]
    absent = impact1d.sweep(case5, [{"dt_out": None}, {"dt_out": 0.01}])
    assert (absent["error"] == "").all() and absent.loc[0, "steps"] == impact1d.simulate(case5).steps


def test_t_rest_without_a_stopping_event(case5):
    """The vissim method stops bodies by its velocity threshold and logs no rest: t_rest is
    then the first sample from which both stay at rest (it was NaN)."""
    table = impact1d.sweep(case5, [{"method": "vissim", "r_left": 0.5}, {"method": "vissim", "dt": 1e-3}])
    res = impact1d.simulate(case5, method="vissim")
    moving = (res.v1 != 0) | (res.v2 != 0)
    assert not moving[-1]
    first_still = res.t[np.flatnonzero(moving)[-1] + 1]
    assert table.loc[1, "t_rest"] == first_still and abs(first_still - 3.0) < 0.05
    # Batch (numbers only) and per-run (a text field) paths give the same rule.
    batch = impact1d.sweep(case5.__class__(**{**vars(case5), "method": "vissim"}), [{"dt": 1e-3}])
    assert batch.loc[0, "t_rest"] == first_still


def test_plot_legend_writes_whole_numbers_whole(case5):
    """A varied work limit is a count: max_rows = 10000000 in the legend, not 1e+07."""
    from impact1d import plot

    table = impact1d.sweep(case5, {"r_left": [0.2, 0.8], "max_rows": [1e4, 1e7]})
    labels = [line.get_label() for line in plot.sweep(table, "r_left").axes[0].lines]
    assert labels == ["max_rows = 10000", "max_rows = 10000000"]


def test_sweep_rows_carry_the_springs_energy_and_the_dampers_loss():
    """pe_end and damping_loss (issue 22, item 6): the last sample's, through the core's
    batch path and through runs kept as Results alike; 0 for a scene without them."""
    scene = impact1d.load_scene(INPUT / "mounted_stop.nml")
    res = impact1d.simulate(scene, dt=2e-3)
    batch = impact1d.sweep(scene, [dict(dt=2e-3)], workers=1)
    kept, _ = impact1d.sweep(scene, [dict(dt=2e-3)], workers=1, keep="results")
    for table in (batch, kept):
        assert table.loc[0, "pe_end"] == res.pe[-1] and table.loc[0, "damping_loss"] == res.damping_loss[-1]
    assert res.damping_loss[-1] > 0 and res.pe[-1] > 0
    plain = impact1d.sweep(impact1d.load_scene(INPUT / "case3.nml"), [dict(r_left=1.0)], workers=1)
    assert plain.loc[0, "pe_end"] == 0.0 and plain.loc[0, "damping_loss"] == 0.0


# --- steady state over [settle, t_end] (issue 22 item 6) ---------------------------------

def _steady_bounds(amplitude, omega, length, h):
    """impact1d.sweep.steady_state's sampling-error bounds (its docstring derives them):
    |rms - A/sqrt(2)| <= sqrt(2) A eps, 2 A (1 - (w h)^2 / 8) <= p2p <= 2 A."""
    eps = math.pi / (4 * omega * length) + (math.pi / (omega * length)) ** 2
    return math.sqrt(2) * amplitude * eps, 2 * amplitude * (omega * h) ** 2 / 8


@pytest.mark.parametrize("settle, dt_out", [(3.3, 1e-3), (0.0, 1e-2), (11.05, 5e-2)])
def test_steady_state_of_a_free_harmonic_oscillator(settle, dt_out):
    """x = x_rest + A cos(w t): RMS A/sqrt(2) and peak-to-peak 2A (about the rest position,
    not 0), v's with A w, within the sampling error; RK4's own error (~1e-12 here) is far
    below it. A window of a non-whole number of periods, and a coarse dt_out."""
    amplitude, omega, rest, t_end = 0.2, 2 * math.pi, 0.3, 20.0
    scene = impact1d.Scene(m1=1.0, k1=omega ** 2, x1_rest=rest, x1=rest + amplitude, v1=0.0,
                           t_end=t_end, dt=1e-3)
    row = impact1d.sweep(scene, {"dt_out": [dt_out]}, settle=settle).iloc[0]
    for name, a in (("x1", amplitude), ("v1", amplitude * omega)):
        rms_error, p2p_error = _steady_bounds(a, omega, t_end - settle, dt_out)
        assert abs(row[f"{name}_rms"] - a / math.sqrt(2)) <= rms_error + 1e-9, name
        assert -p2p_error - 1e-9 <= row[f"{name}_p2p"] - 2 * a <= 1e-9, name
    assert all(math.isnan(row[c]) for c in ("x2_p2p", "x2_rms", "v2_p2p", "v2_rms", "impacts_per_period"))


def test_steady_state_columns_only_when_asked_and_equal_to_the_results():
    """Without settle the table is as it was; with it each measure is the definition's,
    computed from the run's samples and events (impacts per period of the forced impact
    oscillator: impacts with t >= settle times f1_period over the window)."""
    scene = impact1d.load_scene(INPUT / "impact_oscillator.nml")
    grid = {"f1_amp": [4.0, 10.0]}
    plain = impact1d.sweep(scene, grid, workers=1)
    assert "x1_rms" not in plain.columns
    table, results = impact1d.sweep(scene, grid, workers=2, settle=12.0, keep="results")
    assert table[plain.columns].equals(plain)
    for row, result in zip(table.itertuples(), results):
        window = result.t >= 12.0
        x = result.x1[window]
        assert row.x1_p2p == x.max() - x.min() and row.x1_rms == np.sqrt(np.mean((x - x.mean()) ** 2))
        hits = np.count_nonzero((result.events["kind"] == "left") & (result.events["t"] >= 12.0))
        assert hits > 0 and row.impacts_per_period == hits * 2.4 / (20.0 - 12.0)


def test_impacts_per_period_of_a_sine_given_as_a_record():
    """The impact oscillator's drive written as a &sine record (f1_amp = 0) is the same
    run; impacts_per_period counted per that record's period (it read only f1/f2_period
    and gave NaN), the same number as with f1_amp."""
    scene = impact1d.load_scene(INPUT / "impact_oscillator.nml")
    as_record = dataclasses.replace(scene, f1_amp=0.0, sines=[dict(body=1, amp=10.0, period=2.4, phase=0.0)])
    plain = impact1d.sweep(scene, {"r_left": [0.8]}, workers=1, settle=12.0)
    record = impact1d.sweep(as_record, {"r_left": [0.8]}, workers=1, settle=12.0)
    assert plain["impacts_per_period"][0] > 0
    assert record["impacts_per_period"][0] == plain["impacts_per_period"][0]


@pytest.mark.parametrize("settle, message", [(-1.0, "must be a time of 0 s or more"),
                                             (math.nan, "must be a time"),
                                             (20.0, "settle = 20.0 is not before t_end = 20.0")])
def test_settle_outside_the_run_is_refused(settle, message):
    scene = impact1d.load_scene(INPUT / "impact_oscillator.nml")
    with pytest.raises(impact1d.InputError, match=message):
        impact1d.sweep(scene, {"f1_amp": [4.0]}, settle=settle)


def test_sweep_cli_settle(tmp_path):
    out = tmp_path / "t.csv"
    done = subprocess.run([find_tool("impact1d-sweep"), str(INPUT / "impact_oscillator.nml"),
                           "--vary", "f1_amp=4,10", "--settle", "12", "-o", str(out)],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(out)
    scene = impact1d.load_scene(INPUT / "impact_oscillator.nml")
    expected = impact1d.sweep(scene, {"f1_amp": [4.0, 10.0]}, settle=12.0)
    np.testing.assert_allclose(table["impacts_per_period"], expected["impacts_per_period"], rtol=1e-15)
    np.testing.assert_allclose(table["v1_rms"], expected["v1_rms"], rtol=1e-15)


def test_steady_state_columns_plot_with_their_units():
    import matplotlib

    matplotlib.use("Agg")
    table = impact1d.sweep(impact1d.load_scene(INPUT / "impact_oscillator.nml"), {"f1_amp": [4.0, 10.0]},
                           settle=12.0)
    fig = impact1d.plot.sweep(table, "f1_amp", value=["x1_rms", "v2_p2p", "impacts_per_period"])
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["x1_rms (m)", "v2_p2p (m/s)", "impacts_per_period"]
