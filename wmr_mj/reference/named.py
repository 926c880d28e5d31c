"""C's reference of a run on its control grid: a named path (:data:`PATH_NAMES`) or a route, the last few kept.

:func:`build_reference` is what every run's reference is built by (:func:`wmr_mj.sim.parts.resolve_run`, a log's
replay, a result made elsewhere): the paper's circle, the lane change and the figure eight by name, a route (a
packaged name, a .toml/.json file, canonical JSON) through :func:`wmr_mj.reference.route.route_reference`.

Usage::

    from wmr_mj.reference.named import build_reference
    reference, settle_s = build_reference("paper-circle", C80, dt=1e-3, duration=35.0)
"""

from __future__ import annotations

import functools
import os
from typing import Any

import numpy as np

from wmr_mj.carts import CartFile
from wmr_mj.errors import InfeasiblePathError, StiffReferenceError, UnknownNameError, WmrMjError
from wmr_mj.params import C80Parameters, parameters_of_cart_text
from wmr_mj.reference import paths as ref
from wmr_mj.reference.route import default_path_of, is_route_spec, route_names, route_of, route_reference

__all__ = ["PATH_NAMES", "DEFAULT_PATH", "default_path", "default_path_note", "build_reference",
           "run_reference", "REFERENCE_CACHE_SIZE", "path_label",
           "LANE_CHANGE_LEAD_IN_M", "LANE_CHANGE_OFFSET_M", "LANE_CHANGE_LENGTH_M", "PATH_OPTION_HINT"]

#: the paths of C a run names (the others are routes)
PATH_NAMES = ("paper-circle", "lane-change", "figure-eight")

#: the path of a run that names none, on a cart that declares none (``[paths] default`` declares a cart's own)
DEFAULT_PATH = "paper-circle"

#: the named path lane-change: a lead-in line, the lane change (lateral offset over a length), then a line that
#: fills the duration [m]
LANE_CHANGE_LEAD_IN_M, LANE_CHANGE_OFFSET_M, LANE_CHANGE_LENGTH_M = 0.5, 0.5, 4.0


def default_path(cart: CartFile | None) -> str:
    """The path a run on ``cart`` takes where it names none: the one the cart declares (``[paths] default``); else
    the paper circle (:data:`DEFAULT_PATH`) where the cart steers it at no more than
    :data:`wmr_mj.reference.route.DEFAULT_PATH_STOP_FRACTION` of its stops (the C80 and the shipped carts: 0.659 of
    +-0.9 rad); else a loop of half-turns whose steady angle is that fraction of the stops
    (:func:`wmr_mj.reference.route.default_path_of`; :func:`default_path_note` names it). ``cart`` None: the C80.
    ``wmr_mj.sim.coerce`` gives a config whose path is None this path."""
    if cart is None:
        return DEFAULT_PATH
    return cart.default_path if cart.default_path is not None else _derived_path(cart.text, str(cart.path))[0]


def default_path_note(cart: CartFile | None) -> str | None:
    """The line that names the default path derived from ``cart``'s stops (:func:`default_path`); None where the
    cart declares its own or takes the paper circle."""
    if cart is None or cart.default_path is not None:
        return None
    return _derived_path(cart.text, str(cart.path))[1]


@functools.lru_cache(maxsize=8)  # once per cart text: every coercion of a config on the cart asks
def _derived_path(text: str, path: str) -> tuple[str, str | None]:
    """(the default path of the cart of ``text``, the note naming it or None): :func:`default_path`'s rule,
    :func:`wmr_mj.reference.route.default_path_of` on the cart's parameters."""
    return default_path_of(parameters_of_cart_text(text, path))


def build_reference(path: str | None, params: C80Parameters, *, dt: float, duration: float):
    """(reference, settle_s) for a path of C on a grid of step dt: a named path (PATH_NAMES) or
    a route (a packaged route name, a route file, canonical route JSON; a closed route is
    repeated lap after lap to fill the duration).

    settle_s is when the entry transient ends: for the paper's circle, the
    time C enters the circle; 0 for the other paths.

    The last :data:`REFERENCE_CACHE_SIZE` references are kept (a Reference's arrays are read-only):
    runs that share a path, as a comparison's scenarios on one path or a sweep's chunks do, build it
    once (it costs about a quarter of a 35 s run's physics). A route file is keyed by its
    modification time and size as well as its name, so an edited file is read again.

    ``path`` None is the default path of a cart of ``params`` (:func:`wmr_mj.reference.route.default_path_of`:
    the paper circle on the C80), what a ``RunConfig`` whose path is None runs on where its cart declares none.
    """
    if path is None:
        path = default_path_of(params)[0]
    file_key = None
    if path not in PATH_NAMES and not path.lstrip().startswith("{") and os.path.isfile(path):
        st = os.stat(path)
        file_key = (os.path.abspath(path), st.st_mtime_ns, st.st_size)
    return _cached_reference(path, file_key, params, float(dt), float(duration))


def run_reference(path: str | None, estimate: C80Parameters, *, period: float,
                  duration: float) -> tuple[Any, float]:
    """(reference, settle_s): C's reference of a run on its control grid, as ``wmr_mj.sim.parts.resolve_run``
    builds it -- ``round(duration / period)`` control steps of ``period`` [s] on the controller's belief
    ``estimate`` (:func:`build_reference`): the one builder of a run's reference. A log's replay, a result made
    elsewhere, the certified design's rule and the checks that refuse a path before any run build theirs here."""
    n = int(round(duration / period))
    return build_reference(path, estimate, dt=period, duration=n * period)


#: references kept by :func:`build_reference`
REFERENCE_CACHE_SIZE = 16

#: what an infeasible path's message says changes it, where the path is the user's (a command's --path); a caller
#: whose path is another's (compare's scenario, the suite's) replaces it with its own option
PATH_OPTION_HINT = ("--path changes it (a path this cart steers: e.g. a route of larger radius, or the cart file's "
                    "[paths] default)")


@functools.lru_cache(maxsize=REFERENCE_CACHE_SIZE)
def _cached_reference(path: str, file_key: tuple | None, params: C80Parameters, dt: float, duration: float):
    try:
        return _build_reference(path, params, dt=dt, duration=duration)
    except StiffReferenceError:
        raise
    except InfeasiblePathError as exc:  # the path, the stops and the option that changes it, named
        raise InfeasiblePathError(f"{exc} -- on path {path_label(path)}, with the cart's steering stops at "
                                  f"+-{params.steering_range:g} rad; {PATH_OPTION_HINT}") from None


def path_label(path: str) -> str:
    """What a message calls the path ``path``: its name, a route file's path, a route's own name for canonical JSON."""
    if path in PATH_NAMES or not path.lstrip().startswith("{"):
        return repr(path)
    try:
        return f"route {route_of(path).name!r}"
    except WmrMjError:
        return "a route given as JSON"


def _build_reference(path: str, params: C80Parameters, *, dt: float, duration: float):
    """:func:`build_reference` without the cache."""
    if path not in PATH_NAMES:
        if not is_route_spec(path):
            raise UnknownNameError("path", path, PATH_NAMES + route_names() + ("<route file .toml/.json>",))
        return route_reference(route_of(path), params, dt=dt, duration=duration), 0.0
    if path == "paper-circle":
        p = ref.paper_circle(params, duration=duration)
    elif path == "lane-change":
        p = (ref.line(LANE_CHANGE_LEAD_IN_M) + ref.lane_change(LANE_CHANGE_OFFSET_M, LANE_CHANGE_LENGTH_M)
             + ref.line(max(duration * params.V_A, 1.0)))
    elif path == "figure-eight":
        p = ref.line(0.5) + ref.figure_eight(1.5, laps=max(1, int(duration * params.V_A / 20.0) + 1))
    else:
        raise UnknownNameError("path", path, PATH_NAMES)
    reference = ref.make_reference(p, params, dt=dt, duration=duration)
    settle_s = 0.0
    if path == "paper-circle":
        circle_start = float(p.starts[-2])  # starts ends with the total length
        reached = np.nonzero(np.asarray(reference.s) >= circle_start)[0]
        settle_s = float(reference.t[reached[0]]) if reached.size else float(reference.t[-1])
    return reference, settle_s
