"""Video rendering speed: `replay --video` before and after wmr_mj.logs.video, in one process.

    .venv/bin/python bench/bench_video.py [--repeats 2] [--duration 10] [--old-frames 30]

Renders a logged run (paper circle, --duration seconds, 30 frames per second) offscreen with
MuJoCo's Renderer (MUJOCO_GL, default egl) and prints medians over --repeats of:
  before: ms per frame of the former renderer's settings (960x540; the model's defaults:
          4096-pixel shadow map, floor reflection, skybox, 4x multisampling; mj_forward;
          400 path spheres), on --old-frames frames spread over the run; render only;
  now:    wmr_mj.logs.video.write_video on every frame (640x360; no shadow, reflection or sky;
          4x multisampling; mj_kinematics; the path as lines; overlay; H.264 encode), per stage;
  now at 960x540: the same, at the former size (what the settings alone save);
  ratio:  before / now per frame, and the estimate for the whole video before vs now;
  end-to-end: wmr_mj.logs.video.render_video (child process, backend probe, load, atomic write).
"""

from __future__ import annotations

import argparse
import functools
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is imported
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from wmr_mj.logs.reader import load_log  # noqa: E402
from wmr_mj.logs.video import render_video, write_video  # noqa: E402
from wmr_mj.logs.writer import RunLogger  # noqa: E402
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig


def old_ms_per_frame(log, n_frames: int, fps: int = 30) -> float:
    """The former `_render_worker`'s per-frame work (without its ffmpeg pipe), median ms."""
    m = mujoco.MjModel.from_xml_string(log.mjcf_xml)
    m.vis.global_.offwidth = max(m.vis.global_.offwidth, 960)
    m.vis.global_.offheight = max(m.vis.global_.offheight, 540)
    d = mujoco.MjData(m)
    t, qpos = log.state["t"], log.state["qpos"]
    rows = np.clip(np.searchsorted(t, np.arange(0.0, t[-1], 1.0 / fps)), 0, t.size - 1)
    rows = rows[np.linspace(0, rows.size - 1, n_frames).round().astype(int)]
    path = np.asarray(log.reference_path, float)
    path = path[np.linspace(0, len(path) - 1, 400).round().astype(int)]
    r = mujoco.Renderer(m, 540, 960)
    cam = mujoco.MjvCamera()
    cam.type, cam.trackbodyid = mujoco.mjtCamera.mjCAMERA_TRACKING, 1
    cam.distance, cam.elevation, cam.azimuth = 4.0, -35.0, 135.0
    times = []
    for k in rows:
        t0 = time.perf_counter()
        d.qpos[:] = qpos[k]
        mujoco.mj_forward(m, d)
        r.update_scene(d, camera=cam)
        s = r.scene
        for x, y in path:
            mujoco.mjv_initGeom(s.geoms[s.ngeom], int(mujoco.mjtGeom.mjGEOM_SPHERE), np.array([0.012, 0, 0]),
                                np.array([x, y, 0.005]), np.eye(3).ravel(), np.array([0.9, 0.2, 0.1, 1], np.float32))
            s.ngeom += 1
        r.render().tobytes()
        times.append(time.perf_counter() - t0)
    r.close()
    return 1e3 * statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--old-frames", type=int, default=30)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        log_path = Path(tmp) / "run.mcap"
        run_closed_loop(RunConfig(duration=args.duration), logger_factory=functools.partial(RunLogger, log_path),
                        progress=False)
        log = load_log(log_path)
        old, new, big = [], [], []
        for _ in range(args.repeats):
            old.append(old_ms_per_frame(log, args.old_frames))
            new.append(write_video(log, Path(tmp) / "now.mp4"))
            big.append(write_video(log, Path(tmp) / "big.mp4", width=960, height=540))
        frames = new[0].frames
        stages = {k: statistics.median(r.seconds[k] for r in new) for k in new[0].seconds}
        t0 = time.perf_counter()
        result = render_video(log_path, Path(tmp) / "end-to-end.mp4")
        e2e = time.perf_counter() - t0
    old_ms = statistics.median(old)
    now_ms = 1e3 * stages["total"] / frames
    print(f"MUJOCO_GL={os.environ['MUJOCO_GL']}, {args.duration:g} s log, {frames} frames at 30 fps, "
          f"medians of {args.repeats}")
    print(f"before  960x540  {old_ms:7.1f} ms/frame (render only, {args.old_frames} frames) "
          f"-> {old_ms * frames / 1e3:6.1f} s for the video")
    print(f"now     640x360  {now_ms:7.1f} ms/frame (all stages)                -> {stages['total']:6.1f} s")
    for k in ("load", "kinematics", "scene", "render", "overlay", "encode"):
        print(f"          {k:11s} {1e3 * stages[k] / frames:7.2f} ms/frame  ({stages[k]:.2f} s)")
    big_ms = 1e3 * statistics.median(r.seconds["total"] for r in big) / frames
    big_render = 1e3 * statistics.median(r.seconds["render"] for r in big) / frames
    print(f"now     960x540  {big_ms:7.1f} ms/frame (all stages; render {big_render:.1f})")
    print(f"ratio   before / now = {old_ms / now_ms:.1f}x per frame at 640x360, {old_ms / big_ms:.1f}x at 960x540")
    print(f"end-to-end render_video ({result.backend}, child process): {e2e:.1f} s wall for {result.frames} frames")


if __name__ == "__main__":
    main()
