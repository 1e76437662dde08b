"""The N-body event point's work scoped to what an event touches (issue 20 item 3,
docs/nbody-plan.md section 5) gives the numbers of the solves over all N bodies.

Without moving grounds the engine solves the mode of a frictionless scene cluster by cluster
(impact1d_nbody_event's scoped_mode: only the clusters of candidate rows, every other body
alone) and a closed row's free gap acceleration from its ends' clusters alone
(scoped_gap_acceleration). A `ground_v = 0` on the first record sends the same scene
through the solves over all bodies (moving grounds keep them), whose numbers these must be
exactly: same events, same samples, bit for bit. Scenes: a stack of five balls of mixed
restitution dropped on a floor (clusters close, rest, release, bounce series settle), and
five blocks with friction pushed onto a wall (the mode over all, the free gap acceleration
scoped: break-aways, sticks, rests among frictional blocks).
"""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np
import pytest

import impact1d

STACK = """&scene   title = 'a stack of five balls of mixed restitution' /
&bodies  m = 4.0, 2.0, 1.0, 0.5, 0.25,  g = 9.81 /
&initial x = 1.0, 1.375, 1.75, 2.2, 2.9, v = 0.0, 0.5, -1.0, 0.0, -2.0 /
&forces  f = -39.24, -19.62, -9.81, -4.905, -2.4525 /
&contact a = 0, b = 1, d_min = 0.0625, r_min = 0.5, name = 'floor' /
&contact a = 1, b = 2, d_min = 0.125, r_min = 0.0, name = 'b12' /
&contact a = 2, b = 3, d_min = 0.125, r_min = 0.8, name = 'b23' /
&contact a = 3, b = 4, d_min = 0.125, r_min = 1.0, name = 'b34' /
&contact a = 4, b = 5, d_min = 0.125, r_min = 0.3, name = 'b45' /
&run     t_end = 3.0, dt = 1.0e-3, dt_out = 1.0e-2 /
"""

BLOCKS = """&scene   title = 'five blocks with friction pushed onto a wall' /
&bodies  m = 1.0, 2.0, 1.0, 3.0, 1.0, mu = 0.1, 0.2, 0.0, 0.1, 0.3, mus = 0.2, 0.3, 0.1, 0.15, 0.4,
         g = 9.81 /
&initial x = 0.5, 1.0, 1.6, 2.0, 2.8, v = 0.0, -0.5, 1.0, 0.0, -2.0 /
&forces  f = 0.0, 0.0, 0.0, 0.0, -12.0 /
&contact a = 0, b = 1, d_min = 0.25, r_min = 0.6, name = 'wall' /
&link    d_min = 4*0.25, r_min = 0.9, 0.0, 0.7, 1.0 /
&run     t_end = 3.0, dt = 1.0e-3, dt_out = 1.0e-2 /
"""


@pytest.mark.parametrize("text, kinds", [(STACK, ("rest_b23", "release_b23", "rest_b12", "b45")),
                                         (BLOCKS, ("stick2", "rest_link2", "release_link3", "wall"))],
                         ids=["stack", "blocks"])
def test_scoped_event_points_are_the_solves_over_all_bodies(tmp_path, text, kinds):
    path = tmp_path / "scene.nml"
    path.write_text(text)
    scene = impact1d.load_scene(str(path))
    scoped = impact1d.simulate(scene)
    contacts = [dict(c) for c in scene.contacts]
    contacts[0]["ground_v"] = 0.0
    everything = impact1d.simulate(dataclasses.replace(scene, contacts=contacts))
    # (the scenes do what they are here for: clusters that rest and release, sticks)
    seen = Counter(str(k) for k in scoped.events["kind"])
    assert all(seen[k] > 0 for k in kinds), seen
    assert len(scoped.events) > 1000
    assert list(scoped.events["kind"]) == list(everything.events["kind"])
    for name in scoped.events.dtype.names:
        assert np.array_equal(scoped.events[name], everything.events[name]), name
    assert np.array_equal(scoped.x, everything.x)
    assert np.array_equal(scoped.v, everything.v)
