"""Cartesian errors of C (wmr_mj.analysis.path_error) against closed forms."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

from wmr_mj import C80
from wmr_mj.analysis.path_error import PathErrors, path_error_series, path_errors, wrap_angle
from wmr_mj.errors import ParameterError
from wmr_mj.reference.paths import circle, figure_eight, line, make_reference

L1, VA = C80.l1, C80.V_A


@pytest.fixture(scope="module")
def straight():
    return make_reference(line(3.0), C80, dt=2e-3)


def _normal(ref):
    phi = np.asarray(ref.theta) + np.asarray(ref.alpha0)  # C's direction of travel
    return np.column_stack([-np.sin(phi), np.cos(phi)])


def test_exact_tracking_gives_zero(straight):
    e = path_errors(straight, straight.t, straight.C_xy, straight.theta)
    assert isinstance(e, PathErrors)
    # on a line alpha0 = 0: the reference's points are the polyline's; projection arithmetic on a
    # 3 m line rounds to ~4e-16 m (measured), so these bounds are rounding bounds
    assert e.cross_track_max < 1e-9 and e.along_track_max < 1e-9 and e.heading_error_max < 1e-12
    assert e.beyond_end_samples == 0 and e.samples == len(straight)


@pytest.mark.parametrize("d", [0.05, -0.3])
def test_lateral_offset_from_a_straight_line(straight, d):
    C = np.asarray(straight.C_xy) + [0.0, d]
    e = path_errors(straight, straight.t, C, straight.theta)
    # a line's chords are the line: rounding only (measured <= 4.4e-16 m)
    assert e.cross_track_max == pytest.approx(abs(d), abs=1e-12)
    assert e.cross_track_final == pytest.approx(d, abs=1e-12)  # > 0: left of the direction of travel
    assert e.cross_track_rms == pytest.approx(abs(d), abs=1e-12)
    assert e.along_track_max < 1e-9


@pytest.mark.parametrize("R", [1.0, -1.5])
@pytest.mark.parametrize("d", [0.02, -0.2])
def test_concentric_circle(R, d):
    ref = make_reference(circle(R, turns=1.3), C80, dt=2e-3)
    phi = np.asarray(ref.theta) + np.asarray(ref.alpha0)
    C = np.asarray(ref.C_xy)
    centre = C[0] + np.array([-math.sin(phi[0]), math.cos(phi[0])]) * R
    # C on the concentric circle of radius |R| + d, at the reference's angle
    rad = C - centre
    C_off = centre + rad * (abs(R) + d) / abs(R)
    e = path_errors(ref, ref.t, C_off, ref.theta)
    # outside a left turn is to the right: cross-track = -d for R > 0, +d for R < 0
    want = -d if R > 0 else d
    assert e.cross_track_final == pytest.approx(want, abs=2e-6)
    assert e.cross_track_max == pytest.approx(abs(d), abs=2e-6)
    assert e.along_track_max < 2e-6  # the radial projection keeps the reference's arc length
    assert e.beyond_end_samples == 0


@pytest.mark.parametrize("path", ["line", "circle"])
def test_timed_lag_gives_minus_lag_times_speed(path):
    ref = make_reference(line(3.0) if path == "line" else circle(1.0, turns=1.2), C80, dt=1e-3)
    lag = 0.5
    t = np.asarray(ref.t)
    k = int(round(lag / ref.dt))
    C = np.asarray(ref.C_xy)[:-k]
    th = np.asarray(ref.theta)[:-k]
    e = path_errors(ref, t[k:], C, th)  # C at time t is where the reference was at t - lag
    V_C = VA / math.cos(float(ref.alpha0[-1]))  # C's speed: V_A on the line, V_A / cos(alpha0) on the circle
    assert e.along_track_final == pytest.approx(-lag * V_C, rel=1e-6)
    assert e.along_track_max == pytest.approx(lag * V_C, rel=1e-6)
    # C on its own path: the heading error is kappa times the projection's error in s. On the chords
    # (<= 4 mm, POLYLINE_SPACING) of an arc of radius R a point of the arc projects with an error in s
    # of at most R b^3 / (9 sqrt 3), b = chord / (2 R): 5.1e-10 m on the 1 m circle, so 5.1e-10 rad
    # (measured 4.4e-10); 1e-9 is twice the method's bound. (On the line: 0.)
    assert e.cross_track_max < 2e-6 and e.heading_error_max < 1e-9


def test_heading_error_is_wrapped(straight):
    h = np.asarray(straight.theta) + 0.1 + 4.0 * math.pi
    e = path_errors(straight, straight.t, straight.C_xy, h)
    # wrapping 0.1 + 4 pi: rounding of the sum (~1e-15)
    assert e.heading_error_final == pytest.approx(0.1, abs=1e-12)
    assert e.heading_error_max == pytest.approx(0.1, abs=1e-12)
    assert float(wrap_angle(math.pi)) == pytest.approx(math.pi)
    assert float(wrap_angle(-math.pi)) == pytest.approx(math.pi)


def test_figure_eight_crossing_does_not_jump():
    """A lateral offset through a figure eight's crossing: a global nearest point would jump to
    the other branch there (distance 0 at the crossing); the continuous projection does not."""
    ref = make_reference(line(0.5) + figure_eight(1.5, laps=2), C80, dt=2e-3)
    d = 0.1
    C = np.asarray(ref.C_xy) + d * _normal(ref)
    ser = path_error_series(ref, ref.t, C, ref.theta)
    assert np.max(np.abs(ser.cross_track - d)) < 2e-5
    assert np.max(np.abs(ser.along_track)) < 2e-5
    assert np.all(np.diff(ser.s) > 0)
    # the path does cross itself: the same point is passed at two arc lengths
    crossings = np.nonzero(np.diff(np.sign(np.asarray(ref.C_xy)[:, 1] - ref.C_xy[0, 1])))[0]
    assert crossings.size >= 4


def test_ahead_of_the_path_end_is_continued():
    ref = make_reference(circle(1.0, turns=0.5), C80, dt=2e-3)
    lead = 0.3
    k = int(round(lead / ref.dt))
    C = np.asarray(ref.C_xy)[k:]
    e = path_errors(ref, np.asarray(ref.t)[:-k], C, np.asarray(ref.theta)[k:])
    assert e.along_track_final == pytest.approx(lead * VA / math.cos(float(ref.alpha0[-1])), rel=1e-6)
    assert e.cross_track_max < 2e-6
    assert e.beyond_end_samples == 0  # no sample needs the continuation here...
    ser = path_error_series(ref, np.asarray(ref.t)[-1:] + 0.2, C[-1:] + [0.0, 0.0], ref.theta[-1:])
    assert ser.cross_track.shape == (1,)


def test_settle_and_to_dict(straight):
    C = np.asarray(straight.C_xy) + np.where(np.asarray(straight.t)[:, None] < 1.0, [0.0, 0.2], [0.0, 0.01])
    e = path_errors(straight, straight.t, C, straight.theta, settle_s=1.0)
    assert e.cross_track_max == pytest.approx(0.2)
    assert e.cross_track_max_after_settle == pytest.approx(0.01)
    d = e.to_dict()
    for key in ("cross_track_max", "cross_track_rms", "cross_track_final", "along_track_final", "along_track_max",
                "heading_error_max", "heading_error_final"):
        assert isinstance(d[key], float)
    with pytest.raises(dataclasses.FrozenInstanceError):
        e.cross_track_max = 0.0


def test_bad_input(straight):
    with pytest.raises(ParameterError, match="must agree"):
        path_errors(straight, straight.t, np.zeros((3, 2)), straight.theta)
    with pytest.raises(ParameterError, match="finite"):
        C = np.array(straight.C_xy)
        C[3, 0] = np.nan
        path_errors(straight, straight.t, C, straight.theta)
    with pytest.raises(ParameterError, match="Reference"):
        path_errors(object(), [0.0], [[0.0, 0.0]], [0.0])


@pytest.mark.slow
def test_replay_reports_the_path_of_c(tmp_path, capsys):
    """A real logged run (certified design, lane change, 6 s): `replay` prints C's path errors,
    --json carries them, --plot draws the path panels; they equal the errors computed directly."""
    import json

    from wmr_mj.cli.app import main
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.writer import RunLogger
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig, build_reference
    from wmr_mj.sim.designs import CERTIFIED

    path = tmp_path / "run.mcap"
    config = RunConfig(**CERTIFIED.config_changes(), path="lane-change", duration=6.0)
    run_closed_loop(config, logger_factory=lambda header: RunLogger(path, header), progress=False)
    assert main(["replay", str(path), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    pe = rep["path_errors"]
    log = load_log(path)
    ref, _ = build_reference("lane-change", C80, dt=1e-3, duration=6.0)
    direct = path_errors(ref, log.signals["t"], log.signals["C_pos"], log.signals["heading"],
                         settle_s=rep["settle_s"])
    assert pe == direct.to_dict()
    assert 0.0 < pe["cross_track_max"] < 0.05 and abs(pe["along_track_final"]) < 0.05
    # a lane change has straights: the certificate gives no Cartesian guarantee there
    assert rep["path_bound"]["cross_track_bound"] is None and rep["path_verdict"]["verdict"] == "no-guarantee"
    png = tmp_path / "run.png"
    assert main(["replay", str(path), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "path of C  cross-track max" in out and "along-track final" in out
    assert "path bound no-guarantee: no Cartesian guarantee" in out
    assert png.stat().st_size > 20000


def test_replay_without_a_path_says_why(tmp_path, capsys):
    from helpers import synthetic_run

    from wmr_mj.cli.app import main

    path = tmp_path / "synthetic.mcap"
    synthetic_run(path, 0.2, block_rows=100)
    assert main(["replay", str(path)]) == 0
    assert "path of C  n/a: the log's configuration names no path" in capsys.readouterr().out


@pytest.mark.parametrize("far", [(0.1, 1e200), (0.1, -1e200), (1e200, 0.0), (1e160, 1e160), (1e300, -1e300)])
def test_a_diverged_position_projects_without_a_warning(straight, far):
    """A point whose squared distance from the path overflows (beyond ~1.3e154 m): once kappa * inf
    (NaN on a line) warned 'invalid value encountered in multiply'; now its cross-track is +-inf by its
    side (+inf on the path's line, ahead), the samples beside it projected as they always were."""
    from wmr_mj.analysis.path_error import PathProjector

    X = np.array([straight.C_xy[10], far, straight.C_xy[20]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s, d, _ = PathProjector(straight).project_many(X, 0.0)
        series = path_error_series(straight, np.array([0.0, 1.0, 2.0]), X, np.zeros(3))
    side = 1.0 if far[1] >= 0.0 else -1.0  # the line runs along +x from the origin: left is +y
    assert d[1] == side * math.inf and series.cross_track[1] == side * math.inf
    # on the path; on a line the chords are the path: rounding of metres only
    assert np.all(np.isfinite(s)) and abs(d[0]) < 1e-9


def _series_with(backend: str, monkeypatch, *args):
    from wmr_mj.analysis import path_error

    monkeypatch.setenv("WMR_MJ_COMPILED_PROJECTION", "1" if backend == "C" else "0")
    if path_error.projection_backend() != backend:
        pytest.skip("wmr_mj.analysis._nearest_chord is not built (no C compiler at install)")
    return path_error_series(*args)


def test_the_compiled_projection_gives_numpys_bits(monkeypatch):
    """C's projection in C (wmr_mj/analysis/_nearest_chord.c) against the NumPy code it replaces, to the
    bit: paths with curvature of both signs, a crossing and a second lap, points on and off the path,
    noisy, far (1e3 m), overflowing (beyond 1e154 m: +-inf) and beyond the path's ends, sampled densely
    and sparsely (windows of a few to thousands of chords); the signs of zeros included."""
    rng = np.random.default_rng(7)
    # sampled every 20 ms (4 mm of path at 0.2 m/s): the NumPy side's windows over scattered points span
    # the whole path, (128 x thousands) arrays a block
    refs = [make_reference(circle(1.0, turns=1.25), C80, dt=2e-2),
            make_reference(line(0.5) + figure_eight(1.5, laps=2), C80, dt=2e-2),
            make_reference(line(3.0), C80, dt=2e-2)]
    compared = 0
    for ref in refs:
        t, C, theta = np.asarray(ref.t), np.asarray(ref.C_xy), np.asarray(ref.theta)
        noisy = C + rng.normal(0.0, 0.3, C.shape)
        huge = C * 1e150 + 1e152
        mixed = C.copy()
        mixed[::97] = rng.choice([-1.0, 1.0], size=mixed[::97].shape) * 10.0 ** rng.uniform(150, 300, mixed[::97].shape)
        point_sets = {"on": C, "offset": C + [0.4, -0.25], "noisy": noisy, "far": C * 1e3, "huge": huge,
                      "mixed": mixed, "reversed": C[::-1], "past the end": C + (C[-1] - C[0]) * 0.5}
        for name, X in point_sets.items():
            # scattered points move the window by metres a block: the NumPy side's (128 x chords) arrays
            # then span the whole path, so they go sparser
            scattered = name in ("noisy", "far", "huge", "mixed")
            for stride in (15, 50) if scattered else (1, 5, 50):
                args = (ref, t[::stride], X[::stride], theta[::stride])
                with np.errstate(all="ignore"):  # the NumPy code's warnings on overflowing points are not compared
                    a, b = _series_with("NumPy", monkeypatch, *args), _series_with("C", monkeypatch, *args)
                for field in ("s", "cross_track", "along_track", "heading_error", "beyond_end"):
                    x, y = getattr(a, field), getattr(b, field)
                    assert np.array_equal(x, y, equal_nan=True), (name, stride, field)
                    assert np.array_equal(np.signbit(x), np.signbit(y)), (name, stride, field)
                compared += 1
    assert compared == 3 * (4 * 3 + 4 * 2)


def test_the_compiled_projection_takes_numpys_first_nan(monkeypatch):
    """numpy.argmin returns the first NaN of a row; the C loop must too. No finite run's point makes a NaN
    distance (the inputs are checked finite), so the polyline is crafted: a straight line of 4 mm chords,
    one vertex NaN, single points projected from arc lengths around it (a NaN projection ends the
    search, so one point a call)."""
    from wmr_mj.analysis import path_error

    s = np.arange(0.0, 2.0, 4e-3)
    gxy = np.column_stack([s, np.zeros_like(s)])
    gxy[300] = np.nan  # s = 1.2 m
    gk = np.zeros_like(s)
    starts = np.linspace(0.9, 1.5, 61)
    out = {}
    for backend in ("NumPy", "C"):
        monkeypatch.setenv("WMR_MJ_COMPILED_PROJECTION", "1" if backend == "C" else "0")
        if path_error.projection_backend() != backend:
            pytest.skip("wmr_mj.analysis._nearest_chord is not built (no C compiler at install)")
        with np.errstate(all="ignore"):
            out[backend] = np.array([path_error._project(s, gxy, gk, np.array([[x, 0.03]]), x, 0.1)
                                     for x in starts])
    assert np.isnan(out["NumPy"]).any() and np.isfinite(out["NumPy"]).any()  # windows with and without it
    assert np.array_equal(out["NumPy"], out["C"], equal_nan=True)
