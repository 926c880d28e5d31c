"""``wmr-mj replay LOG``: summarise, plot, verify or render a run log (MCAP).

Everything comes from the log alone: its configuration, signals, attachments (the exact MJCF,
the initial state) and the summary written at close. The work is done by
:mod:`wmr_mj.logs.replay` (summary, bit-exact verify, figure); this module parses the command line
and prints.

- default: a text summary (configuration, sup|E| and sup|E'| over the whole run and after
  ``settle_s``, the analytic bounds E_max / Edot_max when the log carries them, inside/outside);
  ``--json`` prints it as one JSON object;
- ``--plot PATH.png``: E and E' over time, the armature voltage, and the (|E|, |E'|) plane;
- ``--verify``: first hash each plug-in file the log names (its law's, its tracker's) and refuse,
  before anything is imported, one whose SHA-256 is not the log's record or that is gone (exit 2, one
  line); say on stderr which file it will import. Then rebuild the model from the attached MJCF, set
  the initial state, re-apply the logged ctrl and compare qpos/qvel at every control step; then re-run
  the logged configuration with its controller imported again (which runs the plug-in's code: verify
  only logs whose plug-ins you trust) and compare the voltages it applies with the logged ones: exit 0
  when both are bit-identical, 1 otherwise (with one line saying why a controller could not be re-run);
- ``--video PATH.mp4``: the run rendered offscreen by :mod:`wmr_mj.logs.video` (MuJoCo's Renderer on EGL
  or OSMesa, imageio's ffmpeg writer): the steering seen through the chassis, E against E_max.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from wmr_mj.cli._common import positive_float, positive_int, print_json
from wmr_mj.cli.options import add_json

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
    p.set_defaults(func=run)


# --------------------------------------------------------------------------- command


def run(args: argparse.Namespace) -> int:
    from wmr_mj.logs.reader import load_log
    from wmr_mj.logs.replay import (
        checked_plugins,
        format_summary,
        format_verify,
        format_verify_controller,
        plot,
        summarize,
        verify,
        verify_controller,
    )

    log = load_log(args.log)
    if args.verify:  # a changed or missing plug-in is refused before any work, and before it is imported
        for plugin in checked_plugins(log):
            print(plugin.will_import(), file=sys.stderr)
    rep = summarize(log, args.settle)
    status = 0
    if args.plot:
        rep["plot"] = str(plot(log, args.plot, rep))
    if args.video:
        from wmr_mj.logs.video import parse_size, render_video

        width, height = parse_size(args.size)
        video = render_video(args.log, args.video, fps=args.fps, width=width, height=height)
        rep.update(video=video.path, video_backend=video.backend, video_seconds=video.seconds)
    if args.verify:
        rep["verify"] = verify(log)
        ctrl = rep["verify_controller"] = verify_controller(log)
        reproduced = ctrl["identical"] or not (ctrl["checked"] or ctrl["required"])
        status = 0 if rep["verify"]["identical"] and reproduced else 1
    if args.json:
        print_json(rep)
        return status
    print(format_summary(rep))
    if args.plot:
        print(f"plot       {args.plot}")
    if args.video:
        print(f"video      {args.video} ({rep['video_backend']})")
    if args.verify:
        print(format_verify(rep["verify"]))
        print(format_verify_controller(rep["verify_controller"]))
    return status

