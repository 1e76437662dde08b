"""bench/cvode_peer.c: the CVODE event-restart loop models the scenes it is compared on.

The CVODE peer (bench/cvode_peer.py, `make bench`) times this program against impact1d;
its numbers mean something only if it computes the same motion. Checked against the
closed form of tests/exact_reference.py on case 3 (41 impacts: walls and slot, elastic)
and on case 5's first impacts (both walls at once, r = 0.5). Needs SUNDIALS' headers
(libsundials-dev) and a C compiler; skipped without them.
"""

import json
import shutil
import subprocess
from pathlib import Path

import pytest

import impact1d
from exact_reference import simulate_exact

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "bench" / "cvode_peer.c"
CC = shutil.which("cc")

pytestmark = pytest.mark.skipif(
    CC is None or not Path("/usr/include/cvode/cvode.h").exists(),
    reason="needs a C compiler and SUNDIALS CVODE (libsundials-dev)")


@pytest.fixture(scope="module")
def peer(tmp_path_factory):
    exe = tmp_path_factory.mktemp("cvode") / "cvode_peer"
    subprocess.run([CC, "-O2", "-o", str(exe), str(SOURCE), "-lsundials_cvode",
                    "-lsundials_nvecserial", "-lm"], check=True)
    return exe


def run_peer(exe, scene, rtol=1e-10):
    fields = ("m1", "m2", "f1", "f2", "x1", "v1", "x2", "v2", "x_left", "r_left", "x_right",
              "r_right", "d_min", "r_min", "d_max", "r_max", "t_end")
    args = [f"{name}={float(getattr(scene, name) or 0.0)!r}" for name in fields]
    out = subprocess.run([str(exe), *args, f"rtol={rtol!r}", f"atol={rtol * 1e-3!r}"],
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def test_case3_events_and_final_state_match_the_closed_form(peer):
    scene = impact1d.load_scene(ROOT / "input" / "case3.nml")
    events, segments = simulate_exact(scene)
    res = run_peer(peer, scene)
    assert res["stop_reason"] == "t_end reached"
    assert [k for _, k in res["events"]] == [kind for _, kind, *_ in events]
    assert len(res["events"]) == 41
    errors = [abs(t - t_exact) for (t, _), (t_exact, *_) in zip(res["events"], events)]
    assert max(errors) < 1e-10
    final = segments[-1][1:]
    assert max(abs(a - float(b)) for a, b in zip(res["final"], final)) < 1e-9


def test_case5_simultaneous_wall_impacts_before_the_accumulation(peer):
    # Both bodies 1 m from their walls, pushed at 2 m/s^2, r = 0.5: impact n on each wall
    # at t_n = 3 - 2^(2-n) (1, 2, 2.5, ...), both walls at once.
    scene = impact1d.load_scene(ROOT / "input" / "case5.nml")
    res = run_peer(peer, scene)
    for wall in ("left", "right"):
        times = [t for t, k in res["events"] if k == wall][:5]
        assert times == pytest.approx([1.0, 2.0, 2.5, 2.75, 2.875], abs=1e-11)
