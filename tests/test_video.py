"""wmr_mj.logs.video: the MP4 of a run log, what its frames show, and the error without OpenGL."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.logs import video

FPS = 10
WIDTH, HEIGHT = 640, 360


@pytest.fixture(scope="module")
def log_path(tmp_path_factory):
    from wmr_mj.logs.writer import RunLogger
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    path = tmp_path_factory.mktemp("video") / "run.mcap"
    # the paper circle needs more than 2 s of lead-in; the figure eight starts at once
    run_closed_loop(RunConfig(duration=2.0, path="figure-eight"), logger_factory=functools.partial(RunLogger, path),
                    progress=False)
    return path


@pytest.fixture(scope="module")
def videos(log_path):
    """The same 2 s log rendered with the translucent chassis and with an opaque one."""
    pytest.importorskip("imageio_ffmpeg", reason="the 'video' extra (imageio, imageio-ffmpeg) is not installed")
    out = {}
    for name, alpha in (("glass", video.CHASSIS_ALPHA), ("opaque", 1.0)):
        try:
            out[name] = video.render_video(log_path, log_path.parent / f"{name}.mp4", fps=FPS, width=WIDTH,
                                           height=HEIGHT, chassis_alpha=alpha)  # fmt: skip
        except video.NoRenderBackendError as exc:
            pytest.skip(f"no OpenGL backend for offscreen rendering here: {exc}")
    return out


def _frames(path) -> list[np.ndarray]:
    import imageio.v2 as imageio

    with imageio.get_reader(path) as reader:
        return [np.asarray(f) for f in reader]


def _centre(frame: np.ndarray) -> np.ndarray:
    """The middle half of the picture: the cart (the camera looks at it), clear of the overlay."""
    h, w = frame.shape[:2]
    return frame[h // 4 : 3 * h // 4, w // 4 : 3 * w // 4].astype(int)


def _steering_blue(px: np.ndarray) -> int:
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    return int(np.count_nonzero((b > 150) & (b - r > 110) & (b - g > 50)))


def _path_magenta(px: np.ndarray) -> int:
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    return int(np.count_nonzero((r > 150) & (b > 110) & (r - g > 90) & (b - g > 60)))


@pytest.mark.slow
def test_mp4_has_one_frame_per_tick_at_the_asked_size(videos):
    res = videos["glass"]
    frames = _frames(res.path)
    # 2000 control steps of 1 ms: the last state is at t = 1.999 s, so frames at 0, 0.1, ..., 1.9 s
    assert res.frames == 20 and len(frames) == 20
    assert all(f.shape == (HEIGHT, WIDTH, 3) for f in frames)
    assert res.backend in ("egl", "osmesa", "glfw", "glx")
    assert set(res.seconds) >= {"load", "kinematics", "scene", "render", "overlay", "encode", "total"}


@pytest.mark.slow
def test_frame_shows_path_and_steering_unit_through_the_chassis(videos):
    glass, opaque = (_centre(_frames(videos[k].path)[10]) for k in ("glass", "opaque"))  # t = 1 s
    # Over the chassis, the steering needle is blue in both pictures; the steering unit (beam,
    # wheels) lies under the chassis and adds its blue only when the chassis is see-through.
    blue_glass, blue_opaque = _steering_blue(glass), _steering_blue(opaque)
    assert blue_opaque > 40, blue_opaque  # the needle
    assert blue_glass > 2.5 * blue_opaque and blue_glass - blue_opaque > 150, (blue_glass, blue_opaque)
    # The 2 s run's path ends 0.4 m ahead of C, under the chassis: seen through it, hidden by
    # an opaque one (which also shows that nothing else in the scene reads as path colour).
    assert _path_magenta(glass) > 25 and _path_magenta(opaque) < 5, (_path_magenta(glass), _path_magenta(opaque))


def test_no_gl_backend_is_one_line_exit_2(log_path, capsys, monkeypatch):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.setattr(video, "BACKENDS", ("no-such-backend",))
    out = log_path.parent / "none.mp4"
    code = main(["replay", str(log_path), "--video", str(out)])
    _, err = capsys.readouterr()
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "no OpenGL backend (EGL/OSMesa) available: no-such-backend:" in err
    assert not out.exists() and not list(log_path.parent.glob(".none.*"))


@pytest.mark.parametrize("size", ["640", "641x360", "8x8", "axb"])
def test_bad_size_names_what_is_accepted(size):
    with pytest.raises(ParameterError, match="WxH with even W, H"):
        video.parse_size(size)
