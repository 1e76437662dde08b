"""Gap of every constraint a scene has, at every sample of a result: shared by the tests
that check no step ends inside a constraint (docs/method.md section 3)."""


def gaps(res, scene):
    """{contact name: gap array} for the constraints present in `scene`."""
    out = {}
    if scene.x_left is not None:
        out["left"] = res.x1 - scene.x_left
    if scene.x_right is not None:
        out["right"] = scene.x_right - res.x2
    if scene.d_min is not None:
        out["slot_min"] = (res.x2 - res.x1) - scene.d_min
    if scene.d_max is not None:
        out["slot_max"] = scene.d_max - (res.x2 - res.x1)
    return out
