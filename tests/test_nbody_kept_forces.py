"""The N-body step keeps a step's end forces for the next step's first stage (issue 19: the
per-step costs; impact1d_nbody_step's kept_forces_type): whatever changes the state or the
mode without a step (an event point) must leave nothing kept in use.

A scene of three bodies (the N-body engine, on its path that keeps the forces: no moving
ground, no compliant stop, no friction law), each on its own: body 1 a damped spring-mass
under a sine force bouncing on a wall (each impact changes its velocity, so its damper's
force), body 2 a block on a spring under a sine force with dry friction (it sticks and
slips: each time the mode changes its acceleration), body 3 free and far away. Each of the
first two run alone is a one-body scene (the two-body engine's once, whose kept force was keyed
on the whole state): the same events, each within 1e-9 s, and samples within 1e-9 (measured
6e-13 m, 4e-12 m/s; with the event point's forgetting left out, 3e-4 m and 3e-3 m/s, and
body 2's stick-slip sequence changed).
"""

from __future__ import annotations

import numpy as np

import impact1d

RUN = dict(t_end=8.0, dt=1e-3, dt_out=1e-2)
WALL = dict(x_left=-0.05, r_left=0.8)
TOL = 1e-9


def test_kept_forces_are_forgotten_at_impacts_and_mode_changes():
    three = impact1d.simulate(impact1d.Scene(
        m=[1.0, 1.0, 1.0], x=[0.0, 10.0, 20.0], v=[0.0, 0.0, 0.0], mu=[0.0, 0.8, 0.0], mus=[0.0, 1.0, 0.0],
        k=[40.0, 100.0, 0.0], x_rest=[0.0, 10.0, 0.0], c=[0.4, 0.0, 0.0], f_amp=[10.0, 20.0, 0.0],
        f_period=[2.4, 1.3, 1.0], **WALL, **RUN))
    oscillator = impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.0, v1=0.0, k1=40.0, x1_rest=0.0, c1=0.4,
                                                  f1_amp=10.0, f1_period=2.4, **WALL, **RUN))
    block = impact1d.simulate(impact1d.Scene(m1=1.0, x1=10.0, v1=0.0, mu1=0.8, mus1=1.0, k1=100.0, x1_rest=10.0,
                                             f1_amp=20.0, f1_period=1.3, **RUN))
    kinds = list(three.events["kind"])
    assert kinds.count("left") >= 10 and kinds.count("stick2") >= 10 and kinds.count("slip2") >= 10
    # Body 1's events are the wall's, body 2's its stick and slip (stick1, slip1 alone).
    for i, alone, own in ((0, oscillator, ("left",)), (1, block, ("stick2", "slip2"))):
        mine = np.isin(three.events["kind"], own)
        assert [kind.replace("2", "1") for kind in three.events["kind"][mine]] == list(alone.events["kind"])
        assert np.max(np.abs(three.events["t"][mine] - alone.events["t"])) < TOL
        assert np.max(np.abs(three.x[:, i] - alone.x[:, 0])) < TOL
        assert np.max(np.abs(three.v[:, i] - alone.v[:, 0])) < TOL


def test_kept_forces_under_constant_forces_are_forgotten_too():
    """Under constant forces (no sine, no table) a slot holds at any time (kept_forces_type's
    timeless: the end's forces serve the next step whatever the clock's rounding), so after
    every event point the first stage would take a stale one were it not forgotten. The same
    three-body comparison with the sines replaced by constant forces: body 1 pressed by its
    spring and a constant force onto the wall, bouncing until it rests there; body 2 a
    block on a spring, launched, its friction turning it round until it sticks."""
    three = impact1d.simulate(impact1d.Scene(
        m=[1.0, 1.0, 1.0], x=[0.0, 10.0, 20.0], v=[-1.5, 3.0, 0.0], mu=[0.0, 0.2, 0.0], mus=[0.0, 0.3, 0.0],
        k=[40.0, 100.0, 0.0], x_rest=[0.0, 10.0, 0.0], c=[0.4, 0.0, 0.0], f=[-1.0, 0.5, 0.0], **WALL, **RUN))
    oscillator = impact1d.simulate(impact1d.Scene(m1=1.0, x1=0.0, v1=-1.5, k1=40.0, x1_rest=0.0, c1=0.4, f1=-1.0,
                                                  **WALL, **RUN))
    block = impact1d.simulate(impact1d.Scene(m1=1.0, x1=10.0, v1=3.0, mu1=0.2, mus1=0.3, k1=100.0, x1_rest=10.0,
                                             f1=0.5, **RUN))
    kinds = list(three.events["kind"])
    assert kinds.count("left") >= 5 and kinds.count("stick2") == 1
    # (body 2 turns round at each of its stops, an event point that logs nothing, then sticks)
    turning = np.sign(three.v[:, 1])
    turning = turning[turning != 0]
    assert np.count_nonzero(turning[1:] != turning[:-1]) >= 5
    for i, alone, own in ((0, oscillator, ("left",)), (1, block, ("stick2",))):
        mine = np.isin(three.events["kind"], own)
        assert [kind.replace("2", "1") for kind in three.events["kind"][mine]] == list(alone.events["kind"])
        assert np.max(np.abs(three.events["t"][mine] - alone.events["t"])) < TOL
        assert np.max(np.abs(three.x[:, i] - alone.x[:, 0])) < TOL
        assert np.max(np.abs(three.v[:, i] - alone.v[:, 0])) < TOL
