"""``wmr-mj model``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.options import add_json
from wmr_mj.cli.run_options import add_option

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "write/check the MJCF files generated from the C80 parameter set"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("model", help=HELP)
    p.add_argument("action", choices=("write", "check", "params", "slip", "friction", "card", "image"),
                   help="write: regenerate models/*.xml; check: exit 1 if they differ from the parameter set; "
                        "params: print the parameter set with sources and the derived coefficients; "
                        "slip: measure the wheels' side slip on the 1 m circle; friction: measure the steering "
                        "joint's friction law (break-away, creep, sliding) for each friction model; "
                        "card: write models/README.md; image: render models/c80.png (the scene at its home "
                        "keyframe, offscreen: EGL or OSMesa)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE", help="override a parameter (repeatable)")
    add_json(p, help="with 'params', 'slip' or 'friction': print one JSON object")

    add_option(p, "--cart")  # params, slip, friction on the cart (its card: wmr-mj cart card FILE)
