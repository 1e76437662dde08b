"""Runs from several threads at once (issue 13 items 2 and 3, issue 11 item 2): each call
returns its own results, the Fortran run releases the GIL, and texts and paths may be any
UTF-8."""

import shutil
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import impact1d

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
# Rounds of 4 threads: the corruption this guards against hit 6-11% of runs.
ROUNDS = 30


def scenes():
    """Four different scenes (different sample counts and event logs)."""
    return [(impact1d.load_scene(INPUT / f"case{n}.nml"), {"dt_out": dt_out})
            for n, dt_out in ((3, 1e-3), (5, 2e-3), (6, 1e-2), (2, 5e-3))]


def same(a, b):
    return (a.columns == b.columns and all(np.array_equal(getattr(a, c), getattr(b, c)) for c in a.columns)
            and np.array_equal(a.events, b.events) and a.steps == b.steps
            and a.energy_residual == b.energy_residual)


def test_threads_get_exactly_the_sequential_results():
    jobs = scenes()
    expected = [impact1d.simulate(scene, **kw) for scene, kw in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        for _ in range(ROUNDS):
            got = list(pool.map(lambda job: impact1d.simulate(job[0], **job[1]), jobs))
            assert all(same(g, e) for g, e in zip(got, expected))


def test_long_runs_overlap_in_time():
    """Two long runs in two threads: both start before either ends, which cannot happen
    while one holds the GIL through its whole Fortran run."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    marks = {}
    started = threading.Barrier(2)

    def run(name):
        started.wait()
        marks[name, "start"] = time.perf_counter()
        impact1d.simulate(scene, t_end=3000.0, dt_out=1.0)
        marks[name, "end"] = time.perf_counter()

    threads = [threading.Thread(target=run, args=(name,)) for name in "ab"]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert marks["a", "start"] < marks["b", "end"] and marks["b", "start"] < marks["a", "end"]
    # The overlap is real work, not two runs' edges touching: each ran while the other did.
    overlap = min(marks["a", "end"], marks["b", "end"]) - max(marks["a", "start"], marks["b", "start"])
    shortest = min(marks["a", "end"] - marks["a", "start"], marks["b", "end"] - marks["b", "start"])
    assert overlap > 0.5 * shortest


def test_result_owns_its_arrays():
    """Nothing of a run stays in the core: the Result's arrays are numpy's own (freed with
    it), and a second run does not touch the first one's numbers."""
    scene = impact1d.load_scene(INPUT / "case3.nml")
    first = impact1d.simulate(scene)
    kept = first.x1.copy()
    impact1d.simulate(scene, v1=-3.0)
    assert np.array_equal(first.x1, kept)
    base = first.x1
    while base.base is not None:
        base = base.base
    assert base.flags.owndata


def test_non_ascii_title():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    res = impact1d.simulate(scene, title="Café: ½ Δt ✓")
    assert res.scene.title == "Café: ½ Δt ✓"
    assert same(res, impact1d.simulate(scene))


def test_non_ascii_scene_and_table_paths(tmp_path):
    folder = tmp_path / "études"
    folder.mkdir()
    shutil.copy(INPUT / "triangle.dat", folder / "triangle_ü.dat")
    text = (INPUT / "case6.nml").read_text().replace("triangle.dat", "triangle_ü.dat")
    (folder / "cas_6_é.nml").write_text(text, encoding="utf-8")
    scene = impact1d.load_scene(folder / "cas_6_é.nml")
    assert scene.f1_table.endswith("triangle_ü.dat")
    res = impact1d.simulate(scene)
    assert same(res, impact1d.simulate(impact1d.load_scene(INPUT / "case6.nml")))


def test_threads_building_error_messages_at_once_get_their_own():
    """Runs that fail in several threads at once each get their own message. gfortran 12
    kept the length of a function's deferred-length string result in a static variable of
    the caller, shared by all threads: two threads formatting numbers into messages at once
    corrupted 6 of 20000 (and could overrun a buffer). Every run here fails with a message
    naming its own dt."""
    from impact1d._simulate import run_summaries
    scene = impact1d.load_scene(INPUT / "case3.nml")
    runs = [{"dt": -1.5 - k, "t_end": 1.0} for k in range(2000)]
    expected = [f"dt = {-1.5 - k:g} must be positive" for k in range(2000)]
    assert run_summaries(scene, runs)[1] == expected
    with ThreadPoolExecutor(max_workers=2) as pool:
        for _ in range(5):
            halves = list(pool.map(lambda k: run_summaries(scene, runs[k::2])[1], (0, 1)))
            assert halves[0] == expected[0::2] and halves[1] == expected[1::2]


def test_the_core_keeps_no_static_string_lengths():
    """The deterministic side of the test above: the compiled core has none of gfortran's
    static result-length variables (named slen.N.M), i.e. no function returns a string of
    deferred length (see fmt in src/impact1d_error.f90)."""
    from impact1d import _core
    assert b"slen." not in Path(_core.__file__).read_bytes()
