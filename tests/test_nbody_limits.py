"""What the N-body engine cannot do yet ends in a clear error, never a crash (the library
never stops; a run that cannot go on is a SimulationError, exit status 2 on the CLI).

A cluster of bodies joined by closed contacts is solved densely (docs/method.md section 9):
past impact1d_body_mode's max_dense_unknowns (10,000: rows + 2 per body) the run says so
instead of allocating matrices the machine does not have (a 10,000-wagon train with its
buffers touching needed 28.8 GB and ended in gfortran's allocation failure).
"""

from __future__ import annotations

import subprocess

import pytest

import impact1d
from tools import find_tool

N = 3400          # 3399 rows + 2 x 3400 bodies = 10,199 unknowns: just past the limit


def touching_train(n: int, dt: float = 1e-3) -> impact1d.Scene:
    """n wagons at rest with their buffers touching, with friction, pushed at the back."""
    return impact1d.Scene(m=[1.0] * n, x=[float(i) for i in range(n)], mu=[0.01] * n, mus=[0.02] * n,
                          f=[0.0] * (n - 1) + [-1.0], d_min=[1.0] * (n - 1), t_end=10 * dt, dt=dt,
                          dt_out=10 * dt)


def test_a_cluster_past_the_dense_limit_is_a_simulation_error():
    with pytest.raises(impact1d.SimulationError, match=r"too large for the dense mode solve"):
        impact1d.simulate(touching_train(N))


def test_the_cli_ends_such_a_run_with_status_2(tmp_path):
    scene = touching_train(N)
    path = tmp_path / "train.nml"
    path.write_text(f"&bodies m = {N}*1.0, mu = {N}*0.01, mus = {N}*0.02 /\n"
                    f"&initial x = {', '.join(str(float(i)) for i in range(N))} /\n"
                    f"&forces f = {N - 1}*0.0, -1.0 /\n&link d_min = {N - 1}*1.0 /\n"
                    f"&run t_end = {scene.t_end!r}, dt = {scene.dt!r} /\n")
    done = subprocess.run([find_tool("impact1d"), str(path), "-o", str(tmp_path / "t.dat")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "too large for the dense mode solve" in done.stderr
