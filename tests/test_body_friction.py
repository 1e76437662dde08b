"""Friction between two bodies (issue 21 item 2; DESIGN "Laws added on the records"): the
repeatable record `&friction a = 1, b = 2, mu = 0.3, mus = 0.4, normal = 9.81 /`, a friction
contact between bodies a and b pressed together by a given constant normal load N, acting on
their relative velocity u = v_b - v_a. It runs on the N-body engine, whatever N.

(a) Two blocks sliding on each other, closed form. The lower block (mass m1) lies on a
    frictionless ground at rest, the upper one (m2) is launched on it at v0 > 0. While they
    slide (u > 0) the contact pushes the upper block back with F = mu N and the lower one
    forward with F, and nothing else acts:
        x1 = F t^2 / (2 m1),        v1 = F t / m1,
        x2 = v0 t - F t^2 / (2 m2), v2 = v0 - F t / m2,
    so u = v0 - F t (1/m1 + 1/m2) reaches 0 at t* = v0 / (F (1/m1 + 1/m2)). Friction's loss is
    F times the distance slid, F (v0 t - F t^2 (1/m1 + 1/m2) / 2), which is the kinetic energy
    lost: the ledger closes. Constant forces: RK4 is exact, at dt = 1e-3 and at a coarse dt.
"""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

import impact1d
import tools

M1, M2, MU, MUS, G, V0 = 2.0, 1.0, 0.3, 0.4, 9.81, 1.0
NORMAL = M2 * G
F = MU * NORMAL
T_STAR = V0 / (F * (1.0 / M1 + 1.0 / M2))


def sliding_blocks(dt, t_end, **extra):
    """The two blocks of (a), the friction record named 'pad'."""
    return impact1d.Scene(m=[M1, M2], x=[0.0, 0.0], v=[0.0, V0], t_end=t_end, dt=dt,
                          frictions=[{"a": 1, "b": 2, "mu": MU, "mus": MUS, "normal": NORMAL, "name": "pad"}],
                          **extra)


@pytest.mark.parametrize("dt", [1e-3, 0.05])
def test_blocks_sliding_on_each_other_have_the_closed_form(dt):
    r = impact1d.simulate(sliding_blocks(dt, 0.9 * T_STAR))
    t = r.t
    scale = 1e-15 * (1 + V0 * T_STAR)
    np.testing.assert_allclose(r.x1, F * t**2 / (2 * M1), rtol=0, atol=scale)
    np.testing.assert_allclose(r.v1, F * t / M1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.x2, V0 * t - F * t**2 / (2 * M2), rtol=0, atol=scale)
    np.testing.assert_allclose(r.v2, V0 - F * t / M2, rtol=0, atol=1e-15)
    slid = V0 * t - F * t**2 * (1.0 / M1 + 1.0 / M2) / 2
    np.testing.assert_allclose(r.friction_loss, F * slid, rtol=0, atol=1e-14)
    assert np.max(np.abs(r.residual)) < 1e-14
    assert len(r.events) == 0


def test_the_contact_acts_on_its_two_bodies_only():
    """A third body (free, apart) keeps its velocity; the pair as in (a) whatever N, and the
    record's ends may be given either way round (the force acts on u = v_b - v_a)."""
    for frictions, order in (([{"a": 1, "b": 2, "mu": MU, "normal": NORMAL}], (0, 1)),
                             ([{"a": 2, "b": 1, "mu": MU, "normal": NORMAL}], (0, 1))):
        scene = impact1d.Scene(m=[M1, M2, 1.5], x=[0.0, 0.0, 5.0], v=[0.0, V0, 0.25], t_end=0.9 * T_STAR,
                               dt=1e-3, frictions=frictions)
        r = impact1d.simulate(scene)
        t = r.t[-1]
        assert r.x[-1][2] == pytest.approx(5.0 + 0.25 * t, abs=1e-15)
        assert r.v[-1][order[0]] == pytest.approx(F * t / M1, abs=1e-15)
        assert r.v[-1][order[1]] == pytest.approx(V0 - F * t / M2, abs=1e-15)


def test_relative_rest_is_located_and_stick_not_yet_run():
    """The relative velocity reaches 0 at t* (located as a body's stop is); the stick there is
    not solved yet, and the run says so (SimulationError, naming the contact)."""
    for dt in (1e-3, 0.05):
        with pytest.raises(impact1d.SimulationError, match="friction contact 'pad' come to relative rest") as info:
            impact1d.simulate(sliding_blocks(dt, 2 * T_STAR))
        t = float(str(info.value).split("at t = ")[1].split(":")[0])
        assert t == pytest.approx(T_STAR, abs=1e-15)


def test_scene_file_cli_header_and_read_output_carry_the_record(tmp_path):
    nml = tmp_path / "blocks.nml"
    nml.write_text("&bodies m = 2.0, 1.0 /\n&initial x = 0.0, 0.0, v = 0.0, 1.0 /\n"
                   "&friction a = 1, b = 2, mu = 0.3, mus = 0.4, normal = 9.81, name = 'pad' /\n"
                   "&run t_end = 0.2, dt = 1e-3 /\n")
    scene = impact1d.load_scene(str(nml))
    assert scene.frictions == [{"a": 1, "b": 2, "mu": 0.3, "mus": 0.4, "normal": 9.81, "name": "pad"}]
    out = tmp_path / "blocks.dat"
    subprocess.run([tools.find_tool("impact1d"), str(nml), "-o", str(out)], check=True, capture_output=True)
    header = out.read_text()
    assert "# friction.1.normal = 9.81" in header and "# friction.1.name = pad" in header
    back = impact1d.read_output(str(out))
    assert back.scene.frictions == scene.frictions
    mine = impact1d.simulate(scene)
    assert np.array_equal(back.x2, mine.x2) and np.array_equal(back.v1, mine.v1)


def test_unnamed_record_takes_its_place_as_name():
    scene = sliding_blocks(1e-3, 2 * T_STAR)
    scene.frictions = [{"a": 1, "b": 2, "mu": MU, "normal": NORMAL}]
    with pytest.raises(impact1d.SimulationError, match="'friction1'"):
        impact1d.simulate(scene)


@pytest.mark.parametrize("record, words", [
    ({"a": 0, "b": 2, "mu": 0.3, "normal": 1.0}, "a = 0 is the ground"),
    ({"a": 1, "b": 1, "mu": 0.3, "normal": 1.0}, "between two different bodies"),
    ({"a": 1, "b": 3, "mu": 0.3, "normal": 1.0}, "b = 3.0 is not a body"),
    ({"a": 1, "b": 2, "normal": 1.0}, "mu is required but not given"),
    ({"a": 1, "b": 2, "mu": 0.3}, "normal is required but not given"),
    ({"a": 1, "b": 2, "mu": -0.3, "normal": 1.0}, "mu = -0.3 must not be negative"),
    ({"a": 1, "b": 2, "mu": 0.3, "normal": -1.0}, "normal = -1.0 must not be negative"),
    ({"a": 1, "b": 2, "mu": 0.3, "mus": 0.2, "normal": 1.0}, "mus = 0.2 is below mu = 0.3"),
    ({"a": 1, "b": 2, "mu": 0.3, "normal": math.inf}, "normal = Inf is not a finite number"),
])
def test_friction_record_inputs_are_checked(record, words):
    scene = impact1d.Scene(m=[M1, M2], x=[0.0, 0.0], v=[0.0, V0], t_end=0.1, dt=1e-3, frictions=[record])
    with pytest.raises(impact1d.InputError, match=words.replace("(", r"\(").replace(")", r"\)")):
        impact1d.simulate(scene)


def test_vissim_and_compliant_stops_refuse_the_record():
    with pytest.raises(impact1d.InputError, match="friction between two bodies"):
        impact1d.simulate(sliding_blocks(1e-3, 0.1, method="vissim"))
    with pytest.raises(impact1d.InputError, match="cannot be combined with &friction records"):
        impact1d.simulate(sliding_blocks(1e-3, 0.1, contacts=[{"a": 0, "b": 1, "d_min": -1.0, "k": 1e4}]))
