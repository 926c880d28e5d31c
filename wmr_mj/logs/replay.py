"""What ``wmr-mj replay`` does with a run log, as library functions.

- :func:`summarize`: sup|E| and sup|E'| over the whole run and after ``settle_s``, against the
  analytic bounds E_max, Edot_max of (4.21)-(4.23) when the log carries them (the run's summary,
  else its config), with the run's status; a JSON-ready dict.
- :func:`verify`: rebuild the model from the attached MJCF, set the attached initial state,
  re-apply the logged ctrl and compare qpos and qvel at every control step, bit for bit; where the
  run had a sensor, regenerate what the law read (the sensing chain of the config in the header, its
  noise from its seed) from the reproduced state and compare it with /measured, bit for bit.
- :func:`path_of_log`: C's Cartesian errors (:mod:`wmr_mj.analysis.path_error`) against the desired
  path of C, rebuilt from the log's configuration as the run built it; :func:`summarize` adds
  their sup, RMS and final values under ``path_errors``.
- :func:`plot`: E and E' over time with the bounds, the armature voltage with the supply limit,
  the (|E|, |E'|) plane with the bounds' rectangle and the region polygon (4.21), and C's path:
  desired against actual, and the cross-track and along-track errors over time.
- :func:`checked_plugins`: the plug-in files the log names (its law's, its tracker's), each hashed and
  checked against the log's record before anything is imported; :func:`verify_controller` imports
  them only then, to re-run the law. Importing a file runs its code: verify only logs whose
  plug-ins you trust.
- :func:`format_summary`, :func:`format_verify`: the command's text.

Usage::

    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.replay import summarize, verify
    log = load_log("logs/run.mcap")
    rep = summarize(log)                     # rep["sup_abs_E"], rep["E_max"], rep["inside"], ...
    assert verify(log)["identical"]          # the run is reproduced bit for bit
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from controllers.registry import check_recorded_source
from wmr_mj.analysis.path_bound import guaranteed_E_max, path_bound, path_verdict, without_guarantee
from wmr_mj.analysis.path_error import path_error_series, summarize_series
from wmr_mj.analysis.verdicts import PAPER_CLAIM_NOT_APPLICABLE, format_verdict
from wmr_mj.carts import load_cart_text
from wmr_mj.errors import LogError, ParameterError, WmrMjError
from wmr_mj.hardware import Actuation, Sensing, SensingChain, Transmission
from wmr_mj.logs.reader import RunLog
from wmr_mj.params import C80, C80Parameters, parameters_of_cart, with_params
from wmr_mj.plant.mjcf import steering_joint_addresses
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import config_from_dict, controller_name, estimate_parameters
from wmr_mj.sim.engine import load_fields
from wmr_mj.sim.parts import run_reference
from wmr_mj.sim.signals import signals_from
from wmr_mj.sim.summary import PAPER_KEYS_DEPRECATED, PAPER_REGION_KEYS, shown_config

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

    from controllers.registry import LocatedSource

__all__ = ["summarize", "verify", "plot", "format_summary", "format_verify", "path_of_log", "LogPath",
           "hardware_labels", "checked_plugins", "CheckedPlugin"]


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _lookup(sources: list[dict[str, Any]], key: str) -> float | None:
    """The first finite number under ``key`` in the summary, then the config (None: no bound)."""
    for src in sources:
        v = _number(src.get(key))
        if v is not None:
            return v
    return None


def _region_polygon(summary: dict[str, Any]) -> list[list[float]] | None:
    """The region (4.21) of the run's analysis: its vertices in the (|E|, |E'|) plane."""
    analysis = summary.get("analysis")
    verts = analysis.get("vertices") if isinstance(analysis, dict) else None
    if not isinstance(verts, list) or len(verts) < 3:
        return None
    try:
        pts = [[float(a), float(b)] for a, b in verts]
    except (TypeError, ValueError):
        return None
    return pts if all(math.isfinite(x) for p in pts for x in p) else None


def _sup(x: Any) -> tuple[float | None, int]:
    """(max |x| over the finite values, or None; number of non-finite values)."""
    a = np.abs(np.asarray(x, float))
    finite = a[np.isfinite(a)]
    return (float(finite.max()) if finite.size else None), int(a.size - finite.size)


@dataclass(frozen=True, eq=False)
class LogPath:
    """C's path in a log: the desired one (``reference``, rebuilt from the log's configuration),
    the per-sample errors (``series``, a PathErrorSeries) and their summary (``errors``,
    a PathErrors), what the run's certificate implies for the path (``bound``, a PathBound) and
    the run judged against it (``verdict``, a PathVerdict); or, when they cannot be had,
    ``reason`` (and the rest None)."""

    reference: Any = None
    series: Any = None
    errors: Any = None
    reason: str | None = None
    bound: Any = None  # PathBound: what the run's certificate implies for the path
    verdict: Any = None  # PathVerdict: the run's cross-track against it


def path_of_log(log: RunLog, settle_s: float | None = None) -> LogPath:
    """C's Cartesian errors in ``log``: the desired path rebuilt as the run built it (its path, the
    controller's parameter set, its control period and duration), C's logged positions and the
    chassis heading. Never raises for a log without them: ``reason`` says why."""
    sig, cfg = log.signals, log.config or {}
    missing = [k for k in ("t", "C_pos", "heading") if sig.get(k) is None or not np.asarray(sig[k]).size]
    if missing:
        return LogPath(reason=f"the log has no {', '.join(missing)} rows")
    path, duration = cfg.get("path"), _number(cfg.get("duration"))
    if not isinstance(path, str) or duration is None:
        return LogPath(reason="the log's configuration names no path and duration to rebuild C's desired path from")
    period = log.timestep * log.control_substeps
    if not (math.isfinite(period) and period > 0):
        return LogPath(reason="the log has no control period")
    try:  # C's reference as the run built it (resolve_run's run_reference)
        reference, _ = run_reference(path, estimate_parameters(_base_of(cfg, C80)), period=period, duration=duration)
        t, C, h = np.asarray(sig["t"], float), np.asarray(sig["C_pos"], float), np.asarray(sig["heading"], float)
        ok = np.isfinite(t) & np.isfinite(C).all(axis=1) & np.isfinite(h)
        series = path_error_series(reference, t[ok], C[ok], h[ok])
    except WmrMjError as exc:
        return LogPath(reason=f"C's desired path cannot be rebuilt ({exc})")
    errors = summarize_series(series, settle_s)
    cert = (log.summary or {}).get("certificate")
    E_max, why_not = None, ""
    if isinstance(cert, dict):  # a certificate whose assumptions fail bounds no path (guaranteed_E_max)
        unmet = [a.get("name") for a in cert.get("assumptions") or [] if not a.get("met")]
        E_max, why_not = guaranteed_E_max(E_max=_number(cert.get("E_max")) if cert.get("valid") else None,
                                          valid=bool(cert.get("valid")), unmet=unmet)
    try:
        stops = _number(log.parameters.get("steering_range"))
    except LogError:
        stops = None
    try:
        bound = path_bound(reference, E_max, settle_s=settle_s, max_angle=stops)
    except WmrMjError:
        bound = path_bound(reference, E_max, max_angle=stops)
    bound = without_guarantee(bound, why_not)
    return LogPath(reference=reference, series=series, errors=errors, bound=bound,
                   verdict=path_verdict(errors, bound))


def _base_of(cfg: Mapping[str, Any], default: Any) -> Any:
    """The base parameter set of a logged run: its cart's (the config's "cart" record, the file's text), else
    ``default`` (the C80)."""
    cart = cfg.get("cart")
    if not isinstance(cart, Mapping) or not isinstance(cart.get("text"), str):
        return default

    return parameters_of_cart(load_cart_text(cart["text"], path=str(cart.get("path", "<log>"))))


def hardware_labels(config: dict[str, Any] | None) -> dict[str, str]:
    """The cart a logged run simulated, as one short line per part: ``{"sensing", "actuation", "gear"}``, each
    the ``label()`` of :class:`wmr_mj.hardware.Sensing`, :class:`~wmr_mj.hardware.Actuation` and
    :class:`~wmr_mj.hardware.Transmission` (the gear's backlash) read from the config in the header; "ideal"
    where it names none (``RunConfig.to_dict`` leaves an ideal part out), "not read (...)" where wmr_mj does
    not accept what it names. Never raises."""
    out = {}
    for key, name, cls in (("sensing", "sensing", Sensing), ("actuation", "actuation", Actuation),
                           ("gear", "transmission", Transmission)):
        spec = (config or {}).get(name)
        try:
            out[key] = cls.from_spec(spec).label()
        except WmrMjError as exc:
            out[key] = f"not read ({exc})"
    return out


def summarize(log: RunLog, settle_s: float | None = None) -> dict[str, Any]:
    """The replay summary of a loaded log (JSON-ready). ``settle_s`` [s] defaults to the log's."""
    sig = log.signals
    summary = log.summary or {}
    sources = [summary, log.config]
    if settle_s is None:
        settle_s = _lookup(sources, "settle_s")
    t = sig.get("t", np.empty(0))
    E = sig.get("E", np.empty(0))
    Ed = sig.get("E_dot", np.empty(0))
    out: dict[str, Any] = {
        "file": str(log.path),
        "status": log.status,
        "truncated": bool(log.truncated),
        "schema_version": log.info.get("schema_version"),
        "rows": int(log.rows),
        "signal_rows": int(t.size),
        "log_every": log.log_every,
        "timestep": log.timestep,
        "control_substeps": log.control_substeps,
        "duration_s": float(t[-1]) if t.size else None,
        "seed": log.seed,
        "config": log.config,
        "hardware": hardware_labels(log.config),
        "sensed": log.sensed,
    }
    if log.truncated:
        out["truncated_reason"] = log.truncated_reason
    sE, badE = _sup(E)
    sEd, badEd = _sup(Ed)
    out.update(sup_abs_E=sE, sup_abs_E_dot=sEd, non_finite_E=badE + badEd, settle_s=settle_s)
    out["sup_abs_E_after_settle"] = out["sup_abs_E_dot_after_settle"] = None
    if settle_s is not None and t.size:
        late = t >= settle_s
        out["sup_abs_E_after_settle"], _ = _sup(E[late])
        out["sup_abs_E_dot_after_settle"], _ = _sup(Ed[late])
    if sig.get("voltage") is not None and sig["voltage"].size:
        out["max_abs_voltage"], _ = _sup(sig["voltage"])
        with np.errstate(invalid="ignore"):
            sat = np.abs(sig["voltage_cmd"]) > np.abs(sig["voltage"]) + 1e-12
        out["voltage_saturated_fraction"] = float(np.mean(sat))
    e_max, ed_max = _lookup(sources, "E_max"), _lookup(sources, "Edot_max")
    out.update(E_max=e_max, Edot_max=ed_max, region_polygon=_region_polygon(summary))
    out["inside"] = out["inside_after_settle"] = None
    if (e_max is not None or ed_max is not None) and t.size:  # the runner's test: sup|E| <= E_max, sup|E'| <= Edot_max
        aE, aEd = np.abs(E), np.abs(Ed)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(aE) & np.isfinite(aEd)
            if e_max is not None:
                ok &= aE <= e_max
            if ed_max is not None:
                ok &= aEd <= ed_max
        out["inside"] = bool(np.all(ok))
        out["samples_outside"] = int(np.count_nonzero(~ok))
        if settle_s is not None:
            late = ok[t >= settle_s]
            out["inside_after_settle"] = bool(np.all(late)) if late.size else None
            out["samples_outside_after_settle"] = int(np.count_nonzero(~late))
    out["verdict"] = summary.get("verdict")  # the runner's separated verdict (wmr_mj.analysis.verdicts)
    lp = path_of_log(log, settle_s)
    out["path_errors"] = None if lp.errors is None else lp.errors.to_dict()
    out["path_bound"] = None if lp.bound is None else lp.bound.to_dict()
    out["path_verdict"] = None if lp.verdict is None else lp.verdict.to_dict()
    if lp.reason is not None:
        out["path_errors_note"] = lp.reason
    out["summary"] = log.summary
    out["versions"] = log.versions
    return out


def _signals_of(log: RunLog, n: int, substeps: int) -> tuple[np.ndarray | None, dict[int, dict[str, np.ndarray]]]:
    """(disturbance torque per control step or None, {control step: load fields}) of a logged run's signals."""
    config = log.config
    if not config.get("signals"):
        return None, {}

    signals = signals_from(config["signals"])
    if signals is None:
        return None, {}
    period = log.timestep * substeps
    dist = None if signals.disturbance is None else signals.disturbance.samples(np.arange(n) * period)
    params = C80Parameters(**log.parameters)
    options = {k: v for k, v in config.items() if k in ("steering_friction", "tyre_contact")}
    loads: dict[int, dict[str, np.ndarray]] = {}
    for t, m1 in signals.load_steps(params.m1):
        k = int(np.ceil(t / period - 1e-9))
        if k < n:
            changed = with_params(params, m1_inertia=config.get("m1_inertia", "payload"), m1=m1)
            loads[k] = load_fields(changed, **options)
    return dist, loads


def verify(log: RunLog) -> dict[str, Any]:
    """Re-simulate from the attached MJCF and initial state with the logged ctrl; compare qpos and
    qvel at every control step. {"identical": bool, "rows", "mj_steps", and where it first and
    most differs}. A run with signals (config "signals", :mod:`wmr_mj.sim.signals`) gets them again:
    its disturbance torque on the steering joint at every control step, its load changes' model
    fields (then mj_setConst) at theirs."""
    import mujoco

    try:
        m = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    except ValueError as exc:
        why = str(exc).strip().splitlines()[0] if str(exc).strip() else "compile error"
        raise LogError(f"{log.path}: the attached MJCF does not compile ({why})") from None
    d = mujoco.MjData(m)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    s0 = np.asarray(log.initial_state, np.float64).ravel()
    if s0.size != mujoco.mj_stateSize(m, spec):
        raise LogError(f"{log.path}: the initial state has {s0.size} values; the attached model's integration "
                       f"state has {mujoco.mj_stateSize(m, spec)}")
    st = log.state
    if not st:
        raise LogError(f"{log.path}: the log has no /sim/state channel to verify against")
    qpos, qvel, ctrl, t = st["qpos"], st["qvel"], st["ctrl"], st["t"]
    n = len(t)
    if qpos.shape[1:] != (m.nq,) or qvel.shape[1:] != (m.nv,) or ctrl.shape[1:] != (m.nu,):
        raise LogError(f"{log.path}: /sim/state sizes (nq, nv, nu) do not match the attached model")
    mujoco.mj_setState(m, d, s0, spec)
    sub = log.control_substeps
    dist, loads = _signals_of(log, n, sub)
    dof = int(m.jnt_dofadr[m.joint("steer").id])
    sim_q, sim_v = np.empty_like(qpos), np.empty_like(qvel)
    step = mujoco.mj_step
    for k in range(n):  # the runner's loop: record, apply the row's ctrl, step
        for name, value in loads.get(k, {}).items():
            getattr(m, name)[...] = value
        if k in loads:
            mujoco.mj_setConst(m, mujoco.MjData(m))
        if dist is not None:
            d.qfrc_applied[dof] = dist[k]
        sim_q[k] = d.qpos
        sim_v[k] = d.qvel
        d.ctrl[:] = ctrl[k]
        for _ in range(sub):
            step(m, d)
    same_q = (sim_q == qpos) | (np.isnan(sim_q) & np.isnan(qpos))
    same_v = (sim_v == qvel) | (np.isnan(sim_v) & np.isnan(qvel))
    row_ok = same_q.all(axis=1) & same_v.all(axis=1)
    out: dict[str, Any] = {"rows": n, "mj_steps": n * sub, "identical": bool(row_ok.all())}
    measured = _verify_measured(log, m, sim_q, sim_v)
    if measured is not None:  # a sensed run: what the law read is reproduced too, or the log is not
        out["measured"] = measured
    if not row_ok.all():
        with np.errstate(invalid="ignore"):
            dev = np.maximum(
                np.where(same_q, 0.0, np.nan_to_num(np.abs(sim_q - qpos), nan=np.inf)).max(axis=1, initial=0.0),
                np.where(same_v, 0.0, np.nan_to_num(np.abs(sim_v - qvel), nan=np.inf)).max(axis=1, initial=0.0),
            )
        k = int(np.argmax(dev))
        first = int(np.flatnonzero(~row_ok)[0])
        out.update(
            max_deviation=float(dev[k]), max_deviation_t=float(t[k]), max_deviation_row=k,
            max_deviation_in="qpos" if np.flatnonzero(~same_q[k]).size else "qvel",
            first_mismatch_t=float(t[first]), first_mismatch_row=first,
            mismatched_rows=int(np.count_nonzero(~row_ok)),
        )  # fmt: skip
    if measured is not None:
        out["state_identical"] = out["identical"]
        out["identical"] = bool(out["identical"] and measured["identical"])
    return out


def _bitwise_mismatch(again: np.ndarray, logged: np.ndarray) -> np.ndarray:
    """True where two float arrays differ in value (NaN equals NaN; +0.0 equals -0.0, as ``==`` says)."""
    return ~((again == logged) | (np.isnan(again) & np.isnan(logged)))


def _verify_measured(log: RunLog, m: Any, qpos: np.ndarray, qvel: np.ndarray) -> dict[str, Any] | None:
    """What the law read, regenerated and compared with the log's /measured; None for an ideal run.

    The sensing chain (:class:`wmr_mj.hardware.SensingChain`) is built from the config in the header (its
    noise drawn again from its seed, over the run's control steps) and stepped over the reproduced true state,
    as the runner steps it: alpha and alpha' on the axle, the motor shaft's angle i2 times its joint's.

    Returns:
        {"identical": bool, "rows": n, "sensing": its label} and where it is not identical
        "reason" (one line), and for differing values "first_mismatch_t" [s], "max_deviation",
        "max_deviation_in" ("alpha_measured" rad or "alpha_dot_measured" rad/s), "mismatched_rows".

    Raises:
        LogError: a sensing spec in the header that wmr_mj does not accept.
    """
    spec = (log.config or {}).get("sensing")
    if spec is None and not log.sensed:
        return None
    n = len(qpos)
    if spec is None:
        return {"identical": False, "rows": n, "sensing": "ideal",
                "reason": "the log has a /measured channel but its configuration names no sensing"}
    try:
        sensing = Sensing.from_spec(spec)
    except WmrMjError as exc:
        raise LogError(f"{log.path}: the sensing in the log's configuration is not accepted ({exc})") from None
    out: dict[str, Any] = {"identical": False, "rows": n, "sensing": sensing.label()}
    logged = log.measured
    if logged is None:
        return {**out, "reason": "the configuration names a sensor but the log has no /measured channel"}
    if len(logged["t"]) != n:
        return {**out, "reason": f"/measured has {len(logged['t'])} rows; /sim/state has {n}"}
    period = log.timestep * log.control_substeps
    duration = _number((log.config or {}).get("duration"))
    steps = n if duration is None else max(n, int(round(duration / period)))  # the noise is drawn for the run
    try:
        chain = SensingChain(sensing, control_period=period, n_steps=max(steps, 1),
                             gear_ratio=float(log.parameters["i2"]))
    except (WmrMjError, KeyError, TypeError, ValueError) as exc:
        raise LogError(f"{log.path}: its sensing cannot be regenerated ({type(exc).__name__}: {exc})") from None
    where = steering_joint_addresses(m)
    i2 = float(log.parameters["i2"])
    again = np.array([chain.step(k, float(qpos[k, where.axle_qpos]), float(qvel[k, where.axle_dof]),
                                 i2 * float(qpos[k, where.motor_qpos])) for k in range(n)]).reshape(n, 2)
    names = ("alpha_measured", "alpha_dot_measured")
    bad = np.stack([_bitwise_mismatch(again[:, j], np.asarray(logged[k], float)) for j, k in enumerate(names)], 1)
    out["identical"] = not bad.any()
    if bad.any():
        rows = np.flatnonzero(bad.any(axis=1))
        with np.errstate(invalid="ignore"):
            dev = np.where(bad, np.nan_to_num(np.abs(again - np.stack([logged[k] for k in names], 1)), nan=np.inf),
                           0.0)
        worst = np.unravel_index(int(np.argmax(dev)), dev.shape)
        out.update(reason=f"{rows.size} of {n} rows differ", first_mismatch_t=float(logged["t"][rows[0]]),
                   max_deviation=float(dev[worst]), max_deviation_in=names[worst[1]],
                   mismatched_rows=int(rows.size))
    return out



@dataclass(frozen=True)
class CheckedPlugin:
    """A plug-in the log names, its file checked against the log's record (:func:`checked_plugins`).

    Attributes:
        kind: 'controller' or 'tracker'.
        name: its name, as the record gives it.
        source: its file (:class:`controllers.registry.LocatedSource`), whose SHA-256 is the record's.
    """

    kind: str
    name: str
    source: LocatedSource

    def will_import(self) -> str:
        """The line said before the file is imported (and so run)."""
        return (f"replay: will import the {self.kind} plug-in {self.name!r} from {self.source.describe()}; its "
                f"SHA-256 {self.source.sha256[:12]}... is the log's")


def checked_plugins(log: RunLog) -> list[CheckedPlugin]:
    """The plug-in files that re-running the log imports, each found and hashed without running any code,
    and checked against the SHA-256 the log records (:func:`controllers.registry.check_recorded_source`).

    A plug-in given as an object is left out: it is not imported (:func:`verify_controller` says it cannot be
    rebuilt). A law or tracker named without a record is a built-in or an installed entry point, code of
    this installation, not of the log.

    Raises:
        ParameterError: a plug-in's file that is gone, cannot be found without running code or has changed
            since the run (one line: the file, the recorded and the found SHA-256 prefix); a plug-in named in
            the configuration without its record (nothing to check it against).
    """
    cfg = log.config or {}
    out: list[CheckedPlugin] = []
    for kind in ("controller", "tracker"):
        record = cfg.get(f"{kind}_plugin")
        given = cfg.get(kind)
        if record is None:
            if isinstance(given, str) and ":" in given:  # FILE.py:Class, module:Class
                raise ParameterError(f"{log.path}: the {kind} {given!r} is a plug-in and the log holds no record of "
                                     f"its source ({kind}_plugin, its SHA-256) to check it by: not imported")
            continue
        if not isinstance(record, dict):
            raise ParameterError(f"{log.path}: the log's {kind}_plugin is not a plug-in record: not imported")
        if record.get("origin") == "instance":
            continue
        out.append(CheckedPlugin(kind=kind, name=str(record.get("name")),
                                 source=check_recorded_source(record, kind=kind)))
    return out


def verify_controller(log: RunLog) -> dict[str, Any]:
    """Re-run the log's configuration with its controller (and tracker) imported again, and compare the
    voltage the law applied at every logged control step with the log's, bit for bit.

    Returns:
        {"checked": bool, "identical": bool, "controller": name, "rows": n, "reason": why not checked,
        "required": bool, "first_mismatch_t": s}: ``checked`` False (with ``reason``, one line) where the
        run cannot be made again; ``required`` True where that is a failure to reproduce (a plug-in given
        as an object, a file or module that is gone, a source whose SHA-256 differs from the one
        recorded), False where the log holds no wmr-mj run configuration at all.
    """
    import mujoco

    cfg = log.config
    name = str(cfg.get("controller", "?")) if cfg else "?"
    if not cfg:
        return {"checked": False, "identical": False, "controller": name, "required": False,
                "reason": "the log has no run configuration to re-run"}
    try:
        checked_plugins(log)  # a changed or missing plug-in file is refused here, before it is imported
        config = config_from_dict(cfg)  # imports the plug-ins (and checks their source again, once imported)
    except WmrMjError as exc:  # the law cannot be found again, or its source has changed: not reproduced
        return {"checked": False, "identical": False, "controller": name, "required": True, "reason": str(exc)}
    except (KeyError, TypeError) as exc:  # a log another program wrote: nothing to re-run
        return {"checked": False, "identical": False, "controller": name, "required": False,
                "reason": f"the log's configuration is not a wmr-mj run's ({type(exc).__name__}: {exc})"}
    name = controller_name(config)
    st = log.state
    if not st:
        return {"checked": False, "identical": False, "controller": name,
                "reason": "the log has no /sim/state channel to compare with"}
    m = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    act = int(m.actuator("steering_motor").id)
    logged = np.asarray(st["ctrl"])[:, act]
    n = len(logged)
    result = run_closed_loop(config, progress=False)
    again = np.asarray(result.rows["voltage"])[:n]
    same = (again == logged[:len(again)]) | (np.isnan(again) & np.isnan(logged[:len(again)]))
    out: dict[str, Any] = {"checked": True, "identical": bool(len(again) == n and same.all()), "controller": name,
                           "rows": n, "required": True}
    if not out["identical"]:
        bad = np.flatnonzero(~same)
        k = int(bad[0]) if bad.size else len(again)
        out["first_mismatch_t"] = float(np.asarray(st["t"])[min(k, n - 1)])
        out["reason"] = (f"the re-run stopped after {len(again)} of {n} control steps" if len(again) < n else
                         f"{bad.size} of {n} voltages differ")
    elif log.measured is not None:  # a sensed run: the re-run's law read what the log says it read
        differs = np.zeros(n, bool)
        for key, logged_k in log.measured.items():
            if key == "t":
                continue
            again_k = np.asarray(result.rows.get(key, np.full(n, np.inf)))[:n]
            if len(logged_k) != n or len(again_k) != n:
                differs[:] = True
                continue
            differs |= _bitwise_mismatch(again_k, np.asarray(logged_k))
        if differs.any():
            out.update(identical=False, first_mismatch_t=float(np.asarray(st["t"])[int(np.argmax(differs))]),
                       reason=f"the voltages agree, but at {int(differs.sum())} of {n} control steps the re-run's law "
                              "read other values than /measured")
    return out


def format_verify_controller(ver: dict[str, Any]) -> str:
    """One line for :func:`verify_controller`'s dict."""
    if not ver["checked"]:
        return f"controller {ver['controller']!r} not re-run: {ver['reason']}"
    if ver["identical"]:
        return (f"controller {ver['controller']!r} re-run: the voltages it applied are bit-identical at all "
                f"{ver['rows']} control steps")
    return (f"controller {ver['controller']!r} re-run: MISMATCH, {ver['reason']} (first at "
            f"t = {ver['first_mismatch_t']:.6g} s)")


def _band(ax: Any, bound: float | None, ls: str, color: str, label: str, unit: str) -> None:
    """Horizontal lines at +-bound (nothing when the bound is None)."""
    if bound is None:
        return
    ax.axhline(bound, ls=ls, lw=0.8, color=color, label=f"{label} = {bound:.3g} {unit}")
    ax.axhline(-bound, ls=ls, lw=0.8, color=color)

def _path_panels(e: Any, f: Any, lp: LogPath, settle: float | None) -> None:
    """(c) C's desired path against the actual one; (f) cross-track and along-track over time."""
    e.set(xlabel="x [m]", ylabel="y [m]", title="(c) path of C")
    f.set(xlabel="t [s]", ylabel="error [m]", title="(f) path errors of C")
    if lp.errors is None:
        for axis in (e, f):
            axis.text(0.5, 0.5, f"n/a: {lp.reason}", ha="center", va="center", wrap=True, fontsize=8,
                      transform=axis.transAxes)
        return
    ref, ser, err = lp.reference, lp.series, lp.errors
    des = np.asarray(ref.C_xy)
    e.plot(des[:, 0], des[:, 1], lw=1.6, color="0.6", label="desired")
    e.plot(ser.C_xy[:, 0], ser.C_xy[:, 1], lw=0.9, color="C0", label="actual")
    e.plot(des[0, 0], des[0, 1], "o", ms=4, color="0.4", label="start")
    e.set_aspect("equal", adjustable="datalim")
    e.legend(loc="best", fontsize=7, frameon=False)
    f.plot(ser.t, ser.cross_track, lw=0.9, color="C0",
           label=f"cross-track (> 0 left), max {err.cross_track_max:.3g} m")
    f.plot(ser.t, ser.along_track, lw=0.9, color="C1",
           label=f"along-track (> 0 ahead), final {err.along_track_final:+.3g} m")
    if settle is not None:
        f.axvline(settle, color="0.5", lw=0.6, ls="-.")
    f.axhline(0.0, color="k", lw=0.5)
    f.legend(loc="best", fontsize=7, frameon=False)


def _measured_error_line(ax: Any, log: RunLog, sig: dict[str, np.ndarray]) -> None:
    """Where the run was sensed: the error as the law read it, alpha0 - alpha_measured [rad], beside the true E,
    at the /signals rows (every log_every-th control step of /measured); nothing for an ideal run."""
    ms = log.measured
    if ms is None or not len(ms["t"]):
        return
    alpha_m = np.asarray(ms["alpha_measured"])[::max(1, log.log_every)]
    k = min(len(alpha_m), len(sig["t"]))
    ax.plot(sig["t"][:k], sig["alpha0"][:k] - alpha_m[:k], lw=0.6, color="C5", alpha=0.8,
            label="measured (what the law read)")


def plot(log: RunLog, path: str | os.PathLike, rep: dict[str, Any]) -> Path:
    """Write the replay figure (PNG) for ``rep`` = :func:`summarize` of ``log``; returns the path."""
    fig = replay_figure(log, rep)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=200)
    return out


def replay_figure(log: RunLog, rep: dict[str, Any]):
    """The replay figure: (a) E, (b) E', (c) C's path; (d) the voltage, (e) the error plane with the
    certificate's region beside the paper's, (f) C's path errors (panels read a b c / d e f)."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Polygon, Rectangle

    sig = log.signals
    t = sig.get("t")
    if t is None or t.size == 0:
        raise LogError(f"{log.path}: the log has no signal rows to plot")
    E, Ed = sig["E"], sig["E_dot"]
    settle = rep.get("settle_s")
    e_max, ed_max, poly = rep.get("E_max"), rep.get("Edot_max"), rep.get("region_polygon")
    style: dict[RcKeyType, Any] = {"font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False,
                                   "axes.spines.right": False}
    import matplotlib

    with matplotlib.rc_context(style):
        fig = Figure(figsize=(15, 6.8), constrained_layout=True)
        ax = fig.subplots(2, 3)
        a = ax[0, 0]
        a.plot(t, E, lw=0.9, color="C0", label="E = alpha0 - alpha" + (" (true)" if log.sensed else ""))
        _measured_error_line(a, log, sig)
        cert = (log.summary or {}).get("certificate") or {}
        _band(a, cert.get("E_max"), "-", "C2", "certificate ±E_max", "rad")
        _band(a, e_max, "--", "C3", "paper's claim ±E_max", "rad")
        a.set(xlabel="t [s]", ylabel="E [rad]", title="(a) steering error")
        b = ax[0, 1]
        b.plot(t, Ed, lw=0.9, color="C1", label="E' = alpha0' - alpha'")
        _band(b, cert.get("Edot_max"), "-", "C2", "certificate ±Edot_max", "rad/s")
        _band(b, ed_max, "--", "C3", "paper's claim ±Edot_max", "rad/s")
        b.set(xlabel="t [s]", ylabel="E' [rad/s]", title="(b) error rate")
        c = ax[1, 0]  # drawn as (d): the panels read a b c / d e f
        c.plot(t, sig["voltage_cmd"], lw=0.7, color="0.6", label="controller output")
        c.plot(t, sig["voltage"], lw=0.9, color="C2", label="applied (limited)")
        try:
            vlim = _number(log.parameters.get("voltage_limit"))
        except LogError:
            vlim = None
        if vlim is not None:
            c.axhline(vlim, ls=":", lw=0.8, color="k", label=f"supply ±{vlim:g} V")
            c.axhline(-vlim, ls=":", lw=0.8, color="k")
        c.set(xlabel="t [s]", ylabel="u [V]", title="(d) armature voltage")
        d = ax[1, 1]
        aE, aEd = np.abs(E), np.abs(Ed)
        late = t >= settle if settle is not None else np.ones(t.size, bool)
        if settle is not None and np.any(~late):
            d.plot(aE[~late], aEd[~late], lw=0.6, color="0.7", label=f"t < {settle:g} s")
        d.plot(aE[late], aEd[late], lw=0.8, color="C0", label=f"t ≥ {settle:g} s" if settle is not None else "run")
        fin = np.flatnonzero(np.isfinite(aE) & np.isfinite(aEd))
        if fin.size:
            d.plot(aE[fin[-1]], aEd[fin[-1]], "o", ms=4, color="C0", label=f"end (t = {t[fin[-1]]:.3g} s)")
        if e_max is not None and ed_max is not None:
            d.add_patch(Rectangle((0, 0), e_max, ed_max, fc="C3", alpha=0.15, ec="C3", ls="--", lw=0.9,
                                  label="paper's claim: E_max x Edot_max"))
        if poly:
            d.add_patch(Polygon(np.asarray(poly), closed=True, fc="C4", alpha=0.1, ec="C4", lw=0.9,
                                label="paper's claim: region (4.21)"))
        cert_poly = cert.get("vertices")
        if isinstance(cert_poly, list) and len(cert_poly) >= 3:
            # the certificate's region, which the verdict is judged by
            whose = f" ({cert['claimant']})" if cert.get("claimant") else ""
            d.add_patch(Polygon(np.asarray(cert_poly, float), closed=True, fc="C2", alpha=0.15, ec="C2", lw=1.2,
                                label=f"certificate's region{whose}: verdict {(log.summary or {}).get('verdict')}"))
        own = (log.summary or {}).get("paper_claim_applies") is False
        d.set(xlabel="|E| [rad]", ylabel="|E'| [rad/s]",
              title="(e) error plane: the law's own claim" if own else "(e) error plane: both regions")
        d.set_xlim(left=0)
        d.set_ylim(bottom=0)
        for axis in (a, b, c):
            if settle is not None:
                axis.axvline(settle, color="0.5", lw=0.6, ls="-.")
        _path_panels(ax[0, 2], ax[1, 2], path_of_log(log, settle), settle)
        for axis in (a, b, c, d):
            axis.legend(loc="best", fontsize=7, frameon=False)

        cfg = shown_config(log.config or {}, log.summary)  # the law's own settings only
        bits = [f"{k}={cfg[k]}" for k in ("controller", "path", "model", "seed")
                if k in cfg and not isinstance(cfg[k], (dict, list))]
        key = "inside_after_settle" if rep.get("inside_after_settle") is not None else "inside"
        verdict = {True: "inside the paper's claim", False: "outside the paper's claim", None: ""}[rep.get(key)]
        if verdict and key == "inside_after_settle":
            verdict += " after settling"
        if (log.summary or {}).get("paper_claim_applies") is False:  # judged by its own claim only
            # the law owns its claim; a claimant other than the law (the sampled-data certificate a built-in
            # sampled law is judged by, issue 44) is how it certifies, named after it
            claimant = cert.get("claimant") or ""
            inputs = cert.get("inputs")
            law = (inputs.get("controller") if isinstance(inputs, dict) else None) or claimant
            claim = (f"{law}'s claim" + (f" ({claimant})" if claimant not in ("", law) else "")
                     if law else "its own claim")
            inside = cert.get("inside")
            verdict = "" if inside is None else f"{'inside' if inside else 'outside'} {claim}"
        extra = [v for v in (rep.get("verdict"), verdict, "TRUNCATED" if log.truncated else "") if v]
        hw = rep.get("hardware") or hardware_labels(log.config)
        cart = ("" if all(v == "ideal" for v in hw.values())  # an ideal cart's title as it was
                else f"\nsensing: {hw['sensing']} | actuation: {hw['actuation']} | gear: {hw['gear']}")
        fig.suptitle(f"{Path(str(log.path)).name}: " + ", ".join(bits + extra) + cart, fontsize=10)
    return fig


def _fmt(v: Any, unit: str = "") -> str:
    if v is None:
        return "n/a"
    if isinstance(v, float):
        return f"{v:.4g}{(' ' + unit) if unit else ''}"
    return str(v)


def format_summary(rep: dict[str, Any]) -> str:
    """The text of ``wmr-mj replay`` for :func:`summarize`'s dict."""
    lines = [f"log        {rep['file']}"]
    dur = rep["duration_s"]
    lines.append(
        f"status     {rep['status']}: {rep['rows']} control steps, {rep['signal_rows']} signal rows"
        + (f", t = 0 .. {dur:.4g} s" if dur is not None else "")
        + f" (timestep {rep['timestep']:.4g} s x {rep['control_substeps']}, log every {rep['log_every']}; "
        f"schema {rep['schema_version']})"
    )
    if rep["truncated"]:
        lines.append(f"TRUNCATED  the file ends without its footer ({rep.get('truncated_reason')}): the run was "
                     "killed; what was flushed is shown")

    cfg = shown_config(rep["config"] or {}, rep.get("summary"))  # the law's own settings only
    scalars = [f"{k}={v}" for k, v in cfg.items() if isinstance(v, (str, int, float, bool)) or v is None]
    if scalars:
        lines.append("config     " + "  ".join(scalars))
    nested = [k for k, v in cfg.items() if isinstance(v, (dict, list))]
    if nested:
        lines.append("           (+ " + ", ".join(nested) + ": see --json)")
    hw = rep.get("hardware")
    if hw:
        lines.append(f"cart       sensing: {hw['sensing']} | actuation: {hw['actuation']} | gear: {hw['gear']}"
                     + ("; the law read /measured, E is judged on the true state" if rep.get("sensed") else ""))
    settle = rep["settle_s"]
    after = f" (t >= {settle:g} s: " if settle is not None else None
    lines.append(f"sup|E|     {_fmt(rep['sup_abs_E'], 'rad')}"
                 + (f"{after}{_fmt(rep['sup_abs_E_after_settle'], 'rad')})" if after else ""))
    lines.append(f"sup|E'|    {_fmt(rep['sup_abs_E_dot'], 'rad/s')}"
                 + (f"{after}{_fmt(rep['sup_abs_E_dot_after_settle'], 'rad/s')})" if after else ""))
    if rep["non_finite_E"]:
        lines.append(f"non-finite {rep['non_finite_E']} values of E or E' are NaN/inf")
    if rep.get("max_abs_voltage") is not None:
        lines.append(f"voltage    max |u| = {_fmt(rep['max_abs_voltage'], 'V')}, saturated "
                     f"{100 * rep['voltage_saturated_fraction']:.1f}% of rows")
    if (rep.get("summary") or {}).get("paper_claim_applies") is False:
        lines.append(f"paper's claim {PAPER_CLAIM_NOT_APPLICABLE}")
    elif rep["E_max"] is not None or rep["Edot_max"] is not None:
        def verdict(inside: Any, count: Any) -> str:
            return {True: "INSIDE", False: f"OUTSIDE ({count} samples)", None: "n/a"}[inside]

        text = f"paper's claim E_max = {_fmt(rep['E_max'], 'rad')}, Edot_max = {_fmt(rep['Edot_max'], 'rad/s')}: "
        text += f"whole run {verdict(rep['inside'], rep.get('samples_outside'))}"
        if settle is not None:
            late = verdict(rep["inside_after_settle"], rep.get("samples_outside_after_settle"))
            text += f"; after t = {settle:g} s {late}"
        lines.append(text)
    else:
        lines.append("bounds     none in the log (no finite E_max / Edot_max in its summary or config)")
    if rep.get("summary"):
        lines.extend(_verdict_block(format_verdict(rep["summary"])))
    pe = rep.get("path_errors")
    if pe:
        def signed(v: float, pos: str, neg: str) -> str:
            return f"{v:+.4g} m ({pos if v > 0 else neg})" if v else "0 m"

        lines.append(f"path of C  cross-track max {pe['cross_track_max']:.4g} m, rms {pe['cross_track_rms']:.4g} m, "
                     f"final {signed(pe['cross_track_final'], 'left', 'right')}"
                     + (f"; max after t = {pe['settle_s']:g} s {pe['cross_track_max_after_settle']:.4g} m"
                        if pe.get("cross_track_max_after_settle") is not None else ""))
        lines.append(f"           along-track final {signed(pe['along_track_final'], 'ahead', 'behind')} of the "
                     f"timed reference, max {pe['along_track_max']:.4g} m; heading error max "
                     f"{pe['heading_error_max']:.4g} rad, final {pe['heading_error_final']:+.4g} rad")
        if rep.get("path_verdict"):
            lines.append(f"path bound {rep['path_verdict']['verdict']}: {rep['path_verdict']['text']}")
    elif rep.get("path_errors_note"):
        lines.append(f"path of C  n/a: {rep['path_errors_note']}")
    if rep["summary"]:
        # the paper's region under its own names only (a log written before they existed keeps the old ones)
        renamed = set(PAPER_KEYS_DEPRECATED) if "paper_E_max" in rep["summary"] else set()
        # a law outside the paper's family: the keys it has no value for (the paper's region, settings it
        # does not read) are null with a reason; not printed
        renamed |= {k for k, v in rep["summary"].items() if v is None and (
            k in PAPER_REGION_KEYS or k in (rep["summary"].get("not_applicable") or {}))}
        extra = {k: v for k, v in rep["summary"].items() if k not in ("status", "rows", "last_t") and k not in renamed}
        sc = [f"{k}={_fmt(v) if isinstance(v, float) else v}" for k, v in extra.items()
              if isinstance(v, (str, int, float, bool)) or v is None]
        if sc:
            lines.append("summary    " + "  ".join(sc))
    return "\n".join(lines)


def _verdict_block(verdict_lines: list[str]) -> list[str]:
    """The verdict's lines (:func:`wmr_mj.analysis.verdicts.format_verdict`) under the label ``verdict``: the
    verdict on the labelled line (its own "verdict: " dropped), the lines after it indented under it, a
    CERTIFIED-OUTSIDE banner above it as ``run`` prints it."""
    out: list[str] = []
    labelled = False
    for line in verdict_lines:
        if line.startswith("!!!") and not labelled:
            out.append(line)
        elif not labelled:
            out.append("verdict    " + line.removeprefix("verdict: "))
            labelled = True
        else:
            out.append(" " * len("verdict    ") + line)
    return out


def format_verify(ver: dict[str, Any]) -> str:
    """The text for :func:`verify`'s dict: one line, and a second for a sensed run's /measured."""
    if ver.get("state_identical", ver["identical"]):
        text = (f"verify     bit-identical: qpos and qvel reproduced exactly at all {ver['rows']} control steps "
                f"({ver['mj_steps']} mj_step calls)")
    else:
        text = (f"verify     MISMATCH: largest deviation {ver['max_deviation']:.3g} in {ver['max_deviation_in']} at "
                f"t = {ver['max_deviation_t']:.6g} s (row {ver['max_deviation_row']}); first at "
                f"t = {ver['first_mismatch_t']:.6g} s; {ver['mismatched_rows']} of {ver['rows']} rows differ")
    ms = ver.get("measured")
    if ms is None:
        return text
    if ms["identical"]:
        return text + (f"\n           bit-identical: what the law read (/measured: alpha, alpha') regenerated "
                       f"exactly at all {ms['rows']} control steps by the sensing in the header ({ms['sensing']})")
    where = (f": largest deviation {ms['max_deviation']:.3g} in {ms['max_deviation_in']}, first at "
             f"t = {ms['first_mismatch_t']:.6g} s" if "max_deviation" in ms else "")
    return text + (f"\n           MISMATCH in what the law read (/measured, sensing {ms['sensing']}): "
                   f"{ms['reason']}{where}")
