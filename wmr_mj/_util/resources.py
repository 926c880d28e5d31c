"""Where the package finds its data files (model folder, schemas, layouts).

In a source checkout the model files live in the repository's ``models/``
(``wmr-mj model write`` regenerates them there). An installed wheel carries a
copy in ``wmr_mj/models/`` (setup.py puts it there), used when no checkout
surrounds the package.

Usage::

    from wmr_mj._util.resources import MODELS_DIR, MODELS_IN_CHECKOUT
    print(MODELS_DIR / "c80.xml", "(checkout)" if MODELS_IN_CHECKOUT else "(installed copy)")
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["MODELS_DIR", "MODELS_IN_CHECKOUT", "PACKAGE_DIR", "DATA_DIR", "SCHEMAS_DIR"]

PACKAGE_DIR = Path(__file__).resolve().parent.parent
#: JSON schemas of the MCAP channels.
SCHEMAS_DIR = PACKAGE_DIR / "schemas"
#: Other shipped data (the Foxglove layout).
DATA_DIR = PACKAGE_DIR / "data"

_CHECKOUT = PACKAGE_DIR.parent
#: True when the package sits in a source checkout whose models/ is used (editable install or run from the repo).
MODELS_IN_CHECKOUT = (_CHECKOUT / "pyproject.toml").is_file() and (_CHECKOUT / "models" / "c80.xml").is_file()
#: The model folder (c80.xml, scene.xml, model card): the checkout's models/, else the copy inside the package.
MODELS_DIR = _CHECKOUT / "models" if MODELS_IN_CHECKOUT else PACKAGE_DIR / "models"
