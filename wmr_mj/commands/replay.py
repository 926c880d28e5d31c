"""``wmr-mj replay LOG``: summarise, plot, verify or render a run log (MCAP).

Everything comes from the log alone: its configuration, signals, attachments (the
exact MJCF, the initial state) and the summary written at close.

- default: a text summary (configuration, sup|E| and sup|E'| over the whole run
  and after ``settle_s``, the analytic bounds E_max / Edot_max when the log
  carries them, inside/outside); ``--json`` prints it as one JSON object;
- ``--plot PATH.png``: E and E' over time, the armature voltage, and the
  (|E|, |E'|) plane with the bounds' rectangle (and polygon, when given);
- ``--verify``: rebuild the model from the attached MJCF, set the initial state,
  re-apply the logged ctrl and compare qpos/qvel at every control step: exit 0
  when bit-identical, 1 otherwise (with the largest deviation and when);
- ``--video PATH.mp4``: offscreen rendering with MuJoCo's Renderer (EGL, then
  OSMesa), encoded by ffmpeg (system ffmpeg or the imageio-ffmpeg package).

Bounds are looked up in the summary, then in the config, under ``E_max`` and
``Edot_max`` (also ``E_dot_max``; or inside a ``bounds`` / ``region`` dict); a
polygon in the (|E|, |E'|) plane under ``region_polygon`` ([[E, Edot], ...]).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import Any

from ._common import positive_float, positive_int, print_json

E_MAX_KEYS = ("E_max", "e_max")
EDOT_MAX_KEYS = ("Edot_max", "E_dot_max", "edot_max", "e_dot_max")
POLYGON_KEYS = ("region_polygon", "polygon")
SETTLE_KEYS = ("settle_s", "settle_time", "t_settle")


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "replay",
        help="summarise, plot, verify (bit for bit) or render a run log",
        description="summarise, plot, verify (bit for bit) or render a wmr-mj run log (MCAP)",
    )
    p.add_argument("log", metavar="LOG", help="MCAP run log written by `wmr-mj run`")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.add_argument("--plot", metavar="PATH.png", help="write a figure: E, E', voltage over time and the (|E|,|E'|) plane")
    p.add_argument("--verify", action="store_true", help="re-simulate from the attached MJCF and initial state; exit 1 unless bit-identical")
    p.add_argument("--video", metavar="PATH.mp4", help="render the run offscreen (needs EGL or OSMesa, and ffmpeg)")
    p.add_argument("--settle", type=positive_float, metavar="S", help="settling time for the sup after settling [s] (default: settle_s of the log's config)")
    p.add_argument("--fps", type=positive_int, default=30, help="video frame rate (default 30)")
    p.add_argument("--size", default="960x540", metavar="WxH", help="video size in pixels (default 960x540)")
    p.set_defaults(func=run)


# --------------------------------------------------------------------------- summary


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _lookup(sources: list[dict], keys: tuple[str, ...]) -> float | None:
    for src in sources:
        for k in keys:
            v = _number(src.get(k))
            if v is not None:
                return v
        for nest in ("bounds", "region"):
            sub = src.get(nest)
            if isinstance(sub, dict):
                for k in keys:
                    v = _number(sub.get(k))
                    if v is not None:
                        return v
    return None


def _polygon(sources: list[dict]) -> list[list[float]] | None:
    for src in sources:
        for where in (src, src.get("bounds") if isinstance(src.get("bounds"), dict) else {}, src.get("region") if isinstance(src.get("region"), dict) else {}):
            for k in POLYGON_KEYS:
                v = where.get(k)
                if isinstance(v, list) and len(v) >= 3 and all(isinstance(p, (list, tuple)) and len(p) == 2 for p in v):
                    try:
                        pts = [[float(a), float(b)] for a, b in v]
                    except (TypeError, ValueError):
                        continue
                    if all(math.isfinite(x) for p in pts for x in p):
                        return pts
    return None


def _sup(x: Any) -> tuple[float | None, int]:
    """(max |x| over finite values or None, number of non-finite values)."""
    import numpy as np

    a = np.abs(np.asarray(x, float))
    bad = int(np.count_nonzero(~np.isfinite(a)))
    finite = a[np.isfinite(a)]
    return (float(finite.max()) if finite.size else None), bad


def summarize(log: Any, settle_s: float | None = None) -> dict[str, Any]:
    """The replay summary of a loaded RunLog, as a JSON-ready dict."""
    import numpy as np

    sig = log.signals
    summary = log.summary or {}
    sources = [summary, log.config]
    if settle_s is None:
        settle_s = _lookup(sources, SETTLE_KEYS)
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
    }
    if log.truncated:
        out["truncated_reason"] = log.truncated_reason
    sE, badE = _sup(E)
    sEd, badEd = _sup(Ed)
    out.update(sup_abs_E=sE, sup_abs_E_dot=sEd, non_finite_E=badE + badEd)
    out["settle_s"] = settle_s
    if settle_s is not None and t.size:
        late = t >= settle_s
        out["sup_abs_E_after_settle"], _ = _sup(E[late])
        out["sup_abs_E_dot_after_settle"], _ = _sup(Ed[late])
    else:
        out["sup_abs_E_after_settle"] = out["sup_abs_E_dot_after_settle"] = None
    if "voltage" in sig and sig["voltage"].size:
        out["max_abs_voltage"], _ = _sup(sig["voltage"])
        with np.errstate(invalid="ignore"):
            sat = np.abs(sig["voltage_cmd"]) > np.abs(sig["voltage"]) + 1e-12
        out["voltage_saturated_fraction"] = float(np.mean(sat))
    e_max, ed_max = _lookup(sources, E_MAX_KEYS), _lookup(sources, EDOT_MAX_KEYS)
    poly = _polygon(sources)
    out.update(E_max=e_max, Edot_max=ed_max, region_polygon=poly)
    out["inside"] = out["inside_after_settle"] = None
    if (e_max is not None or ed_max is not None or poly) and t.size:
        aE, aEd = np.abs(E), np.abs(Ed)
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(aE) & np.isfinite(aEd)
            if e_max is not None:
                ok &= aE <= e_max
            if ed_max is not None:
                ok &= aEd <= ed_max
        if poly:
            from matplotlib.path import Path as MplPath

            ok &= MplPath(np.asarray(poly)).contains_points(np.column_stack([np.nan_to_num(aE, nan=np.inf), np.nan_to_num(aEd, nan=np.inf)]))
        out["inside"] = bool(np.all(ok))
        out["samples_outside"] = int(np.count_nonzero(~ok))
        if settle_s is not None:
            late = ok[t >= settle_s]
            out["inside_after_settle"] = bool(np.all(late)) if late.size else None
            out["samples_outside_after_settle"] = int(np.count_nonzero(~late))
    out["summary"] = log.summary
    out["versions"] = log.versions
    return out


def _fmt(v: Any, unit: str = "") -> str:
    if v is None:
        return "n/a"
    if isinstance(v, float):
        return f"{v:.4g}{(' ' + unit) if unit else ''}"
    return str(v)


def _text(rep: dict[str, Any]) -> str:
    lines = [f"log        {rep['file']}"]
    dur = rep["duration_s"]
    lines.append(
        f"status     {rep['status']}: {rep['rows']} control steps, {rep['signal_rows']} signal rows"
        + (f", t = 0 .. {dur:.4g} s" if dur is not None else "")
        + f" (timestep {rep['timestep']:.4g} s x {rep['control_substeps']}, log every {rep['log_every']}; schema {rep['schema_version']})"
    )
    if rep["truncated"]:
        lines.append(f"TRUNCATED  the file ends without its footer ({rep.get('truncated_reason')}): the run was killed; what was flushed is shown")
    cfg = rep["config"] or {}
    scalars = [f"{k}={v}" for k, v in cfg.items() if isinstance(v, (str, int, float, bool)) or v is None]
    if scalars:
        lines.append("config     " + "  ".join(scalars))
    nested = [k for k, v in cfg.items() if isinstance(v, (dict, list))]
    if nested:
        lines.append("           (+ " + ", ".join(nested) + ": see --json)")
    settle = rep["settle_s"]
    after = f" (t >= {settle:g} s: " if settle is not None else None
    lines.append(f"sup|E|     {_fmt(rep['sup_abs_E'], 'rad')}" + (f"{after}{_fmt(rep['sup_abs_E_after_settle'], 'rad')})" if after else ""))
    lines.append(f"sup|E'|    {_fmt(rep['sup_abs_E_dot'], 'rad/s')}" + (f"{after}{_fmt(rep['sup_abs_E_dot_after_settle'], 'rad/s')})" if after else ""))
    if rep["non_finite_E"]:
        lines.append(f"non-finite {rep['non_finite_E']} values of E or E' are NaN/inf")
    if rep.get("max_abs_voltage") is not None:
        lines.append(f"voltage    max |u| = {_fmt(rep['max_abs_voltage'], 'V')}, saturated {100 * rep['voltage_saturated_fraction']:.1f}% of rows")
    if rep["E_max"] is not None or rep["Edot_max"] is not None or rep["region_polygon"]:
        def verdict(inside: Any, count: Any) -> str:
            return {True: "INSIDE", False: f"OUTSIDE ({count} samples)", None: "n/a"}[inside]

        poly = " and the region polygon" if rep["region_polygon"] else ""
        text = f"bounds     E_max = {_fmt(rep['E_max'], 'rad')}, Edot_max = {_fmt(rep['Edot_max'], 'rad/s')}{poly}: "
        text += f"whole run {verdict(rep['inside'], rep.get('samples_outside'))}"
        if settle is not None:
            text += f"; after t = {settle:g} s {verdict(rep['inside_after_settle'], rep.get('samples_outside_after_settle'))}"
        lines.append(text)
    else:
        lines.append("bounds     none in the log (no E_max / Edot_max in config or summary)")
    if rep["summary"]:
        extra = {k: v for k, v in rep["summary"].items() if k not in ("status", "rows", "last_t")}
        sc = [f"{k}={_fmt(v) if isinstance(v, float) else v}" for k, v in extra.items() if isinstance(v, (str, int, float, bool)) or v is None]
        if sc:
            lines.append("summary    " + "  ".join(sc))
    return "\n".join(lines)


# --------------------------------------------------------------------------- verify


def verify_log(log: Any) -> dict[str, Any]:
    """Re-simulate from the attached MJCF + initial state with the logged ctrl; compare qpos/qvel."""
    import mujoco
    import numpy as np

    from ..errors import LogError

    try:
        m = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    except Exception as exc:
        raise LogError(f"{log.path}: the attached MJCF does not compile ({str(exc).splitlines()[0] if str(exc) else exc})") from None
    d = mujoco.MjData(m)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    s0 = np.asarray(log.initial_state, np.float64).ravel()
    if s0.size != mujoco.mj_stateSize(m, spec):
        raise LogError(f"{log.path}: the initial state has {s0.size} values; the attached model's integration state has {mujoco.mj_stateSize(m, spec)}")
    st = log.state
    if not st:
        raise LogError(f"{log.path}: the log has no /sim/state channel to verify against")
    qpos, qvel, ctrl, t = st["qpos"], st["qvel"], st["ctrl"], st["t"]
    n = len(t)
    if qpos.shape[1:] != (m.nq,) or qvel.shape[1:] != (m.nv,) or ctrl.shape[1:] != (m.nu,):
        raise LogError(f"{log.path}: /sim/state sizes (nq, nv, nu) do not match the attached model")
    mujoco.mj_setState(m, d, s0, spec)
    sub = log.control_substeps
    sim_q = np.empty_like(qpos)
    sim_v = np.empty_like(qvel)
    step = mujoco.mj_step
    for k in range(n):
        sim_q[k] = d.qpos
        sim_v[k] = d.qvel
        d.ctrl[:] = ctrl[k]
        for _ in range(sub):
            step(m, d)
    same_q = (sim_q == qpos) | (np.isnan(sim_q) & np.isnan(qpos))
    same_v = (sim_v == qvel) | (np.isnan(sim_v) & np.isnan(qvel))
    row_ok = same_q.all(axis=1) & same_v.all(axis=1)
    out: dict[str, Any] = {"rows": n, "mj_steps": n * sub, "identical": bool(row_ok.all())}
    if not out["identical"]:
        with np.errstate(invalid="ignore"):
            dev = np.maximum(
                np.where(same_q, 0.0, np.nan_to_num(np.abs(sim_q - qpos), nan=np.inf)).max(axis=1, initial=0.0),
                np.where(same_v, 0.0, np.nan_to_num(np.abs(sim_v - qvel), nan=np.inf)).max(axis=1, initial=0.0),
            )
        k = int(np.argmax(dev))
        first = int(np.flatnonzero(~row_ok)[0])
        where_q = np.flatnonzero(~same_q[k])
        out.update(
            max_deviation=float(dev[k]),
            max_deviation_t=float(t[k]),
            max_deviation_row=k,
            max_deviation_in=("qpos" if where_q.size else "qvel"),
            first_mismatch_t=float(t[first]),
            first_mismatch_row=first,
            mismatched_rows=int(np.count_nonzero(~row_ok)),
        )
    return out


# --------------------------------------------------------------------------- plot


def plot_log(log: Any, path: str | os.PathLike, rep: dict[str, Any]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import Polygon, Rectangle

    from ..errors import LogError

    sig = log.signals
    t = sig.get("t")
    if t is None or t.size == 0:
        raise LogError(f"{log.path}: the log has no signal rows to plot")
    E, Ed = sig["E"], sig["E_dot"]
    settle = rep.get("settle_s")
    e_max, ed_max, poly = rep.get("E_max"), rep.get("Edot_max"), rep.get("region_polygon")
    plt.rcParams.update({"font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "axes.spines.top": False, "axes.spines.right": False})
    fig, ax = plt.subplots(2, 2, figsize=(10, 6.8), constrained_layout=True)
    a = ax[0, 0]
    a.plot(t, E, lw=0.9, color="C0", label="E = alpha0 - alpha")
    if e_max is not None:
        a.axhline(e_max, ls="--", lw=0.8, color="C3", label=f"±E_max = {e_max:.3g} rad")
        a.axhline(-e_max, ls="--", lw=0.8, color="C3")
    a.set(xlabel="t [s]", ylabel="E [rad]", title="(a) steering error")
    b = ax[0, 1]
    b.plot(t, Ed, lw=0.9, color="C1", label="E' = alpha0' - alpha'")
    if ed_max is not None:
        b.axhline(ed_max, ls="--", lw=0.8, color="C3", label=f"±Edot_max = {ed_max:.3g} rad/s")
        b.axhline(-ed_max, ls="--", lw=0.8, color="C3")
    b.set(xlabel="t [s]", ylabel="E' [rad/s]", title="(b) error rate")
    c = ax[1, 0]
    c.plot(t, sig["voltage_cmd"], lw=0.7, color="0.6", label="controller output")
    c.plot(t, sig["voltage"], lw=0.9, color="C2", label="applied (limited)")
    try:
        vlim = _number(log.parameters.get("voltage_limit"))
    except Exception:
        vlim = None
    if vlim is not None:
        c.axhline(vlim, ls=":", lw=0.8, color="k", label=f"supply ±{vlim:g} V")
        c.axhline(-vlim, ls=":", lw=0.8, color="k")
    c.set(xlabel="t [s]", ylabel="u [V]", title="(c) armature voltage")
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
        d.add_patch(Rectangle((0, 0), e_max, ed_max, fc="C3", alpha=0.15, ec="C3", ls="--", lw=0.9, label="E_max x Edot_max"))
    if poly:
        d.add_patch(Polygon(np.asarray(poly), closed=True, fc="C4", alpha=0.1, ec="C4", lw=0.9, label="region"))
    d.set(xlabel="|E| [rad]", ylabel="|E'| [rad/s]", title="(d) error plane")
    d.set_xlim(left=0)
    d.set_ylim(bottom=0)
    for axis in (a, b, c):
        if settle is not None:
            axis.axvline(settle, color="0.5", lw=0.6, ls="-.")
    for axis in (a, b, c, d):
        axis.legend(loc="best", fontsize=7, frameon=False)
    cfg = log.config or {}
    bits = [f"{k}={cfg[k]}" for k in ("controller", "path", "model", "seed") if k in cfg and not isinstance(cfg[k], (dict, list))]
    key = "inside_after_settle" if rep.get("inside_after_settle") is not None else "inside"
    verdict = {True: "inside bounds", False: "outside bounds", None: ""}[rep.get(key)]
    if verdict and key == "inside_after_settle":
        verdict += " after settling"
    title = f"{Path(str(log.path)).name}: " + ", ".join(bits + [v for v in (verdict, "TRUNCATED" if log.truncated else "") if v])
    fig.suptitle(title, fontsize=10)
    out = Path(path)
    if out.parent and not out.parent.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=200)
    plt.close(fig)


# --------------------------------------------------------------------------- video

_PROBE = (
    "import mujoco\n"
    "m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><light pos=\"0 0 2\"/><geom size=\".1\"/></worldbody></mujoco>')\n"
    "r = mujoco.Renderer(m, 32, 32)\n"
    "d = mujoco.MjData(m)\n"
    "mujoco.mj_forward(m, d)\n"
    "r.update_scene(d)\n"
    "r.render()\n"
    "r.close()\n"
)


def _ffmpeg() -> str | None:
    import shutil

    exe = shutil.which("ffmpeg")
    if exe:
        return exe
    try:
        import imageio_ffmpeg  # type: ignore[import-not-found]

        return imageio_ffmpeg.get_ffmpeg_exe()
    except Exception:
        return None


def _last_line(text: str) -> str:
    lines = [ln.strip() for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1] if lines else "failed without a message"


def render_video(log_path: str | os.PathLike, out: str | os.PathLike, *, fps: int = 30, size: str = "960x540") -> str:
    """Render the logged run to an mp4; returns the GL backend used. Raises WmrMjError."""
    import subprocess

    from ..errors import WmrMjError

    try:
        w, h = (int(v) for v in size.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
    except ValueError:
        raise WmrMjError(f"--size {size!r} is not WxH with W, H >= 16 (e.g. 960x540)") from None
    w, h = w - w % 2, h - h % 2
    errors = []
    backend = None
    for cand in ("egl", "osmesa"):
        env = dict(os.environ, MUJOCO_GL=cand, PYOPENGL_PLATFORM=cand)
        try:
            probe = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, timeout=120)
        except subprocess.TimeoutExpired:
            errors.append(f"{cand}: timed out")
            continue
        if probe.returncode == 0:
            backend = cand
            break
        errors.append(f"{cand}: {_last_line(probe.stderr)}")
    if backend is None:
        raise WmrMjError("no OpenGL backend (EGL/OSMesa) available: " + "; ".join(errors))
    ffmpeg = _ffmpeg()
    if ffmpeg is None:
        raise WmrMjError(
            f"rendering works ({backend}) but no mp4 writer is available: install ffmpeg "
            "(apt-get install ffmpeg) or the imageio-ffmpeg Python package"
        )
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    cmd = [sys.executable, "-m", "wmr_mj.commands.replay", "--render-worker", str(log_path), str(out), str(fps), str(w), str(h), ffmpeg]
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        raise WmrMjError(f"video rendering failed ({backend}): {_last_line(proc.stderr)}")
    return backend


def _render_worker(log_path: str, out: str, fps: int, w: int, h: int, ffmpeg: str) -> int:
    """Child process: MUJOCO_GL is set before mujoco is imported."""
    import subprocess

    import mujoco
    import numpy as np

    from ..logs import load_log

    log = load_log(log_path)
    m = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), w)
    m.vis.global_.offheight = max(int(m.vis.global_.offheight), h)
    d = mujoco.MjData(m)
    st = log.state
    t, qpos = st["t"], st["qpos"]
    if t.size == 0:
        print("the log has no rows to render", file=sys.stderr)
        return 3
    frames_t = np.arange(0.0, float(t[-1]) + 1e-12, 1.0 / fps)
    idx = np.clip(np.searchsorted(t, frames_t), 0, t.size - 1)
    renderer = mujoco.Renderer(m, h, w)
    cam = mujoco.MjvCamera()
    chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    cam.trackbodyid = chassis if chassis >= 0 else 1
    cam.distance, cam.elevation, cam.azimuth = 4.0, -35.0, 135.0
    path = log.reference_path
    if path is not None:
        path = np.asarray(path, float).reshape(-1, 2)
        path = path[np.all(np.isfinite(path), axis=1)]
        if len(path) > 400:
            path = path[np.linspace(0, len(path) - 1, 400).round().astype(int)]
    encoders = subprocess.run([ffmpeg, "-hide_banner", "-encoders"], capture_output=True, text=True).stdout
    codec = "libx264" if "libx264" in encoders else "mpeg4"
    enc = subprocess.Popen(
        [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}", "-r", str(fps),
         "-i", "-", "-an", "-c:v", codec, "-pix_fmt", "yuv420p", "-q:v", "3", str(out)],
        stdin=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        for k in idx:
            d.qpos[:] = qpos[k]
            mujoco.mj_forward(m, d)
            renderer.update_scene(d, camera=cam)
            scn = renderer.scene
            if path is not None:
                for x, y in path:
                    if scn.ngeom >= scn.maxgeom:
                        break
                    mujoco.mjv_initGeom(
                        scn.geoms[scn.ngeom], int(mujoco.mjtGeom.mjGEOM_SPHERE), np.array([0.012, 0, 0]),
                        np.array([x, y, 0.005]), np.eye(3).ravel(), np.array([0.9, 0.2, 0.1, 1.0], np.float32),
                    )  # fmt: skip
                    scn.ngeom += 1
            enc.stdin.write(renderer.render().tobytes())
        enc.stdin.close()
        err = enc.stderr.read().decode(errors="replace")
        if enc.wait() != 0:
            print(f"ffmpeg failed: {_last_line(err)}", file=sys.stderr)
            return 3
    finally:
        renderer.close()
    return 0


# --------------------------------------------------------------------------- command


def run(args: argparse.Namespace) -> int:
    from ..logs import load_log
    from ..mcaplog import json_safe

    log = load_log(args.log)
    rep = summarize(log, args.settle)
    status = 0
    if args.plot:
        plot_log(log, args.plot, rep)
        rep["plot"] = str(args.plot)
    if args.video:
        rep["video_backend"] = render_video(args.log, args.video, fps=args.fps, size=args.size)
        rep["video"] = str(args.video)
    if args.verify:
        ver = verify_log(log)
        rep["verify"] = ver
        status = 0 if ver["identical"] else 1
    if args.json:
        print_json(json_safe(rep))
        return status
    print(_text(rep))
    if args.plot:
        print(f"plot       {args.plot}")
    if args.video:
        print(f"video      {args.video} ({rep['video_backend']})")
    if args.verify:
        ver = rep["verify"]
        if ver["identical"]:
            print(f"verify     bit-identical: qpos and qvel reproduced exactly at all {ver['rows']} control steps ({ver['mj_steps']} mj_step calls)")
        else:
            print(
                f"verify     MISMATCH: largest deviation {ver['max_deviation']:.3g} in {ver['max_deviation_in']} at t = {ver['max_deviation_t']:.6g} s "
                f"(row {ver['max_deviation_row']}); first at t = {ver['first_mismatch_t']:.6g} s; {ver['mismatched_rows']} of {ver['rows']} rows differ"
            )
    return status


if __name__ == "__main__":  # the --video child process
    if len(sys.argv) == 8 and sys.argv[1] == "--render-worker":
        try:
            sys.exit(_render_worker(sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]), sys.argv[7]))
        except Exception as exc:  # one line for the parent
            print(f"{type(exc).__name__}: {exc}".splitlines()[0], file=sys.stderr)
            sys.exit(3)
    sys.exit("usage: wmr-mj replay LOG [--json] [--plot PATH.png] [--verify] [--video PATH.mp4]")
