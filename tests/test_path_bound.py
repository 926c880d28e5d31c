"""What |E| <= E_max implies for C's path (wmr_mj.analysis.path_bound): closed forms of the
kinematic model, checked against an independent integration measured by path_error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wmr_mj import C80
from wmr_mj.analysis.path_bound import (
    PathBound,
    circle_bound,
    line_bound,
    path_bound,
    path_verdict,
    steady_angle,
    steady_radius,
    steady_radius_slope,
    straight_line_drift,
)
from wmr_mj.analysis.path_error import path_errors
from wmr_mj.errors import ParameterError
from wmr_mj.reference.paths import circle, lane_change, line, make_reference, paper_circle

L1, VA = C80.l1, C80.V_A


def _drive(alpha: float, A0, theta0: float, T: float, dt: float = 1e-3):
    """RK4 of the no-slip kinematics at a constant steering angle: A' = V_A (cos, sin)(theta),
    theta' = V_A tan(alpha)/l1; returns t, C (n, 2), theta."""
    n = int(round(T / dt)) + 1
    x = np.empty((n, 3))
    x[0] = [A0[0], A0[1], theta0]
    w = VA * math.tan(alpha) / L1

    def f(s):
        return np.array([VA * math.cos(s[2]), VA * math.sin(s[2]), w])

    for i in range(n - 1):
        s = x[i]
        k1 = f(s)
        k2 = f(s + 0.5 * dt * k1)
        k3 = f(s + 0.5 * dt * k2)
        k4 = f(s + dt * k3)
        x[i + 1] = s + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    C = x[:, :2] + L1 * np.column_stack([np.cos(x[:, 2]), np.sin(x[:, 2])])
    return np.arange(n) * dt, C, x[:, 2]


def test_steady_radius_closed_forms():
    a0 = steady_angle(1.0)
    assert a0 == pytest.approx(0.6586, abs=1e-4)  # the paper's circle: sin/cos^3 = 1.24
    assert steady_radius(a0) == pytest.approx(1.0, rel=1e-12)
    assert steady_radius_slope(a0) == pytest.approx(-1.29, abs=0.005)
    h = 1e-6
    assert steady_radius_slope(0.4) == pytest.approx((steady_radius(0.4 + h) - steady_radius(0.4 - h)) / (2 * h),
                                                     rel=1e-6)
    assert math.isinf(steady_radius(0.0))
    with pytest.raises(ParameterError, match="l1"):
        steady_angle(0.5)


@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_constant_offset_on_a_circle_gives_the_kinematic_radius(sign):
    """alpha = alpha0 -+ e held from a point of the desired circle, along its tangent: C moves on
    the circle l1/sin(alpha); it strays 2 (R_C - R) from the desired one half a lap later."""
    R, E = 1.0, 0.05
    ref = make_reference(circle(R, turns=1.6), C80, dt=2e-3)
    a0 = float(ref.alpha0[0])
    alpha = a0 + sign * E
    theta0 = a0 - alpha  # C's direction theta + alpha = the circle's tangent a0
    A0 = np.asarray(ref.C_xy[0]) - L1 * np.array([math.cos(theta0), math.sin(theta0)])
    T = 0.99 * ref.duration
    t, C, th = _drive(alpha, A0, theta0, T, dt=2e-3)
    # C's circle: the RK4 trajectory has constant curvature radius l1/sin(alpha)
    centre = C[0] + np.array([-math.sin(a0), math.cos(a0)]) * L1 / math.sin(alpha)
    # RK4's error at dt = 2e-3 s: measured 5e-13 m, the same at dt = 4e-3 s (round-off, not truncation)
    assert np.max(np.abs(np.hypot(*(C - centre).T) - L1 / math.sin(alpha))) < 1e-9
    err = path_errors(ref, t, C, th)
    shift = L1 / math.sin(alpha) - R
    assert err.cross_track_max == pytest.approx(2.0 * abs(shift), rel=1e-4)
    b = circle_bound(R, E)
    assert b.cross_track_bound is not None and b.radius_shift == pytest.approx(L1 / math.sin(a0 - E) - R)
    assert b.radius_shift <= b.radius_shift_linear <= 1.15 * b.radius_shift
    assert b.radius_shift_linear == pytest.approx(L1 * math.cos(a0 - E) / math.sin(a0 - E) ** 2 * E)
    assert err.cross_track_max <= b.cross_track_bound * (1 + 1e-4)
    if sign < 0:  # the smaller angle is the larger shift: the bound is reached
        assert err.cross_track_max == pytest.approx(b.cross_track_bound, rel=1e-4)
    # along the path no bound: C drifts from the timed reference at R V_A |tan(alpha) - tan(a0)| / l1 on
    # average (the circles' centres differ by the shift: the projection swings by about that much about it)
    rate = R * VA * abs(math.tan(alpha) - math.tan(a0)) / L1
    assert abs(err.along_track_final) == pytest.approx(rate * t[-1], abs=2.0 * abs(shift))
    assert math.copysign(1.0, err.along_track_final) == sign  # a larger angle runs ahead, a smaller one lags
    assert rate <= b.along_track_rate_max * (1 + 1e-12)  # two closed forms: rounding
    v = path_verdict(err, circle_bound(R, 1.01 * E))  # the bound is tight for sign < 0: leave room for round-off
    assert v.verdict == "within-bound" and v.ratio <= 1.0


@pytest.mark.parametrize("e", [0.02, -0.046])
def test_straight_line_has_no_guarantee_and_drifts_as_predicted(e):
    ref = make_reference(line(6.0), C80, dt=2e-3)
    t, C, th = _drive(e, (0.0, 0.0), 0.0, 20.0, dt=2e-3)
    err_series_cross, heading = straight_line_drift(e, t)
    from wmr_mj.analysis.path_error import path_error_series

    ser = path_error_series(ref, t, C, th)
    assert np.max(np.abs(ser.cross_track - err_series_cross)) < 1e-6
    assert np.max(np.abs(ser.heading_error - heading)) < 1e-6
    b = line_bound(abs(e))
    assert isinstance(b, PathBound) and b.cross_track_bound is None and b.kind == "line"
    assert "no Cartesian guarantee" in b.reason
    assert b.heading_rate_max == pytest.approx(VA * math.tan(abs(e)) / L1)
    assert b.cross_track_rate_initial == pytest.approx(VA * math.tan(abs(e)))
    # C leaves the line at V_A tan(e) from the first instant, then faster (the chassis turns)
    assert ser.cross_track[10] == pytest.approx(VA * math.tan(e) * t[10], rel=1e-2)
    assert abs(ser.cross_track[-1]) > abs(VA * math.tan(e) * t[-1])
    v = path_verdict(path_errors(ref, t, C, th), b)
    assert v.verdict == "no-guarantee" and v.cross_track_bound is None and "no Cartesian guarantee" in v.text


def test_path_bound_classifies_the_reference():
    paper = make_reference(paper_circle(C80), C80)
    settle = float(paper.t[np.nonzero(paper.s >= paper_circle(C80).starts[-2])[0][0]])
    b = path_bound(paper, 0.046334, settle_s=settle)
    assert b.kind == "circle" and b.radius == pytest.approx(1.0)
    # the certificate's |E| <= 0.0463 rad: dR/dalpha = -1.29 m/rad at alpha0, -1.52 at alpha0 - E_max, so
    # C's steady circle stays within 0.065 m (exact; linear 1.52 x 0.0463 = 0.070 m) of 1 m
    assert b.radius_shift == pytest.approx(L1 / math.sin(b.alpha0 - 0.046334) - 1.0)
    assert b.radius_shift == pytest.approx(0.0648, abs=1e-4)
    assert b.radius_shift_linear == pytest.approx(0.0703, abs=1e-4)
    assert b.cross_track_bound == pytest.approx(2 * b.radius_shift)
    whole = path_bound(paper, 0.046334)
    assert whole.kind == "none" and whole.cross_track_bound is None and "with straights" in whole.reason
    lane = make_reference(line(0.5) + lane_change(0.5, 4.0) + line(2.0), C80, dt=1e-2)
    assert path_bound(lane, 0.05).cross_track_bound is None
    assert path_bound(paper, None, settle_s=settle).reason.startswith("no Cartesian guarantee: there is no bound")
    wide = circle_bound(1.0, 0.7)  # alpha0 - E_max <= 0: C may go straight
    assert wide.cross_track_bound is None and "go straight" in wide.reason
    d = b.to_dict()
    assert isinstance(d["assumptions"], list) and any("steady state" in a for a in d["assumptions"])
    assert any("transient" in a for a in d["assumptions"])


def test_verdict_beyond_and_bad_input():
    b = circle_bound(1.0, 0.01)
    v = path_verdict({"cross_track_max": 1.0, "cross_track_max_after_settle": None}, b)
    assert v.verdict == "beyond-bound" and v.ratio > 1 and "BEYOND" in v.text
    with pytest.raises(ParameterError):
        circle_bound(1.0, -0.1)
    with pytest.raises(ParameterError):
        path_bound(object(), 0.1)
