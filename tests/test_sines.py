"""Several sines per force (issue 21 item 5): the repeatable `&sine body, amp, period, phase /`
record (Python: Scene(sines=[{...}])) adds amp sin(2 pi t / period + phase) to body `body`'s
force, beside f, f_table and the body's own f_amp/f_period/f_phase sine.

References are closed forms evaluated with mpmath at 50 digits (derivations in the tests'
docstrings); tolerances come from RK4's error C dt^4, C measured on the coarse runs."""

import subprocess
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import impact1d
from tools import find_tool

mp.mp.dps = 50

# Two incommensurate periods: 0.7 s and 0.7 phi s (phi, the golden ratio, is irrational).
PHI = (1 + mp.sqrt(5)) / 2
M, X0, V0, F0 = 2.0, 0.25, 0.3, 0.5
SINES = ((1.5, 0.7, 0.0), (0.8, 0.7 * float(PHI), 0.4))


def free_flight(t, m, x0, v0, f0, sines):
    """x(t), v(t) of a free body (no friction, no contact) of mass m under the force
    f0 + sum_j A_j sin(w_j t + phi_j), w_j = 2 pi / P_j.

    m v' = f0 + sum_j A_j sin(w_j t + phi_j), v(0) = v0, so
      v(t) = v0 + f0 t / m + sum_j A_j / (m w_j) (cos(phi_j) - cos(w_j t + phi_j)),
    and integrating once more with x(0) = x0 (int_0^t cos(w s + phi) ds = (sin(w t + phi) -
    sin(phi)) / w):
      x(t) = x0 + v0 t + f0 t^2 / (2 m)
             + sum_j A_j / (m w_j^2) (sin(phi_j) + w_j t cos(phi_j) - sin(w_j t + phi_j)).
    Checked: x'' = f/m term by term (d^2/dt^2 of the bracket is w^2 sin(w t + phi)), x(0) =
    x0 (the bracket is 0 at t = 0) and x'(0) = v0 (its derivative w cos(phi) - w cos(phi) is
    0); test_the_closed_form_solves_the_equation integrates the equation with mpmath's
    odefun against it (the sign of each term)."""
    t = mp.mpf(t)
    x = x0 + v0 * t + f0 * t ** 2 / (2 * m)
    v = v0 + f0 * t / m
    for amp, period, phase in sines:
        amp, w, phase = mp.mpf(amp), 2 * mp.pi / mp.mpf(period), mp.mpf(phase)
        x += amp / (m * w ** 2) * (mp.sin(phase) + w * t * mp.cos(phase) - mp.sin(w * t + phase))
        v += amp / (m * w) * (mp.cos(phase) - mp.cos(w * t + phase))
    return x, v


def sine_records(sines, body=1):
    return [{"body": body, "amp": a, "period": p, "phase": ph} for a, p, ph in sines]


def one_body(dt, t_end=5.0, **fields):
    return impact1d.Scene(m1=M, x1=X0, v1=V0, f1=F0, t_end=t_end, dt=dt, dt_out=0.25,
                          sines=sine_records(SINES), **fields)


def test_the_closed_form_solves_the_equation():
    """free_flight against mpmath's Taylor integrator on m x'' = f(t): 25 digits agree, so
    the closed form's signs are right (a wrong sign moves x(5) by more than 0.1)."""
    mp.mp.dps = 30
    try:
        def rhs(t, y):
            f = F0 + sum(mp.mpf(a) * mp.sin(2 * mp.pi * t / mp.mpf(p) + mp.mpf(ph)) for a, p, ph in SINES)
            return [y[1], f / M]
        ode = mp.odefun(rhs, 0, [mp.mpf(X0), mp.mpf(V0)])
        for t in (1, 5):
            x, v = free_flight(t, M, X0, V0, F0, SINES)
            y = ode(t)
            assert abs(y[0] - x) < mp.mpf(10) ** -25 and abs(y[1] - v) < mp.mpf(10) ** -25
    finally:
        mp.mp.dps = 50


def test_free_body_under_two_sines_matches_the_closed_form():
    """A free body under f0 + two &sine terms of incommensurate periods: every sample
    within 3e-12 m (and m/s) of free_flight at dt = 1e-3. RK4's global error is C dt^4
    with C ~ 1.1 m/s^4 here (2.7e-8 m at dt = 0.0125): 1.1e-12 at 1e-3 (measured 1.1e-12)."""
    res = impact1d.simulate(one_body(1e-3))
    exact = [free_flight(t, M, X0, V0, F0, SINES) for t in res.t]
    assert np.abs(res.x1 - [float(x) for x, _ in exact]).max() < 3e-12
    assert np.abs(res.v1 - [float(v) for _, v in exact]).max() < 3e-12
    assert len(res.events) == 0


def test_two_bodies_each_take_their_own_records():
    """Two free bodies (a slot limit far out of reach), the records interleaved in the file
    (body 2, body 1, body 2, body 1): each body follows free_flight under its own records
    only: body 1 within the one-body test's 3e-12 at dt = 1e-3, body 2 (periods 0.3 and
    0.49 s, RK4's error growing as (w dt)^4: measured 9.0e-12) within 2e-11."""
    s2 = ((2.0, 0.3, 1.0), (-0.6, 0.3 * float(PHI), 0.0))
    records = [sine_records(s2[:1], 2)[0], sine_records(SINES[:1])[0],
               sine_records(s2[1:], 2)[0], sine_records(SINES[1:])[0]]
    scene = impact1d.Scene(m1=M, m2=1.5, x1=X0, v1=V0, x2=5.0, v2=-0.5, f1=F0, d_min=-1e9,
                           t_end=5.0, dt=1e-3, dt_out=0.25, sines=records)
    res = impact1d.simulate(scene)
    for x, v, exact, bound in ((res.x1, res.v1, lambda t: free_flight(t, M, X0, V0, F0, SINES), 3e-12),
                               (res.x2, res.v2, lambda t: free_flight(t, 1.5, 5.0, -0.5, 0.0, s2), 2e-11)):
        ref = [exact(t) for t in res.t]
        assert np.abs(x - [float(a) for a, _ in ref]).max() < bound
        assert np.abs(v - [float(b) for _, b in ref]).max() < bound


def test_the_end_state_converges_at_order_four():
    """The end state's error against free_flight at dt = 0.1, 0.05, 0.025, 0.0125 (t = 5 s,
    a whole number of steps each): each halving divides it by 2^p, p within 0.3 of 4
    (measured 3.82, 4.01, 4.00: the first pair is not yet asymptotic)."""
    x_end, _ = free_flight(5.0, M, X0, V0, F0, SINES)
    errors = []
    for dt in (0.1, 0.05, 0.025, 0.0125):
        res = impact1d.simulate(one_body(dt))
        assert res.t[-1] == 5.0
        errors.append(abs(res.x1[-1] - float(x_end)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4.0) < 0.3), orders
    assert errors[-1] < 1e-7


def test_wall_impact_time_under_quasi_periodic_forcing():
    """A right wall at L = 3 m: the first impact is the first root of x(t) = L on the exact
    flight (free_flight until then), found by a scan at 0.01 s and mpmath's findroot at 50
    digits (t* = 3.2099715532817733...). The engine locates it within 2e-12 s at dt = 1e-3
    (measured 5e-13) and within 1e-4 s at the coarse dt = 0.1 (measured 4.4e-5), the
    velocity before impact likewise."""
    L = 3.0
    gap = lambda t: free_flight(t, M, X0, V0, F0, SINES)[0] - L
    grid = [mp.mpf(k) / 100 for k in range(1, 1000)]
    after = next(t for t in grid if gap(t) > 0)
    root = mp.findroot(gap, (after - mp.mpf(1) / 100, after), solver="anderson")
    assert after - mp.mpf(1) / 100 < root < after
    v_root = float(free_flight(root, M, X0, V0, F0, SINES)[1])
    for dt, bound in ((1e-3, 2e-12), (0.1, 1e-4)):
        res = impact1d.simulate(one_body(dt, t_end=4.0, x_right=L, r_right=0.5))
        first = res.events[0]
        assert first["kind"] == "right"
        assert abs(first["t"] - float(root)) < bound
        assert abs(first["v1_before"] - v_root) < 10 * bound
        assert first["v1_after"] == pytest.approx(-0.5 * first["v1_before"], rel=1e-15)


CASE_SINE = dict(m1=1.0, m2=2.0, mu1=0.3, mu2=0.1, g=10.0, x_left=0.0, r_left=0.8, x_right=10.0,
                 r_right=0.9, d_min=1.0, r_min=0.5, d_max=2.0, r_max=0.7, x1=1.0, v1=-3.0, x2=2.5,
                 v2=1.0, f1=0.5, t_end=20.0, dt=1e-3, dt_out=1e-2)


def assert_same_bits(a, b):
    assert np.array_equal(a.samples, b.samples)
    assert a.events.tobytes() == b.events.tobytes()


@pytest.mark.parametrize("method", ["event", "vissim"])
@pytest.mark.parametrize("body", [1, 2])
@pytest.mark.parametrize("phase", [None, 0.3])
def test_a_sine_record_runs_as_the_bodys_own_sine(body, phase, method):
    """`&sine body = i, amp, period, phase` in place of f<i>_amp, f<i>_period, f<i>_phase:
    the same force, f_i + amp sin(w t + phase) with w = 2 pi / period computed alike
    (angular_frequency), summed in the same order, so the same run bit for bit (the brief's
    "to rounding" holds with no rounding at all): case 3's geometry with friction, impacts,
    rests and stick-slip (the rate of the force decides slips), phase given or not, by
    both methods."""
    own = {f"f{body}_amp": 20.0, f"f{body}_period": 0.7}
    record = {"body": body, "amp": 20.0, "period": 0.7}
    if phase is not None:
        own[f"f{body}_phase"] = phase
        record["phase"] = phase
    a = impact1d.simulate(impact1d.Scene(**CASE_SINE, **own), method=method)
    b = impact1d.simulate(impact1d.Scene(**CASE_SINE, sines=[record]), method=method)
    assert len(a.events) >= 4
    assert method == "vissim" or "stick1" in a.events["kind"]     # (vissim logs no sticks)
    assert_same_bits(a, b)


NAMELIST = """&scene title = 'two sines' /
&bodies m1 = 1.0, m2 = 2.0, mu1 = 0.3, mu2 = 0.1, g = 10.0 /
&walls x_left = 0.0, r_left = 0.8, x_right = 10.0, r_right = 0.9 /
&link d_min = 1.0, r_min = 0.5, d_max = 2.0, r_max = 0.7 /
&initial x1 = 1.0, v1 = -3.0, x2 = 2.5, v2 = 1.0 /
&sine period = 0.7, amp = 20.0, body = 1 /
&forces f1 = 0.5, f1_amp = 3.0, f1_period = 2.0 /
&sine body = 2, amp = -7.5, period = 1.1326237921249264, phase = 0.4 /
&sine body = 1, amp = 4.0, period = 0.3, phase = -1.0 /
&run t_end = 20.0, dt = 1e-3, dt_out = 1e-2 /
"""
NAMELIST_SINES = [{"body": 1, "amp": 20.0, "period": 0.7},
                  {"body": 2, "amp": -7.5, "period": 1.1326237921249264, "phase": 0.4},
                  {"body": 1, "amp": 4.0, "period": 0.3, "phase": -1.0}]


def test_python_and_namelist_forms_give_the_same_bits(tmp_path):
    """The namelist above (records in any place, fields in any order, beside the body's own
    sine) read by load_scene, and the same scene written in Python with Scene(sines=...):
    the same records, and the same run bit for bit."""
    path = tmp_path / "sines.nml"
    path.write_text(NAMELIST)
    loaded = impact1d.load_scene(path)
    assert loaded.sines == NAMELIST_SINES
    written = impact1d.Scene(**{k: v for k, v in CASE_SINE.items() if k not in ("f1",)}, f1=0.5,
                             f1_amp=3.0, f1_period=2.0, title="two sines", sines=NAMELIST_SINES)
    a, b = impact1d.simulate(loaded), impact1d.simulate(written)
    assert len(a.events) > 10
    assert_same_bits(a, b)
    # the records change the run (each one counts)
    c = impact1d.simulate(written, sines=NAMELIST_SINES[:2])
    assert not np.array_equal(a.samples, c.samples)
    assert a.scene.sines == NAMELIST_SINES


def test_the_output_header_records_the_sines(tmp_path):
    """The CLI writes a '# sine.K.field = value' line per given field (phase only when
    given), and read_output rebuilds Scene.sines from them exactly."""
    path = tmp_path / "sines.nml"
    path.write_text(NAMELIST)
    out = tmp_path / "sines.dat"
    proc = subprocess.run([find_tool("impact1d"), str(path), "-o", str(out)], capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert proc.returncode == 0, proc.stderr
    header = [line for line in out.read_text().splitlines() if line.startswith("# sine.")]
    assert header == ["# sine.1.body = 1.0", "# sine.1.amp = 20.0", "# sine.1.period = 0.7",
                      "# sine.2.body = 2.0", "# sine.2.amp = -7.5", "# sine.2.period = 1.1326237921249265",
                      "# sine.2.phase = 0.4", "# sine.3.body = 1.0", "# sine.3.amp = 4.0",
                      "# sine.3.period = 0.3", "# sine.3.phase = -1.0"]
    back = impact1d.read_output(out)
    assert back.scene.sines == NAMELIST_SINES
    # read back with its scene, whose forces must be the header's: the sines count too
    assert impact1d.read_output(out, scene=path).scene.sines == NAMELIST_SINES
    other = tmp_path / "other.nml"
    other.write_text(NAMELIST.replace("amp = 4.0", "amp = 4.5"))
    with pytest.raises(impact1d.InputError, match="was not run from the scene .*: its header has sines = "):
        impact1d.read_output(out, scene=other)
    assert np.allclose(back.samples, impact1d.simulate(impact1d.load_scene(path)).samples,
                       rtol=1e-15, atol=1e-15)


TWO_BODIES = """&bodies m1 = 1.0, m2 = 2.0 /
&link d_min = 1.0 /
&initial x1 = 0.0, x2 = 2.0 /
&run t_end = 1.0, dt = 1e-3 /
"""


@pytest.mark.parametrize("record, message", [
    ("body = 1, amp = 1.0, period = 0.5, freq = 2.0",
     "unknown variable 'freq' (&sine has: body, amp, period, phase)"),
    ("body = 0, amp = 1.0, period = 0.5", "body = 0.0 is not a body: the bodies are 1 to N = 2"),
    ("body = 3, amp = 1.0, period = 0.5", "body = 3.0 is not a body: the bodies are 1 to N = 2"),
    ("body = 1.5, amp = 1.0, period = 0.5", "body = 1.5 is not a body"),
    ("body = 1, amp = 1.0, period = 0.0", "period = 0.0 must be positive"),
    ("body = 1, amp = 1.0, period = -0.5", "period = -0.5 must be positive"),
    ("body = 1, amp = nan, period = 0.5", "amp = NaN is not a finite number"),
    ("body = 1, amp = 1.0, period = 0.5, phase = inf", "phase = Inf is not a finite number"),
    ("body = 1, period = 0.5", "amp is required but not given"),
    ("body = 1, amp = 1.0", "period is required but not given"),
    ("amp = 1.0, period = 0.5", "body is required but not given"),
    ("body = 1, amp = 1.0, amp = 2.0, period = 0.5", "amp is given twice"),
])
def test_bad_records_are_refused_naming_the_field(tmp_path, record, message):
    """Each bad &sine record is an InputError naming the record's line and the field."""
    path = tmp_path / "bad.nml"
    path.write_text(TWO_BODIES + f"&sine body = 1, amp = 1.0, period = 2.0 /\n&sine {record} /\n")
    with pytest.raises(impact1d.InputError) as info:
        impact1d.simulate(impact1d.load_scene(path))
    assert message in str(info.value)
    assert "bad.nml:6: in &sine: " in str(info.value) or "bad.nml: &sine (line 6): " in str(info.value)


def test_bad_records_from_python_are_refused():
    """Scene(sines=...) is checked as the file is: an unknown key names it, a bad value
    names the record by its place."""
    base = dict(m1=1.0, x1=0.0, t_end=1.0, dt=1e-3)
    with pytest.raises(impact1d.InputError, match=r"sines\[0\] has no field 'freq'"):
        impact1d.simulate(impact1d.Scene(**base, sines=[{"body": 1, "amp": 1.0, "period": 1.0, "freq": 2}]))
    with pytest.raises(impact1d.InputError, match=r"&sine record 2: body = 2.0 is not a body: the bodies are 1 to N = 1"):
        impact1d.simulate(impact1d.Scene(**base, sines=[{"body": 1, "amp": 1.0, "period": 1.0},
                                                        {"body": 2, "amp": 1.0, "period": 1.0}]))
    with pytest.raises(impact1d.InputError, match=r"&sine record 1: period = -1.0 must be positive"):
        impact1d.simulate(impact1d.Scene(**base, sines=[{"body": 1, "amp": 1.0, "period": -1.0}]))
    with pytest.raises(impact1d.InputError, match="sines must be a list of dicts"):
        impact1d.simulate(impact1d.Scene(**base, sines={"body": 1}))


def test_the_cli_refuses_a_bad_record_with_status_1(tmp_path):
    path = tmp_path / "bad.nml"
    path.write_text(TWO_BODIES + "&sine body = 1, amp = 1.0 /\n")
    proc = subprocess.run([find_tool("impact1d"), str(path), "-o", str(tmp_path / "out.dat")],
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert proc.returncode == 1
    assert "&sine (line 5): period is required but not given" in proc.stderr
    assert not (tmp_path / "out.dat").exists()


def test_applied_forces_include_the_records():
    """impact1d.plot.applied_forces (the forces panel) adds each body's records."""
    from impact1d.plot import applied_forces
    res = impact1d.simulate(one_body(1e-2))
    t = np.linspace(0.0, 5.0, 11)
    want = F0 + sum(a * np.sin(2 * np.pi * t / p + ph) for a, p, ph in SINES)
    assert np.allclose(applied_forces(res, t)["f1"], want, rtol=0, atol=1e-14)


def test_the_core_takes_no_vector_math():
    """Every sine is libm's sin, so the bits follow the source: gfortran vectorised the
    &sine loop with glibc's vector sin (_ZGVbN2v_sin, up to 4 ulps from sin) until the loop
    said novector."""
    from impact1d import _core
    assert b"_ZGV" not in Path(_core.__file__).read_bytes()


def test_the_documented_example_reads(tmp_path):
    """docs/formats.md's &sine example (under "Rules") reads as two records on body 1,
    the first with no phase, and runs."""
    doc = (Path(__file__).resolve().parent.parent / "docs" / "formats.md").read_text()
    lines = [line.strip() for line in doc.splitlines() if line.startswith("      &")]
    assert [line.split()[0] for line in lines] == ["&forces", "&sine", "&sine"]
    path = tmp_path / "doc.nml"
    path.write_text("&bodies m1 = 1.0 /\n&initial x1 = 0.0 /\n&run t_end = 1.0, dt = 1e-2 /\n"
                    + "\n".join(lines) + "\n")
    scene = impact1d.load_scene(path)
    assert scene.sines == [{"body": 1, "amp": 2.0, "period": 0.7},
                           {"body": 1, "amp": 0.8, "period": 1.1326, "phase": 0.4}]
    assert impact1d.simulate(scene).x1[-1] != 0.0


def test_a_scene_of_n_bodies_reads_its_sines(tmp_path):
    """A chain of three bodies (the N-body engine's input) reads its &sine records, body
    checked against N = 3; running it waits for the cluster solver."""
    chain = "&bodies m = 3*1.0 /\n&initial x = 0.0, 1.0, 2.0 /\n&run t_end = 1.0, dt = 1e-3 /\n"
    path = tmp_path / "chain.nml"
    path.write_text(chain + "&sine body = 3, amp = 1.0, period = 0.5 /\n")
    assert impact1d.load_scene(path).sines == [{"body": 3, "amp": 1.0, "period": 0.5}]
    path.write_text(chain + "&sine body = 4, amp = 1.0, period = 0.5 /\n")
    with pytest.raises(impact1d.InputError, match=r"&sine \(line 4\): body = 4.0 is not a body: the bodies are 1 to N = 3"):
        impact1d.load_scene(path)
