"""Tests of the section-4 robustness analysis (wmr_mj.analysis.robustness) and `wmr-mj robustness`."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, optimize, signal

from wmr_mj import C80
from wmr_mj.analysis.robustness import (
    PAPER_CONDITION,
    ParameterBox,
    ReferenceBounds,
    analyse,
    damping_regime,
    exact_gammas,
    gains_from_omega_r,
    impulse_responses,
    paper_gammas,
)
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError, WmrMjError

REPO = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------- reference integrals
def _h_g(kp: float, kd: float):
    """Impulse responses from the characteristic roots (independent of the module)."""
    p1, p2 = np.roots([1.0, kd, kp]).astype(complex)
    if abs(p1 - p2) < 1e-9 * abs(p1):
        p = p1.real
        return (lambda t: t * math.exp(p * t)), (lambda t: (1.0 + p * t) * math.exp(p * t))

    def h(t: float) -> float:
        return ((np.exp(p1 * t) - np.exp(p2 * t)) / (p1 - p2)).real

    def g(t: float) -> float:
        return ((p1 * np.exp(p1 * t) - p2 * np.exp(p2 * t)) / (p1 - p2)).real

    return h, g


def _abs_integral(f, kp: float, kd: float) -> float:
    """int_0^inf |f| by quad, split at the sign changes found on a dense grid."""
    rates = abs(np.roots([1.0, kd, kp]).real)
    T = 45.0 / min(rates)  # exp(-45) ~ 3e-20
    t = np.linspace(0.0, T, 200001)
    v = np.vectorize(f)(t)
    idx = np.nonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)[0]
    zeros = [optimize.brentq(f, t[i], t[i + 1]) for i in idx]
    fast = [k / max(rates) for k in (1.0, 10.0, 45.0) if k / max(rates) < T]  # resolve the fast transient
    edges = sorted({0.0, *zeros, *fast, T})
    return sum(abs(integrate.quad(f, a, b, limit=200, epsabs=1e-14, epsrel=1e-12)[0]) for a, b in zip(edges, edges[1:]))


GAIN_CASES = [
    (6.0, 9.0),  # the paper's example: over-damped
    (4.0, 4.0),  # critical
    (25.0, 10.0),  # critical
    (1e-2, 5.0),  # strongly over-damped
    (4.0, 1.0),  # under-damped
    (25.0, 2.0),  # lightly damped
    (1.0, 0.3),  # lightly damped, many half-periods
    (4.0, 4.0 * (1 - 1e-4)),  # just under critical
    (4.0, 4.0 * (1 + 1e-4)),  # just over critical
]


@pytest.mark.parametrize("kp,kd", GAIN_CASES)
def test_exact_gammas_match_quadrature(kp, kd):
    h, g = _h_g(kp, kd)
    g1, g2 = exact_gammas(kp, kd)
    assert g1 == pytest.approx(_abs_integral(h, kp, kd), rel=1e-7)
    assert g2 == pytest.approx(_abs_integral(g, kp, kd), rel=1e-7)


@pytest.mark.slow
@pytest.mark.parametrize("kp,kd", [(6.0, 9.0), (4.0, 1.0), (4.0, 4.0)])
def test_exact_gammas_match_scipy_impulse(kp, kd):
    t = np.linspace(0.0, 45.0 / min(abs(np.roots([1.0, kd, kp]).real)), 400001)
    _, h = signal.impulse(signal.lti([1.0], [1.0, kd, kp]), T=t)
    _, g = signal.impulse(signal.lti([1.0, 0.0], [1.0, kd, kp]), T=t)
    g1, g2 = exact_gammas(kp, kd)
    assert g1 == pytest.approx(integrate.trapezoid(np.abs(h), t), rel=2e-4)
    assert g2 == pytest.approx(integrate.trapezoid(np.abs(g), t), rel=2e-4)
    # the module's own h, g agree with scipy's
    hm, gm = impulse_responses(t[:2000], kp, kd)
    # scipy's impulse is a matrix exponential, not a stepped integration: both are closed forms up to
    # rounding (measured <= 1.9e-14 on responses ~0.1-0.3)
    np.testing.assert_allclose(hm, h[:2000], atol=1e-9)
    np.testing.assert_allclose(gm, g[:2000], atol=1e-9)


def test_paper_example_gammas():
    g1, g2 = exact_gammas(6.0, 9.0)
    assert g1 == pytest.approx(1 / 6)
    assert g2 == pytest.approx(0.191301, abs=2e-6)
    p1, p2 = paper_gammas(6.0, 9.0)
    assert (p1, p2) == pytest.approx((1 / 6, 4 / (9 * math.e)))
    assert g2 / p2 == pytest.approx(1.170, abs=1e-3)  # (4.16) understates gamma2 by 17 %
    assert damping_regime(6.0, 9.0) == "over-damped"


@pytest.mark.parametrize("kp", [0.25, 1.0, 6.0, 100.0])
def test_critical_damping_matches_paper_closed_forms(kp):
    kd = 2.0 * math.sqrt(kp)
    assert damping_regime(kp, kd) == "critically damped"
    assert exact_gammas(kp, kd) == pytest.approx(paper_gammas(kp, kd), rel=1e-14)
    assert exact_gammas(kp, kd)[1] == pytest.approx(4.0 / (math.e * kd), rel=1e-14)


@pytest.mark.parametrize("eps", [1e-15, 1e-12, 1e-9, 1e-6, 1e-4])
def test_near_critical_is_smooth(eps):
    kp, kd = 6.0, 2.0 * math.sqrt(6.0)
    crit = paper_gammas(kp, kd)
    for factor in (1 - eps, 1 + eps):
        g1, g2 = exact_gammas(kp, kd * factor)
        # gamma2 ~ 4/(e K_D): first order in eps, no cancellation blow-up
        assert g2 == pytest.approx(crit[1] / factor, rel=10 * eps + 1e-13)
        assert g1 == pytest.approx(crit[0], rel=10 * eps + 1e-13)


def test_gains_from_omega_r():
    assert gains_from_omega_r(6.0) == (9.0, 6.0)
    kp, kd = gains_from_omega_r(3.7)
    assert damping_regime(kp, kd) == "critically damped"
    for bad in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(ParameterError, match="omega_r"):
            gains_from_omega_r(bad)
    for kp, kd in ((0.0, 9.0), (6.0, -1.0), (math.nan, 9.0), (6.0, math.inf)):
        with pytest.raises(ParameterError, match="K_P|K_D"):
            exact_gammas(kp, kd)


# ----------------------------------------------------------------- the (5.1) example
def test_corrected_reading_by_hand():
    r = analyse(ParameterBox.paper())
    # worst case: true P = 0.37, estimate P^ = 0.40
    assert r.delta_E == pytest.approx(6 * 0.03 / 0.37)
    assert r.delta_Edot == pytest.approx((0.03 * 9 + 0.08) / 0.37)
    assert r.delta1 == pytest.approx((0.03 * 0.4 + 0.03 + 0.08 * 0.23 + 0.09 * 1.24) / 0.37)
    assert (r.delta2, r.delta3) == (r.delta_E, r.delta_Edot)
    assert r.condition == pytest.approx(r.gamma1 * r.delta_E + r.gamma2 * r.delta_Edot)
    assert r.condition == pytest.approx(0.26204, abs=1e-5)
    assert abs(r.condition - PAPER_CONDITION) / PAPER_CONDITION < 0.01
    assert r.stable
    assert r.E_max == pytest.approx(r.gamma1 * r.delta1 / (1 - r.condition))
    assert r.E_max == pytest.approx(0.10499, abs=1e-5)
    assert r.Edot_max == pytest.approx(0.12051, abs=1e-5)


def test_other_readings_do_not_reproduce_paper():
    box = ParameterBox.paper()
    printed = analyse(box, reading="printed").condition
    literal = analyse(box, reading="printed-literal").condition
    paper_g = analyse(box, gammas="paper").condition
    assert printed == pytest.approx(0.25072, abs=1e-5)
    assert literal == pytest.approx(0.22802, abs=1e-5)
    assert paper_g == pytest.approx(0.23575, abs=1e-5)
    for value in (printed, literal, paper_g):
        assert abs(value - PAPER_CONDITION) / PAPER_CONDITION > 0.04


def test_cli_json_reproduces_paper(capsys):
    assert main(["robustness", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("gamma1", "gamma2", "delta1", "condition", "stable", "E_max", "Edot_max"):
        assert key in out
    assert out["condition"] == pytest.approx(0.2613, rel=0.01)
    assert out["stable"] is True
    assert out["gamma2"] == pytest.approx(0.191301, abs=2e-6)
    assert out["relative_difference"] == pytest.approx((out["condition"] - 0.2613) / 0.2613)
    assert len(out["vertices"]) == 4


def test_cli_human_output(capsys):
    assert main(["robustness"]) == 0
    text = capsys.readouterr().out
    assert "0.2613" in text and "0.26204" in text and "+0.28%" in text


def test_cli_options(capsys):
    assert main(["robustness", "--json", "--omega-r", "6", "--gammas", "paper"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["kp"], out["kd"]) == (9.0, 6.0)
    assert out["gamma2"] == pytest.approx(4 / (6 * math.e))
    assert main(["robustness", "--json", "--reading", "printed", "--alpha-ddot", "0"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["delta1"] == pytest.approx((0.03 + 0.08 * 0.23 + 0.09 * 1.24) / 0.37)
    assert out["reading"] == "printed"


def test_unstable_gives_nulls(capsys):
    r = analyse(ParameterBox.paper(), kp=100.0, kd=1.0)
    assert not r.stable and r.condition > 1
    assert math.isinf(r.E_max) and math.isinf(r.Edot_max) and r.vertices == ()
    d = r.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["E_max"] is None and d["Edot_max"] is None and d["stable"] is False
    assert main(["robustness", "--json", "--kp", "100", "--kd", "1"]) == 0
    assert json.loads(capsys.readouterr().out)["E_max"] is None


# ----------------------------------------------------------------- extreme gains (no overflow, no traceback)
@pytest.mark.parametrize("kp,kd", [(1e308, 1e308), (1e308, 1.0), (1.0, 1e308), (1e-300, 1e300)])
def test_extreme_gains_give_finite_gammas(kp, kd):
    g1, g2 = exact_gammas(kp, kd)
    assert math.isfinite(g1) and math.isfinite(g2) and g1 > 0 and g2 > 0
    if kd * kd > 4 * kp or math.isinf(kd * kd):  # strongly over-damped: 1/K_P and ~2/K_D
        assert g1 == pytest.approx(1.0 / kp)
        assert g2 == pytest.approx(2.0 / kd, rel=1e-6)


def test_gammas_accepted_over_stated_range():
    rng = np.random.default_rng(0)
    for _ in range(2000):
        kp = 10.0 ** rng.uniform(-100, 100)
        kd = math.sqrt(kp * 10.0 ** rng.uniform(-100, 100))
        if not (1e-100 <= kd <= 1e100):
            continue
        g1, g2 = exact_gammas(kp, kd)
        assert math.isfinite(g1) and math.isfinite(g2) and g1 > 0 and g2 > 0
    # critical damping still matches (4.16) at the extremes
    for kp in (1e-200, 1e200):
        assert exact_gammas(kp, 2 * math.sqrt(kp)) == pytest.approx(paper_gammas(kp, 2 * math.sqrt(kp)), rel=1e-12)


def test_cli_extreme_gains(capsys):
    assert main(["robustness", "--kp", "1e308", "--kd", "1e308", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["stable"] is True and out["gamma1"] == pytest.approx(1e-308)
    assert main(["robustness", "--kp", "1e300", "--kd", "1e-300"]) == 2  # gamma1 ~ 1e450
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "gamma1" in err and "accepted" in err
    assert main(["robustness", "--kp", "5e-324", "--kd", "5e-324"]) == 2  # subnormal
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "smallest normal float" in err


# ----------------------------------------------------------------- region vs LP
REGION_CASES = [
    dict(),
    dict(kp=4.0, kd=4.0),
    dict(kp=9.0, kd=2.5),  # under-damped, still stable
    dict(reading="printed"),
    dict(estimate={"P": 0.385, "C_V": 4.77}),
    dict(bounds=ReferenceBounds(alpha_ddot_max=2.0, alpha_dot_max=1.0, sin_cos3_max=0.5)),
]


@pytest.mark.parametrize("kwargs", REGION_CASES)
def test_bounds_match_linear_programme(kwargs):
    r = analyse(ParameterBox.paper(), **kwargs)
    assert r.stable
    g1, g2, d1, dE, dD = r.gamma1, r.gamma2, r.delta1, r.delta_E, r.delta_Edot
    # variables (x, y, n) = (||E||, ||E'||, ||eta||): x <= g1 n, y <= g2 n, n <= d1 + dE x + dD y
    A = [[1, 0, -g1], [0, 1, -g2], [-dE, -dD, 1]]
    b = [0, 0, d1]
    for c, expected in (([-1, 0, 0], r.E_max), ([0, -1, 0], r.Edot_max)):
        lp = optimize.linprog(c, A_ub=A, b_ub=b, bounds=[(0, None)] * 3, method="highs")
        assert lp.status == 0
        assert -lp.fun == pytest.approx(expected, rel=1e-9)
    # polygon: every vertex feasible, and the LP over random directions hits a vertex
    V = np.array(r.vertices)
    for x, y in V:
        assert x <= g1 * (d1 + dE * x + dD * y) + 1e-12
        assert y <= g2 * (d1 + dE * x + dD * y) + 1e-12
    rng = np.random.default_rng(0)
    for _ in range(5):
        w = rng.uniform(0, 1, 2)
        lp = optimize.linprog([-w[0], -w[1], 0], A_ub=A, b_ub=b, bounds=[(0, None)] * 3, method="highs")
        assert -lp.fun == pytest.approx(np.max(V @ w), rel=1e-9)


def test_lines_of_4_21_pass_through_corner():
    r = analyse(ParameterBox.paper())
    lines = r.lines()
    for c0, c1 in lines.values():
        assert r.E_max == pytest.approx(c0 + c1 * r.Edot_max)


# ----------------------------------------------------------------- estimate
def test_explicit_estimate():
    box = ParameterBox.paper()
    centre = {"P": 0.385, "C_V": 4.77, "F": 1.515, "K": 5.335}
    r = analyse(box, estimate=centre)
    # truth at P = 0.37 (|P - P^| = 0.015) is the worst case
    assert r.delta_E == pytest.approx(6 * 0.015 / 0.37)
    assert r.delta_Edot == pytest.approx((0.015 * 9 + 0.04) / 0.37)
    assert r.delta1 == pytest.approx((0.015 * 0.4 + 0.015 + 0.04 * 0.23 + 0.045 * 1.24) / 0.37)
    assert r.condition < analyse(box).condition
    # estimate at the far corner reproduces the "anywhere in the box" worst case
    corner = analyse(box, estimate={"P": 0.4, "C_V": 4.81, "F": 1.53, "K": 5.38})
    assert corner.delta_E == pytest.approx(analyse(box).delta_E)
    with pytest.raises(UnknownNameError, match="valid estimate names: C_V, F, K, P"):
        analyse(box, estimate={"Q": 1.0})
    with pytest.raises(ParameterError, match="P"):
        analyse(box, estimate={"P": 0.0})


# ----------------------------------------------------------------- boxes
def test_paper_box_values():
    b = ParameterBox.paper()
    assert (b.P, b.C_V, b.F, b.K) == ((0.37, 0.4), (4.73, 4.81), (1.5, 1.53), (5.29, 5.38))


def test_derived_box_from_c80():
    box = ParameterBox.from_parameters(C80)
    assert box.K[0] == pytest.approx(5.29, abs=0.01)
    assert box.K[1] == pytest.approx(5.38, abs=0.01)
    assert 0.37 < box.P[0] <= box.P[1] < 0.4
    assert box.F[0] < 1.5 and box.F[1] > 1.53  # friction scales with the whole weight
    wide = ParameterBox.from_parameters(C80, ranges={"mu": (0.015, 0.02)})
    assert wide.F[0] < box.F[0] and wide.F[1] > box.F[1]
    assert wide.K == pytest.approx(box.K)
    nh = ParameterBox.from_parameters(C80, model="nonholonomic")
    assert nh.K == (0.0, 0.0)


def test_cli_cart_alone_takes_the_box_derived_from_it(capsys):
    """--cart with no --box: the box derived from the cart's parameters over its m1 box (the paper's (5.1) box is
    the C80's); the same answer as --box derived given, and another than the paper's box."""
    assert main(["robustness", "--json", "--cart", "c80-magmotor"]) == 0
    alone = json.loads(capsys.readouterr().out)
    assert main(["robustness", "--json", "--cart", "c80-magmotor", "--box", "derived"]) == 0
    assert alone == json.loads(capsys.readouterr().out)
    assert main(["robustness", "--json"]) == 0
    assert alone["box"] != json.loads(capsys.readouterr().out)["box"]


def test_cli_derived_box(capsys):
    assert main(["robustness", "--json", "--box", "derived", "--m1-range", "550", "750"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["box"]["K"] == pytest.approx([5.29, 5.38], abs=0.01)
    # P and C_V do not depend on m1: no multiplicative uncertainty
    assert out["delta_E"] == 0.0 and out["delta_Edot"] == 0.0


@pytest.mark.parametrize(
    "kwargs,exc,pattern",
    [
        (dict(m1_range=(750.0, 550.0)), ParameterError, "m1.*inverted"),
        (dict(m1_range=(550.0, 550.0)), ParameterError, "m1.*lo < hi"),
        (dict(m1_range=(550.0, math.inf)), ParameterError, "m1.*not finite"),
        (dict(ranges={"mu": (0.02, 0.01)}), ParameterError, "mu.*inverted"),
        (dict(ranges={"bogus": (1.0, 2.0)}), UnknownNameError, "bogus.*valid parameters: .*mu"),
        (dict(model="lagrange"), UnknownNameError, "lagrange"),
    ],
)
def test_box_validation(kwargs, exc, pattern):
    with pytest.raises(exc, match=pattern):
        ParameterBox.from_parameters(C80, **kwargs)


def test_box_and_bounds_validation():
    with pytest.raises(ParameterError, match="P"):
        ParameterBox(P=(0.0, 0.4), C_V=(1, 2), F=(1, 2), K=(1, 2))
    with pytest.raises(ParameterError, match="K.*inverted"):
        ParameterBox(P=(0.3, 0.4), C_V=(1, 2), F=(1, 2), K=(2, 1))
    with pytest.raises(ParameterError, match="alpha_dot_max"):
        ReferenceBounds(alpha_dot_max=-1.0)
    with pytest.raises(UnknownNameError, match="corrected"):
        analyse(ParameterBox.paper(), reading="swapped")
    with pytest.raises(UnknownNameError, match="exact"):
        analyse(ParameterBox.paper(), gammas="numeric")


# ----------------------------------------------------------------- CLI errors
@pytest.mark.parametrize(
    "argv,pattern",
    [
        (["--box", "derived", "--range", "m1=5:"], "NAME=LO:HI"),
        (["--box", "derived", "--range", "mu=0.02:0.01"], "inverted"),
        (["--box", "derived", "--range", "nope=1:2"], "unknown parameter 'nope'"),
        (["--box", "paper", "--range", "mu=0.01:0.02"], "--range applies only to --box derived"),
        (["--box", "paper", "--cart", "c80-magmotor", "--m1-range", "500", "600"],
         "--m1-range, --cart apply only to --box derived"),
        (["--omega-r", "4", "--kd", "4"], "--omega-r"),
        (["--estimate", "X=1"], "unknown estimate name"),
    ],
)
def test_cli_bad_input_one_line(capsys, argv, pattern):
    assert main(["robustness", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("wmr-mj: error:")
    assert "Traceback" not in err
    assert re.search(pattern, err)


@pytest.mark.parametrize("argv", [["--kp", "0"], ["--kd", "-3"], ["--omega-r", "nan"], ["--alpha-dot", "-1"]])
def test_cli_bad_gain_is_argparse_error(capsys, argv):
    with pytest.raises(SystemExit) as info:
        main(["robustness", *argv])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "is not accepted" in err


@pytest.mark.slow
def test_cli_exit_codes_subprocess():
    exe = REPO / ".venv" / "bin" / "wmr-mj"
    if not exe.exists():
        exe = Path(sys.executable).with_name("wmr-mj")
    proc = subprocess.run(
        [str(exe), "robustness", "--box", "derived", "--range", "m1=5:"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "NAME=LO:HI" in proc.stderr
    assert issubclass(ParameterError, WmrMjError)
