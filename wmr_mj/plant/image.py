"""``models/c80.png``: the C80 scene at its ``home`` keyframe, rendered offscreen, the picture a MuJoCo
Menagerie model folder carries beside its MJCF and model card.

Usage::

    wmr-mj model image                              # writes models/c80.png
    from wmr_mj.plant.image import write_model_image
    write_model_image()                             # the same, from Python

MuJoCo picks its OpenGL backend when it is first imported, so the picture is rendered in a child
process with ``MUJOCO_GL`` set: EGL first, then OSMesa (or only the backend ``MUJOCO_GL`` names), as
``wmr_mj.logs.video`` renders its videos. The pixels depend on the OpenGL implementation; the
scene, the keyframe and the camera do not.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

from wmr_mj._util.resources import MODELS_DIR
from wmr_mj.errors import NoRenderBackendError, WmrMjError
from wmr_mj.params import C80, C80Parameters

__all__ = ["IMAGE_NAME", "IMAGE_SIZE", "BACKENDS", "render_model_png", "write_model_image"]

IMAGE_NAME = "c80.png"
#: width, height in pixels (within MuJoCo's default offscreen buffer, 640x480)
IMAGE_SIZE = (640, 480)
#: OpenGL backends tried, in order (values of MUJOCO_GL)
BACKENDS: tuple[str, ...] = ("egl", "osmesa")
# the free camera: looking at the cart from the front left, a little above
_AZIMUTH, _ELEVATION, _DISTANCE = 30.0, -30.0, 3.4
#: opacity of the chassis in the picture (the model draws it at 0.6), so that the axles show
CHASSIS_ALPHA = 0.3
_EXIT_NO_BACKEND = 3


def render_model_png(params: C80Parameters = C80, *, width: int = IMAGE_SIZE[0], height: int = IMAGE_SIZE[1]) -> bytes:
    """PNG bytes of the scene of ``params`` at its ``home`` keyframe.

    Needs a working OpenGL backend in this process (``MUJOCO_GL`` set before ``mujoco`` was
    imported); :func:`write_model_image` arranges that.
    """
    # MuJoCo (and so the model compiler, which imports it) is imported here, not at the top: it picks its OpenGL
    # backend on import, and the child of write_model_image imports this module before it tries the backend
    import mujoco
    from PIL import Image  # Pillow, imported where a picture is written

    from wmr_mj.plant.mjcf import compile_model  # imports mujoco (above)

    model, _ = compile_model(params)
    model.geom_rgba[model.geom("chassis_body").id, 3] = CHASSIS_ALPHA  # the picture only: the files keep 0.6
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    camera = mujoco.MjvCamera()
    mujoco.mjv_defaultFreeCamera(model, camera)
    camera.lookat[:] = data.body("chassis").xpos
    camera.azimuth, camera.elevation, camera.distance = _AZIMUTH, _ELEVATION, _DISTANCE
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(data, camera=camera)
        pixels = renderer.render()
    buf = io.BytesIO()
    Image.fromarray(pixels).save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def write_model_image(directory: str | os.PathLike | None = None) -> Path:
    """Render the C80 parameter set's scene into ``directory``/c80.png (default: the models folder).

    Raises:
        NoRenderBackendError: neither EGL nor OSMesa can render here (one line, each backend's reason).
        WmrMjError: the renderer failed for another reason.
    """
    out = Path(directory) if directory is not None else MODELS_DIR
    out.mkdir(parents=True, exist_ok=True)
    path = out / IMAGE_NAME
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    failures = []
    for backend in (chosen,) if chosen else BACKENDS:
        env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
        proc = subprocess.run([sys.executable, "-m", "wmr_mj.plant.image", str(path)], env=env,
                              capture_output=True, text=True)
        if proc.returncode == 0:
            return path
        why = (proc.stderr.strip().splitlines() or ["no message"])[-1]
        if proc.returncode != _EXIT_NO_BACKEND:
            raise WmrMjError(f"rendering {path} failed ({backend}): {why}")
        failures.append(f"{backend}: {why}")
    hint = "set MUJOCO_GL to a working backend" if chosen else "install libegl1 (EGL) or libosmesa6 (OSMesa)"
    raise NoRenderBackendError(f"no OpenGL backend (EGL/OSMesa) available: {'; '.join(failures)}; {hint}")


def _main(argv: list[str]) -> int:
    """Child process: render into argv[0] with the backend MUJOCO_GL names; exit 3 without one."""
    try:
        import mujoco

        mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
    except Exception as exc:  # noqa: BLE001  (whatever stops a context from opening: this backend cannot render)
        print(f"{type(exc).__name__}: {exc}".strip().splitlines()[0], file=sys.stderr)
        return _EXIT_NO_BACKEND
    Path(argv[0]).write_bytes(render_model_png())
    return 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
