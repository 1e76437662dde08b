"""The example scenes of issue 19 item 8 that have no other test (input/gear_train.nml,
input/burridge_knopoff.nml), held to closed forms where they have one."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

import impact1d

INPUT = Path(__file__).resolve().parent.parent / "input"
EVENT_TIME_TOL = 1e-9     # s: every event time (tests/test_reference.py's)


def load(name: str) -> impact1d.Scene:
    cwd = os.getcwd()
    os.chdir(INPUT.parent)     # (a scene names its tables from the project's root)
    try:
        return impact1d.load_scene(f"input/{name}")
    finally:
        os.chdir(cwd)


def events(res) -> list:
    return [(float(t), str(k)) for t, k in zip(res.events["t"], res.events["kind"])]


def gear_train_first_impacts(J, T, load, gap, r):
    """The gear train's first two impacts, from rest, every mesh centred in its backlash
    (half-width gap), torque T on shaft 1 and -load on shaft 3, restitution r.

    Shaft 1 turns alone at T / J1 and takes up mesh 1 when x1 = gap:
    t1 = sqrt(2 gap J1 / T), at v1 = T t1 / J1. Newton's impulse on x2 - x1 with r (shaft
    2 at rest): P = (1 + r) v1 / (1 / J1 + 1 / J2), v1' = v1 - P / J1, v2' = P / J2.
    Meanwhile the braked shaft 3 turns back, x3 = -load t^2 / (2 J3). After t1, with
    s = t - t1, mesh 2's gap (x3 - x2) - (-gap) = gap - v2' s - load (t1 + s)^2 / (2 J3)
    closes at the positive root of (load / (2 J3)) s^2 + (v2' + load t1 / J3) s +
    (load t1^2 / (2 J3) - gap) = 0, provided mesh 1 does not close again first: its gap
    (v2' - v1') s - T s^2 / (2 J1) is back to 0 at s1 = 2 J1 (v2' - v1') / T (checked)."""
    j1, j2, j3 = J
    t1 = math.sqrt(2 * gap * j1 / T)
    v1 = T * t1 / j1
    p = (1 + r) * v1 / (1 / j1 + 1 / j2)
    v1_after, v2_after = v1 - p / j1, p / j2
    a, b, c = load / (2 * j3), v2_after + load * t1 / j3, load * t1 ** 2 / (2 * j3) - gap
    s = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    assert s < 2 * j1 * (v2_after - v1_after) / T
    return t1, t1 + s


def test_gear_train_takes_up_the_backlash_mesh_by_mesh():
    """The first two impacts in closed form (0.1 s and 0.1 + 0.0381 s); then the meshes
    rattle on their drive flanks and settle (both rest), and the train turns as one at
    (T - load) / (J1 + J2 + J3), its shafts' velocities equal at t_end."""
    scene = load("gear_train.nml")
    assert scene.title == "Gear train: backlash taken up at two meshes under a drive torque"
    t1, t2 = gear_train_first_impacts(scene.m, scene.f[0], -scene.f[2], -scene.d_min[0], scene.r_min[0])
    assert t1 == pytest.approx(0.1, abs=1e-15) and t2 == pytest.approx(0.13808315196468, abs=1e-13)
    res = impact1d.simulate(scene)
    log = events(res)
    assert [k for _, k in log[:2]] == ["link1_min", "link2_min"]
    assert abs(log[0][0] - t1) < EVENT_TIME_TOL and abs(log[1][0] - t2) < EVENT_TIME_TOL
    kinds = [k for _, k in log]
    assert "rest_link1_min" in kinds and "rest_link2_min" in kinds
    assert not any(k.endswith("_max") for k in kinds)        # never on the coast flank
    a = (scene.f[0] + scene.f[2]) / sum(scene.m)
    v = res.v[-1]
    assert np.max(np.abs(v - v[0])) < 1e-12
    # the velocity gained after the rest at t_rest, at the common acceleration
    t_rest = max(t for t, k in log if k.startswith("rest_"))
    i = int(np.searchsorted(res.t, t_rest, side="right"))
    assert np.allclose(np.diff(res.v[i:, 0]) / np.diff(res.t[i:]), a, rtol=1e-9, atol=0)
    assert abs(res.energy_residual) < 1e-9


def test_burridge_knopoff_first_break_away_is_the_weakest_block():
    """From rest every spring is at its rest length, so each block feels only its leaf
    spring's pull k V t (its anchor moves at V: ground_v) and the first to break away is the
    block with the least static bound, when k V t = mus_i m g: block 3 (mus = 0.45) at
    t = 0.45 * 9.81 / (4 * 0.25) = 4.4145 s. Its slip then loads its neighbours; every block
    slips and sticks again. The ledger closes with the driver's work (drive_work), which
    the forces' work no longer stands in for (the old force ramp booked ~1100 J of work)."""
    scene = load("burridge_knopoff.nml")
    assert scene.title.startswith("Burridge-Knopoff chain")
    leaves = [r for r in scene.springs if r.get("ground_v")]
    assert len(leaves) == 10 and len({(r["k"], r["ground_v"]) for r in leaves}) == 1
    k, v_drive = leaves[0]["k"], leaves[0]["ground_v"]
    weakest = int(np.argmin(scene.mus))
    t_break = scene.mus[weakest] * scene.m[weakest] * scene.g / (k * v_drive)
    assert t_break == pytest.approx(4.4145, abs=1e-14)
    res = impact1d.simulate(scene)
    log = events(res)
    assert log[0][1] == f"slip{weakest + 1}" and abs(log[0][0] - t_break) < EVENT_TIME_TOL
    kinds = {kind for _, kind in log}
    assert {f"slip{i}" for i in range(1, 11)} <= kinds and {f"stick{i}" for i in range(1, 11)} <= kinds
    assert abs(res.energy_residual) < 1e-6
    assert np.all(res.work == 0.0) and res.drive_work[-1] > 0.0