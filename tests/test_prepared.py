"""Prepared scenes (issue 20 item 1): a scene run again with the same values is validated
and built once in the core (api prepare / run_prepared), not at every call. Its runs must
be those of the whole set-up bit for bit, say what it said (warnings, errors), read force
tables afresh, and free the core's copy with the form that holds it, also while other
threads run it."""

import shutil
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import impact1d
from impact1d import _scene, _simulate
from impact1d._scene import CoreForm

ROOT = Path(__file__).resolve().parents[1]
INPUT = ROOT / "input"
ONE_SPRING = dict(m1=2.0, x1=0.1, k1=800.0, x1_rest=0.0)      # w = 20 rad/s (test_stability)


def same(a, b):
    return (a.columns == b.columns and all(np.array_equal(getattr(a, c), getattr(b, c)) for c in a.columns)
            and np.array_equal(a.events, b.events) and a.events.dtype == b.events.dtype and a.steps == b.steps
            and a.energy_residual == b.energy_residual and a.warnings == b.warnings and a.scene == b.scene
            and a.bodies == b.bodies and np.array_equal(a.x, b.x) and np.array_equal(a.v, b.v))


def form_of(scene, **overrides) -> CoreForm:
    return _scene.core_form(scene, overrides, _simulate._make_form)


@pytest.mark.parametrize("name, overrides", [("case3", dict(t_end=1e-3, dt=1e-3)), ("case3", {}),
                                             ("case5", dict(dt_out=2e-3)), ("newtons_cradle", {}),
                                             ("train", {})])
def test_a_scene_run_again_is_prepared_once_with_the_same_results(name, overrides):
    """The first run sets the scene up whole, the second prepares it, later runs use it:
    all give the same Result (one, two and N bodies, events or none)."""
    scene = impact1d.load_scene(INPUT / f"{name}.nml")
    runs = [impact1d.simulate(scene, **overrides) for _ in range(4)]
    assert form_of(scene, **overrides).handle > 0
    assert all(same(run, runs[0]) for run in runs[1:])
    assert runs[-1].scene is not runs[-2].scene       # each Result has its own copy of the scene


def test_a_prepared_run_keeps_its_warning():
    scene = impact1d.Scene(**ONE_SPRING, t_end=0.5, dt=0.07)
    runs = [impact1d.simulate(scene) for _ in range(3)]
    assert form_of(scene).handle > 0
    assert len(runs[0].warnings) == 1 and "coarse" in runs[0].warnings[0]
    assert all(run.warnings == runs[0].warnings for run in runs)


def test_a_bad_scene_is_not_prepared_and_says_the_same_each_run():
    scene = impact1d.load_scene(INPUT / "case3.nml")
    scene.m1 = -1.0
    messages = []
    for _ in range(3):
        with pytest.raises(impact1d.InputError) as info:
            impact1d.simulate(scene)
        messages.append(str(info.value))
    assert form_of(scene).handle == 0
    assert messages == [messages[0]] * 3 and "m1" in messages[0]


def test_a_force_table_is_read_afresh_each_run(tmp_path):
    """A scene that reads a table file is not prepared: a table changed between runs is
    the one the next run uses (as the whole set-up read it at every call)."""
    for name in ("case6.nml", "triangle.dat"):
        shutil.copy(INPUT / name, tmp_path / name)
    scene = impact1d.load_scene(tmp_path / "case6.nml")
    first = [impact1d.simulate(scene, t_end=2.0) for _ in range(3)]
    assert form_of(scene, t_end=2.0).handle == 0
    table = tmp_path / "triangle.dat"
    table.write_text(table.read_text().replace("1.0   30.0", "1.0   60.0"))
    changed = impact1d.simulate(scene, t_end=2.0)
    assert same(first[1], first[0]) and same(first[2], first[0])
    assert not np.array_equal(changed.x1, first[0].x1)
    table.unlink()
    with pytest.raises(impact1d.InputError, match="f1_table"):
        impact1d.simulate(scene, t_end=2.0)


def test_a_form_dropped_from_the_cache_frees_its_prepared_scene(monkeypatch):
    released = []
    real = CoreForm._release
    monkeypatch.setattr(CoreForm, "_release", staticmethod(lambda handle: (released.append(handle), real(handle))))
    scene = impact1d.load_scene(INPUT / "case3.nml")
    for _ in range(3):
        impact1d.simulate(scene, t_end=0.5)
    handle = form_of(scene, t_end=0.5).handle
    assert handle > 0 and handle not in released
    _scene._CORE_FORMS.clear()
    assert released.count(handle) == 1
    # (a scene run again after that is prepared anew)
    again = [impact1d.simulate(scene, t_end=0.5) for _ in range(3)]
    assert form_of(scene, t_end=0.5).handle > 0 and same(again[2], again[0])


def test_a_handle_that_names_no_scene_is_an_internal_error():
    buffers = _simulate._buffers
    samples = np.empty((3, len(_simulate.COLUMNS)), order="F")
    _scene._api.run_prepared(0, 0, samples, *buffers.outputs, -1)
    status, length = int(buffers.info[0]), int(buffers.info[5])
    message = bytes(buffers.text_codes[:length, 0].astype(np.uint8)).decode()
    assert status == 1 and message.startswith("internal: no prepared scene")


def test_threads_run_one_prepared_scene_at_once_while_the_cache_is_cleared():
    """Four threads run the same prepared scenes at once while a fifth drops every form
    from the cache again and again: each run gives the sequential result (a form a run
    holds is freed only after it)."""
    jobs = [(impact1d.load_scene(INPUT / f"case{n}.nml"), {"dt_out": dt_out}) for n, dt_out in ((3, 1e-3), (5, 2e-3))]
    expected = [impact1d.simulate(scene, **kw) for scene, kw in jobs for _ in range(2)][::2]
    assert all(form_of(scene, **kw).handle > 0 for scene, kw in jobs)
    done = threading.Event()

    def clear():
        while not done.is_set():
            _scene._CORE_FORMS.clear()
            done.wait(0.001)

    clearing = threading.Thread(target=clear)
    clearing.start()
    try:
        with ThreadPoolExecutor(max_workers=4) as pool:
            for _ in range(10):
                got = list(pool.map(lambda k: impact1d.simulate(jobs[k % 2][0], **jobs[k % 2][1]), range(8)))
                assert all(same(g, expected[k % 2]) for k, g in enumerate(got))
    finally:
        done.set()
        clearing.join()
