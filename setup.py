"""Build hook: ship the repository's models/ inside the wheel as ``wmr_mj/models/``.

All project metadata lives in pyproject.toml. An installed wheel has no
repository beside it, so ``wmr_mj.resources.MODELS_DIR`` falls back to this copy
(``wmr-mj model check`` then compares it with the parameter set).
"""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

MODEL_FILES = ("c80.xml", "scene.xml", "README.md")


class BuildPyWithModels(build_py):
    """build_py that also copies models/{c80.xml,scene.xml,README.md} to wmr_mj/models/."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return  # an editable install reads models/ of the checkout itself
        source = Path(__file__).resolve().parent / "models"
        target = Path(self.build_lib) / "wmr_mj" / "models"
        self.mkpath(str(target))
        for name in MODEL_FILES:
            self.copy_file(str(source / name), str(target / name))


setup(cmdclass={"build_py": BuildPyWithModels})
