"""``wmr-mj replay``'s parser."""

from __future__ import annotations

from typing import Any

from wmr_mj.cli.options import add_json, positive_float, positive_int

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = "summarise, plot, verify (bit for bit) or render a run log"


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "replay",
        help=HELP,
        description="summarise, plot, verify (bit for bit) or render a wmr-mj run log (MCAP)",
    )
    p.add_argument("log", metavar="LOG", help="MCAP run log written by `wmr-mj run`")
    add_json(p, help="print the summary as one JSON object")
    p.add_argument("--plot", metavar="PATH.png",
                   help="write a figure: E, E', voltage over time and the (|E|,|E'|) plane")
    p.add_argument("--verify", action="store_true",
                   help="re-simulate from the attached MJCF and initial state, and re-run the law (a plug-in's file "
                        "is checked against its SHA-256 before it is imported and run; exit 2 if changed or gone); "
                        "exit 1 unless bit-identical")
    p.add_argument("--video", metavar="PATH.mp4", help="render the run offscreen to MP4 (needs EGL or OSMesa)")
    p.add_argument("--settle", type=positive_float, metavar="S",
                   help="settling time for the sup after settling [s] (default: the log's settle_s)")
    p.add_argument("--fps", type=positive_int, default=30, help="video frame rate (default 30)")
    p.add_argument("--size", default="640x360", metavar="WxH", help="video size in pixels (default 640x360)")
