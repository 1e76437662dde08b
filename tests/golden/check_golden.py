"""Bit-identity check of the engine: runs a fixed list of scenes through
impact1d.simulate and compares a SHA-256 of the exact bytes of the samples and of
the event log (t, kind, velocities before/after) with tests/golden/hashes.json.

    python tests/golden/check_golden.py            # compare; exit 1 naming each change
    python tests/golden/check_golden.py --update   # store the current engine's hashes

The scenes: the seed cases input/case*.nml at their own dt and at dt = 0.1, the bench
scenes bench/scenes/*.nml, and GENERATED scenes of tests/test_reference.py (its own
generator, fixed indices) at two steps.  A refactoring that must change no result
runs this on every commit; --update only when a result is meant to change.
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


def _digest(res) -> str:
    h = hashlib.sha256()
    samples = np.ascontiguousarray(np.asarray(res.samples, dtype=np.float64))
    h.update(str(samples.shape).encode())
    h.update(samples.tobytes())
    for e in res.events:
        h.update(np.array([e["t"], e["v1_before"], e["v2_before"], e["v1_after"],
                           e["v2_after"]], dtype=np.float64).tobytes())
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
        for path in sorted((ROOT / "input").glob("case*.nml")):
            scene = impact1d.load_scene(str(path.relative_to(ROOT)))
            yield f"input/{path.name}", _run(scene)
            yield f"input/{path.name}@dt={COARSE_DT}", _run(scene, dt=COARSE_DT)
        for path in sorted((ROOT / "bench" / "scenes").glob("*.nml")):
            scene = impact1d.load_scene(str(path.relative_to(ROOT)))
            yield f"bench/scenes/{path.name}", _run(scene)
    finally:
        os.chdir(cwd)
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
