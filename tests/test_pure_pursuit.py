"""Pure pursuit at C (controllers/pure_pursuit.py) against its closed forms, and on the MuJoCo plant.

Independent truths: the chord geometry of Coulter's arc (a goal point on a circle through C,
with C's direction of travel tangent, lies on the arc of curvature 1/R; on a straight path with C
at lateral offset e, kappa = -2 e/(L_d^2 + e^2); on a circle with C at radial offset e, the
triangle centre-C-goal), and the steady steering angle sin(alpha) = l1/R of
wmr_mj.reference.paths, computed here by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.pure_pursuit import PurePursuit
from controllers.tracking import TRACKER_BOUNDS_ASSUMPTION
from wmr_mj.params import C80
from wmr_mj.reference.paths import circle, line, make_reference

L1 = C80.l1


def _expected(kappa: float, alpha_max: float = 0.75) -> float:
    """asin(l1 kappa), clipped to the tracker's +-alpha_max."""
    return math.asin(max(-math.sin(alpha_max), min(math.sin(alpha_max), L1 * kappa)))


def _tracker(reference, **params) -> PurePursuit:
    tr = PurePursuit(**params)
    tr.reset(reference, control_period=1e-3)
    return tr


@pytest.mark.parametrize("R, lookahead", [(2.0, 0.5), (-2.0, 0.5), (1.5, 0.3), (3.0, 1.2)])
def test_on_the_circle_the_command_is_the_steady_angle(R, lookahead):
    """C on its circle, travelling along the tangent (heading theta = tangent - alpha0 with the
    filter at alpha0): the arc through the goal is the circle itself, kappa = 1/R, and the command
    is asin(l1/R) at every point. Tolerance 1e-7 rad: the goal point is interpolated linearly
    between the reference's samples (1 ms, 0.2 mm apart: a sagitta below 1e-8 m) and C's path is
    the reference's integrated one (rtol of its ODE)."""
    ref = make_reference(circle(R, angle=2.0), C80, dt=1e-3)
    expected = math.asin(L1 / R)
    assert ref.alpha0[0] == pytest.approx(expected, abs=1e-12)
    tr = _tracker(ref, lookahead=lookahead)
    for i in (0, 1234, 3000, len(ref.t) // 2):
        tr.s_prev = float(ref.s[i])
        tr.filter.d = float(ref.alpha0[i])
        tr.measure(float(ref.t[i]), ref.C_xy[i], float(ref.theta[i]), 0.2)
        assert tr.kappa == pytest.approx(1.0 / R, abs=1e-7)
        assert tr.command == pytest.approx(expected, abs=1e-7)


@pytest.mark.parametrize("e", [-0.2, -0.05, 0.0, 0.03, 0.15])
def test_off_a_straight_path_the_command_is_the_closed_form(e):
    """Straight path along x from C's start; C at (x0, e), heading along the path (alpha = 0):
    the goal is (x0 + L_d, 0), kappa = 2 (-e)/(L_d^2 + e^2), the command asin(l1 kappa) (clipped
    at alpha_max = 0.75 rad: e = -0.2 m asks for l1 kappa = 0.84 > sin 0.75)."""
    ref = make_reference(line(5.0), C80, dt=1e-3)
    L = 0.5
    tr = _tracker(ref, lookahead=L)
    x0 = float(ref.C_xy[4000, 0])
    tr.s_prev = float(ref.s[4000])
    tr.measure(4.0, np.array([x0, float(ref.C_xy[4000, 1]) + e]), 0.0, 0.2)
    kappa = -2.0 * e / (L * L + e * e)
    assert tr.kappa == pytest.approx(kappa, abs=1e-9)
    assert tr.command == pytest.approx(_expected(kappa), abs=1e-9)


@pytest.mark.parametrize("e", [-0.1, 0.05, 0.1, 0.2])
def test_off_a_circle_the_command_is_the_closed_form(e):
    """C at radial offset e (> 0 outside) from a left circle of radius R, travelling tangent: in
    the frame centre = 0, C = (R + e, 0) travelling +y, the goal at angle beta = L_d/R is
    R (cos beta, sin beta), and kappa = 2 (R + e - R cos beta)/((R cos beta - R - e)^2 + R^2 sin^2 beta)
    (e = 0.2 m: l1 kappa = 1.02, the command clipped at alpha_max)."""
    R, L = 2.0, 0.5
    ref = make_reference(circle(R, angle=2.0), C80, dt=1e-3)
    tr = _tracker(ref, lookahead=L)
    i = 2000
    direction = float(ref.theta[i] + ref.alpha0[i])
    left = np.array([-math.sin(direction), math.cos(direction)])
    C = ref.C_xy[i] - e * left  # outward by e
    tr.s_prev = float(ref.s[i])
    tr.filter.d = float(ref.alpha0[i])
    tr.measure(float(ref.t[i]), C, float(ref.theta[i]), 0.2)
    b = L / R
    kappa = 2.0 * (R + e - R * math.cos(b)) / ((R * math.cos(b) - R - e) ** 2 + (R * math.sin(b)) ** 2)
    assert tr.kappa == pytest.approx(kappa, abs=1e-6)  # the projection's s: polyline + sagitta correction
    assert tr.command == pytest.approx(_expected(kappa), abs=1e-7)


def test_declared_bounds_are_its_own_and_the_filter_keeps_them():
    from wmr_mj.reference.bounds import PAPER_BOUNDS, sin_cos3

    tr = PurePursuit(alpha_max=0.4, rate_max=0.2, acc_max=0.3)
    b = tr.declared_bounds(PAPER_BOUNDS)
    assert (b.alpha_max, b.alpha_dot_max, b.alpha_ddot_max) == (0.4, 0.2, 0.3)
    assert b.sin_cos3_max == pytest.approx(sin_cos3(0.4))
    ref = make_reference(line(5.0), C80, dt=1e-3)
    tr.reset(ref, control_period=1e-3)
    tr.command = 1.0  # beyond alpha_max: the filter saturates
    a, ad, add = tr.block(0, 5000)
    assert np.max(np.abs(a)) <= 0.4 and np.max(np.abs(ad)) <= 0.2 + 1e-12 and np.max(np.abs(add)) <= 0.3
    # consistent: a' and a'' integrate to a (a'' held over each step)
    np.testing.assert_allclose(np.diff(a)[:1000], (ad[:-1] * 1e-3 + 0.5 * add[:-1] * 1e-6)[:1000], atol=1e-15)
    with pytest.raises(Exception, match="alpha_max"):
        PurePursuit(alpha_max=2.0)


@pytest.mark.slow
def test_lane_change_on_mujoco_is_certified_with_the_tracker_measured():
    """10 s of the lane change with pure pursuit over the sliding-mode law (its claim computed for
    the tracker's declared bounds): the tracker's assumption is measured and met, the run is
    certified-inside, and C's cross-track error is reported (measured 0.013 m, bound asserted 0.05 m).
    The law's layer is one its sampled-data certificate proves on the ideal cart (lam 20, phi 6, k 24:
    docs/guides/certificates.md, "Sampling bounded on every cart"; the default phi 0.2 is not, issue 44)."""
    from wmr_mj.sim.closed_loop import RunConfig, run_closed_loop

    result = run_closed_loop(RunConfig(controller="sliding-mode", model="nonholonomic", tracker="pure-pursuit",
                                       path="lane-change", duration=10.0,
                                       controller_params={"lam": 20.0, "phi": 6.0, "k": 24.0}), progress=False)
    s = result.summary
    cert = s.certificate.certificate
    tracked = [a for a in cert.assumptions if a.name == TRACKER_BOUNDS_ASSUMPTION]
    assert len(tracked) == 1 and tracked[0].met and tracked[0].kind == "checked"
    assert any(a.name == "pure-pursuit direction of travel" for a in cert.assumptions)
    assert s.verdict == "certified-inside", (s.verdict, s.certificate.unmet)
    assert s.correction["tracker"] == "pure-pursuit" and s.correction["alpha_max_used"] <= 0.75
    assert s.path_error is not None and s.path_error.cross_track_max < 0.05


class _Overshooting(PurePursuit):
    """Declares pure pursuit's bounds but writes alpha0 0.1 rad beyond them (a test's bad tracker)."""

    name = "overshooting-pursuit"  # a plug-in names itself (controllers.registry.refuse_builtin_name)

    def block(self, k0, count):
        a, ad, add = super().block(k0, count)
        return a + self.alpha_max + 0.1, ad, add


@pytest.mark.slow
def test_a_tracker_beyond_its_declared_bounds_is_uncertified():
    from wmr_mj.sim.closed_loop import RunConfig, run_closed_loop

    result = run_closed_loop(RunConfig(controller="sliding-mode", model="nonholonomic",
                                       tracker=_Overshooting(alpha_max=0.3), path="lane-change", duration=2.0),
                             progress=False)
    s = result.summary
    assert TRACKER_BOUNDS_ASSUMPTION in s.certificate.unmet
    assert s.verdict.startswith("uncertified"), s.verdict
