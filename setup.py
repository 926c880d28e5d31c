"""Build hooks: ship the repository's models/ inside the wheel as ``wmr_mj/models/``, build the
steering law as MuJoCo's control callback (``wmr_mj.sim._compiled_law``) and the inner loop of C's
projection on its path (``wmr_mj.analysis._nearest_chord``).

All project metadata lives in pyproject.toml. An installed wheel has no
repository beside it, so ``wmr_mj._util.resources.MODELS_DIR`` falls back to this copy
(``wmr-mj model check`` then compares it with the parameter set).

The compiled law reads mjModel and mjData, so it is built against the headers of the
mujoco wheel of the build (pyproject's build requirements) and checks at import that it
runs with the same MuJoCo. It is optional: without a C compiler the install goes on and
the batch uses the NumPy law (``wmr_mj.sim.compiled_law.unavailable_reason`` says so). So is the
projection's: without it ``wmr_mj.analysis.path_error`` computes the same bits in NumPy.
"""

from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_py import build_py

MODEL_FILES = ("c80.xml", "scene.xml", "README.md", "c80.png", "CHANGELOG.md")


class BuildPyWithModels(build_py):
    """build_py that also copies the model folder (MODEL_FILES of models/) to wmr_mj/models/."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return  # an editable install reads models/ of the checkout itself
        source = Path(__file__).resolve().parent / "models"
        target = Path(self.build_lib) / "wmr_mj" / "models"
        self.mkpath(str(target))
        for name in MODEL_FILES:
            self.copy_file(str(source / name), str(target / name))


def compiled_law_extensions() -> list[Extension]:
    """wmr_mj.sim._compiled_law, where the mujoco wheel with its C headers is importable."""
    try:
        import mujoco
    except ImportError:
        return []
    include = Path(mujoco.__file__).resolve().parent / "include"
    if not (include / "mujoco" / "mujoco.h").is_file():
        return []
    # -ffp-contract=off: no fused multiply-adds, so that the C law rounds as the Python law does
    return [Extension("wmr_mj.sim._compiled_law", sources=["wmr_mj/sim/_compiled_law.c"], include_dirs=[str(include)],
                      extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math"], libraries=["m"],
                      optional=True)]


def projection_extensions() -> list[Extension]:
    """wmr_mj.analysis._nearest_chord: plain C, no MuJoCo headers."""
    # -ffp-contract=off: no fused multiply-adds, so that the loop rounds as NumPy's element-wise operations do
    return [Extension("wmr_mj.analysis._nearest_chord", sources=["wmr_mj/analysis/_nearest_chord.c"],
                      extra_compile_args=["-O2", "-ffp-contract=off", "-fno-fast-math"], optional=True)]


setup(cmdclass={"build_py": BuildPyWithModels}, ext_modules=compiled_law_extensions() + projection_extensions())
