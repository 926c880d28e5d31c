"""Reference trajectories (wmr_mj.reference.paths) against independent truths.

Geometry (circle fits), kinematics (an independent RK4 unicycle), calculus
(numerical derivatives), the paper's bounds (5.1), continuity, feasibility and
argument checks.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from wmr_mj import C80, with_params
from wmr_mj.errors import InfeasiblePathError, ParameterError
from wmr_mj.reference.paths import (
    PAPER_BOUNDS,
    Path,
    Reference,
    circle,
    figure_eight,
    join,
    lane_change,
    line,
    make_reference,
    paper_circle,
    steering_limits,
    steering_ramp,
    transition,
)

L1, VA = C80.l1, C80.V_A


@pytest.fixture(scope="module")
def paper_ref() -> Reference:
    return make_reference(paper_circle(C80), C80)


@pytest.fixture(scope="module")
def blend_ref() -> Reference:
    return make_reference(paper_circle(C80, entry="blend"), C80)


@pytest.fixture(scope="module")
def lane_ref() -> Reference:
    return make_reference(line(1.0) + lane_change(1.0, 5.0) + line(5.0), C80)


@pytest.fixture(scope="module")
def eight_ref() -> Reference:
    return make_reference(line(0.5) + figure_eight(1.0) + line(0.5), C80)


def fit_circle(xy: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Kasa least-squares circle: centre, radius, max |distance - radius|."""
    x, y = xy[:, 0], xy[:, 1]
    M = np.column_stack([x, y, np.ones_like(x)])
    c = np.linalg.lstsq(M, x * x + y * y, rcond=None)[0]
    centre = c[:2] / 2
    r = math.sqrt(c[2] + centre @ centre)
    d = np.hypot(x - centre[0], y - centre[1])
    return centre, r, float(np.max(np.abs(d - r)))


def rk4_unicycle(ref: Reference) -> tuple[np.ndarray, np.ndarray]:
    """A's path from alpha0 alone: x' = V_A cos th, y' = V_A sin th, th' = V_A tan(alpha0)/l1.

    Classical RK4 with step 2 dt, taking alpha0 at the grid samples k, k+1
    (midpoint), k+2. Returns A at the even samples and theta there.
    """
    a = ref.alpha0
    h = 2 * ref.dt
    n = (len(a) - 1) // 2
    state = np.array([ref.A_xy[0, 0], ref.A_xy[0, 1], ref.theta[0]])
    out = np.empty((n + 1, 3))
    out[0] = state

    def f(z, alpha):
        return np.array([VA * math.cos(z[2]), VA * math.sin(z[2]), VA * math.tan(alpha) / L1])

    for k in range(n):
        a0, am, a1 = a[2 * k], a[2 * k + 1], a[2 * k + 2]
        k1 = f(state, a0)
        k2 = f(state + 0.5 * h * k1, am)
        k3 = f(state + 0.5 * h * k2, am)
        k4 = f(state + h * k3, a1)
        state = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[k + 1] = state
    return out[:, :2], out[:, 2]


def at_s(ref: Reference, s: float, values: np.ndarray) -> np.ndarray:
    """Linear interpolation of per-sample values at C's arc length s."""
    values = np.asarray(values)
    if values.ndim == 1:
        return np.interp(s, ref.s, values)
    return np.array([np.interp(s, ref.s, values[:, j]) for j in range(values.shape[1])])


# --------------------------------------------------------------------------
# (a) steady circle
@pytest.mark.parametrize("radius", [1.0, -2.0, 0.8])
def test_steady_circle_angle_and_radius(radius: float) -> None:
    ref = make_reference(circle(radius, turns=1.25), C80)
    expected = math.asin(L1 / radius)
    # the integration starts at the steady angle, an equilibrium of alpha' = kappa - sin(alpha)/l1:
    # measured <= 1.1e-16; 1e-9 is 10 times the integration's rtol 1e-10 (paths._RTOL)
    assert np.max(np.abs(ref.alpha0 - expected)) < 1e-9
    assert np.max(np.abs(ref.alpha0_dot)) < 1e-9
    assert np.max(np.abs(ref.alpha0_ddot)) < 1e-9
    _, r, resid = fit_circle(ref.C_xy)
    assert abs(r - abs(radius)) < 1e-6 and resid < 1e-6
    # A runs on the concentric circle of radius sqrt(R^2 - l1^2)
    _, rA, residA = fit_circle(ref.A_xy)
    assert abs(rA - math.sqrt(radius**2 - L1**2)) < 1e-6 and residA < 1e-6
    # C moves at V_C = V_A / cos(alpha)
    vC = np.hypot(*np.gradient(ref.C_xy, ref.dt, axis=0).T)[1:-1]
    assert np.allclose(vC, VA / math.cos(expected), rtol=1e-5)


def test_paper_circle_on_the_circle(paper_ref: Reference) -> None:
    path = paper_circle(C80)
    on = paper_ref.s >= path.starts[-2] + 1e-9
    assert on.sum() > 20000
    assert np.max(np.abs(paper_ref.alpha0[on] - math.asin(L1 / 1.0))) < 1e-8
    _, r, resid = fit_circle(paper_ref.C_xy[on])
    assert abs(r - 1.0) < 1e-6 and resid < 1e-6


# --------------------------------------------------------------------------
# (b) independent kinematics
@pytest.mark.slow
@pytest.mark.parametrize("name", ["paper_ref", "blend_ref", "lane_ref", "eight_ref"])
def test_A_and_C_from_independent_unicycle(name: str, request: pytest.FixtureRequest) -> None:
    ref: Reference = request.getfixturevalue(name)
    assert np.allclose(ref.A_xy[0], [0.0, 0.0], atol=1e-15) and ref.theta[0] == 0.0
    A, theta = rk4_unicycle(ref)
    assert np.max(np.abs(A - ref.A_xy[::2][: len(A)])) < 1e-7
    assert np.max(np.abs(theta - ref.theta[::2][: len(A)])) < 1e-7
    C = A + L1 * np.column_stack([np.cos(theta), np.sin(theta)])
    assert np.max(np.abs(C - ref.C_xy[::2][: len(A)])) < 1e-7
    # C's arc length: ds/dt = V_A / cos(alpha0)
    ds = np.gradient(ref.s, ref.dt)[1:-1]
    assert np.allclose(ds, VA / np.cos(ref.alpha0[1:-1]), rtol=1e-6)


# --------------------------------------------------------------------------
# (c) analytic derivatives vs numerical ones
@pytest.mark.parametrize("name", ["paper_ref", "blend_ref", "lane_ref", "eight_ref"])
def test_derivatives_match_numerical(name: str, request: pytest.FixtureRequest) -> None:
    ref: Reference = request.getfixturevalue(name)
    inner = slice(5, -5)
    d1 = np.gradient(ref.alpha0, ref.dt)[inner]
    d2 = np.gradient(ref.alpha0_dot, ref.dt)[inner]
    assert np.max(np.abs(d1 - ref.alpha0_dot[inner])) < 1e-6
    assert np.max(np.abs(d2 - ref.alpha0_ddot[inner])) < 1e-4 * max(1.0, np.max(np.abs(ref.alpha0_ddot)))


# --------------------------------------------------------------------------
# (d) the paper's bounds (5.1)
def test_paper_circle_bounds(paper_ref: Reference) -> None:
    b = paper_ref.bounds()
    assert b.alpha_dot_max == pytest.approx(PAPER_BOUNDS.alpha_dot_max, rel=0.03)
    assert b.alpha_ddot_max <= PAPER_BOUNDS.alpha_ddot_max
    assert 1.23 <= b.sin_cos3_max <= 1.25
    # alpha settles on the circle's steady angle (a stable equilibrium) within the integration's
    # rtol 1e-10 (measured 2e-16); 1e-9 is 10 times that. The duration is grid arithmetic: rounding
    assert b.alpha_max == pytest.approx(math.asin(L1), abs=1e-9)
    assert paper_ref.duration == pytest.approx(35.0, abs=1e-9)
    assert len(paper_ref) == 35001
    assert paper_ref.s[-1] == pytest.approx(paper_circle(C80).length, abs=1e-6)
    # the straight lead-in: alpha0 = 0 for 0.4 m = 2 s
    assert np.all(paper_ref.alpha0[paper_ref.t < 1.999] == 0.0)


def test_paper_circle_blend_entry(blend_ref: Reference) -> None:
    b = blend_ref.bounds()
    # the acceleration bound binds; a monotone curvature cannot give more than V_A/R
    assert b.alpha_ddot_max == pytest.approx(0.4, rel=1e-3)
    # the blend's length is found by brentq (xtol 1e-9 m on ~1.5 m): that moves the peak by < 1e-9
    # relative; the sampled peak lies below (measured 4.1e-7 below)
    assert b.alpha_ddot_max <= 0.4 + 1e-9
    assert b.alpha_dot_max < VA / 1.0
    # the path's own curvature function, evaluated: rounding; the duration is grid arithmetic
    assert np.all(np.diff(blend_ref.kappa) >= -1e-12) and blend_ref.kappa.max() <= 1.0 + 1e-12
    assert blend_ref.duration == pytest.approx(35.0, abs=1e-9)


def test_paper_circle_other_speed() -> None:
    fast = with_params(C80, V_A=0.3)
    b = make_reference(paper_circle(fast, duration=20.0), fast).bounds()
    assert b.alpha_dot_max == pytest.approx(0.23, rel=0.01)
    assert b.alpha_ddot_max <= 0.4


# --------------------------------------------------------------------------
# (e) continuity
def _max_jump_ratio(x: np.ndarray, window: int = 10) -> float:
    """Largest one-step change over the largest window-averaged step: ~1 when smooth."""
    one = np.max(np.abs(np.diff(x)))
    avg = np.max(np.abs(x[window:] - x[:-window])) / window
    return float(one / max(avg, 1e-300))


def test_jump_detector_catches_a_jump() -> None:
    t = np.linspace(0, 1, 1001)
    smooth = np.sin(3 * t)
    assert _max_jump_ratio(smooth) < 1.1
    assert _max_jump_ratio(smooth + 0.01 * (t > 0.5)) > 3


@pytest.mark.parametrize("name", ["paper_ref", "blend_ref", "lane_ref", "eight_ref"])
def test_continuity(name: str, request: pytest.FixtureRequest) -> None:
    ref: Reference = request.getfixturevalue(name)
    for x in (ref.alpha0, ref.alpha0_dot, ref.alpha0_ddot, ref.kappa):
        assert _max_jump_ratio(x) < 1.5


def test_curvature_c2_at_joints() -> None:
    path = paper_circle(C80)
    for s in path.starts[1:-1]:
        e = 1e-7
        for f in (path.curvature, path.curvature_rate):
            left, right = f(np.array([s - e, s + e]))
            assert abs(left - right) < 1e-5


def test_curvature_jump_refused_and_join_bridges() -> None:
    with pytest.raises(ParameterError, match="curvature jumps"):
        line(1.0) + circle(1.0)
    with pytest.raises(ParameterError, match="transition"):
        join(line(1.0), circle(1.0))
    p = join(line(1.0), circle(2.0, angle=1.0), line(1.0), transition=0.5)
    assert [s.kind for s in p.segments] == ["line", "transition", "arc", "transition", "line"]
    assert p.length == pytest.approx(1.0 + 0.5 + 2.0 + 0.5 + 1.0)
    assert p.heading_change == pytest.approx(1.0 + 2 * 0.5 * 0.5 / 2.0)
    ref = make_reference(p, C80)
    assert _max_jump_ratio(ref.alpha0_ddot) < 1.5


# --------------------------------------------------------------------------
# (f) infeasible paths
def _s_t(msg: str) -> tuple[float, float]:
    m = re.search(r"s = ([-\d.]+) m \(t = ([-\d.]+) s\)", msg)
    assert m, msg
    return float(m.group(1)), float(m.group(2))


def test_radius_below_wheelbase_is_infeasible() -> None:
    with pytest.raises(InfeasiblePathError, match="wheelbase") as e:
        make_reference(circle(0.5), C80)
    assert _s_t(str(e.value)) == (0.0, 0.0)
    with pytest.raises(InfeasiblePathError, match="wheelbase") as e:
        make_reference(line(0.4) + transition(0.5, to_radius=0.5) + circle(0.5), C80)
    s, t = _s_t(str(e.value))
    assert s == pytest.approx(0.9, abs=1e-4) and 0.9 * math.cos(0.9) / VA < t < 0.9 / VA
    with pytest.raises(InfeasiblePathError, match="wheelbase"):
        paper_circle(C80, radius=0.5)


@pytest.mark.parametrize(
    "kw, limit",
    [({}, "max_angle"), ({"max_rate": 0.1}, "max_rate"), ({"max_accel": 0.05}, "max_accel")],
)
def test_too_fast_lane_change_is_infeasible(kw: dict, limit: str) -> None:
    path = line(0.5) + lane_change(1.0, 1.4 if not kw else 3.0) + line(1.0)
    with pytest.raises(InfeasiblePathError, match=limit) as e:
        make_reference(path, C80, **kw)
    s, t = _s_t(str(e.value))
    assert 0.5 < s < path.length
    assert s * math.cos(0.9) / VA - 1e-3 < t < s / VA
    value = {"max_angle": 0.9, **kw}[limit]
    assert f"{value:.4g}" in str(e.value)


def test_default_limits() -> None:
    lim = steering_limits(C80)
    assert lim["max_angle"] == C80.steering_range
    assert lim["max_rate"] == pytest.approx(24.0 / (C80.k_b * C80.i2))
    assert lim["max_accel"] == pytest.approx(24.0 / C80.coefficients().P)
    with pytest.raises(InfeasiblePathError, match="max_accel"):
        make_reference(line(0.5) + transition(0.001, to_radius=1.0) + circle(1.0), C80)


# --------------------------------------------------------------------------
# (g) lane change and figure eight geometry
@pytest.mark.parametrize("offset", [1.0, -0.5])
def test_lane_change_offset_and_heading(offset: float) -> None:
    lc = lane_change(offset, 5.0)
    ref = make_reference(line(1.0) + lc + line(6.0), C80)
    s_end = 1.0 + lc.length
    C_end = at_s(ref, s_end, ref.C_xy)
    assert C_end[1] == pytest.approx(offset, abs=1e-6)  # C starts at y = 0
    assert C_end[0] - at_s(ref, 1.0, ref.C_xy)[0] == pytest.approx(5.0, abs=1e-6)
    phi = ref.theta + ref.alpha0  # C's direction of motion
    assert abs(at_s(ref, s_end, phi)) < 1e-6
    assert np.all(np.abs(ref.C_xy[ref.s >= s_end, 1] - offset) < 1e-6)
    assert abs(ref.theta[-1]) < 1e-3 and abs(ref.alpha0[-1]) < 1e-3  # settled on the straight


def test_figure_eight_closes() -> None:
    f8 = figure_eight(1.0, laps=2)
    assert f8.heading_change == pytest.approx(0.0, abs=1e-12)
    ref = make_reference(line(0.5) + f8 + line(0.5), C80)
    phi = ref.theta + ref.alpha0
    start = at_s(ref, 0.5, ref.C_xy)
    lobe = f8.length / 4
    for j in range(1, 5):  # back at the crossing point after every lobe
        assert np.allclose(at_s(ref, 0.5 + j * lobe, ref.C_xy), start, atol=1e-6)
    assert abs(at_s(ref, 0.5 + f8.length, phi)) < 1e-6
    # the lobes turn left then right, |kappa| <= 1/R, and cross at an angle
    assert ref.kappa.max() == pytest.approx(1.0) and ref.kappa.min() == pytest.approx(-1.0)
    psi = at_s(ref, 0.5 + lobe, phi)
    assert math.pi < psi < 2 * math.pi - 0.1


# --------------------------------------------------------------------------
# the Reference object
def test_at_interpolates(paper_ref: Reference) -> None:
    fine = make_reference(paper_circle(C80), C80, dt=5e-4)
    t_mid = fine.t[1:-1:2][:69000]
    a, ad, add = paper_ref.at(t_mid)
    # one integration (dense output over s) sampled on two grids: the difference is at()'s cubic
    # Hermite error, O(dt^4): measured 9e-15 rad (alpha0) and 1.5e-12 rad/s (alpha0'); 1e-10 is the
    # integration's rtol
    assert np.max(np.abs(a - fine.alpha0[1:-1:2][:69000])) < 1e-10
    assert np.max(np.abs(ad - fine.alpha0_dot[1:-1:2][:69000])) < 1e-8
    assert np.max(np.abs(add - fine.alpha0_ddot[1:-1:2][:69000])) < 1e-4
    g = paper_ref.at(paper_ref.t)
    assert np.array_equal(g[0], paper_ref.alpha0) or np.allclose(g[0], paper_ref.alpha0, atol=1e-15)
    x = paper_ref.at(12.3456)
    assert all(isinstance(v, float) for v in x)
    with pytest.raises(ParameterError, match="duration"):
        paper_ref.at(35.1)
    with pytest.raises(ParameterError):
        paper_ref.at(-0.01)


def test_reference_fields(paper_ref: Reference) -> None:
    n = len(paper_ref)
    for name in ("t", "s", "alpha0", "alpha0_dot", "alpha0_ddot", "theta", "kappa"):
        arr = getattr(paper_ref, name)
        assert arr.shape == (n,) and not arr.flags.writeable
    assert paper_ref.A_xy.shape == (n, 2) and paper_ref.C_xy.shape == (n, 2)
    assert np.allclose(np.diff(paper_ref.t), 1e-3)
    assert np.allclose(np.hypot(*(paper_ref.C_xy - paper_ref.A_xy).T), L1)
    assert set(paper_ref.bounds().to_dict()) == {"alpha_dot_max", "alpha_ddot_max", "sin_cos3_max", "alpha_max"}


def test_pose_and_duration_options() -> None:
    base = make_reference(line(0.2) + steering_ramp(1.0, l1=L1, to_radius=2.0) + circle(2.0), C80, duration=10.0)
    moved = make_reference(
        line(0.2) + steering_ramp(1.0, l1=L1, to_radius=2.0) + circle(2.0), C80, duration=10.0,
        origin=(1.0, -2.0), heading=0.5,
    )
    assert base.duration == pytest.approx(10.0)
    rot = np.array([[math.cos(0.5), -math.sin(0.5)], [math.sin(0.5), math.cos(0.5)]])
    # the pose is applied to the same integrated positions: rounding (measured 9e-16 m, 2e-16 rad)
    assert np.allclose(moved.A_xy, base.A_xy @ rot.T + [1.0, -2.0], atol=1e-9)
    assert np.allclose(moved.theta, base.theta + 0.5, atol=1e-12)
    assert np.array_equal(moved.alpha0, base.alpha0)
    with pytest.raises(ParameterError, match="duration"):
        make_reference(line(1.0), C80, duration=6.0)  # the path takes 5 s


# --------------------------------------------------------------------------
# bad arguments
@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: line(0.0), "length"),
        (lambda: line(-1.0), "length"),
        (lambda: line(float("nan")), "length"),
        (lambda: line("1"), "length"),
        (lambda: circle(0.0), "radius"),
        (lambda: circle(math.inf), "radius"),
        (lambda: circle(1.0, turns=-1.0), "turns"),
        (lambda: circle(1.0, turns=1.0, angle=1.0), "one of"),
        (lambda: circle(1.0, length=float("inf")), "length"),
        (lambda: transition(0.0, to_radius=1.0), "length"),
        (lambda: transition(1.0, to_radius=0.0), "to_radius"),
        (lambda: steering_ramp(1.0, l1=L1, to_radius=0.5), "to_radius"),
        (lambda: lane_change(0.0, 1.0), "offset"),
        (lambda: lane_change(1.0, -1.0), "length"),
        (lambda: lane_change(1.0, 1.0), "offset"),
        (lambda: figure_eight(1.0, laps=0), "laps"),
        (lambda: figure_eight(1.0, transition=5.0), "transition"),
        (lambda: make_reference(line(1.0), C80, dt=0.0), "dt"),
        (lambda: make_reference(line(1.0), C80, dt=float("nan")), "dt"),
        (lambda: make_reference(line(1.0), C80, dt=10.0), "dt"),
        (lambda: make_reference(line(1.0), C80, duration=-1.0), "duration"),
        (lambda: make_reference(line(1.0), C80, max_rate=0.0), "max_rate"),
        (lambda: make_reference(line(1.0), C80, max_angle=2.0), "max_angle"),
        (lambda: make_reference(line(1.0), C80, origin=(0.0, math.nan)), "origin"),
        (lambda: make_reference("path", C80), "path"),
        (lambda: paper_circle(C80, duration=0.0), "duration"),
        (lambda: paper_circle(C80, duration=3.0), "duration"),
        (lambda: paper_circle(C80, lead_in=-0.4), "lead_in"),
        (lambda: paper_circle(C80, entry="spline"), "entry"),
        (lambda: Path(()), "segment"),
    ],
)
def test_bad_arguments(call, name: str) -> None:
    with pytest.raises(ParameterError, match=name):
        call()


def test_too_short_a_duration_names_the_minimum_the_paper_circle_needs():
    """The message states C's time over the lead-in and entry, computed here by hand: on the line alpha = 0
    and C moves at V_A; on the ramp alpha(s) = asin(l1/R) S7(s/L) and dt/ds = cos(alpha)/V_A (C outruns A)."""
    from scipy.integrate import quad

    lead, L, R = 0.4, 1.5, 1.0
    a1 = math.asin(L1 / R)
    ramp = quad(lambda s: math.cos(a1 * (35 * (s / L) ** 4 - 84 * (s / L) ** 5 + 70 * (s / L) ** 6
                                         - 20 * (s / L) ** 7)), 0.0, L, epsabs=1e-13, epsrel=1e-12)[0]
    t_min = (lead + ramp) / VA
    with pytest.raises(ParameterError) as info:
        paper_circle(C80, radius=R, lead_in=lead, transition=L, duration=2.0)
    msg = str(info.value)
    assert "\n" not in msg and "duration = 2.0 s" in msg
    took, least = (float(x) for x in re.search(r"take (\d+\.\d+) s; .*at least (\d+\.\d+) s", msg).groups())
    # the message rounds to 1 ms (nearest, then up); the path's own integration (DOP853) is far finer
    assert abs(took - t_min) <= 0.5e-3 + 1e-9
    assert t_min <= least < t_min + 1e-3 + 1e-9
    paper_circle(C80, radius=R, lead_in=lead, transition=L, duration=least)  # the minimum it names is accepted
