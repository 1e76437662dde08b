"""Every result bit for bit as stored in tests/golden/hashes.json (see check_golden.py)."""

import json
import re
import sys
from pathlib import Path

import impact1d
import numpy as np
import pytest

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


@pytest.mark.parametrize("fields, zeros", [
    (dict(m1=1.0, m2=1.0, x_left=0.0, r_left=0.5, x1=0.0, v1=0.0, f1=-1.0, x2=1.0, v2=-1.0,
          t_end=2.0, dt=0.01), ("x_left", "x1", "v1")),
    # (the sample at t = 1 is the event point's: the body just put on the wall)
    (dict(m1=1.0, x1=-1.0, v1=1.0, x_right=0.0, r_right=0.0, t_end=2.0, dt=0.01, dt_out=0.5),
     ("x_right",)),
])
def test_signed_zero_inputs_give_the_bits_of_plus_zero(fields, zeros):
    """A -0 position, velocity or wall enters the model as +0 (x1 = -0.0 was the first
    sample's; a body snapped onto a wall at x_right = -0.0 sat at x1 = -0.0): the N-body sums drop absent terms exactly only when
    no value they meet is -0, so none may come from the input."""
    plus = impact1d.simulate(impact1d.Scene(**fields))
    minus = impact1d.simulate(impact1d.Scene(**dict(fields, **{name: -0.0 for name in zeros})))
    assert len(plus.events) > 0
    assert check_golden._digest(minus) == check_golden._digest(plus)
