"""The user's routes (wmr_mj.reference.route): files round-trip, run closed loop, and a malformed
or infeasible route gets one line and exit status 2."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wmr_mj import C80
from wmr_mj.cli.app import main
from wmr_mj.errors import InfeasiblePathError, ParameterError
from wmr_mj.reference.paths import circle, join, line
from wmr_mj.reference.route import load_route, route_names, route_reference
from wmr_mj.sim.config import RunConfig, build_reference, coerce

S_BEND = """
[route]
name = "s-bend"
transition = 0.6

[[segment]]
type = "line"
length = 0.5

[[segment]]
type = "arc"
radius = 2.0
angle_deg = 30

[[segment]]
type = "transition"
length = 1.0

[[segment]]
type = "arc"
radius = -1.5
length = 0.8

[[segment]]
type = "line"
length = 3.0
"""


def test_segments_route_round_trips(tmp_path):
    f = tmp_path / "s-bend.toml"
    f.write_text(S_BEND)
    r = load_route(f)
    assert r.name == "s-bend" and not r.closed
    kinds = [s.kind for s in r.path.segments]
    # a transition inserted into the first arc (route transition = 0.6 m), the explicit one between the arcs,
    # one inserted out of the second arc into the line
    assert kinds == ["line", "transition", "arc", "transition", "arc", "transition", "line"]
    assert r.path.segments[2].length == pytest.approx(2.0 * math.radians(30))
    assert r.path.segments[3].start_curvature == 0.5 and r.path.segments[3].end_curvature == pytest.approx(-1 / 1.5)
    expect = join(line(0.5), circle(2.0, angle=math.radians(30)), transition=0.6)
    assert r.path.segments[:3] == expect.segments
    # canonical text and a JSON file give the same Path, exactly
    assert load_route(r.text).path == r.path
    data = {"route": {"name": "s-bend", "transition": 0.6},
            "segment": [{"type": "line", "length": 0.5}, {"type": "arc", "radius": 2.0, "angle_deg": 30},
                        {"type": "transition", "length": 1.0}, {"type": "arc", "radius": -1.5, "length": 0.8},
                        {"type": "line", "length": 3.0}]}
    g = tmp_path / "s-bend.json"
    g.write_text(json.dumps(data))
    assert load_route(g).path == r.path
    assert r.part_at(0.2) == "segment 0 (line)" and r.part_at(0.5) == "the transition into segment 1 (arc)"


def test_route_runs_closed_loop_and_config_stays_json(tmp_path):
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.designs import CERTIFIED

    f = tmp_path / "s-bend.toml"
    f.write_text(S_BEND)
    by_file = RunConfig(**CERTIFIED.config_changes(), path=str(f), duration=5.0)
    by_path = coerce(by_file.replace(path=load_route(f).path))  # a Path object: coerced to its canonical JSON
    assert isinstance(by_path.path, str) and by_path.path.startswith("{")
    for cfg in (by_file, by_path):
        json.dumps(cfg.to_dict())
    a = run_closed_loop(by_file, progress=False)
    b = run_closed_loop(by_path, progress=False)
    assert a.status == "completed" and a.summary.steps == 5000
    assert np.array_equal(a.rows["E"], b.rows["E"])  # the same route, to the bit
    assert a.summary.path == str(f)
    ref, settle = build_reference(str(f), C80, dt=1e-3, duration=5.0)
    assert settle == 0.0 and np.array_equal(ref.alpha0[:5000], a.rows["alpha0"])


def test_waypoints_and_the_packaged_agv_loop():
    assert "agv-loop" in route_names()
    r = load_route("agv-loop")
    # a sum of closed-form turns of the segments: rounding (measured 9e-16)
    assert r.closed and r.path.heading_change == pytest.approx(2 * math.pi, abs=1e-9)
    radii = sorted({round(abs(1 / s.start_curvature), 6) for s in r.path.segments if s.kind == "arc"})
    assert len(radii) >= 4 and min(radii) >= 1.0
    assert any(s.start_curvature < 0 for s in r.path.segments if s.kind == "arc")  # a right turn
    # feasible for the steering limits over a lap and more; a closed route is repeated to fill the duration
    T = 1.3 * r.path.length / C80.V_A
    ref = route_reference(r, C80, dt=1e-2, duration=T)
    assert ref.duration == pytest.approx(T, abs=1e-2) and np.max(np.abs(ref.alpha0)) < C80.steering_range
    cfg = RunConfig(path="agv-loop")
    assert cfg.to_dict()["path"] == "agv-loop"


def test_waypoint_corners_close_an_open_polyline():
    pts = {"route": {"transition": 0.5, "corner_radius": 1.5, "waypoints": [[0, 0], [6, 0], [6, 6, 2.0], [0, 6]]}}
    from wmr_mj.reference.route import parse_route

    r = parse_route(pts)
    assert not r.closed and r.path.heading_change == pytest.approx(math.pi)
    ref = route_reference(r, C80, dt=1e-2)
    # C's path rebuilt by the reference ends on the last leg, 6 m above its start, heading back (-x); the
    # last grid sample is short of the path's end by what is left of its arc length
    end, start = np.asarray(ref.C_xy[-1]), np.asarray(ref.C_xy[0])
    assert end[1] - start[1] == pytest.approx(6.0, abs=1e-6)
    assert end[0] - (r.path.length - ref.s[-1]) - start[0] == pytest.approx(0.0, abs=1e-6)


BAD = {
    "unknown-type": ('[route]\n[[segment]]\ntype = "spiral"\nlength = 2\n',
                     "segment 0: unknown segment type 'spiral'; one of line, arc, transition"),
    "zero-radius": ('[route]\n[[segment]]\ntype = "arc"\nradius = 0\nlength = 2\n', "segment 0 (arc): radius = 0"),
    "negative-corner": ('[route]\ntransition = 0.5\nwaypoints = [[0, 0], [5, 0, -1.0], [5, 5]]\n',
                        "waypoint 1: corner radius -1.0 m is not accepted"),
    "missing-field": ('[route]\n[[segment]]\ntype = "line"\n[[segment]]\ntype = "arc"\nradius = 2\n',
                      "segment 0 (line): missing field 'length'"),
    "arc-angle": ('[route]\n[[segment]]\ntype = "arc"\nradius = 2\n', "segment 0 (arc): give exactly one of"),
    "jump": ('[route]\n[[segment]]\ntype = "line"\nlength = 1\n[[segment]]\ntype = "arc"\nradius = 2\nlength = 1\n',
             "segment 1 (arc): the curvature jumps from 0 to 0.5 1/m here"),
    "not-toml": ('[route\n', "not valid TOML"),
    "open-loop": ('[route]\nclosed = true\n[[segment]]\ntype = "line"\nlength = 3\n', "the route does not close"),
    "infeasible": ('[route]\ntransition = 0.5\n[[segment]]\ntype = "line"\nlength = 1\n[[segment]]\ntype = "arc"\n'
                   'radius = 0.5\nangle_deg = 90\n[[segment]]\ntype = "line"\nlength = 9\n',
                   "segment 1 (arc): path infeasible at s = 1.5000 m (t = 7.4"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_route_exits_2_with_one_line(tmp_path, capsys, case):
    text, want = BAD[case]
    f = tmp_path / f"{case}.toml"
    f.write_text(text)
    code = main(["run", "--path", str(f), "--no-log", "--duration", "20" if case == "infeasible" else "1"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("wmr-mj: error: route ")
    assert want in err, err


def test_bad_route_in_the_library(tmp_path):
    with pytest.raises(ParameterError, match="does not exist"):
        load_route(tmp_path / "none.toml")
    f = tmp_path / "tight.toml"
    f.write_text(BAD["infeasible"][0])
    with pytest.raises(InfeasiblePathError, match=r"segment 1 \(arc\).*below the wheelbase"):
        build_reference(str(f), C80, dt=1e-3, duration=20.0)
    with pytest.raises(Exception, match="unknown path 'nowhere'"):  # refused where the config is coerced
        RunConfig.from_inputs(path="nowhere")


def _run_json(capsys, *argv) -> dict:
    capsys.readouterr()
    assert main(["run", *argv, "--no-log", "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_route_longer_than_the_run_is_reported_unfinished(capsys):
    """An 8.1 m straight route (its length: the distance between its two waypoints) and 35 s at
    V_A = 0.2 m/s: on a straight alpha = 0 and C moves at V_A, so the reference covers 7.0 m."""
    straight = json.dumps({"route": {"waypoints": [[0, 0], [8.1, 0]]}})
    s = _run_json(capsys, "--path", straight, "--duration", "35")
    # the reference's t(s) is integrated at rtol 1e-10 (paths._RTOL); 1e-9 relative is 10x that
    assert s["route_length_m"] == pytest.approx(8.1, rel=1e-9)
    assert s["route_driven_m"] == pytest.approx(C80.V_A * 35.0, rel=1e-9) and C80.V_A == 0.2
    assert s["route_finished"] is False
    assert main(["run", "--path", straight, "--duration", "35", "--no-log"]) == 0
    text = capsys.readouterr().out
    assert "route not finished: its reference covers 7 m of the route's 8.1 m in 35 s" in text


def test_the_packaged_loop_run_short_is_unfinished_and_a_closed_named_path_has_no_route_keys(capsys):
    s = _run_json(capsys, "--path", "agv-loop", "--duration", "5")
    lap = load_route("agv-loop").path.length
    # one lap, not the laps the reference repeats; its corners cut the waypoints' 52 m polygon
    assert s["route_length_m"] == lap and 40.0 < lap < 52.0
    # it starts mid-way along its first straight leg: C at V_A for 5 s (tolerance as above)
    assert s["route_driven_m"] == pytest.approx(C80.V_A * 5.0, rel=1e-9) and s["route_finished"] is False
    # the paper circle has no end to reach; the lane change has a manoeuvre, judged as a route (issue 36:
    # a lane change cut short is partial, tests/test_slips36.py)
    named = _run_json(capsys, "--path", "paper-circle", "--duration", "10")
    assert not any(k.startswith("route_") for k in named)


def test_route_progress_finishes_at_the_route_end():
    from wmr_mj.reference.route import FINISHED_TOL_M, RouteProgress, route_progress

    assert RouteProgress(length_m=8.1, driven_m=8.1 - 0.5 * FINISHED_TOL_M).finished
    assert not RouteProgress(length_m=8.1, driven_m=8.1 - 2 * FINISHED_TOL_M).finished
    assert route_progress("paper-circle", None, 35.0) is None


@pytest.mark.slow
def test_a_batch_reports_the_route_progress_as_its_single_runs_do():
    from wmr_mj.sim.batch import run_batch
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    configs = [RunConfig(path="agv-loop", duration=10.0, m1=m) for m in (600.0, 700.0)]
    for batched, config in zip(run_batch(configs, nthread=1), configs):
        single = run_closed_loop(config, progress=False).summary
        assert batched.route == single.route and not batched.route.finished
        assert batched.to_dict()["route_driven_m"] == single.to_dict()["route_driven_m"]



def test_a_reference_is_built_once_and_an_edited_route_file_read_again(tmp_path):
    """build_reference keeps a path's reference (the same object back); a route file edited in place (its
    first arc now 2.5 m in radius: a new size and mtime) is read again, and C's desired path changes."""
    f = tmp_path / "s-bend.toml"
    f.write_text(S_BEND)
    first, _ = build_reference(str(f), C80, dt=1e-3, duration=10.0)
    assert build_reference(str(f), C80, dt=1e-3, duration=10.0)[0] is first
    assert not first.C_xy.flags.writeable  # kept, so read-only
    f.write_text(S_BEND.replace("radius = 2.0", "radius = 2.5"))
    edited, _ = build_reference(str(f), C80, dt=1e-3, duration=10.0)
    assert edited is not first
    assert float(np.max(np.abs(edited.C_xy - first.C_xy))) > 0.01  # m: the arc from 0.5 m on is wider
