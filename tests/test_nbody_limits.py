"""What the N-body engine cannot do yet ends in a clear error, never a crash (the library
never stops; a run that cannot go on is a SimulationError, exit status 2 on the CLI).

A cluster of bodies joined by closed contacts whose rows do not form a path is solved
densely (docs/method.md section 9): past impact1d_body_mode's max_dense_unknowns (10,000:
rows + 2 per body) the run says so instead of allocating matrices the machine does not have
(a 10,000-wagon train with its buffers touching needed 28.8 GB and ended in gfortran's
allocation failure). Such a train is a path and no longer meets the limit
(impact1d_path_mode); a train of rigid couplers (two closed rows between each pair) still does.
"""

from __future__ import annotations

import subprocess

import pytest

import impact1d
from tools import find_tool

N = 3400          # 3399 rows + 2 x 3400 bodies = 10,199 unknowns: just past the limit


def touching_train(n: int, dt: float = 1e-3, rigid: bool = False) -> impact1d.Scene:
    """n wagons at rest with their buffers touching, with friction, pushed at the back; with
    rigid couplers (d_max = d_min) if rigid."""
    return impact1d.Scene(m=[1.0] * n, x=[float(i) for i in range(n)], mu=[0.01] * n, mus=[0.02] * n,
                          f=[0.0] * (n - 1) + [-1.0], d_min=[1.0] * (n - 1),
                          d_max=[1.0] * (n - 1) if rigid else None, t_end=10 * dt, dt=dt, dt_out=10 * dt)


def train_file(path, rigid: bool) -> None:
    """touching_train(N, rigid=rigid) as a scene file."""
    scene = touching_train(N)
    path.write_text(f"&bodies m = {N}*1.0, mu = {N}*0.01, mus = {N}*0.02 /\n"
                    f"&initial x = {', '.join(str(float(i)) for i in range(N))} /\n"
                    f"&forces f = {N - 1}*0.0, -1.0 /\n&link d_min = {N - 1}*1.0"
                    + (f", d_max = {N - 1}*1.0 /\n" if rigid else " /\n")
                    + f"&run t_end = {scene.t_end!r}, dt = {scene.dt!r}, dt_out = {scene.t_end!r} /\n")


def test_a_cluster_past_the_dense_limit_is_a_simulation_error():
    with pytest.raises(impact1d.SimulationError, match=r"too large for the dense mode solve"):
        impact1d.simulate(touching_train(N, rigid=True))


def test_the_cli_ends_such_a_run_with_status_2(tmp_path):
    train_file(tmp_path / "train.nml", rigid=True)
    done = subprocess.run([find_tool("impact1d"), str(tmp_path / "train.nml"), "-o", str(tmp_path / "t.dat")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "too large for the dense mode solve" in done.stderr


def test_a_train_past_the_dense_limit_runs_as_a_path(tmp_path):
    """The same train with buffers only (one closed row between neighbours: a path) runs:
    the push at its back (1 N) is held by the static friction of the last six wagons
    (0.196 N each), so no wagon moves."""
    train_file(tmp_path / "train.nml", rigid=False)
    done = subprocess.run([find_tool("impact1d"), str(tmp_path / "train.nml"), "-o", str(tmp_path / "t.dat")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rows = [line.split() for line in (tmp_path / "t.dat").read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    assert len(rows) == 2
    x_start = [float(v) for v in rows[0][1:2 * N + 1:2]]
    x_end = [float(v) for v in rows[-1][1:2 * N + 1:2]]
    assert x_end == x_start
