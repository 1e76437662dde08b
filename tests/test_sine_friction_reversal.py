"""A block sliding under a sine force and Coulomb friction (no stops), against its exact
motion: on a still ground and with `ground_v = 0` on a record (the moving-ground path; the
two engines these were before issue 19's one engine).

Body 2 (m = 2 kg, mu = 0.1, g = 9.81) is pushed by F sin(w t), F = 10 N, w = 2 pi / 0.7;
body 1 stays stuck (nothing pushes it) and the buffer between them never closes. Between
events the block is a sine-forced mass under the constant friction -s mu m g of its
sliding direction s, so

    v(t) = v0 + F / (m w) (cos w t0 - cos w t) - s mu g (t - t0)
    x(t) = x0 + v0 (t - t0) + F / (m w) (cos w t0 (t - t0) - (sin w t - sin w t0) / w)
           - s mu g (t - t0)^2 / 2

from its break-away t0 = asin(mu m g / F) / w on; each reversal (v = 0 again, with
|F sin w t| > mu m g there, so it slides on the other way) is a root of v: mpmath's
findroot at 50 digits. The engines locate the reversal on the step's Hermite cubic and
polish it by Newton's method on their own RK4 state; the cubic's root may fall before the
exact one (the cubic's velocity is the motion's to O(h^3)), so Newton must be free to go
past it within the step taken. Stopped at the cubic's root instead, the block reversed
~2e-10 s early at about half the reversals, its velocity off by a |a| there (7e-10 m/s),
its position by 7e-10 m at 5 s; the two engines, whose cubics differ in their last bits,
erred at different reversals (1.2e-9 m apart at 5 s).
"""

from __future__ import annotations

import numpy as np
import pytest

import impact1d

mp = pytest.importorskip("mpmath", reason="the reference needs mpmath")

M, F, PERIOD, MU, G, X0 = 2, 10, "0.7", "0.1", "9.81", "1.5"
T_END = 5
# Between reversals RK4's quadrature of the sine keeps the positions to ~1e-12 m (measured:
# 1.1e-12 before the second reversal); a reversal taken 2e-10 s early costs 7e-10 m.
POSITION_TOL = 1e-11
VELOCITY_TOL = 1e-11


def scene(n_body_engine: bool) -> impact1d.Scene:
    wall = dict(a=0, b=1, d_min=0.0, name="wall")
    if n_body_engine:
        wall["ground_v"] = 0.0
    return impact1d.Scene(m1=1, m2=M, x1=0.5, x2=float(X0), mu1=0.2, mu2=float(MU), g=float(G), f2_amp=F,
                          f2_period=float(PERIOD), d_min=-1e9, t_end=T_END, dt=1e-3,
                          contacts=[dict(a=1, b=2, d_min=0.6, name="buffer"), wall])


class Reference:
    """The block's exact motion: pieces (t0, x0, v0, s) from its break-away to T_END."""

    def __init__(self):
        mp.mp.dps = 50
        self.m, self.f, self.w = mp.mpf(M), mp.mpf(F), 2 * mp.pi / mp.mpf(PERIOD)
        self.c = mp.mpf(MU) * mp.mpf(G)
        t = mp.asin(self.c * self.m / self.f) / self.w
        self.pieces = [(mp.mpf(0), mp.mpf(X0), mp.mpf(0), 0)]
        x, v, s = mp.mpf(X0), mp.mpf(0), 1
        self.reversals = []
        while t < T_END:
            self.pieces.append((t, x, v, s))
            piece = self.pieces[-1]
            # The next zero of v: bracketed on a 1 ms grid, then polished.
            h = mp.mpf("1e-3")
            b = t + h
            while s * self.velocity(b, piece) > 0:
                b += h
            t = mp.findroot(lambda tau: self.velocity(tau, piece), (b - h, b), solver="anderson")
            x = self.position(t, piece)
            force = self.f * mp.sin(self.w * t)
            assert abs(force) > self.c * self.m       # it slides on: no sticking in this scene
            s = 1 if force > 0 else -1
            self.reversals.append(t)

    def piece(self, tau):
        return next(p for p in reversed(self.pieces) if p[0] <= tau)

    def velocity(self, tau, piece=None):
        t0, x0, v0, s = piece or self.piece(tau)
        if s == 0:
            return v0
        return v0 + self.f / (self.m * self.w) * (mp.cos(self.w * t0) - mp.cos(self.w * tau)) - s * self.c * (tau - t0)

    def position(self, tau, piece=None):
        t0, x0, v0, s = piece or self.piece(tau)
        if s == 0:
            return x0
        d = tau - t0
        return x0 + v0 * d + self.f / (self.m * self.w) * (mp.cos(self.w * t0) * d - (mp.sin(self.w * tau) -
                                                                                  mp.sin(self.w * t0)) / self.w) \
            - s * self.c * d ** 2 / 2


@pytest.fixture(scope="module")
def reference():
    return Reference()


@pytest.mark.parametrize("n_body_engine", [False, True], ids=["two-body", "n-body"])
def test_sliding_block_reverses_at_the_exact_instants(reference, n_body_engine):
    """Positions and velocities at every 10th sample, across the 13 reversals, agree with the
    exact motion; the slip is logged at its exact instant."""
    res = impact1d.simulate(scene(n_body_engine))
    assert sum(t < T_END for t in reference.reversals) == 13
    assert [str(k) for k in res.events["kind"]] == ["slip2"]
    assert abs(res.events["t"][0] - float(reference.pieces[1][0])) < 1e-15
    samples = np.arange(0, len(res.t), 10)
    x = np.array([float(reference.position(mp.mpf(float(res.t[k])))) for k in samples])
    v = np.array([float(reference.velocity(mp.mpf(float(res.t[k])))) for k in samples])
    np.testing.assert_allclose(res.x[samples, 1], x, rtol=0, atol=POSITION_TOL)
    np.testing.assert_allclose(res.v[samples, 1], v, rtol=0, atol=VELOCITY_TOL)
    assert np.all(res.x[:, 0] == 0.5)


def test_engines_agree_on_the_sliding_block():
    a = impact1d.simulate(scene(False))
    b = impact1d.simulate(scene(True))
    np.testing.assert_allclose(b.x, a.x, rtol=0, atol=2 * POSITION_TOL)
    np.testing.assert_allclose(b.v, a.v, rtol=0, atol=2 * VELOCITY_TOL)
