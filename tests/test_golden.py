"""Every result bit for bit as stored in tests/golden/hashes.json (see check_golden.py)."""

import json
import sys
from pathlib import Path

GOLDEN = Path(__file__).resolve().parent / "golden"
sys.path.insert(0, str(GOLDEN))

import check_golden  # noqa: E402


def test_results_are_bit_identical_to_the_stored_hashes():
    want = json.loads((GOLDEN / "hashes.json").read_text())
    got = dict(check_golden.scenes())
    changed = sorted(k for k in set(got) | set(want) if got.get(k) != want.get(k))
    assert not changed, f"results changed: {changed}"
