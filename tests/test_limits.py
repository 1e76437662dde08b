"""Overflow is an error, never a result; work limits stop only runs that stop advancing
(issue 13, items 6 and 9)."""

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

import impact1d
from tools import find_tool

ROOT = Path(__file__).resolve().parents[1]
CASE3 = ROOT / "input" / "case3.nml"
RUN_TIMEOUT = 120


@pytest.mark.parametrize("v1", [1e300, 1e160], ids=["state-huge", "ke-overflows"])
def test_overflowing_kinetic_energy_is_a_simulation_error(v1):
    # 1e160 is a finite velocity whose square is not: KE = inf, residual NaN.
    with pytest.raises(impact1d.SimulationError, match=r"at t = 0\.0: the kinetic energy"):
        impact1d.simulate(impact1d.load_scene(CASE3), v1=v1)


def test_overflow_under_vissim_too():
    with pytest.raises(impact1d.SimulationError, match="no longer finite"):
        impact1d.simulate(impact1d.load_scene(CASE3), v1=1e160, method="vissim")


def test_overflow_cli_exit_2_and_nothing_written(tmp_path):
    scene = tmp_path / "huge.nml"
    scene.write_text(CASE3.read_text().replace("v1 = -9.0", "v1 = 1e300"))
    done = subprocess.run([find_tool("impact1d"), str(scene), "-o", str(tmp_path / "o.dat")],
                          capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert done.returncode == 2 and "no longer finite" in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["huge.nml"]


def test_step_below_the_clock_resolution_is_refused():
    with pytest.raises(impact1d.InputError, match="dt = .* below the clock's resolution"):
        impact1d.simulate(impact1d.load_scene(CASE3), dt=1e-320)
    # The smallest accepted step is a few ulps of t_end (t_end = 6: spacing 8.9e-16).
    with pytest.raises(impact1d.InputError):
        impact1d.simulate(impact1d.load_scene(CASE3), dt=2e-15)


def test_many_events_are_fine():
    """Case 3 shrunk 1000 times (events 1000 times as frequent): 2.4 million elastic impacts
    in 320 s, more than the 2e6 that used to stop the run, with KE kept."""
    scene = impact1d.Scene(m1=1.0, m2=2.0, x_left=0.0, r_left=1.0, x_right=0.01, r_right=1.0,
                           d_min=0.001, r_min=1.0, d_max=0.002, r_max=1.0,
                           x1=0.001, v1=-9.0, x2=0.0025, v2=1.0, t_end=320.0, dt=1e-3, dt_out=1.0)
    res = impact1d.simulate(scene)
    assert len(res.events) > 2_000_000
    assert res.t[-1] == 320.0
    # 2.4e6 impacts each rounding KE by ~1 ulp of 41.5 J: a random walk far below 1e-9 J.
    assert abs(res.ke[-1] - 41.5) < 1e-9
    assert np.all(np.isfinite(res.ke))


def test_work_limits_are_run_options():
    """Every remaining cap is a &run option, named in its message."""
    case3 = impact1d.load_scene(CASE3)
    with pytest.raises(impact1d.InputError, match=r"max_rows"):
        impact1d.simulate(case3, max_rows=100)          # 6001 rows asked for
    assert len(impact1d.simulate(case3, max_rows=6001).t) == 6001
    # The pinned elastic chain of a light body between a wall and a heavy one needs about
    # pi sqrt(M/m) = 315 impulses at one instant for M/m = 10^4.
    chain = impact1d.Scene(m1=1.0, m2=1e4, x_left=0.0, r_left=1.0, d_min=1.0, r_min=1.0,
                           x1=0.0, x2=1.0, v2=-1.0, t_end=0.1, dt=1e-3)
    assert len(impact1d.simulate(chain).events) > 300
    with pytest.raises(impact1d.SimulationError, match=r"after 100 impulses .*raise &run max_impulses\)"):
        impact1d.simulate(chain, max_impulses=100)
    shrunk = dict(x_right=0.01, d_min=0.001, d_max=0.002, x1=0.001, x2=0.0025, t_end=1.0)
    with pytest.raises(impact1d.SimulationError, match=r"more than 3 events within one step .*max_step_events"):
        impact1d.simulate(case3, max_step_events=3, **shrunk)
    for bad in (0, 2.5, -1, 1e300):
        with pytest.raises(impact1d.InputError, match="max_impulses .* must be a whole number"):
            impact1d.simulate(case3, max_impulses=bad)
