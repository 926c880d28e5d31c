"""``wmr-mj cart``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.options import positive_float

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "check a cart file (TOML): schema, compile and step, identification"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("cart", help=HELP)
    p.add_argument("action", choices=("check", "card"),
                   help="check: read the file against its schema, compile and step the generated model for 1 s "
                        "with random controls (no MuJoCo warning), identify P, C_V, F, K, gyro from a simulated "
                        "excitation and compare them with what the file implies, and report the certified design's "
                        "certificate on the cart; exit 1 if a check fails. card: write the cart's model card "
                        "(Markdown, as models/README.md is the C80's; about a minute of measurements)")
    p.add_argument("cart", metavar="FILE|NAME", help="a cart file (.toml, see wmr_mj/carts/c80.toml) or a shipped "
                                                     "cart's name (c80)")
    p.add_argument("--duration", type=positive_float, default=20.0,
                   help="length of the identification's excitation, s (default 20)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random controls and the excitation (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--path", metavar="NAME|FILE", default=None,
                   help="check: the path the certified design and the design search answer for (a path name, a "
                        "packaged route or a route file; default: the cart's own, [paths] default in its file, "
                        "else paper-circle)")
    p.add_argument("--out", metavar="PATH", default=None,
                   help="card: the Markdown file to write (default: logs/<cart file's stem>-card.md)")
