"""What the event log keeps (issue 22, item 4): `&run events = 'all' | 'impacts' | 'none'`,
`Scene(events=...)`, the CLI's `--events`. A 1e5 s run wrote 1.48 M events (213 MB) with no
way to keep fewer. The samples, the summary's counts and a sweep's row are the same whatever
the log keeps; 'none' writes no events file (an earlier one beside the output is removed with
the pair it belonged to)."""

import subprocess
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
CASE5 = ROOT / "input" / "case5.nml"
IMPACTS = {"left", "right", "slot_min", "slot_max"}


def test_python_keeps_what_it_is_asked_and_the_samples_do_not_change():
    scene = impact1d.load_scene(CASE5)
    every = impact1d.simulate(scene)
    impacts = impact1d.simulate(scene, events="Impacts")
    none = impact1d.simulate(scene, events="none")
    kinds = set(map(str, every.events["kind"]))
    assert kinds - IMPACTS                         # rests there too, to be dropped
    keep = np.isin(every.events["kind"], sorted(IMPACTS))
    np.testing.assert_array_equal(impacts.events, every.events[keep])
    assert len(none.events) == 0
    for res in (impacts, none):
        np.testing.assert_array_equal(res.samples, every.samples)
    with pytest.raises(impact1d.InputError, match="events = 'some' is unknown"):
        impact1d.simulate(scene, events="some")


@pytest.mark.parametrize("events", ["impacts", "none"])
def test_sweep_rows_are_exact_whatever_the_log_keeps(events):
    scene = impact1d.load_scene(CASE5)
    table, results = impact1d.sweep(scene, [dict(), dict(events=events)], workers=1, keep="results")
    summary = [c for c in table.columns if c not in ("events", "error")]
    assert table.loc[0, summary].equals(table.loc[1, summary])
    assert table.loc[1, "n_impacts"] == 94 and table.loc[1, "t_rest"] == 3.0
    kept = set(map(str, results[1].events["kind"]))
    if events == "impacts":
        assert kept and kept <= IMPACTS
    else:
        assert kept == set()
    # The same through the core's batch path (the scene itself asks for the smaller log).
    batch = impact1d.sweep(impact1d.Scene(**{**vars(scene), "events": events}),
                           {"r_left": [0.5]}, workers=1)
    assert batch.loc[0, "n_impacts"] == 94 and batch.loc[0, "t_rest"] == 3.0


def test_cli_events_option_and_namelist(tmp_path):
    cli = find_tool("impact1d")
    out = tmp_path / "o.dat"
    events_file = tmp_path / "o.events.dat"

    def run(*options):
        done = subprocess.run([cli, str(CASE5), "-o", str(out), *options], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    run()
    samples = out.read_text()
    every = events_file.read_text().splitlines()
    summary = run("--events", "impacts")
    kept = events_file.read_text().splitlines()
    assert kept == [line for line in every if line.startswith("#") or line.split()[1] in IMPACTS]
    assert "94 impacts of 96 events" in summary and out.read_text() == samples
    summary = run("--events=none")
    assert not events_file.exists() and out.read_text() == samples
    assert "no event log" in summary and "left 47 right 47 rest_left 1 rest_right 1" in summary
    # In the scene file, any letter case; the option overrides it.
    scene = tmp_path / "s.nml"
    scene.write_text(CASE5.read_text().replace("&run ", "&run events = 'NONE', "))
    done = subprocess.run([cli, str(scene), "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0 and not events_file.exists(), done.stderr
    done = subprocess.run([cli, str(scene), "-o", str(out), "--events", "all"], capture_output=True, text=True)
    assert done.returncode == 0 and events_file.read_text().splitlines() == every
    done = subprocess.run([cli, str(CASE5), "-o", str(out), "--events", "some"], capture_output=True, text=True)
    assert done.returncode == 1 and "events = 'some' is unknown" in done.stderr


# --- the cap: &run max_events, --max-events, Scene(max_events=) -------------------------

CUT_NOTE = "the event log was cut at {n} of {m} events (max_events = {n}); the run went on to its end"


def test_python_log_is_cut_at_max_events_and_says_so():
    scene = impact1d.load_scene(CASE5)
    every = impact1d.simulate(scene)
    assert len(every.events) == 96 and every.warnings == ()     # the default (10^7) holds it
    cut = impact1d.simulate(scene, max_events=10)
    np.testing.assert_array_equal(cut.events, every.events[:10])
    np.testing.assert_array_equal(cut.samples, every.samples)   # the run went on
    assert len(cut.warnings) == 1 and cut.warnings[0].startswith(CUT_NOTE.format(n=10, m=96))
    impacts = impact1d.simulate(scene, events="impacts", max_events=10)
    keep = np.isin(every.events["kind"], sorted(IMPACTS))
    np.testing.assert_array_equal(impacts.events, every.events[keep][:10])
    assert impacts.warnings[0].startswith(CUT_NOTE.format(n=10, m=94))
    assert impact1d.simulate(scene, max_events=96).warnings == ()
    for bad in (0, 1.5, -3):
        with pytest.raises(impact1d.InputError, match="max_events = .* must be a whole number"):
            impact1d.simulate(scene, max_events=bad)


def test_sweep_rows_are_exact_whatever_the_cap():
    scene = impact1d.load_scene(CASE5)
    table, results = impact1d.sweep(scene, [dict(), dict(max_events=10)], workers=1, keep="results")
    summary = [c for c in table.columns if c not in ("max_events", "error")]
    assert table.loc[0, summary].equals(table.loc[1, summary])
    assert table.loc[1, "n_impacts"] == 94 and table.loc[1, "t_rest"] == 3.0
    assert len(results[0].events) == 96 and len(results[1].events) == 10
    assert results[1].warnings[0].startswith(CUT_NOTE.format(n=10, m=96))
    # The core's batch path (the scene itself asks for the cap): the same rows.
    whole = impact1d.sweep(scene, {"r_left": [0.5, 0.9]}, workers=1)
    capped = impact1d.sweep(impact1d.Scene(**{**vars(scene), "max_events": 10}), {"r_left": [0.5, 0.9]}, workers=1)
    assert whole.equals(capped) and whole.loc[0, "n_impacts"] > 10


def test_cli_max_events_option_and_namelist(tmp_path):
    cli = find_tool("impact1d")
    out = tmp_path / "o.dat"
    events_file = tmp_path / "o.events.dat"

    def rows(path):
        return [line for line in path.read_text().splitlines() if not line.startswith("#")]

    done = subprocess.run([cli, str(CASE5), "-o", str(out)], capture_output=True, text=True)
    every, samples = rows(events_file), rows(out)
    for options, scene in [(["--max-events", "10"], CASE5), (["--max-events=10"], CASE5), ([], "nml")]:
        if scene == "nml":
            scene = tmp_path / "s.nml"
            scene.write_text(CASE5.read_text().replace("&run ", "&run max_events = 10, "))
        done = subprocess.run([cli, str(scene), "-o", str(out), *options], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert rows(events_file) == every[:10] and rows(out) == samples
        last = events_file.read_text().splitlines()[-1]
        assert last.startswith("# " + CUT_NOTE.format(n=10, m=96))
        assert "left 47 right 47 rest_left 1 rest_right 1" in done.stdout       # exact counts
        assert "(96 events, cut at 10: max_events)" in done.stdout
        assert "  warning   " + CUT_NOTE.format(n=10, m=96) in done.stdout
        read_back = impact1d.read_output(out)                   # the note comes back too
        assert len(read_back.events) == 10 and read_back.warnings[0].startswith(CUT_NOTE.format(n=10, m=96))
    done = subprocess.run([cli, str(CASE5), "-o", str(out), "--max-events", "2.5"], capture_output=True, text=True)
    assert done.returncode == 1 and "max_events = 2.5 must be a whole number" in done.stderr
