"""Render a run log to an MP4 that shows the steering under test (``wmr-mj replay LOG --video OUT.mp4``).

Each frame sets the logged ``qpos`` (one row per control step, ``/sim/state``) on the
attached MJCF and draws it with :class:`mujoco.Renderer`: nothing is re-simulated. The
picture shows what the controller acts on:

- the chassis translucent (its geoms' alpha overridden on a copy of the model), so the
  steered axle and its wheels (blue) are seen through it;
- a camera that follows the cart (look-at on the cart, azimuth on its smoothed heading);
- the desired path of point C (magenta), and two needles from C: the steering direction
  reached (blue, alpha) and the one asked for (green, alpha0); the angle between them is
  the servo error E = alpha0 - alpha (paper, section 3, before (3.4));
- an overlay: t, alpha, alpha0, E against its bound E_max (the region (4.21) closed by
  (4.23)), a strip of E(t) with the band +-E_max, the run's verdict and C's cross-track (the log's /path channel).

The frames are encoded by imageio's ffmpeg writer (H.264, the ``video`` extra). MuJoCo
picks its OpenGL backend when it is first imported, so :func:`render_video` renders in
a child process with ``MUJOCO_GL`` set, trying EGL then OSMesa (or only the backend
named in ``MUJOCO_GL``); with none, it raises :class:`NoRenderBackendError` (one line).

Usage::

    from wmr_mj.logs.video import render_video

    result = render_video("logs/run.mcap", "run.mp4", fps=30, width=640, height=360)
    print(result.frames, result.backend, result.seconds["render"])

In a process whose ``MUJOCO_GL`` was set to a working backend before ``mujoco`` was
imported, :func:`write_video` does the same work in-process.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from wmr_mj._util.files import check_output_path
from wmr_mj.errors import LogError, NoRenderBackendError, ParameterError, WmrMjError
from wmr_mj.logs.reader import load_log

__all__ = [
    "BACKENDS",
    "VideoResult",
    "parse_size",
    "render_video",
    "write_video",
]

#: OpenGL backends tried for headless rendering, in order (the values of ``MUJOCO_GL``).
BACKENDS: tuple[str, ...] = ("egl", "osmesa")

# Colours (RGBA, 0..1). The steering unit and the path have hues nothing else in the scene has.
STEER_RGBA = (0.10, 0.35, 1.00, 1.0)
DESIRED_RGBA = (0.10, 0.90, 0.25, 1.0)
PATH_RGBA = (1.00, 0.15, 0.85, 1.0)
CHASSIS_RGB = (0.85, 0.85, 0.80)  # neutral glass: an orange one turns the blue seen through it grey
CHASSIS_ALPHA = 0.2

# Rendering cost on a software renderer (Mesa llvmpipe through EGL): the default 4096-pixel
# shadow map and the floor's reflection cost 20x the rest of a frame (bench/bench_video.py),
# so both are off; the shadow map is also allocated smaller.
_SHADOW_SIZE = 1024
_OFFSCREEN_SAMPLES = 4  # multisampling: thin needles and the path without jagged edges

_CAMERA_DISTANCE_M = 4.0
_CAMERA_ELEVATION_DEG = -42.0
_CAMERA_AZIMUTH_OFFSET_DEG = -35.0  # behind the cart and to its left
_HEADING_SMOOTHING_S = 1.0  # the chase camera turns with the cart's heading, low-passed
_PATH_SPACING_M = 0.04  # path drawn as segments at least this long ...
_PATH_RADIUS_M = 9.0  # ... within this distance of the cart
_PATH_HEIGHT_M = 0.01  # above the floor, so the depth test keeps the line
_NEEDLE_LENGTH_M = 1.0
_NEEDLE_RADIUS_M = 0.022

# Child-process exit codes: the backend does not work (try the next) / a user error.
_EXIT_NO_BACKEND = 3
_EXIT_USER_ERROR = 2


@dataclasses.dataclass(frozen=True)
class VideoResult:
    """What :func:`render_video` wrote and how long each stage took.

    ``seconds`` has the keys ``load`` (log, model, renderer), ``kinematics`` (qpos set,
    mj_kinematics), ``scene`` (mjv_updateScene, the path and the needles), ``render``
    (mjr_render and reading the pixels), ``overlay`` (Pillow), ``encode`` (imageio/ffmpeg)
    and ``total`` (wall time of the child process' work, in seconds).
    """

    path: str
    frames: int
    fps: int
    width: int
    height: int
    backend: str
    seconds: dict[str, float]

    @property
    def ms_per_frame(self) -> float:
        return 1e3 * self.seconds["total"] / max(self.frames, 1)


def parse_size(text: str, *, option: str = "--size") -> tuple[int, int]:
    """``"640x360"`` -> (640, 360); both even (H.264 in yuv420p) and >= 16 pixels."""
    try:
        w, h = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        w = h = 0
    if w < 16 or h < 16 or w % 2 or h % 2 or w > 7680 or h > 4320:
        raise ParameterError(
            f"{option} {text!r} is not accepted; WxH with even W, H from 16 to 7680x4320 is (e.g. 640x360)")
    return w, h


def _check_options(fps: int, width: int, height: int) -> None:
    if isinstance(fps, bool) or not isinstance(fps, int) or not 1 <= fps <= 240:
        raise ParameterError(f"--fps {fps!r} is not accepted; an integer from 1 to 240 is")
    parse_size(f"{width}x{height}", option="size")


# --------------------------------------------------------------------------- parent side


def render_video(
    log_path: str | os.PathLike,
    out: str | os.PathLike,
    *,
    fps: int = 30,
    width: int = 640,
    height: int = 360,
    chassis_alpha: float = CHASSIS_ALPHA,
) -> VideoResult:
    """Render the run log at ``log_path`` to the MP4 ``out`` (written atomically).

    Args:
      log_path: an MCAP run log with ``/sim/state`` and the attached MJCF.
      out: the MP4 to write; its folder is created.
      fps: frames per simulated second; frame k shows the logged state at t = k / fps.
      width, height: pixels, even.
      chassis_alpha: opacity of the chassis (1: opaque, as the model draws it).

    Raises:
      NoRenderBackendError: no OpenGL backend works here (one line, naming each tried).
      WmrMjError: a bad option, an unwritable ``out``, a log without states.
    """
    import importlib.util

    _check_options(fps, width, height)
    missing = [m for m in ("imageio", "imageio_ffmpeg") if importlib.util.find_spec(m) is None]
    if missing:
        raise WmrMjError(f"--video needs {' and '.join(missing)}: "
                         "install the video extra (pip install 'wmr-mj[video]')")
    if not 0.0 <= chassis_alpha <= 1.0:
        raise ParameterError(f"chassis_alpha = {chassis_alpha!r} is not accepted; a number from 0 to 1 is")
    out = check_output_path(out, option="--video")
    log_path = Path(log_path)
    if not log_path.is_file():
        raise LogError(f"{str(log_path)!r} is not a file; give an MCAP run log written by `wmr-mj run`")
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    candidates = (chosen,) if chosen else BACKENDS
    fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{out.stem}.", suffix=".mp4")
    os.close(fd)
    failures = []
    try:
        for backend in candidates:
            cmd = [sys.executable, "-m", "wmr_mj.logs.video", str(log_path), tmp,
                   f"--fps={fps}", f"--size={width}x{height}", f"--chassis-alpha={chassis_alpha!r}"]  # fmt: skip
            env = dict(os.environ, MUJOCO_GL=backend)
            if backend in ("egl", "osmesa"):  # PyOpenGL's name for the same platform
                env["PYOPENGL_PLATFORM"] = backend
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
            if proc.returncode == 0:
                fields = json.loads(proc.stdout.strip().splitlines()[-1])
                os.chmod(tmp, 0o666 & ~_umask())
                os.replace(tmp, out)
                return VideoResult(**dict(fields, path=str(out)))
            why = _last_line(proc.stderr) if proc.returncode > 0 else f"crashed (signal {-proc.returncode})"
            if proc.returncode == _EXIT_USER_ERROR:
                raise WmrMjError(why)
            if proc.returncode > 0 and proc.returncode != _EXIT_NO_BACKEND:
                raise WmrMjError(f"--video {str(out)!r}: rendering failed ({backend}): {why}")
            failures.append(f"{backend}: {why}")
        hint = "set MUJOCO_GL to a working backend" if chosen else "install libegl1 (EGL) or libosmesa6 (OSMesa)"
        raise NoRenderBackendError(f"no OpenGL backend (EGL/OSMesa) available: {'; '.join(failures)}; {hint}")
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _last_line(text: str) -> str:
    lines = [ln.strip() for ln in text.strip().splitlines() if ln.strip()]
    return lines[-1] if lines else "failed without a message"


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [type(exc).__name__])[0]


# --------------------------------------------------------------------------- rendering


def write_video(
    log: Any,
    out: str | os.PathLike,
    *,
    fps: int = 30,
    width: int = 640,
    height: int = 360,
    chassis_alpha: float = CHASSIS_ALPHA,
) -> VideoResult:
    """Render a loaded RunLog to ``out`` in this process (not atomically; see :func:`render_video`).

    MuJoCo's OpenGL backend is the one ``MUJOCO_GL`` named when ``mujoco`` was first
    imported; :func:`render_video` takes care of that and is the function to call.
    """
    import imageio.v2 as imageio
    import mujoco

    _check_options(fps, width, height)
    clock = time.perf_counter
    t_start = clock()
    seconds = dict.fromkeys(("load", "kinematics", "scene", "render", "overlay", "encode"), 0.0)
    model, t_state, qpos = _log_model(log)
    ids = _style_model(model, width=width, height=height, chassis_alpha=chassis_alpha)
    data = mujoco.MjData(model)

    n_frames = int(math.floor(float(t_state[-1]) * fps + 1e-9)) + 1
    t_frames = np.arange(n_frames) / fps
    rows = np.clip(np.searchsorted(t_state, t_frames + 1e-9, side="right") - 1, 0, t_state.size - 1)
    sig = _frame_signals(log, t_frames)
    path = _path_points(log.reference_path)
    yaw = _chassis_yaws(model, data, qpos[rows], ids["chassis"])
    cam_azimuth = np.degrees(_low_pass(yaw, fps * _HEADING_SMOOTHING_S)) + _CAMERA_AZIMUTH_OFFSET_DEG
    overlay = _Overlay(width, height, log, t_frames, sig)

    renderer = _make_renderer(model, width, height, max_geom=model.ngeom + len(path) + 8)
    path_px = max(2.0, round(height / 120))  # mjGEOM_LINE widths are in pixels
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.distance, cam.elevation = _CAMERA_DISTANCE_M, _CAMERA_ELEVATION_DEG
    flags = mujoco.mjtRndFlag
    out = Path(out)
    data.qpos[:] = qpos[rows[0]]
    mujoco.mj_kinematics(model, data)
    needle_z = _chassis_top(model, data, ids["chassis"]) + 0.08
    writer = imageio.get_writer(out, format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=7,
                                macro_block_size=2, ffmpeg_log_level="error")  # fmt: skip
    seconds["load"] = clock() - t_start
    try:
        # One pass per frame, long on purpose: each stage is timed in place (``seconds``), and the
        # renderer, scene and camera are reused from frame to frame.
        for k in range(n_frames):
            t0 = clock()
            data.qpos[:] = qpos[rows[k]]
            mujoco.mj_kinematics(model, data)  # positions and orientations: all a picture needs
            mujoco.mj_camlight(model, data)
            t1 = clock()
            cam.lookat[:] = 0.5 * (data.xpos[ids["chassis"]] + data.xpos[ids["steer_body"]])
            cam.azimuth = cam_azimuth[k]
            renderer.update_scene(data, camera=cam)
            scene = renderer.scene
            scene.flags[flags.mjRND_SHADOW] = False  # a shadow map pass costs more than the frame
            scene.flags[flags.mjRND_REFLECTION] = False  # the floor's mirror pass draws the scene twice
            scene.flags[flags.mjRND_SKYBOX] = False  # the camera looks down; no sky in view
            _add_path(scene, path, cam.lookat, path_px)
            _add_steering_needles(scene, data, ids, sig["E"][k], needle_z)
            t2 = clock()
            frame = renderer.render()
            t3 = clock()
            frame = overlay.draw(frame, k)
            t4 = clock()
            writer.append_data(frame)
            t5 = clock()
            seconds["kinematics"] += t1 - t0
            seconds["scene"] += t2 - t1
            seconds["render"] += t3 - t2
            seconds["overlay"] += t4 - t3
            seconds["encode"] += t5 - t4
        t5 = clock()
        writer.close()  # ffmpeg encodes what is still queued
        seconds["encode"] += clock() - t5
    finally:
        writer.close()  # no-op after a normal close
        renderer.close()
    seconds["total"] = clock() - t_start
    backend = os.environ.get("MUJOCO_GL", "")
    return VideoResult(path=str(out), frames=n_frames, fps=fps, width=width, height=height, backend=backend,
                       seconds=seconds)


def _log_model(log: Any) -> tuple[Any, np.ndarray, np.ndarray]:
    """(the compiled model attached to the log, /sim/state t [s], qpos rows) of a loaded RunLog.

    Raises:
        LogError: no /sim/state rows, an MJCF that does not compile, or qpos rows of another size.
    """
    import mujoco

    state = log.state
    t_state = np.asarray(state.get("t", np.empty(0)), float)
    qpos = state.get("qpos")
    if t_state.size == 0 or qpos is None:
        raise LogError(f"{log.path}: the log has no /sim/state rows to render")
    try:
        model = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    except Exception as exc:
        raise LogError(f"{log.path}: the attached MJCF does not compile ({_first_line(exc)})") from None
    if qpos.shape[1:] != (model.nq,):
        raise LogError(f"{log.path}: /sim/state qpos has {qpos.shape[1:]} values per row; "
                       f"the attached model has nq = {model.nq}")
    return model, t_state, qpos


def _make_renderer(model: Any, width: int, height: int, *, max_geom: int) -> Any:
    """mujoco.Renderer, or _BackendUnavailable when the OpenGL context cannot be made."""
    import mujoco

    try:
        return mujoco.Renderer(model, height, width, max_geom=max_geom)
    except Exception as exc:  # the backend's own exception types differ (ImportError, FatalError, EGLError)
        raise _BackendUnavailable(f"{type(exc).__name__}: {_last_line(str(exc))}") from None


class _BackendUnavailable(Exception):
    """The OpenGL context for offscreen rendering could not be made (child exit 3)."""


def _body(model: Any, name: str, fallback: int) -> int:
    import mujoco

    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    return i if i >= 0 else fallback


def _style_model(model: Any, *, width: int, height: int, chassis_alpha: float) -> dict[str, int]:
    """Frame buffer, cheap quality settings and colours on this copy of the model; returns body ids."""
    import mujoco

    model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
    model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
    model.vis.quality.shadowsize = _SHADOW_SIZE
    model.vis.quality.offsamples = _OFFSCREEN_SAMPLES
    chassis = _body(model, "chassis", 1 if model.nbody > 1 else 0)
    steer = _body(model, "steering_unit", chassis)
    site_c = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "C")
    if steer != chassis:
        in_steering_unit = np.zeros(model.nbody, bool)
        for b in range(model.nbody):  # bodies are numbered parents first
            in_steering_unit[b] = b == steer or (b > 0 and in_steering_unit[model.body_parentid[b]])
        model.geom_rgba[in_steering_unit[model.geom_bodyid]] = STEER_RGBA
    model.geom_rgba[model.geom_bodyid == chassis] = (*CHASSIS_RGB, chassis_alpha)
    return {"chassis": chassis, "steer_body": steer, "site_C": site_c}


def _chassis_yaws(model: Any, data: Any, qpos_rows: np.ndarray, chassis: int) -> np.ndarray:
    """Yaw of the chassis at each frame [rad], unwrapped."""
    import mujoco

    yaw = np.empty(len(qpos_rows))
    for k, q in enumerate(qpos_rows):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        xmat = data.xmat[chassis]
        yaw[k] = math.atan2(xmat[3], xmat[0])
    return np.unwrap(yaw)


def _low_pass(x: np.ndarray, samples: float) -> np.ndarray:
    """First-order low-pass run forward then backward (no lag); time constant in samples."""
    if x.size == 0 or samples <= 1:
        return x
    gain = 1.0 / samples

    def sweep(v: np.ndarray) -> np.ndarray:
        y = np.empty_like(v)
        acc = v[0]
        for i, value in enumerate(v):
            acc += gain * (value - acc)
            y[i] = acc
        return y

    return sweep(sweep(x)[::-1])[::-1]


def _frame_signals(log: Any, t_frames: np.ndarray) -> dict[str, np.ndarray]:
    """E, alpha, alpha0 at the frame times (the logged row at or before each); NaN where absent."""
    sig = log.signals
    t = np.asarray(sig.get("t", np.empty(0)), float)
    out = {}
    rows = np.clip(np.searchsorted(t, t_frames + 1e-9, side="right") - 1, 0, max(t.size - 1, 0))
    for key in ("E", "alpha", "alpha0"):
        v = sig.get(key)
        ok = v is not None and t.size and len(v) == t.size
        out[key] = np.asarray(v, float)[rows] if ok else np.full(t_frames.size, np.nan)
    out["t_all"], out["E_all"] = t, np.asarray(sig.get("E", np.full(t.size, np.nan)), float)
    out["cross_track"] = np.full(t_frames.size, np.nan)  # C's cross-track from the /path channel, where the log has it
    try:
        path = log.channel("/path")
        tp, ct = np.asarray(path["t"], float), np.asarray(path["cross_track"], float)
    except Exception:  # noqa: BLE001  (a log written before the channel existed, or a stand-in log)
        tp = np.empty(0)
    if tp.size:
        rows = np.clip(np.searchsorted(tp, t_frames + 1e-9, side="right") - 1, 0, tp.size - 1)
        out["cross_track"] = ct[rows]
    return out


def _path_points(reference_path: Any) -> np.ndarray:
    """The desired path of C as (N, 2) points at least _PATH_SPACING_M apart."""
    if reference_path is None:
        return np.empty((0, 2))
    p = np.asarray(reference_path, float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    if len(p) < 2:
        return np.empty((0, 2))
    keep = [0]
    for i in range(1, len(p)):
        if np.hypot(*(p[i] - p[keep[-1]])) >= _PATH_SPACING_M:
            keep.append(i)
    if keep[-1] != len(p) - 1:
        keep.append(len(p) - 1)
    return p[keep]


def _add_geom(scene: Any, kind: int, width: float, a: np.ndarray, b: np.ndarray, rgba: tuple[float, ...]) -> bool:
    import mujoco

    if scene.ngeom >= scene.maxgeom:
        return False
    g = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(g, kind, np.zeros(3), np.zeros(3), np.eye(3).ravel(), np.asarray(rgba, np.float32))
    mujoco.mjv_connector(g, kind, width, a, b)
    g.category = mujoco.mjtCatBit.mjCAT_DECOR
    g.transparent = rgba[3] < 1.0
    g.castshadow = False
    scene.ngeom += 1
    return True


def _add_path(scene: Any, path: np.ndarray, centre: np.ndarray, width_px: float) -> None:
    """Segments of the desired path near the cart, as lines on the floor.

    Lines, not capsules: 50 capsules double the cost of a frame on a software renderer.
    """
    import mujoco

    if len(path) < 2:
        return
    near = np.hypot(path[:, 0] - centre[0], path[:, 1] - centre[1]) <= _PATH_RADIUS_M
    line = int(mujoco.mjtGeom.mjGEOM_LINE)
    for i in np.flatnonzero(near[:-1] | near[1:]):
        a = np.array([path[i, 0], path[i, 1], _PATH_HEIGHT_M])
        b = np.array([path[i + 1, 0], path[i + 1, 1], _PATH_HEIGHT_M])
        if not _add_geom(scene, line, width_px, a, b, PATH_RGBA):
            break


def _chassis_top(model: Any, data: Any, chassis: int) -> float:
    """Height of the chassis' highest point [m] (from its geoms' bounding boxes), at the current state."""
    geoms = np.flatnonzero(model.geom_bodyid == chassis)
    if geoms.size == 0:
        return 0.5
    return float(np.max(data.geom_xpos[geoms, 2] + np.abs(model.geom_aabb[geoms, 5])))


def _add_steering_needles(scene: Any, data: Any, ids: dict[str, int], error: float, height: float) -> None:
    """Above C: the steering direction reached (alpha) and the one asked for (alpha0 = alpha + E).

    Capsules ("needles") at ``height``, over the chassis, so that neither the chassis hides
    them nor they hide the path; a thin line drops from them to C. mjv_connector sizes
    capsules exactly, while MuJoCo 4 draws an mjGEOM_ARROW at about half its length.
    """
    import mujoco

    steer = ids["steer_body"]
    origin = data.site_xpos[ids["site_C"]].copy() if ids["site_C"] >= 0 else data.xpos[steer].copy()
    xmat = data.xmat[steer]
    yaw = math.atan2(xmat[3], xmat[0])
    start = np.array([origin[0], origin[1], height])
    _add_geom(scene, int(mujoco.mjtGeom.mjGEOM_LINE), 1.5, origin, start, (0.9, 0.9, 0.9, 1.0))
    capsule = int(mujoco.mjtGeom.mjGEOM_CAPSULE)
    # the desired needle thinner and on top, so both show when E is small
    needles = ((yaw, STEER_RGBA, _NEEDLE_RADIUS_M, 0.0), (yaw + error, DESIRED_RGBA, 0.6 * _NEEDLE_RADIUS_M, 0.03))
    for angle, rgba, radius, dz in needles:
        if not math.isfinite(angle):
            continue
        tip = start + [_NEEDLE_LENGTH_M * math.cos(angle), _NEEDLE_LENGTH_M * math.sin(angle), dz]
        _add_geom(scene, capsule, radius, start + [0.0, 0.0, dz], tip, rgba)


# --------------------------------------------------------------------------- overlay


def _bound_and_verdict(summary: dict[str, Any] | None) -> tuple[float | None, str]:
    """E_max ((4.21) under (4.23)) and the verdict line from the log's summary (its certificate when it has one)."""
    summary = summary or {}
    cert = summary.get("certificate")
    if not isinstance(cert, dict):
        cert = {}
    raw = cert.get("E_max", summary.get("E_max"))
    e_max = None
    if isinstance(raw, (int, float)) and not isinstance(raw, bool) and math.isfinite(raw) and raw > 0:
        e_max = float(raw)
    verdict = summary.get("verdict")
    if not isinstance(verdict, str) or not verdict:
        inside = summary.get("inside")
        lines: dict[object, str] = {True: "errors inside the analytic bounds",
                                    False: "errors OUTSIDE the analytic bounds"}
        verdict = lines.get(inside, "no verdict in the log")
    return e_max, verdict


class _Overlay:
    """Text, an |E| / E_max gauge and a strip of E(t), drawn with Pillow on each frame.

    Everything that does not move (the E(t) trace, the band, the legend) is drawn once.
    """

    def __init__(self, width: int, height: int, log: Any, t_frames: np.ndarray, sig: dict[str, np.ndarray]):
        from PIL import Image, ImageDraw, ImageFont

        self.w, self.h = width, height
        self.sig = sig
        self.t_frames = t_frames
        self.e_max, self.verdict = _bound_and_verdict(log.summary)
        self.outside = self.verdict.lower().find("outside") >= 0 or self.verdict.lower().startswith(("fail", "no "))
        px = max(10, round(height / 30))
        try:
            self.font = ImageFont.load_default(size=px)
            self.small = ImageFont.load_default(size=max(9, px - 2))
        except TypeError:  # Pillow without FreeType: the fixed bitmap font
            self.font = self.small = ImageFont.load_default()
        self.line = px + 4
        # the E(t) strip along the bottom
        self.strip_h = max(40, height // 6)
        self.strip_y = height - self.strip_h
        strip = Image.new("RGBA", (width, self.strip_h), (0, 0, 0, 150))
        d = ImageDraw.Draw(strip)
        t_all, e_all = sig["t_all"], sig["E_all"]
        t_end = max(float(t_frames[-1]), 1e-9)
        finite = e_all[np.isfinite(e_all)]
        span = max(float(np.max(np.abs(finite), initial=0.0)), self.e_max or 0.0, 1e-6) * 1.15
        self.x_of = lambda t: 4 + (width - 8) * np.clip(np.asarray(t) / t_end, 0, 1)
        self.y_of = lambda e: self.strip_h / 2 - (self.strip_h / 2 - 3) * np.clip(np.asarray(e) / span, -1, 1)
        if self.e_max is not None:
            y_hi, y_lo = float(self.y_of(self.e_max)), float(self.y_of(-self.e_max))
            d.rectangle([4, y_hi, width - 4, y_lo], fill=(40, 200, 80, 60))
            for y in (y_hi, y_lo):
                d.line([4, y, width - 4, y], fill=(40, 220, 90, 255), width=1)
        d.line([4, self.strip_h / 2, width - 4, self.strip_h / 2], fill=(150, 150, 150, 255), width=1)
        if t_all.size > 1 and finite.size:
            step = max(1, t_all.size // (2 * width))
            xs, ys = self.x_of(t_all[::step]), self.y_of(np.nan_to_num(e_all[::step]))
            d.line(list(zip(xs.tolist(), ys.tolist())), fill=(255, 255, 255, 255), width=1)
        band = f"band: |E| <= E_max = {self.e_max:.3g} rad" if self.e_max is not None else "no E_max in the log"
        d.text((8, 2), f"E(t) [rad]   {band}", font=self.small, fill=(230, 230, 230, 255))
        self.strip_rgb = strip.convert("RGB")
        self.strip_mask = strip.getchannel("A")
        # top-left panel background
        self.col = int(15 * px)  # second column of the panel
        self.panel_h = 4 * self.line + 6
        self.panel_w = min(width, int(31 * px))
        panel = Image.new("RGBA", (self.panel_w, self.panel_h), (0, 0, 0, 140))
        self.panel_rgb, self.panel_mask = panel.convert("RGB"), panel.getchannel("A")

    def draw(self, frame: np.ndarray, k: int) -> np.ndarray:
        from PIL import Image, ImageDraw

        img = Image.fromarray(frame)
        img.paste(self.strip_rgb, (0, self.strip_y), self.strip_mask)
        img.paste(self.panel_rgb, (0, 0), self.panel_mask)
        d = ImageDraw.Draw(img)
        t = float(self.t_frames[k])
        e, a, a0 = (float(self.sig[key][k]) for key in ("E", "alpha", "alpha0"))
        x = float(self.x_of(t))
        d.line([x, self.strip_y + 2, x, self.h - 2], fill=(255, 220, 0), width=2)
        col = self.col
        y = 3
        d.text((6, y), f"t = {t:5.2f} s", font=self.font, fill=(240, 240, 240))
        ct = float(self.sig["cross_track"][k]) if "cross_track" in self.sig else math.nan
        label = "desired path of C" + (f", C off it {ct:+.3f} m" if math.isfinite(ct) else "")
        d.text((col, y), label, font=self.font, fill=_rgb255(PATH_RGBA))
        y += self.line
        d.text((6, y), f"steering alpha = {a:+.3f} rad", font=self.font, fill=_rgb255(STEER_RGBA, lift=80))
        d.text((col, y), f"asked alpha0 = {a0:+.3f} rad", font=self.font, fill=_rgb255(DESIRED_RGBA))
        y += self.line
        if self.e_max is not None and math.isfinite(e):
            ok = abs(e) <= self.e_max
            txt = f"E = alpha0 - alpha = {e:+.4f} rad,  |E| / E_max = {abs(e) / self.e_max:.2f}"
            d.text((6, y), txt, font=self.font, fill=(120, 240, 120) if ok else (255, 90, 80))
        else:
            d.text((6, y), f"E = alpha0 - alpha = {e:+.4f} rad", font=self.font, fill=(240, 240, 240))
        y += self.line
        d.text((6, y), self.verdict[:70], font=self.font, fill=(255, 110, 90) if self.outside else (140, 240, 140))
        return np.asarray(img)


def _rgb255(rgba: tuple[float, ...], *, lift: int = 0) -> tuple[int, int, int]:
    """0..1 RGBA as 0..255 RGB for text, lifted towards white by ``lift`` (dark blue on black)."""
    return tuple(min(255, round(255 * c) + lift) for c in rgba[:3])  # type: ignore[return-value]


# --------------------------------------------------------------------------- child process


def _worker(argv: list[str]) -> int:
    """``python -m wmr_mj.logs.video LOG OUT --fps N --size WxH --chassis-alpha A`` (MUJOCO_GL set by the parent)."""
    import argparse

    p = argparse.ArgumentParser(prog="python -m wmr_mj.logs.video")
    p.add_argument("log")
    p.add_argument("out")
    p.add_argument("--fps", type=int, default=30)
    p.add_argument("--size", default="640x360")
    p.add_argument("--chassis-alpha", type=float, default=CHASSIS_ALPHA)
    args = p.parse_args(argv)
    try:
        import mujoco  # noqa: F401  (an unusable MUJOCO_GL fails here)
    except Exception as exc:
        print(f"{type(exc).__name__}: {exc}".splitlines()[0], file=sys.stderr)
        return _EXIT_NO_BACKEND

    try:
        width, height = parse_size(args.size)
        log = load_log(args.log)
        result = write_video(log, args.out, fps=args.fps, width=width, height=height, chassis_alpha=args.chassis_alpha)
    except _BackendUnavailable as exc:
        print(exc, file=sys.stderr)
        return _EXIT_NO_BACKEND
    except WmrMjError as exc:
        print(str(exc).splitlines()[0], file=sys.stderr)
        return _EXIT_USER_ERROR
    print(json.dumps(dataclasses.asdict(result)))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(_worker(sys.argv[1:]))
    except Exception as exc:  # one line for the parent
        print(f"{type(exc).__name__}: {exc}".splitlines()[0], file=sys.stderr)
        sys.exit(4)
