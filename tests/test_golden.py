"""Every result bit for bit as stored in tests/golden/hashes.json (see check_golden.py)."""

import json
import re
import sys
from pathlib import Path

import impact1d
import numpy as np

GOLDEN = Path(__file__).resolve().parent / "golden"
sys.path.insert(0, str(GOLDEN))

import check_golden  # noqa: E402


def test_results_are_bit_identical_to_the_stored_hashes():
    want = json.loads((GOLDEN / "hashes.json").read_text())
    got = dict(check_golden.scenes())
    changed = sorted(k for k in set(got) | set(want) if got.get(k) != want.get(k))
    assert not changed, f"results changed: {changed}"


def test_one_body_events_are_hashed_not_an_error():
    """A one-body run's events have no v2 fields: the digest hashes the fields they have
    (it raised ValueError on v2_before, and the scene was guarded by an error string)."""
    res = impact1d.simulate(impact1d.Scene(**check_golden.SCENES["one_body/two_walls"]))
    assert len(res.events) > 0 and "v2_before" not in res.events.dtype.names
    digest = check_golden._digest(res)
    res.events["v1_after"][0] = np.nextafter(res.events["v1_after"][0], np.inf)
    assert check_golden._digest(res) != digest


def test_the_guard_scenes_hash_results_not_errors():
    """The scenes added to guard the model's layout run to the end: a stored error string
    would guard nothing but its message."""
    want = json.loads((GOLDEN / "hashes.json").read_text())
    guards = [k for k in want if k in check_golden.SCENES or not k.startswith("generated_")]
    assert len(guards) >= len(check_golden.SCENES)
    assert all(re.fullmatch("[0-9a-f]{64}", want[k]) for k in guards), \
        [k for k in guards if not re.fullmatch("[0-9a-f]{64}", want[k])]
