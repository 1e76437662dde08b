"""Bit-identity check of the engine: runs a fixed list of scenes through
impact1d.simulate and compares a SHA-256 of the exact bytes of the samples and of
the event log (t, kind, velocities before/after) with tests/golden/hashes.json.

    python tests/golden/check_golden.py            # compare; exit 1 naming each change
    python tests/golden/check_golden.py --update   # store the current engine's hashes

The scenes: the seed cases input/case*.nml at their own dt, at dt = 0.1 and under
method='vissim' (and VISSIM_NBODY's N-body scenes under it); the other input/*.nml scenes (springs, dampers, static friction, one
body, contact records, more than two bodies); the bench
scenes bench/scenes/*.nml; the one-body and spring/damper scenes of
SCENES (from tests/test_model_widening.py and tests/test_exact_springs.py); and
GENERATED scenes of tests/test_reference.py (its own generator, fixed indices) at two
steps.  A refactoring that must change no result runs this on every commit; --update
only when a result is meant to change.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
HASHES = Path(__file__).resolve().with_name("hashes.json")
sys.path.insert(0, str(ROOT / "tests"))

import impact1d  # noqa: E402

# Every fourth of the 150 reference scenes (all families, as the family cycles with
# period 6) plus the scenes the reference test singles out as delicate (6, 12, 56, 90).
GENERATED = sorted(set(range(0, 150, 4)) | {6, 12, 56, 90})
GENERATED_DT = (1e-2, 1e-3)
COARSE_DT = 0.1
# N-body scenes of input/ also run under method='vissim' (its N-body form): impacts between
# bodies, walls, springs and friction (burridge_knopoff's driver moves: vissim refuses it).
VISSIM_NBODY = ("newtons_cradle.nml", "gear_train.nml")

# One body (the engine keeps a phantom second body for it: its tolerances read min(m1, 1),
# so m1 on either side of 1) and every spring and damper element, both methods.
_ALL_ELEMENTS = dict(m1=1.2, m2=0.8, mu1=0.2, mus1=0.3, mu2=0.1, x_left=-1.0, r_left=0.7,
                     x_right=2.0, r_right=0.9, d_min=0.2, r_min=0.5, d_max=0.9, r_max=0.8,
                     x1=0.0, v1=1.5, x2=0.5, v2=-4.0, k1=30.0, x1_rest=0.0, c1=0.3, k2=20.0,
                     x2_rest=0.8, c2=0.2, k12=50.0, d_rest=0.5, c12=0.4, f1_amp=40.0,
                     f1_period=0.9, t_end=4.0, dt=1e-3, dt_out=0.01)
_TWO_WALLS = dict(m1=2.0, x1=1.0, v1=3.0, f1=-1.0, x_left=0.0, r_left=0.5, x_right=2.0,
                  r_right=0.9, t_end=4.0, dt=0.1, dt_out=0.1)
SCENES = {
    "one_body/two_walls": _TWO_WALLS,
    "one_body/two_walls@method=vissim": dict(_TWO_WALLS, dt=1e-3, method="vissim"),
    "one_body/impact_oscillator": dict(m1=1.0, x1=0.5, k1=4.0, x1_rest=0.0, x_left=0.0,
                                       r_left=0.8, t_end=20.0, dt=1e-3, dt_out=0.01),
    "one_body/sine_breakaway": dict(m1=1.0, mu1=0.4, g=10.0, x1=0.0, f1=-5.0, f1_amp=2.0,
                                    f1_period=1.0, t_end=1.0, dt=0.01),
    "one_body/released_by_a_sine": dict(m1=1.0, x1=0.0, x_left=-0.05, r_left=0.8, k1=40.0,
                                        x1_rest=0.0, c1=0.4, f1_amp=4.2142857142857135,
                                        f1_period=2.4, t_end=5.0, dt=1e-3, dt_out=0.01),
    "one_body/damper": dict(m1=2.0, x1=0.0, v1=1.0, c1=0.5, t_end=4.0, dt=1e-3, dt_out=0.5),
    "one_body/heavy_rattles_to_rest": dict(m1=2.5, mu1=0.05, x1=0.5, f1=-2.0, x_left=0.0,
                                           r_left=0.5, t_end=3.0, dt=1e-3, dt_out=0.01),
    "one_body/heavy_stick_slip": dict(m1=3.0, mu1=0.3, mus1=0.5, k1=100.0, x1_rest=0.0,
                                      f1_amp=20.0, f1_period=1.5, x_left=-0.2, r_left=0.3,
                                      x1=0.0, t_end=5.0, dt=1e-3, dt_out=0.01),
    "springs/breakaway_k12": dict(m1=3.0, m2=1.0, mu1=1.0, g=10.0, f2=32.0, d_min=0.0,
                                  r_min=0.0, x1=0.0, x2=0.0, k12=28.0, d_rest=0.0, t_end=0.5,
                                  dt=1e-3),
    "springs/damped_pair": dict(m1=1.0, m2=2.0, x1=0.0, v1=1.0, x2=1.5, v2=-0.25, k12=6.0,
                                d_rest=1.0, c12=4.0, t_end=10.0, dt=1e-3, dt_out=0.05),
    "springs/all_elements": _ALL_ELEMENTS,
    "springs/all_elements@method=vissim": dict(_ALL_ELEMENTS, method="vissim"),
}


def _digest(res) -> str:
    h = hashlib.sha256()
    samples = np.ascontiguousarray(np.asarray(res.samples, dtype=np.float64))
    h.update(str(samples.shape).encode())
    h.update(samples.tobytes())
    # The fields an event has, in the dtype's order: t, v1_before, v2_before, v1_after,
    # v2_after for two bodies (the order these hashes were first taken in), t, v1_before,
    # v1_after for one.
    numbers = [name for name in res.events.dtype.names if name != "kind"]
    for e in res.events:
        h.update(np.array([e[name] for name in numbers], dtype=np.float64).tobytes())
        h.update(str(e["kind"]).encode() + b";")
    return h.hexdigest()


def _run(scene, **overrides) -> str:
    try:
        return _digest(impact1d.simulate(scene, **overrides))
    except Exception as exc:  # an error is a result too: it must not change either
        return f"{type(exc).__name__}: {exc}"


def scenes():
    """Yield (name, thunk) for every scene of the fixed list."""
    cwd = os.getcwd()
    os.chdir(ROOT)  # seed cases name their tables relative to the project root
    try:
        for path in sorted((ROOT / "input").glob("*.nml")):
            scene = impact1d.load_scene(str(path.relative_to(ROOT)))
            yield f"input/{path.name}", _run(scene)
            if path.name.startswith("case"):
                yield f"input/{path.name}@dt={COARSE_DT}", _run(scene, dt=COARSE_DT)
            if path.name.startswith("case") or path.name in VISSIM_NBODY:
                yield f"input/{path.name}@method=vissim", _run(scene, method="vissim")
        for path in sorted((ROOT / "bench" / "scenes").glob("*.nml")):
            scene = impact1d.load_scene(str(path.relative_to(ROOT)))
            yield f"bench/scenes/{path.name}", _run(scene)
    finally:
        os.chdir(cwd)
    for name, fields in SCENES.items():
        yield name, _run(impact1d.Scene(**fields))
    import test_reference as reference
    with tempfile.TemporaryDirectory() as folder:
        for index in GENERATED:
            scene, _ = reference.generate(index, folder)
            for dt in GENERATED_DT:
                yield (f"generated_{index:03d}@dt={dt}",
                       _run(scene, dt=dt, dt_out=max(scene.t_end / 100, dt)))


def main(argv) -> int:
    got = dict(scenes())
    if "--update" in argv:
        HASHES.write_text(json.dumps(got, indent=1, sort_keys=True) + "\n")
        print(f"stored {len(got)} hashes in {HASHES}")
        return 0
    want = json.loads(HASHES.read_text())
    differing = sorted(k for k in set(got) | set(want) if got.get(k) != want.get(k))
    for name in differing:
        print(f"CHANGED: {name}")
    print(f"{len(got) - len(differing)}/{len(got)} scenes bit-identical")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
