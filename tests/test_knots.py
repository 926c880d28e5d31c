"""Knot paths (wmr_mj.reference.knots) and reading reference bounds (wmr_mj.reference.bounds).

Truths: the steering reference that make_reference integrates (feasibility against the declared
bounds, the closed-form ramp), a numerical differentiation of the closed-form ramp in time
(ramp_length's peaks, without the package's alpha'' formula), brentq on sin/cos^3, the route text.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from wmr_mj import C80
from wmr_mj.errors import ParameterError
from wmr_mj.reference.bounds import PAPER_BOUNDS, ReferenceBounds, angle_of_sin_cos3, reference_bounds_from, sin_cos3
from wmr_mj.reference.knots import KnotSpace, kappa_max, knot_path, ramp_length
from wmr_mj.reference.paths import _s7, make_reference, paper_circle, steering_limits
from wmr_mj.reference.route import load_route, route_from_path

L1, VA = C80.l1, C80.V_A
PAPER = reference_bounds_from("paper")
# a declaration where the acceleration bound binds on most ramps
SLOW = reference_bounds_from("alpha_dot_max=0.3,alpha_ddot_max=0.05,alpha_max=0.5")


def within(measured: ReferenceBounds, declared: ReferenceBounds) -> None:
    # the measured bounds come from the reference's alpha(s), integrated at rtol 1e-10 (paths._RTOL):
    # 1e-9 relative is 10 times that. Measured: alpha on the angle bound 1e-12 to 1e-11 below it,
    # the rates ~1e-6 below (ramp_length takes the peaks 1e-6 high)
    assert measured.alpha_dot_max <= declared.alpha_dot_max * (1 + 1e-9)
    assert measured.alpha_ddot_max <= declared.alpha_ddot_max * (1 + 1e-9)
    assert measured.alpha_max is not None and measured.alpha_max <= declared.angle_max * (1 + 1e-9)
    assert measured.sin_cos3_max <= declared.sin_cos3_max * (1 + 1e-9)


# --------------------------------------------------------------------------- feasible by construction
@pytest.mark.parametrize(("seed", "hold", "bounds"), [
    (1, 0.0, PAPER), (2, 0.7, PAPER), (3, 2.0, PAPER), (4, 0.0, SLOW), (5, 1.2, SLOW),
])
def test_random_knot_paths_keep_the_declared_bounds(seed, hold, bounds):
    rng = np.random.default_rng(seed)
    km = kappa_max(bounds, C80)
    knots = rng.uniform(-km, km, 4)
    knots[rng.integers(4)] = km * rng.choice([-1.0, 1.0])  # one knot at the angle bound
    path = knot_path(knots, hold_s=hold, bounds=bounds, params=C80, duration=18.0)
    ref = make_reference(path, C80, dt=1e-3, duration=18.0)
    within(ref.bounds(), bounds)


@pytest.mark.parametrize("bounds", [PAPER, SLOW], ids=["paper", "slow"])
def test_a_full_swing_reaches_its_binding_bound(bounds):
    km = kappa_max(bounds, C80)
    path = knot_path([-km, km], hold_s=1.0, bounds=bounds, params=C80, duration=15.0)
    got = make_reference(path, C80, dt=1e-3).bounds()
    within(got, bounds)
    used = max(got.alpha_dot_max / bounds.alpha_dot_max, got.alpha_ddot_max / bounds.alpha_ddot_max)
    assert used == pytest.approx(1.0, rel=1e-3)  # as fast as allowed, not slower
    assert got.alpha_max == pytest.approx(bounds.angle_max, rel=1e-8)  # the arcs sit on the angle bound


def test_alpha0_along_a_ramp_is_the_closed_form_smoothstep():
    k1, k2 = 0.8, -0.6
    path = knot_path([k1, k2], hold_s=1.5, bounds=PAPER, params=C80, duration=15.0)
    kinds = [seg.kind for seg in path.segments]
    assert kinds[:5] == ["line", "ramp", "arc", "ramp", "arc"]
    ramp, s0 = path.segments[3], float(path.starts[3])
    ref = make_reference(path, C80, dt=1e-3)
    m = (ref.s >= s0) & (ref.s <= s0 + ramp.length)
    assert m.sum() > 1000
    a_from, a_to = math.asin(L1 * k1), math.asin(L1 * k2)
    closed = a_from + (a_to - a_from) * _s7((ref.s[m] - s0) / ramp.length)
    assert np.max(np.abs(ref.alpha0[m] - closed)) < 1e-8
    # and the arcs hold the knot's steady angle
    on_arc = (ref.s > float(path.starts[4]) + 1e-3) & (ref.s < float(path.starts[5]))
    assert np.max(np.abs(ref.alpha0[on_arc] - a_to)) < 1e-8


def _ramp_peaks(a_from: float, a_to: float, L: float) -> tuple[float, float]:
    """max |alpha'|, |alpha''| of the closed-form ramp, differentiated numerically in time
    (2e4 steps: a finer grid loses more to round-off than it gains; about 1e-6 relative)."""
    s = np.linspace(0.0, L, 20_001)
    alpha = a_from + (a_to - a_from) * _s7(s / L)
    dt_ds = np.cos(alpha) / VA  # C moves at V_A / cos(alpha)
    t = np.concatenate([[0.0], np.cumsum(0.5 * (dt_ds[1:] + dt_ds[:-1]) * np.diff(s))])
    rate = np.gradient(alpha, t, edge_order=2)
    accel = np.gradient(rate, t, edge_order=2)
    return float(np.max(np.abs(rate))), float(np.max(np.abs(accel)))


@pytest.mark.parametrize(("a_from", "a_to", "bounds"), [
    (0.0, 0.6, PAPER), (-0.65, 0.65, PAPER), (0.3, 0.35, PAPER), (0.45, -0.2, SLOW), (-0.5, 0.5, SLOW),
])
def test_ramp_length_is_the_shortest_feasible(a_from, a_to, bounds):
    L = ramp_length(a_from, a_to, bounds=bounds, V_A=VA)
    rate, accel = _ramp_peaks(a_from, a_to, L)
    used = max(rate / bounds.alpha_dot_max, accel / bounds.alpha_ddot_max)
    assert used == pytest.approx(1.0, abs=1e-5)
    rate, accel = _ramp_peaks(a_from, a_to, 0.99 * L)
    assert rate > bounds.alpha_dot_max or accel > bounds.alpha_ddot_max


def test_ramp_length_edge_cases():
    assert ramp_length(0.4, 0.4, bounds=PAPER, V_A=VA) == 0.0
    # symmetric: steering back is as long as steering out
    assert ramp_length(0.0, 0.5, bounds=PAPER, V_A=VA) == pytest.approx(
        ramp_length(0.5, 0.0, bounds=PAPER, V_A=VA), rel=1e-9)  # mirrored peaks: rounding (6e-16 measured)
    # paper_circle's entry, found from the peaks of its own integration: the same ramp, 1e-6 longer here
    entry = paper_circle(C80, duration=10.0).segments[1]
    assert entry.kind == "ramp"
    assert ramp_length(0.0, math.asin(L1), bounds=PAPER, V_A=VA) == pytest.approx(entry.length, rel=2e-6)
    with pytest.raises(ParameterError, match="alpha_dot_max"):
        ramp_length(0.0, 0.1, bounds={"alpha_dot_max": 0.0}, V_A=VA)
    with pytest.raises(ParameterError, match="a_to"):
        ramp_length(0.0, 1.6, bounds=PAPER, V_A=VA)


# --------------------------------------------------------------------------- bounds
def test_paper_angle_bound_inverts_sin_cos3():
    a = PAPER_BOUNDS.angle_max
    truth = brentq(lambda x: math.sin(x) / math.cos(x) ** 3 - 1.24, 0.0, 1.5, xtol=1e-15)
    assert a == pytest.approx(truth, abs=1e-13)
    circle = math.asin(L1 / 1.0)  # the paper circle's steady angle, sin/cos^3 = 1.237 < 1.24
    assert sin_cos3(circle) == pytest.approx(1.237, abs=1e-3)
    assert circle < a < circle + 1e-3
    assert PAPER.alpha_max == a and PAPER.sin_cos3_max == 1.24
    assert kappa_max(PAPER, C80) == pytest.approx(math.sin(a) / L1, rel=1e-15)
    for c in (0.0, 1e-9, 0.3, 5.0, 1e4):
        assert sin_cos3(angle_of_sin_cos3(c)) == pytest.approx(c, rel=1e-12, abs=1e-18)
    # alpha_max given below sin_cos3_max's angle: the smaller one counts
    assert ReferenceBounds(alpha_max=0.5).angle_max == 0.5


def test_reference_bounds_from_reads_and_round_trips():
    assert reference_bounds_from(None) is None
    assert reference_bounds_from(PAPER_BOUNDS) is PAPER_BOUNDS
    b = reference_bounds_from("alpha_dot_max=0.23, alpha_ddot_max=0.4, alpha_max=0.6")
    assert b == ReferenceBounds(alpha_ddot_max=0.4, alpha_dot_max=0.23, sin_cos3_max=sin_cos3(0.6), alpha_max=0.6)
    assert reference_bounds_from(b.to_dict()) == b
    assert reference_bounds_from(",".join(f"{k}={v!r}" for k, v in b.to_dict().items())) == b
    partial = reference_bounds_from({"alpha_ddot_max": 0.1})
    assert partial.alpha_dot_max == PAPER_BOUNDS.alpha_dot_max and partial.alpha_max == PAPER.alpha_max
    assert reference_bounds_from(f"sin_cos3_max=0.5,alpha_max={angle_of_sin_cos3(0.5)!r}").sin_cos3_max == 0.5


@pytest.mark.parametrize(("value", "culprit"), [
    ("alpha_dot=0.2", "'alpha_dot'"),
    ("alpha_dot_max=fast", "alpha_dot_max = 'fast'"),
    ("alpha_ddot_max=-0.4", "alpha_ddot_max = '-0.4'"),
    ({"alpha_max": float("nan")}, "alpha_max = nan"),
    ("alpha_max=1.6", "alpha_max = '1.6'"),
    ("alpha_max=0.6,sin_cos3_max=1.24", "disagree"),
    ("alpha_dot_max=0.1,alpha_dot_max=0.2", "given twice"),
    ("papr", "'papr'"),
    ({"rate": 1.0}, "'rate'"),
    (42, "42"),
])
def test_reference_bounds_from_refuses_bad_input(value, culprit):
    with pytest.raises(ParameterError) as exc:
        reference_bounds_from(value)
    msg = str(exc.value)
    assert "\n" not in msg and culprit in msg
    if "disagree" not in msg and "twice" not in msg:
        assert "alpha_ddot_max" in msg and "sin_cos3_max" in msg  # what is accepted


# --------------------------------------------------------------------------- refusals, route, space
def test_knot_path_refuses_what_it_cannot_guarantee():
    km = kappa_max(PAPER, C80)
    with pytest.raises(ParameterError, match=r"knot 2 \(path.k2\) = 1\.1 1/m .* kappa_max = 1\.00079"):
        knot_path([0.5, 1.1], hold_s=1.0, bounds=PAPER, duration=10.0)
    knot_path([0.5, -km], hold_s=1.0, bounds=PAPER, duration=10.0)  # exactly at the limit is fine
    lim = steering_limits(C80)
    with pytest.raises(ParameterError, match="rate alpha_dot_max .* max_rate"):
        knot_path([0.5], hold_s=1.0, bounds={"alpha_dot_max": 2 * lim["max_rate"]}, duration=10.0)
    with pytest.raises(ParameterError, match="angle .* max_angle"):
        knot_path([0.5], hold_s=1.0, bounds={"alpha_max": 1.0}, duration=10.0)
    with pytest.raises(ParameterError, match="hold_s"):
        knot_path([0.5], hold_s=-1.0, bounds=PAPER, duration=10.0)


@pytest.mark.parametrize("hold", [0.0, 1.0])
def test_knot_path_lasts_the_duration_and_survives_its_route_text(hold):
    path = knot_path([0.3, -0.9, 0.0], hold_s=hold, bounds=PAPER, params=C80, duration=20.0)
    assert path.start_curvature == 0.0 and path.end_curvature == 0.0
    T = make_reference(path, C80, dt=1e-3).duration
    assert 20.0 <= T < 20.01
    assert load_route(route_from_path(path).text).path == path


def test_knot_space_axes_ranges_and_paths():
    space = KnotSpace(knots=3, hold_range=(0.5, 4.0))
    assert space.names == ("path.k1", "path.k2", "path.k3", "path.hold")
    km = kappa_max(PAPER, C80) * (1.0 - 1e-6)  # the ramps' safety margin
    ranges = space.ranges(PAPER, C80)
    assert ranges == {"path.k1": (-km, km), "path.k2": (-km, km), "path.k3": (-km, km), "path.hold": (0.5, 4.0)}
    # a path held at the range's edge stays within every declared bound after integration (one held at
    # kappa_max itself measured sin/cos^3 2e-11 over 1.24)
    corner = {"path.k1": ranges["path.k1"][1], "path.k2": ranges["path.k2"][0], "path.k3": ranges["path.k3"][1],
              "path.hold": 2.0}
    measured = make_reference(space.path(corner, bounds=PAPER, params=C80, duration=25.0), C80, dt=1e-3,
                              duration=25.0).bounds()
    assert measured.sin_cos3_max <= PAPER.sin_cos3_max and measured.alpha_max <= PAPER.angle_max
    assert measured.alpha_dot_max <= PAPER.alpha_dot_max and measured.alpha_ddot_max <= PAPER.alpha_ddot_max
    values = {"path.k1": 0.2, "path.k2": -0.4, "path.k3": 0.9, "path.hold": 1.5}
    assert space.path(values, bounds=PAPER, params=C80, duration=12.0) == knot_path(
        [0.2, -0.4, 0.9], hold_s=1.5, bounds=PAPER, params=C80, duration=12.0)
    with pytest.raises(ParameterError, match="missing path.hold"):
        space.path({"path.k1": 0.2, "path.k2": -0.4, "path.k3": 0.9}, bounds=PAPER, duration=12.0)
    with pytest.raises(ParameterError, match="knots"):
        KnotSpace(knots=0)
    with pytest.raises(ParameterError, match="hold_range"):
        KnotSpace(knots=2, hold_range=(3.0, 1.0))
