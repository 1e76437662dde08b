"""RK4's stability limit on springs and dampers (issue 18, item 2).

Past the limit RK4 grows every step (a spring at w dt = 2.9 reached positions of 1e76 with a
normal exit); well inside it but coarse, it silently loses the motion (w dt = 1: 5% a period).
The engine finds the modes of M x'' + C x' + K x (the eigenvalues lambda of the first-order
system), refuses a dt past the largest stable step with a message naming the element and that
step, and warns (Result.warnings, the CLI summary) when |lambda| dt > 0.5 with the error RK4
makes on the fastest mode over one period.

The bounds here are computed independently: the eigenvalues by numpy, and the largest stable
step of each as the smallest positive root of |R(h lambda)|^2 = 1 with R RK4's stability
polynomial, a degree-8 polynomial in h (np.roots). Closed forms where they exist:
w dt = 2 sqrt 2 for an undamped spring, c dt / m = 2.7852935634 for a damper alone.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest

import impact1d

ROOT = Path(__file__).resolve().parents[1]

# Bounds found by bisection to ~1e-15 relative in the engine; numpy's roots agree to 1e-9.
BOUND_RTOL = 1e-9
RK4 = np.poly1d([1 / 24, 1 / 6, 1 / 2, 1, 1])          # R(z), highest power first


def modes(masses, k, c):
    n = len(masses)
    m_inv = np.diag(1.0 / np.asarray(masses))
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-m_inv @ k, -m_inv @ c]])
    return np.linalg.eigvals(a)


def stable_step(lam):
    """Smallest h > 0 with |R(h lam)| = 1: |R(h lam)|^2 - 1 as a polynomial in h."""
    if abs(lam) == 0:
        return math.inf
    lam = complex(min(lam.real, 0.0), lam.imag)
    # R(h lam) = sum_j r_j lam^j h^j; |.|^2 = P(h) conj(P)(h) for real h.
    coeffs = [RK4.c[::-1][j] * lam ** j for j in range(5)]      # lowest power first
    p = np.polynomial.Polynomial(coeffs)
    q = np.polynomial.Polynomial(np.conj(coeffs))
    g = (p * q).coef.real
    g[0] -= 1.0
    roots = np.polynomial.Polynomial(g[1:]).roots()       # divide out the root at h = 0
    positive = [r.real for r in roots if abs(r.imag) < 1e-9 * abs(r) and r.real > 1e-12]
    return min(positive) if positive else math.inf


def largest_stable_dt(masses, k, c):
    return min(stable_step(lam) for lam in modes(masses, np.asarray(k, float), np.asarray(c, float)))


# Three scenes: one spring, a two-body spring pair, a stiff damper (and a damped pair).
ONE_SPRING = dict(m1=2.0, x1=0.1, k1=800.0, x1_rest=0.0)                       # w = 20
SPRING_PAIR = dict(m1=1.0, m2=3.0, x1=0.0, x2=1.0, d_min=-5.0, k1=50.0, x1_rest=0.0,
                   k2=10.0, x2_rest=1.0, k12=400.0, d_rest=1.0)
STIFF_DAMPER = dict(m1=0.5, x1=0.0, v1=1.0, c1=40.0)                              # c/m = 80
DAMPED_PAIR = dict(m1=1.0, m2=2.0, x1=0.0, x2=1.0, d_min=-5.0, k12=900.0, d_rest=1.0, c12=10.0,
                   c1=3.0)


def matrices(kw):
    two = "m2" in kw
    n = 2 if two else 1
    k, c = np.zeros((n, n)), np.zeros((n, n))
    k[0, 0] += kw.get("k1", 0.0)
    c[0, 0] += kw.get("c1", 0.0)
    if two:
        k[1, 1] += kw.get("k2", 0.0)
        c[1, 1] += kw.get("c2", 0.0)
        for mat, name in ((k, "k12"), (c, "c12")):
            e = kw.get(name, 0.0)
            mat += e * np.array([[1.0, -1.0], [-1.0, 1.0]])
    masses = [kw["m1"], kw["m2"]] if two else [kw["m1"]]
    return masses, k, c


def test_closed_forms_of_the_bound():
    assert stable_step(20j) * 20 == pytest.approx(2 * math.sqrt(2), rel=1e-12)
    assert stable_step(-80.0 + 0j) * 80 == pytest.approx(2.785293563405282, rel=1e-12)


@pytest.mark.parametrize("kw, element", [(ONE_SPRING, "k1 = 800.0"), (SPRING_PAIR, "k12 = 400.0"),
                                         (STIFF_DAMPER, "c1 = 40.0"), (DAMPED_PAIR, "k12 = 900.0")])
def test_a_step_past_the_limit_is_refused_with_the_exact_bound(kw, element):
    exact = largest_stable_dt(*matrices(kw))
    with pytest.raises(impact1d.InputError) as info:
        impact1d.simulate(impact1d.Scene(**kw, t_end=1.0, dt=exact * 1.001))
    message = str(info.value)
    assert element in message and "stability" in message
    bound = float(re.search(r"needs dt <= ([0-9.eE+-]+)", message).group(1))
    assert bound == pytest.approx(exact, rel=BOUND_RTOL)
    # Just inside the limit it runs, stable, and says the step is coarse; so does vissim.
    for method in ("event", "vissim"):
        res = impact1d.simulate(impact1d.Scene(**kw, t_end=1.0, dt=exact * 0.999, method=method))
        assert np.all(np.isfinite(res.samples))
        assert len(res.warnings) == 1 and "coarse" in res.warnings[0] and element in res.warnings[0]


def test_sweeps_report_the_refusal_per_run():
    exact = largest_stable_dt(*matrices(ONE_SPRING))
    table = impact1d.sweep(impact1d.Scene(**ONE_SPRING, t_end=1.0, dt=1e-3),
                           [dict(dt=exact * 0.99), dict(dt=exact * 1.01)], workers=1)
    assert table["error"].iloc[0] == "" and "stability" in table["error"].iloc[1]


def test_a_fine_step_has_no_warning():
    res = impact1d.simulate(impact1d.Scene(**ONE_SPRING, t_end=1.0, dt=0.5 / 20 * 0.99))
    assert res.warnings == ()


@pytest.mark.parametrize("steps_per_period", [6, 8, 12])
def test_the_warning_predicts_the_error_of_the_fastest_mode(steps_per_period):
    """A free undamped spring (w = 20 rad/s) stepped n times a period: after one period the
    phasor x + i v / w misses its start by what the warning says (RK4's error is a smooth
    function of w dt, so the prediction is the measurement to rounding)."""
    w = 20.0
    period = 2 * math.pi / w
    dt = period / steps_per_period
    scene = impact1d.Scene(**ONE_SPRING, t_end=period, dt=dt, dt_out=period)
    res = impact1d.simulate(scene)
    predicted = float(re.search(r"error on it is about ([0-9.eE+-]+)", res.warnings[0]).group(1))
    start = complex(res.x1[0], res.v1[0] / w)
    end = complex(res.x1[-1], res.v1[-1] / w)
    measured = abs(end / start - 1)
    assert predicted == pytest.approx(measured, rel=0.05)   # two digits printed


def test_the_cli_summary_carries_the_warning(tmp_path):
    import subprocess
    from tools import find_tool
    scene = tmp_path / "spring.nml"
    scene.write_text("&bodies m1 = 2.0 /\n&initial x1 = 0.1 /\n&springs k1 = 800.0, x1_rest = 0.0 /\n"
                     "&run t_end = 1.0, dt = 0.05 /\n")
    out = subprocess.run([find_tool("impact1d"), str(scene), "-o", str(tmp_path / "o.dat")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    warning = [line for line in out.stdout.splitlines() if line.strip().startswith("warning")]
    assert len(warning) == 1 and "k1 = 800.0" in warning[0] and "coarse" in warning[0]


def test_substeps_auto_divides_a_coarse_or_unstable_dt():
    """substeps = 'auto' steps a dt that is coarse (or past the limit) for the fastest mode in
    n = ceil(|lambda| dt / 0.5) steps: the run equals one at dt / n, samples stay at the dt
    given, and no warning remains. Without springs, or with a fine dt, it changes nothing."""
    exact = largest_stable_dt(*matrices(ONE_SPRING))
    for dt in (exact * 1.5, exact * 0.9, 0.1):
        n = math.ceil(20.0 * dt / 0.5)                       # |lambda| = w = 20
        scene = impact1d.Scene(**ONE_SPRING, t_end=1.0, dt=dt, substeps="Auto")
        res = impact1d.simulate(scene)
        reference = impact1d.simulate(scene, substeps=None, dt=dt / n, dt_out=dt)
        np.testing.assert_array_equal(res.samples, reference.samples)
        assert res.steps == reference.steps and res.warnings == ()
    fine = impact1d.Scene(**ONE_SPRING, t_end=1.0, dt=0.01)
    np.testing.assert_array_equal(impact1d.simulate(fine, substeps="auto").samples,
                                  impact1d.simulate(fine).samples)
    case3 = impact1d.load_scene(ROOT / "input" / "case3.nml")
    np.testing.assert_array_equal(impact1d.simulate(case3, substeps="auto").samples,
                                  impact1d.simulate(case3).samples)
    with pytest.raises(impact1d.InputError, match="substeps = 'sometimes' is unknown"):
        impact1d.simulate(fine, substeps="sometimes")


def test_substeps_in_a_namelist(tmp_path):
    scene = tmp_path / "s.nml"
    scene.write_text("&bodies m1 = 2.0 /\n&initial x1 = 0.1 /\n&springs k1 = 800.0, x1_rest = 0.0 /\n"
                     "&run t_end = 1.0, dt = 0.2, substeps = 'AUTO' /\n")
    loaded = impact1d.load_scene(scene)
    assert loaded.substeps == "auto"
    res = impact1d.simulate(loaded)
    assert res.steps == 5 * 8 and res.warnings == ()          # 8 substeps of each 0.2 s step
