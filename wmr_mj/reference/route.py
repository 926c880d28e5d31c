"""The user's own routes for point C: route files (TOML or JSON) turned into a :class:`Path`.

A route file has a ``[route]`` table and either a list of segments or a list of waypoints.

**Segments** (``[[segment]]``, in order)::

    [route]
    name = "s-bend"
    transition = 0.8        # [m] blend inserted wherever the curvature jumps (omit: a jump is an error)
    closed = false          # true: the route must end where it starts; a run repeats it lap after lap

    [[segment]]
    type = "line"
    length = 2.0            # [m]

    [[segment]]
    type = "arc"
    radius = 2.0            # [m], signed: > 0 turns left, < 0 right
    angle_deg = 90          # how far it turns: angle_deg [deg], angle [rad] or length [m] (one of them)

    [[segment]]
    type = "transition"     # an explicit curvature blend from the previous segment's to the next one's
    length = 1.0            # [m]

**Waypoints** (C's corners; the route runs straight between them, and turns at each interior
waypoint on an arc of the corner's radius entered and left through curvature transitions, so
its curvature is continuous)::

    [route]
    name = "loop"
    closed = true           # corners at every waypoint; the route starts and ends mid-way along the first leg
    corner_radius = 1.5     # [m] default radius of a corner
    transition = 0.8        # [m] length of each transition into and out of a corner
    waypoints = [[0, 0], [8, 0, 2.5], [8, 6], [0, 6]]     # [x, y] or [x, y, corner radius] in m

Only the route's shape matters: :func:`~wmr_mj.reference.paths.make_reference` puts its start
at the cart's start (C at l1 ahead of A, heading 0). A JSON file holds the same keys
(``{"route": {...}, "segment": [...]}``).

A malformed route raises :class:`~wmr_mj.errors.ParameterError` naming the file, the segment
(or waypoint) and what is accepted; :func:`route_reference` turns the steering limits'
:class:`~wmr_mj.errors.InfeasiblePathError` (s in m, t in s) into one that also names the
route's segment or corner.

Usage::

    from wmr_mj.reference.route import load_route, route_reference
    route = load_route("my-route.toml")          # or a packaged name: load_route("agv-loop")
    route.path, route.closed, route.text         # the Path, whether it is a loop, its canonical JSON
    reference = route_reference(route, C80, dt=1e-3, duration=60.0)   # laps of a closed route as needed
"""

from __future__ import annotations

import functools
import json
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path as FilePath
from typing import Any, Literal, overload

import numpy as np

from wmr_mj._util.resources import DATA_DIR
from wmr_mj.errors import InfeasiblePathError, ParameterError, UnknownNameError
from wmr_mj.params import C80Parameters
from wmr_mj.reference.paths import Path, Reference, Segment, SegmentKind, _s5_int, make_reference, paper_circle

__all__ = ["Route", "ROUTES_DIR", "route_names", "load_route", "parse_route", "route_from_path",
           "is_route_spec", "route_reference", "RouteProgress", "route_progress",
           "route_length", "route_of", "route_spec_of", "turns_loop", "path_name", "default_path_of",
           "DEFAULT_PATH_STOP_FRACTION", "PAPER_CIRCLE_RADIUS_M"]

#: Routes shipped with the package, selectable by name (the file's stem).
ROUTES_DIR = DATA_DIR / "routes"
SEGMENT_TYPES = ("line", "arc", "transition")
_CLOSE_TOL = 1e-3  # m and rad: how closely a closed route must end at its start


@dataclass(frozen=True)
class Route:
    """A route of C: its ``path`` (a Path), ``closed`` (a loop a run repeats), ``name``, where it came
    from (``source``: a file or "<text>"), its ``parts`` ((s_start, s_end, label) in m of each segment
    or corner, for messages) and ``text``: canonical JSON that rebuilds it exactly."""

    name: str
    path: Path
    closed: bool
    source: str
    parts: tuple[tuple[float, float, str], ...]

    @property
    def text(self) -> str:
        segs = [{f.name: getattr(s, f.name) for f in fields(Segment)} for s in self.path.segments]
        return json.dumps({"route": {"name": self.name, "closed": self.closed}, "path": segs},
                          separators=(",", ":"))

    def part_at(self, s: float) -> str:
        """The label of the segment or corner at arc length s [m] (of one lap)."""
        L = self.path.length
        if self.closed and L > 0:
            s = s % L
        started = [label for lo, _, label in self.parts if lo <= s + 1e-9]  # the last part begun at s
        return started[-1] if started else (self.parts[0][2] if self.parts else "the route")


def route_names() -> tuple[str, ...]:
    """Names of the packaged routes."""
    if not ROUTES_DIR.is_dir():
        return ()
    return tuple(sorted(p.stem for p in ROUTES_DIR.iterdir() if p.suffix in (".toml", ".json")))


def is_route_spec(spec: str) -> bool:
    """Whether ``spec`` names a route: a packaged name, canonical route JSON, or a .toml/.json file."""
    return (spec in route_names() or spec.lstrip().startswith("{")
            or spec.lower().endswith((".toml", ".json")))


# --------------------------------------------------------------------------- parsing
class _Where:
    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, why: str) -> ParameterError:
        return ParameterError(f"route {self.source}: {where}: {why}")


@overload
def _num(w: _Where, where: str, table: dict, key: str, *, positive: bool = ..., unit: str = ...,
         required: Literal[True] = ...) -> float: ...
@overload
def _num(w: _Where, where: str, table: dict, key: str, *, positive: bool = ..., unit: str = ...,
         required: bool) -> float | None: ...
def _num(w: _Where, where: str, table: dict, key: str, *, positive: bool = False, unit: str = "m",
         required: bool = True) -> float | None:
    if key not in table:
        if required:
            raise w.fail(where, f"missing field {key!r} [{unit}]")
        return None
    v = table[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
        raise w.fail(where, f"{key} = {v!r} is not accepted: a finite number [{unit}]")
    x = float(v)
    if positive and x <= 0.0:
        raise w.fail(where, f"{key} = {v!r} {unit} is not accepted: it must be > 0")
    return x


def _check_keys(w: _Where, where: str, table: dict, allowed: tuple[str, ...]) -> None:
    extra = sorted(set(table) - set(allowed))
    if extra:
        raise w.fail(where, f"unknown field(s) {', '.join(map(repr, extra))}; accepted: {', '.join(allowed)}")


def _segments_route(w: _Where, head: dict, items: Any) -> tuple[Path, tuple]:
    if not isinstance(items, list) or not items:
        raise w.fail("segment", "a non-empty list of [[segment]] tables is required")
    blend = _num(w, "[route]", head, "transition", positive=True, required=False)
    # first pass: each item -> (kind, length, curvature) with transitions to resolve
    raw: list[tuple[SegmentKind, float, float, str]] = []
    for i, item in enumerate(items):
        where = f"segment {i}"
        if not isinstance(item, dict):
            raise w.fail(where, f"a table is required, got {item!r}")
        kind = item.get("type")
        if kind not in SEGMENT_TYPES:
            raise w.fail(where, f"unknown segment type {kind!r}; one of {', '.join(SEGMENT_TYPES)}")
        where = f"segment {i} ({kind})"
        if kind == "line":
            _check_keys(w, where, item, ("type", "length"))
            raw.append(("line", _num(w, where, item, "length", positive=True), 0.0, where))
        elif kind == "transition":
            _check_keys(w, where, item, ("type", "length"))
            raw.append(("transition", _num(w, where, item, "length", positive=True), math.nan, where))
        else:
            _check_keys(w, where, item, ("type", "radius", "angle_deg", "angle", "length"))
            R = _num(w, where, item, "radius")
            if R == 0.0:
                raise w.fail(where, "radius = 0 is not accepted: a signed radius in m (> 0 turns left, < 0 right)")
            given = [k for k in ("angle_deg", "angle", "length") if k in item]
            if len(given) != 1:
                raise w.fail(where, "give exactly one of angle_deg [deg], angle [rad], length [m]"
                             + (f"; got {', '.join(given)}" if given else ""))
            key = given[0]
            x = _num(w, where, item, key, positive=True, unit={"angle_deg": "deg", "angle": "rad"}.get(key, "m"))
            L = x if key == "length" else abs(R) * (math.radians(x) if key == "angle_deg" else x)
            raw.append(("arc", L, 1.0 / R, where))
    segs: list[Segment] = []
    parts: list[tuple[float, float, str]] = []
    s = 0.0

    def add(seg: Segment, label: str) -> None:
        nonlocal s
        segs.append(seg)
        parts.append((s, s + seg.length, label))
        s += seg.length

    for i, (kind, L, k, where) in enumerate(raw):
        prev = segs[-1].end_curvature if segs else 0.0
        if kind == "transition":
            nxt = next((kk for kind2, _, kk, _ in raw[i + 1:] if kind2 != "transition"), 0.0)
            add(Segment("transition", L, prev, nxt), where)
            continue
        if abs(prev - k) > 1e-12:
            if blend is None:
                raise w.fail(where, f"the curvature jumps from {prev:.6g} to {k:.6g} 1/m here; add a "
                                    "[[segment]] of type 'transition' or give transition = <length in m> in [route]")
            add(Segment("transition", blend, prev, k), f"the transition into {where}")
        add(Segment(kind, L, k, k), where)
    return Path(tuple(segs)), tuple(parts)


def _corner_geometry(k: float, b: float, delta: float) -> float:
    """Tangent length of a corner: transition (0 -> k over b), arc, transition back, turning by delta
    (> 0) in all; the distance from the corner's vertex to where it leaves the straight [m]."""
    L_arc = delta / k - b
    u = np.linspace(0.0, 1.0, 4001)
    psi = k * b * _s5_int(u)
    dx, dy = np.cos(psi), np.sin(psi)
    wts = np.ones_like(u)  # Simpson's rule on the transition
    wts[1:-1:2], wts[2:-1:2] = 4.0, 2.0
    X = b * float(np.sum(wts * dx)) / (3.0 * (u.size - 1))
    Y = b * float(np.sum(wts * dy)) / (3.0 * (u.size - 1))
    R, p = 1.0 / k, 0.5 * k * b  # then half the arc, from heading p
    q = p + 0.5 * L_arc * k
    X += R * (math.sin(q) - math.sin(p))
    Y -= R * (math.cos(q) - math.cos(p))
    return X + Y * math.tan(0.5 * delta)


def _waypoints_route(w: _Where, head: dict, closed: bool) -> tuple[Path, tuple]:
    """The route of [route] waypoints: straight legs, each corner rounded by transition-arc-transition."""
    xy, radii, b = _read_waypoints(w, head, closed)
    P, legs, length = _legs(w, xy, closed)
    turn, tangent = _corners(w, P, legs, radii, b, closed)
    straight = _straights(w, legs, length, tangent)
    return _assemble(w, legs, straight, turn, radii, b, closed)


def _read_waypoints(w: _Where, head: dict, closed: bool) -> tuple[list, list, float | None]:
    """The waypoints [m], each corner's radius [m] (or None) and the transition length [m] (or None)."""
    pts = head.get("waypoints")
    if not isinstance(pts, list) or len(pts) < (3 if closed else 2):
        raise w.fail("waypoints", f"a list of at least {3 if closed else 2} [x, y] or [x, y, corner radius] "
                                  "points [m] is required")
    default_R = _num(w, "[route]", head, "corner_radius", positive=True, required=False)
    b = _num(w, "[route]", head, "transition", positive=True, required=False)
    xy, radii = [], []
    for i, p in enumerate(pts):
        where = f"waypoint {i}"
        if (not isinstance(p, list) or len(p) not in (2, 3)
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in p)):
            raise w.fail(where, f"{p!r} is not accepted: [x, y] or [x, y, corner radius] with finite numbers [m]")
        xy.append((float(p[0]), float(p[1])))
        if len(p) == 3 and float(p[2]) <= 0.0:
            raise w.fail(where, f"corner radius {p[2]!r} m is not accepted: it must be > 0")
        radii.append(float(p[2]) if len(p) == 3 else default_R)
    if closed and np.hypot(xy[0][0] - xy[-1][0], xy[0][1] - xy[-1][1]) < 1e-9:
        xy, radii = xy[:-1], radii[:-1]  # the loop's closing point repeated
    return xy, radii, b


def _legs(w: _Where, xy: list, closed: bool) -> tuple[np.ndarray, list, np.ndarray]:
    """The points (n, 2), the legs as (from, to) indices and their lengths [m]; consecutive points differ."""
    P = np.asarray(xy)
    n = len(P)
    legs = [(i, (i + 1) % n) for i in range(n if closed else n - 1)]
    vec = np.array([P[j] - P[i] for i, j in legs])
    length = np.hypot(vec[:, 0], vec[:, 1])
    for (i, j), L in zip(legs, length):
        if L < 1e-9:
            raise w.fail(f"waypoint {j}", f"it repeats waypoint {i}: consecutive waypoints must differ")
    return P, legs, length


def _corners(w: _Where, P: np.ndarray, legs: list, radii: list, b: float | None, closed: bool) -> tuple[dict, dict]:
    """Each corner's turn [rad] (signed) and the tangent length [m] its rounding takes from each leg."""
    n = len(P)
    vec = np.array([P[j] - P[i] for i, j in legs])
    heading = np.arctan2(vec[:, 1], vec[:, 0])
    corners = list(range(n)) if closed else list(range(1, n - 1))
    turn, tangent = {}, {}
    for c in corners:
        li = (c - 1) % len(legs)  # the leg into corner c
        d = float((heading[c % len(legs)] - heading[li] + math.pi) % (2.0 * math.pi) - math.pi)
        where = f"waypoint {c}"
        if abs(d) < 1e-12:
            turn[c], tangent[c] = 0.0, 0.0
            continue
        if abs(abs(d) - math.pi) < 1e-9:
            raise w.fail(where, "the route turns back on itself here (180 deg): no corner can round it")
        R = radii[c]
        if R is None:
            raise w.fail(where, "no corner radius: give [x, y, radius] or corner_radius in [route]")
        if b is None:
            raise w.fail("[route]", "missing field 'transition' [m]: the length of the curvature transitions "
                                    "into and out of each corner")
        if R * abs(d) <= b:
            raise w.fail(where, f"a turn of {math.degrees(abs(d)):.4g} deg on radius {R:.4g} m is {R * abs(d):.4g} m "
                                f"of arc, not more than its two transitions of {b:.4g} m: use a larger radius or a "
                                "shorter transition")
        turn[c], tangent[c] = d, _corner_geometry(1.0 / R, b, abs(d))
    return turn, tangent


def _straights(w: _Where, legs: list, length: np.ndarray, tangent: dict) -> list[float]:
    """What is left of each leg [m] once its corners are rounded; a leg too short for them fails."""
    straight = []
    for (i, j), L in zip(legs, length):
        rest = L - tangent.get(i, 0.0) - tangent.get(j, 0.0)
        if rest < -1e-9:
            raise w.fail(f"leg from waypoint {i} to {j}",
                         f"it is {L:.4g} m long, its corners need {L - rest:.4g} m: move the waypoints apart or use "
                         "smaller corner radii")
        straight.append(max(rest, 0.0))
    return straight


def _assemble(w: _Where, legs: list, straight: list, turn: dict, radii: list, b: float | None,
              closed: bool) -> tuple[Path, tuple]:
    """The segments in driving order (a closed loop starts and ends half-way along its first leg) and the
    labelled parts (s from, s to, label)."""
    n = len(radii)
    segs: list[Segment] = []
    parts: list[tuple[float, float, str]] = []
    s = 0.0

    def add(seg_list: list[Segment], label: str) -> None:
        nonlocal s
        start = s
        for seg in seg_list:
            segs.append(seg)
            s += seg.length
        if seg_list:
            parts.append((start, s, label))

    def line_of(L: float) -> list[Segment]:
        return [Segment("line", L, 0.0, 0.0)] if L > 1e-12 else []

    def corner(c: int) -> list[Segment]:
        d = turn.get(c, 0.0)
        if d == 0.0:
            return []
        radius, blend = radii[c], b
        assert radius is not None and blend is not None  # a corner that turns has both (checked above)
        k = math.copysign(1.0 / radius, d)
        L_arc = abs(d) / abs(k) - blend
        return [Segment("transition", blend, 0.0, k), Segment("arc", L_arc, k, k),
                Segment("transition", blend, k, 0.0)]

    if closed:
        add(line_of(0.5 * straight[0]), "leg from waypoint 0 to 1")
        for li in range(1, len(legs)):
            add(corner(li), f"corner at waypoint {li}")
            add(line_of(straight[li]), f"leg from waypoint {li} to {(li + 1) % n}")
        add(corner(0), "corner at waypoint 0")
        add(line_of(0.5 * straight[0]), "leg from waypoint 0 to 1")
    else:
        for li, (i, j) in enumerate(legs):
            if li > 0:
                add(corner(i), f"corner at waypoint {i}")
            add(line_of(straight[li]), f"leg from waypoint {i} to {j}")
    if not segs:
        raise w.fail("waypoints", "the route has no length")
    return Path(tuple(segs)), tuple(parts)


def _closure(path: Path) -> tuple[float, float]:
    """(distance from end to start [m], heading mismatch [rad] modulo 2 pi) of C's path, by quadrature."""
    s = np.linspace(0.0, path.length, max(2001, int(path.length / 1e-3) | 1))
    k = path.curvature(s)
    h = np.concatenate([[0.0], np.cumsum(0.5 * (k[1:] + k[:-1]) * np.diff(s))])
    x = np.trapezoid(np.cos(h), s)
    y = np.trapezoid(np.sin(h), s)
    dh = float((path.heading_change + math.pi) % (2.0 * math.pi) - math.pi)
    return float(math.hypot(x, y)), abs(dh)


def parse_route(data: Any, source: str = "<text>") -> Route:
    """A Route from parsed route data (the dict a TOML or JSON route file holds)."""
    w = _Where(source)
    if not isinstance(data, dict):
        raise w.fail("file", "a table with [route] and [[segment]] or waypoints is required")
    _check_keys(w, "file", data, ("route", "segment", "path"))
    head = data.get("route", {})
    if not isinstance(head, dict):
        raise w.fail("[route]", "a table is required")
    _check_keys(w, "[route]", head, ("name", "closed", "transition", "corner_radius", "waypoints"))
    name = head.get("name", FilePath(source).stem if source != "<text>" else "route")
    if not isinstance(name, str) or not name:
        raise w.fail("[route]", f"name = {name!r} is not accepted: a non-empty string")
    closed = head.get("closed", False)
    if not isinstance(closed, bool):
        raise w.fail("[route]", f"closed = {closed!r} is not accepted: true or false")
    if "path" in data:  # canonical text: the Path's segments as they are
        try:
            path = Path(tuple(Segment(**seg) for seg in data["path"]))
        except (TypeError, ParameterError) as exc:
            raise w.fail("path", str(exc)) from None
        starts = path.starts
        parts = tuple((float(starts[i]), float(starts[i + 1]), f"segment {i} ({seg.kind})")
                      for i, seg in enumerate(path.segments))
    elif "waypoints" in head:
        if "segment" in data:
            raise w.fail("file", "give either [[segment]] tables or waypoints, not both")
        path, parts = _waypoints_route(w, head, closed)
    elif "segment" in data:
        if "corner_radius" in head:
            raise w.fail("[route]", "corner_radius belongs to a waypoints route")
        path, parts = _segments_route(w, head, data["segment"])
    else:
        raise w.fail("file", "no [[segment]] tables and no waypoints: the route is empty")
    if closed:
        gap, dh = _closure(path)
        if gap > _CLOSE_TOL or dh > _CLOSE_TOL or abs(path.start_curvature - path.end_curvature) > 1e-9:
            raise w.fail("closed", f"the route does not close: it ends {gap:.4g} m from its start, its heading "
                                   f"{math.degrees(dh):.3g} deg off, curvature {path.end_curvature:.4g} against "
                                   f"{path.start_curvature:.4g} 1/m")
    return Route(name=name, path=path, closed=closed, source=source, parts=parts)


def route_from_path(path: Path, *, name: str = "path", closed: bool = False) -> Route:
    """A Route around a Path object (its canonical text rebuilds it exactly)."""
    if not isinstance(path, Path):
        raise ParameterError(f"a wmr_mj.reference.paths.Path is required, got {type(path).__name__}")
    return parse_route({"route": {"name": name, "closed": closed},
                        "path": [{f.name: getattr(s, f.name) for f in fields(Segment)} for s in path.segments]})


#: the straight before and after each half-turn of :func:`turns_loop` [m]: the paper circle's lead-in
TURNS_LOOP_STRAIGHT_M = 0.4


def turns_loop(params: C80Parameters, radius: float, *, name: str) -> Route:
    """A closed route of two half-turns of ``radius`` m (left), each entered and left through the paper circle's
    steering ramp (:func:`~wmr_mj.reference.paths.paper_circle`'s entry, matched to params.l1, so the steering
    rises from 0 to asin(l1/R) and back along a septic smoothstep), joined by straights of 2 x
    :data:`TURNS_LOOP_STRAIGHT_M`. It starts mid-way along a straight with the steering at 0, as the plant does;
    the two halves are the same segments, the second turned by pi, so the loop closes exactly.

    Raises:
        ParameterError: a radius at or below the wheelbase, or ramps that alone turn C by pi or more (one line).
    """
    entry = paper_circle(params, radius=radius).segments[1]  # line, ramp, arc: the ramp into the circle
    ramp_in = entry
    ramp_out = Segment("ramp", entry.length, entry.end_curvature, 0.0, wheelbase=entry.wheelbase)
    turn = math.pi - ramp_in.heading_change - ramp_out.heading_change
    if turn <= 0.0:
        raise ParameterError(f"a loop of {radius:.4g} m half-turns: its steering ramps alone turn C by "
                             f"{math.pi - turn:.4g} rad >= pi")
    straight = Segment("line", TURNS_LOOP_STRAIGHT_M, 0.0, 0.0)
    arc = Segment("arc", radius * turn, entry.end_curvature, entry.end_curvature)
    half = (straight, ramp_in, arc, ramp_out, straight)
    return parse_route({"route": {"name": name, "closed": True},
                        "path": [{f.name: getattr(s, f.name) for f in fields(Segment)} for s in half + half]})


#: the steady steering angle of a cart's default path where its file declares none, as a fraction of its stops
DEFAULT_PATH_STOP_FRACTION = 0.85
#: the radius of the paper's circle [m] (section 5; the named path paper-circle)
PAPER_CIRCLE_RADIUS_M = 1.0


@functools.lru_cache(maxsize=8)
def default_path_of(params: C80Parameters) -> tuple[str, str | None]:
    """(the path a cart of ``params`` takes where it names none and declares none, the line naming it or None).

    The paper circle ('paper-circle') where the cart steers it at no more than :data:`DEFAULT_PATH_STOP_FRACTION`
    of its stops (the C80 and the shipped carts: 0.659 of +-0.9 rad), with no line; else a loop of two half-turns
    (:func:`turns_loop`) whose steady angle is that fraction of the stops, as canonical route JSON, and the line
    that names it. A cart file's ``[paths] default`` comes first (``wmr_mj.reference.named.default_path``).
    """
    angle = DEFAULT_PATH_STOP_FRACTION * params.steering_range
    if params.l1 <= PAPER_CIRCLE_RADIUS_M * math.sin(angle):  # the paper circle, steered with margin
        return "paper-circle", None
    radius = params.l1 / math.sin(angle)
    route = turns_loop(params, radius, name=f"loop-of-{radius:.3g}-m-turns")
    return route.text, (f"default path: route {route.name!r}, two half-circles of radius {radius:.3g} m joined by "
                        f"straights, chosen from the cart's stops (steady steering angle {angle:.3g} rad, "
                        f"{DEFAULT_PATH_STOP_FRACTION:g} of +-{params.steering_range:g} rad; the paper's 1 m circle "
                        f"needs {_circle_angle(params.l1)}); declare [paths] default in the cart file to choose")


def _circle_angle(l1: float) -> str:
    """The steady steering angle the paper's 1 m circle needs with wheelbase ``l1`` [m], in words."""
    ratio = l1 / PAPER_CIRCLE_RADIUS_M
    return f"{math.asin(ratio):.3g} rad" if ratio < 1.0 else f"sin(alpha) = {ratio:.3g}, no angle"


def load_route(spec: str | os.PathLike) -> Route:
    """A route from a packaged name (:func:`route_names`), canonical JSON text, or a .toml/.json file."""
    text_spec = os.fspath(spec)
    if isinstance(text_spec, bytes):
        text_spec = text_spec.decode()
    if text_spec.lstrip().startswith("{"):
        try:
            return parse_route(json.loads(text_spec), "<text>")
        except json.JSONDecodeError as exc:
            raise ParameterError(f"route <text>: not valid JSON ({exc})") from None
    file = ROUTES_DIR / f"{text_spec}.toml" if text_spec in route_names() else FilePath(text_spec)
    if not file.is_file() and text_spec in route_names():
        file = ROUTES_DIR / f"{text_spec}.json"
    if not file.is_file():
        if not text_spec.lower().endswith((".toml", ".json")):
            raise UnknownNameError("route", text_spec, route_names())
        raise ParameterError(f"route file {text_spec} does not exist (a .toml or .json route file, or one of the "
                             f"packaged routes: {', '.join(route_names())})")
    try:
        raw = file.read_bytes()
    except OSError as exc:
        raise ParameterError(f"route file {text_spec} cannot be read ({exc.strerror})") from None
    try:
        if file.suffix.lower() == ".json":
            data = json.loads(raw.decode("utf-8"))
        else:
            data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        kind = "JSON" if file.suffix.lower() == ".json" else "TOML"
        raise ParameterError(f"route file {text_spec}: not valid {kind} ({exc})") from None
    return parse_route(data, text_spec)


def route_of(spec: str) -> Route:
    """The route ``spec`` names (a packaged name, a .toml/.json file, canonical JSON; :func:`load_route`), read once
    per version of its file: kept by the file's modification time and size, so an edited file is read again."""
    file_key = None
    if not spec.lstrip().startswith("{") and os.path.isfile(spec):
        st = os.stat(spec)
        file_key = (os.path.abspath(spec), st.st_mtime_ns, st.st_size)
    return _route_of(spec, file_key)


@functools.lru_cache(maxsize=16)
def _route_of(spec: str, file_key: tuple | None) -> Route:
    return load_route(spec)


def route_spec_of(given: Any, *, named: tuple[str, ...]) -> tuple[str, Route | None]:
    """(spec, route): C's path as a run's config keeps it, and the route it names, read once (:func:`route_of`).

    A name of ``named`` (a path built by name) is kept as given, with no route; a route (a packaged name, a file,
    canonical JSON) as given; a :class:`~wmr_mj.reference.paths.Path` as its canonical JSON; a :class:`Route` as
    its file where it has one, else its canonical JSON. A malformed route raises here.

    Raises:
        UnknownNameError: neither a name of ``named`` nor a route. ParameterError: a malformed route, another type.
    """
    if isinstance(given, str) and given in named:
        return given, None  # a named path: nothing to read
    if isinstance(given, Path):
        given = route_from_path(given).text
    elif isinstance(given, Route):
        given = given.text if given.source == "<text>" or not os.path.isfile(given.source) else given.source
    elif not isinstance(given, str):
        raise ParameterError(f"path = {given!r} is not accepted: a path name, a route file or a Path")
    elif not is_route_spec(given):
        raise UnknownNameError("path", given, named + route_names() + ("<route file .toml/.json>",))
    return given, route_of(given)  # malformed: ParameterError naming the file and the segment


def route_reference(route: Route, params: C80Parameters, *, dt: float, duration: float | None = None) -> Reference:
    """The steering reference for ``route`` (laps of a closed route as the duration needs).

    A route the steering cannot follow raises InfeasiblePathError naming the route's segment or
    corner beside s [m] and t [s]; an open route shorter than ``duration`` raises ParameterError.
    """
    path = route.path
    if route.closed and duration is not None:
        # C covers at most V_A duration / cos(max steering) of arc length
        need = params.V_A * float(duration) / math.cos(params.steering_range) + path.length
        laps = max(1, int(math.ceil(need / path.length)))
        path = Path(path.segments * laps)
    try:
        return make_reference(path, params, dt=dt, duration=duration)
    except InfeasiblePathError as exc:
        msg = str(exc)
        m = re.search(r"at s = (-?[0-9.]+) m", msg)
        where = route.part_at(float(m.group(1))) if m else "the route"
        raise InfeasiblePathError(f"route {route.source}: {where}: {msg}") from None
    except ParameterError as exc:
        raise ParameterError(f"route {route.source}: {exc}") from None


#: a route counts as finished when its reference comes this near its end [m]: 1 um, far above the
#: reference's own integration error (t(s) with rtol 1e-10) and far below any route's features
FINISHED_TOL_M = 1e-6


@dataclass(frozen=True)
class RouteProgress:
    """How far a run's reference goes along its route, so that a route longer than the run is not
    left unfinished silently. ``length_m``: the route's length [m] (one lap of a closed route);
    ``driven_m``: the arc length of C's reference over the run's duration [m]; ``finished``: it
    covers the route (a closed route: at least one lap)."""

    length_m: float
    driven_m: float

    @property
    def finished(self) -> bool:
        return self.driven_m >= self.length_m - FINISHED_TOL_M

    @classmethod
    def along(cls, length_m: float, reference: Any, duration: float) -> RouteProgress:
        """The progress of a run of ``duration`` [s] with ``reference`` on a route of ``length_m`` [m]."""
        s = np.asarray(reference.s, float)
        driven = float(np.interp(float(duration), np.asarray(reference.t, float), s)) - float(s[0])
        return cls(length_m=float(length_m), driven_m=driven)

    def to_dict(self) -> dict[str, Any]:
        """The summary keys route_length_m, route_driven_m, route_finished."""
        return {"route_length_m": self.length_m, "route_driven_m": self.driven_m, "route_finished": self.finished}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RouteProgress:
        """The progress of its summary keys ``d`` (what :meth:`to_dict` wrote; route_finished is derived)."""
        return cls(length_m=d["route_length_m"], driven_m=d["route_driven_m"])


def route_progress(spec: str, reference: Any, duration: float) -> RouteProgress | None:
    """The :class:`RouteProgress` of a run of ``duration`` s on the route ``spec`` with ``reference``
    (built by ``route_reference``); None when ``spec`` names no route (a named path, built to fill
    the duration)."""
    length_m = route_length(spec)
    return None if length_m is None else RouteProgress.along(length_m, reference, duration)


def path_name(spec: str) -> str:
    """The path ``spec`` as outputs print it: a route given as canonical JSON by its name (``route 'NAME'``), any
    other path (a name, a route file) as given."""
    if not isinstance(spec, str) or not spec.lstrip().startswith("{"):
        return str(spec)
    try:
        return f"route {load_route(spec).name!r}"
    except ParameterError:
        return "a route given as JSON"


def route_length(spec: str) -> float | None:
    """The length [m] of the route ``spec`` (one lap of a closed route); None when it names no route."""
    if not isinstance(spec, str) or not is_route_spec(spec):
        return None
    return float(load_route(spec).path.length)
