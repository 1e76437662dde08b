"""method = 'vissim' (the tutorial's fixed-step scheme, docs/method.md section 7) on scenes of
more than two bodies (issue 19 item 7): the two-body rules on N bodies and the rows' ends.

- The tutorial's two-body scenes written as three bodies (a far, free third body) give the
  two-body scheme's samples and events: the rules are the same.
- It converges to the exact answer (tests/exact_nbody.py) at order 1 as dt falls, on Newton's
  cradle (input/newtons_cradle.nml) and on a chain of isolated impacts
  (nbody_scenes.bouncing_chain); the event engine is at rounding on both.
- Momentum: impulses between bodies keep it, forces change it by F t.
- What the scheme does not have is refused by name (a compliant stop).
"""

from __future__ import annotations

import numpy as np
import pytest

import impact1d

pytest.importorskip("mpmath", reason="mpmath is needed by tests/exact_nbody.py")

import exact_nbody as nb  # noqa: E402
import nbody_scenes as ns  # noqa: E402
import test_nbody_engine as te  # noqa: E402
import test_nbody_stress as ts  # noqa: E402

DTS = (1e-3, 1e-4, 1e-5)


def exact(scene: dict):
    """The reference's events [(t, kind)] and final state (x then v) as floats."""
    sol = nb.solve(scene)
    final = np.array([float(a) for a in sol.final[0] + sol.final[1]])
    return [(float(e.t), e.kind) for e in sol.events], final


def event_error(run, ref) -> float:
    """max |t_run - t_ref| over the events matched by kind and by order within the kind
    (bench/common.py's measure); every reference event must have its match."""
    by_kind = {}
    for t, kind in run:
        by_kind.setdefault(kind, []).append(t)
    errors = []
    for kind in {k for _, k in ref}:
        want = [t for t, k in ref if k == kind]
        got = by_kind.get(kind, [])
        assert len(got) == len(want), (kind, got, want)
        errors += [abs(a - b) for a, b in zip(got, want)]
    return max(errors)


def order(dts, errors) -> float:
    """Least-squares slope of log error against log dt."""
    return float(np.polyfit(np.log(dts), np.log(errors), 1)[0])


def vissim(scene: impact1d.Scene, dt: float, dt_out: float | None = None):
    return impact1d.simulate(scene, dt=dt, dt_out=dt_out or scene.t_end, method="vissim")


def final_state(res) -> np.ndarray:
    return np.concatenate([res.x[-1], res.v[-1]])


@pytest.mark.parametrize("case", range(1, 7))
def test_two_body_scenes_as_three_bodies_give_the_two_body_scheme(case):
    """The same rules: each tutorial case as three bodies (its walls and slot as records, a
    third body far away) logs the same impacts at the same instants and samples the same
    states as the two-body scheme (to rounding: here, exactly). Case 5 hits both walls in
    one step, where the rule 'a later row of the step sees the velocities the earlier left'
    matters."""
    scene = impact1d.load_scene(te.INPUT / f"case{case}.nml")
    two = vissim(scene, scene.dt, scene.dt_out)
    three = vissim(ts.as_three(scene), scene.dt, scene.dt_out)
    assert list(three.events["kind"]) == list(two.events["kind"])
    assert np.max(np.abs(three.events["t"] - two.events["t"]), initial=0.0) <= 1e-12
    for got, want in ((three.x[:, 0], two.x1), (three.x[:, 1], two.x2), (three.v[:, 0], two.v1),
                      (three.v[:, 1], two.v2)):
        assert np.max(np.abs(got - want)) <= 1e-12
    assert three.x[-1, 2] == 1.0e6 and three.v[-1, 2] == 0.0


@pytest.mark.parametrize("name", ["cradle", "chain"])
def test_vissim_converges_at_order_one(name):
    """vissim sees each impact at the first step end past it and applies it with the
    velocities of the step before, so every event time and the final state are off by
    O(dt): the error falls with dt at a fitted order between 0.7 and 1.3, below 10 dt at
    every step, with the reference's impacts in the reference's order per contact. The
    event method is at rounding on the same scenes (dt = 1e-3)."""
    if name == "cradle":
        scene = impact1d.load_scene(te.INPUT / "newtons_cradle.nml")
        ref_events, ref_final = exact(te.reference_scene(scene))
    else:
        chain = ns.bouncing_chain()
        scene = te.engine_scene(chain)
        ref_events, ref_final = exact(chain)
    ref_impacts = [(t, k) for t, k in ref_events if not k.startswith(nb.RESERVED_PREFIXES)]
    event_errors, final_errors = [], []
    for dt in DTS:
        res = vissim(scene, dt)
        run = [(float(t), str(k)) for t, k in zip(res.events["t"], res.events["kind"])]
        assert len(run) == len(ref_impacts)
        event_errors.append(event_error(run, ref_impacts))
        final_errors.append(np.max(np.abs(final_state(res) - ref_final)))
        assert event_errors[-1] < 10 * dt and final_errors[-1] < 10 * dt, (dt, event_errors, final_errors)
    assert 0.7 < order(DTS, event_errors) < 1.3, event_errors
    assert 0.7 < order(DTS, final_errors) < 1.3, final_errors
    res = impact1d.simulate(scene, dt=1e-3, dt_out=scene.t_end)
    assert np.max(np.abs(final_state(res) - ref_final)) < 1e-12


def test_momentum_is_kept_by_impacts_and_changed_by_forces():
    """The bouncing chain without its walls, no friction. Without forces every impulse is
    between two bodies (equal and opposite): the momentum stays P0 to rounding at every
    sample. With constant forces F it is P0 + sum(F) t, but for the scheme's one-step delay:
    an impact takes its ends' velocities from before the step, so the impulse of their
    forces over that step, dt (f_a + f_b), is lost at each impact (O(dt), as the scheme's
    event errors are). Where it should be: the zero-velocity threshold (0.005 m/s by
    default) zeroes a slow body's velocity in what moves it, in the impulses and in the
    output, and so changes the momentum by design; it is set far below every speed here."""
    chain = ns.bouncing_chain(t_end=3.0)
    chain["contacts"] = [c for c in chain["contacts"] if c["a"] != 0]
    p0 = float(np.dot(chain["m"], chain["v"]))
    f = np.array([1.0, -2.0, 0.5, 0.0, 0.25])
    drift = []
    for forces in (0 * f, f):
        for dt in (1e-3, 1e-4):
            scene = te.engine_scene(dict(chain, f=list(forces)), dt=dt, dt_out=1e-2)
            res = impact1d.simulate(scene, method="vissim", zero_vel=1e-9)
            assert res.events.size >= 4
            drift.append(np.max(np.abs(res.v @ np.array(chain["m"]) - (p0 + forces.sum() * res.t))))
            assert drift[-1] <= res.events.size * dt * np.abs(forces).sum() + 1e-12
    assert drift[0] < 1e-12 and drift[1] < 1e-12
    assert 5 < drift[2] / drift[3] < 20      # O(dt)


def test_impulse_between_bodies_and_wall_clamp():
    """One step's collisions by hand: two equal bodies meeting head on at 1 m/s with r = 0.5
    leave at -0.5 and +0.5 m/s from the step they are seen in; body 3 meeting the wall at
    x3 <= 2 is put on it and thrown back at -r v."""
    scene = impact1d.Scene(m=[1.0, 1.0, 2.0], x=[0.0, 1.0, 1.5], v=[1.0, -1.0, 1.0],
                           contacts=[dict(a=1, b=2, d_min=0.0, r_min=0.5, name="meet"),
                                     dict(a=0, b=3, d_max=2.0, r_max=0.25, name="wall"),
                                     dict(a=2, b=3, d_min=-10.0, name="far")],
                           t_end=0.75, dt=1.0 / 64, dt_out=1.0 / 64)
    res = vissim(scene, 1.0 / 64, 1.0 / 64)
    kinds = [str(k) for k in res.events["kind"]]
    times = list(res.events["t"])
    assert kinds == ["meet", "wall"]
    assert times[0] == 0.5 + 1.0 / 64 and times[1] == 0.5 + 1.0 / 64   # both a step late
    i = int(np.searchsorted(res.t, times[0]))
    assert list(res.v[i]) == [-0.5, 0.5, -0.25]
    assert res.x[i, 2] == 2.0


def test_a_compliant_stop_is_refused_by_name():
    scene = impact1d.Scene(m=[1.0] * 3, x=[0.0, 1.0, 2.0], v=[1.0, 0.0, 0.0],
                           contacts=[dict(a=1, b=2, d_min=0.5, k=1.0e4, name="buffer")], t_end=1.0, dt=1e-3)
    with pytest.raises(impact1d.InputError, match="the &contact 'buffer' has k = 10000"):
        impact1d.simulate(scene, method="vissim")


def test_two_body_wall_impact_reports_both_bodies():
    """One rule for every N, the tutorial's log for one and two bodies: a wall's impact in a
    two-body scene reports (v1, v2) before and after, body 2's velocity where the row's ends
    would give the wall's 0 (the N > 2 record: a, b and the ends' velocities)."""
    scene = impact1d.Scene(m1=1.0, m2=2.0, x1=0.5, v1=-1.0, x2=5.0, v2=0.75, x_left=0.0,
                           r_left=0.5, t_end=0.75, dt=1.0 / 64, dt_out=0.25)
    res = vissim(scene, 1.0 / 64, 0.25)
    assert [str(k) for k in res.events["kind"]] == ["left"]
    e = res.events[0]
    assert (e["v1_before"], e["v2_before"], e["v1_after"], e["v2_after"]) == (-1.0, 0.75, 0.5, 0.75)
