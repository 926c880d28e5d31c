"""Where the package finds its data files (model folder, schemas, layouts)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["MODELS_DIR", "PACKAGE_DIR"]

PACKAGE_DIR = Path(__file__).resolve().parent
#: The model folder (c80.xml, scene.xml, model card) of a source checkout.
MODELS_DIR = PACKAGE_DIR.parent / "models"
