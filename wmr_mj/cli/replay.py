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

from wmr_mj.cli._common import print_json
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
from wmr_mj.logs.video import parse_size, render_video

# --------------------------------------------------------------------------- command


def run(args: argparse.Namespace) -> int:
    log = load_log(args.log)
    if args.verify:  # a changed or missing plug-in is refused before any work, and before it is imported
        for plugin in checked_plugins(log):
            print(plugin.will_import(), file=sys.stderr)
    rep = summarize(log, args.settle)
    status = 0
    if args.plot:
        rep["plot"] = str(plot(log, args.plot, rep))
    if args.video:
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
