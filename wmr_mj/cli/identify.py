"""``wmr-mj identify``: fit the steering model to the driving MuJoCo plant, or to a cart's own recordings.

Without ``--data``: excite the simulated plant and fit P, C_V, F, K, gyro by least squares (as before).
With ``--data FILE[:m1=KG]`` (repeatable): output-error identification from the cart's recordings
(:mod:`wmr_mj.plant.output_error`), written as a cart file (``--out NEW.toml``) with 95 % intervals; a
``--holdout`` recording is predicted by the identified model, and a normalised RMS error above
:data:`wmr_mj.plant.output_error.HOLDOUT_NRMSE_MAX` exits 1. Bad data: one line, exit 2.
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path
from typing import Any

from wmr_mj._util.files import check_output_path, write_json_atomic
from wmr_mj.carts import load_cart, load_cart_text
from wmr_mj.cli._common import cart_parameters, parse_assignments, print_json
from wmr_mj.errors import ParameterError
from wmr_mj.logs.recordings import parse_topics, read_ros2_bag, read_run_log
from wmr_mj.params import (
    COEFFICIENT_MODELS,
    COEFFICIENT_NAMES,
    M1_NOMINAL,
    check_motor_constant,
    parameters_of_cart,
    with_params,
)
from wmr_mj.plant.identified_cart import identified_cart_text
from wmr_mj.plant.identify import identify_plant
from wmr_mj.plant.mjcf_rollouts import import_sysid, mjcf_rollout_nrmse
from wmr_mj.plant.output_error import HOLDOUT_NRMSE_MAX, POORLY_DETERMINED, fit_recordings, holdout_error
from wmr_mj.plant.recordings import check_recording, parse_columns, read_csv
from wmr_mj.report.identify import IdentifyReport


def run(args: argparse.Namespace) -> int:
    if args.data:
        return run_data(args)
    if args.holdout or args.columns or args.report or args.topics or args.sysid:
        raise ParameterError("--holdout, --columns, --topics, --report and --sysid need --data (recordings of the cart "
                             "to identify from)")
    if args.out:  # before the identification, which takes a while
        check_output_path(args.out, kind="file", option="--out")
    base = cart_parameters(args)
    m1 = base.m1 if args.m1 is M1_NOMINAL else args.m1  # --m1 not given: the cart's
    overrides = parse_assignments(args.param)
    params = with_params(base, m1=m1, **overrides)
    if "k_i" in overrides or "k_b" in overrides:
        check_motor_constant(params.k_i, params.k_b)
    result = identify_plant(params, duration=args.duration, seed=args.seed)
    obj = result.to_dict()
    if args.out:
        write_json_atomic(args.out, obj)
    if args.json:
        print_json(obj)
        return 0
    units = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m"}
    se = result.diagnostics["std_error"]
    print(f"Steering identification of the MuJoCo plant: m1 = {params.m1:g} kg, {args.duration:g} s, seed {args.seed}, "
          f"{result.diagnostics['samples']} samples, residual {result.diagnostics['residual_rms_V']:.3g} V rms")
    print(f"{'coef':5s} {'identified':>12s} {'+-':>8s} {'paper':>10s} {'diff':>8s} {'nonholon.':>10s} "
          f"{'diff':>8s}  unit")
    rel = {name: result.relative_difference(name) for name in COEFFICIENT_MODELS}
    for k in COEFFICIENT_NAMES:
        cells = []
        for name in COEFFICIENT_MODELS:
            r = rel[name][k]
            diff = "   n/a" if r is None else f"{100 * r:+7.1f}%"
            cells.append(f"{getattr(result.predicted[name], k):10.4g} {diff:>8s}")
        print(f"{k:5s} {getattr(result.identified, k):12.5g} {se[k]:8.2g} {cells[0]} {cells[1]}  {units[k]}")
    print(result.verdict())
    if args.out:
        print(f"wrote {args.out}")
    return 0


#: what --json says of the two delays: the recordings (the voltage the controller applied, the angle it read) fix
#: only their sum; with the voltage at the motor (u_applied_V) the actuation delay is measured, the rest is sensing
_SPLIT_NOTES = {
    "unknown": ("the recordings fix only the sum (delay_s): each lies in [0, the sum's upper end]; the cart file runs "
                "all of it as sensing ([defaults.delay_split] 'unknown') and its certificates cover every split"),
    "known": ("measured apart: the actuation delay from u_V to u_applied_V (the voltage at the motor), the sensing "
              "delay the rest of delay_s"),
}


def _split_data(item: str) -> tuple[str, float | None]:
    """'FILE[:m1=KG]' -> (FILE, KG or None)."""
    path, sep, rest = item.rpartition(":m1=")
    if not sep:
        return item, None
    try:
        m1 = float(rest)
    except ValueError:
        raise ParameterError(f"--data {item!r}: m1={rest!r} is not a number; accepted: FILE or FILE:m1=KG") from None
    return path, m1


def _read_recording(item: str, columns: dict[str, str], params, topics: dict[str, str] | None = None):
    path, m1 = _split_data(item)
    if topics:
        rec = read_ros2_bag(path, topics, m1=m1)
    elif path.endswith(".mcap"):
        rec = read_run_log(path, m1=m1)
    else:
        rec = read_csv(path, m1=m1, columns=columns)
    check_recording(rec, voltage_limit=params.voltage_limit, steering_range=params.steering_range)
    return rec


def run_data(args: argparse.Namespace) -> int:
    """``identify --data``: recordings -> NEW.toml, intervals, the hold-out's check."""
    out = _checked_data_outputs(args)
    start = load_cart(args.cart or "c80")
    params = parameters_of_cart(start)
    recordings, holdout = _recordings_of(args, params)
    fit = fit_recordings(recordings, params, seed=args.seed)
    date = datetime.datetime.now(datetime.UTC).date().isoformat()
    command = "wmr-mj identify " + " ".join(sys.argv[2:]) if len(sys.argv) > 2 else "wmr-mj identify"
    text = identified_cart_text(start, fit, recordings, date=date, command=command)
    Path(out).write_text(text, encoding="utf-8")
    nrmse = holdout_error(fit, holdout, params) if holdout is not None else None
    report_files: list[str] = []
    if args.report:
        report = IdentifyReport.of(fit, recordings, params, holdout=holdout)
        report_files = [str(p) for p in report.write(args.report)]
    rollouts = _mjcf_rollouts(text, holdout, recordings, fit) if args.sysid else None
    failed = nrmse is not None and not nrmse <= HOLDOUT_NRMSE_MAX
    if rollouts is not None and holdout is not None:
        failed = failed or not rollouts[holdout.name] <= HOLDOUT_NRMSE_MAX
    if args.json:
        print_json(_data_json(fit, recordings, holdout, nrmse, failed, out=out, report_files=report_files,
                              rollouts=rollouts))
    else:
        _print_fit(fit, recordings, holdout, nrmse, out)
        for name, value in (rollouts or {}).items():
            print(f"MuJoCo rollouts of {out}'s MJCF (mujoco.sysid) on {name}: normalised RMS error {value:.3g}")
        for path in report_files:
            print(f"wrote {path}")
    if failed and holdout is not None:
        worst = max(v for v in (nrmse, (rollouts or {}).get(holdout.name)) if v is not None)
        print(f"hold-out {holdout.name}: the identified model does not predict it: normalised RMS error {worst:.3g} "
              f"above {HOLDOUT_NRMSE_MAX:g}", file=sys.stderr)
        return 1
    return 0


def _checked_data_outputs(args: argparse.Namespace) -> Path:
    """``identify --data``'s --out (the cart file to write), checked with --report's folder and the sysid extra
    before any work (one line each, exit status 2)."""
    if not args.out:
        raise ParameterError("identify --data needs --out NEW.toml: the identified cart file")
    if args.sysid:  # asked for: the extra must be there before any work (one line naming it, exit 2)
        import_sysid()
    out = check_output_path(args.out, kind="file", option="--out")
    if args.report:
        check_output_path(args.report, kind="dir", option="--report")
    return out


def _recordings_of(args: argparse.Namespace, params) -> tuple[list, Any]:
    """The --data recordings and the --holdout one (None where not given), each read and checked."""
    columns = parse_columns(args.columns)
    topics = parse_topics(args.topics) if args.topics else None
    recordings = [_read_recording(item, columns, params, topics) for item in args.data]
    holdout = _read_recording(args.holdout, columns, params, topics) if args.holdout else None
    return recordings, holdout


def _data_json(fit, recordings, holdout, nrmse, failed: bool, *, out, report_files: list[str],
               rollouts: dict[str, float] | None) -> dict[str, Any]:
    """``identify --data --json``: the fit's intervals, the delay, the encoder and the noise, the recordings it rests
    on, the hold-out's check and the files written."""
    return {
        "coefficients": {k: v.to_dict() for k, v in fit.coefficients.items()},
        "fixed_from_structure": {"K": "0: absent from the plant (non-holonomic model)",
                                 "gyro": "P / l1: moves with C_V at constant speed, not separable"},
        "physical": {k: v.to_dict() for k, v in fit.physical.items()},
        "delay_s": {**fit.delay.to_dict(), "note": "the voltage-to-angle delay: sensing and actuation together"},
        "sensing_delay_s": {**fit.sensing_delay.to_dict(), "note": _SPLIT_NOTES[fit.delay_split]},
        "actuation_delay_s": {**fit.actuation_delay.to_dict(), "note": _SPLIT_NOTES[fit.delay_split]},
        "delay_split": fit.delay_split,
        "encoder_ticks": fit.encoder_ticks,
        "noise_rad": fit.noise_rad,
        "residual_rms_rad": fit.residual_rms_rad,
        "segments": fit.segments,
        "m1_kg": list(fit.m1),
        "data": [{"file": r.name, "sha256": r.sha256, "m1_kg": m, "duration_s": r.duration}
                 for r, m in zip(recordings, fit.m1)],
        "holdout": None if holdout is None else {"file": holdout.name, "nrmse": nrmse,
                                                 "nrmse_max": HOLDOUT_NRMSE_MAX, "passed": not failed},
        "cart": str(out),
        "report": report_files,
        **({} if rollouts is None else {"mjcf_rollouts": {"nrmse": rollouts, "nrmse_max": HOLDOUT_NRMSE_MAX}}),
    }


def _mjcf_rollouts(text, holdout, recordings, fit) -> dict[str, float]:
    """File -> the normalised RMS error of the identified cart file's MJCF rolled out by mujoco.sysid on the
    hold-out (else on each recording), at its m1 (wmr_mj.plant.mjcf_rollouts)."""
    identified = parameters_of_cart(load_cart_text(text, path="<identified cart>"))
    targets = [(holdout, holdout.m1)] if holdout is not None else list(zip(recordings, fit.m1))
    return {rec.name: mjcf_rollout_nrmse(identified, [rec], delay_steps=fit.delay_steps, m1=m1)
            for rec, m1 in targets}


def _print_fit(fit, recordings, holdout, nrmse, out) -> None:
    units = {"P": "V s^2/rad", "C_V": "V s/rad", "F": "V", "K": "V", "gyro": "V s/m", "front_axle_mass": "kg",
             "k_i": "N m/A", "k_b": "V s/rad", "mu": "-"}
    total = sum(r.duration for r in recordings)
    print(f"Output-error identification from {len(recordings)} recording(s), {total:.4g} s, {fit.segments} segments of "
          f"{fit.segment_steps * fit.period:g} s; residual {fit.residual_rms_rad:.3g} rad rms")
    print(f"{'name':16s} {'value':>12s} {'95 % interval':>26s}  unit")
    for name, iv in {**fit.coefficients, **fit.physical}.items():
        fixed = "  (fixed: K = 0)" if name == "K" else ("  (fixed: P / l1)" if name == "gyro" else "")
        print(f"{name:16s} {iv.value:12.5g} [{iv.lo:11.5g}, {iv.hi:11.5g}]  {units[name]}{fixed}")
    print(f"delay: {fit.delay_steps} control periods = {fit.delay.value * 1e3:g} ms, 95 % interval "
          f"[{fit.delay.lo * 1e3:g}, {fit.delay.hi * 1e3:g}] ms (voltage to angle: sensing and actuation together); "
          + (f"the split is not identifiable: sensing and actuation each in [0, {fit.delay.hi * 1e3:g}] ms, run as "
             "sensing, certified over every split" if fit.actuation_steps is None else
             f"of it actuation {fit.actuation_delay.value * 1e3:g} ms [{fit.actuation_delay.lo * 1e3:g}, "
             f"{fit.actuation_delay.hi * 1e3:g}] (u_V to u_applied_V), sensing {fit.sensing_delay.value * 1e3:g} ms "
             f"[{fit.sensing_delay.lo * 1e3:g}, {fit.sensing_delay.hi * 1e3:g}]"))
    enc = ("not readable (the angle is not on one grid)" if fit.encoder_ticks is None
           else f"{fit.encoder_ticks} ticks/rev")
    print(f"encoder: {enc}; noise beyond the quantisation: {fit.noise_rad:.3g} rad")

    wide = [n for n, iv in fit.physical.items() if iv.relative_half_width > POORLY_DETERMINED]
    if wide:
        print(f"warning: {', '.join(wide)} poorly determined (95 % half-width above {100 * POORLY_DETERMINED:g} %): "
              "the recordings do not excite them (the delay's interval is then the whole search); a box this wide "
              "may decide the certificate (wmr-mj excite writes an experiment that excites them)")
    if holdout is not None:
        print(f"hold-out {holdout.name}: normalised RMS error {nrmse:.3g}")
    print(f"wrote {out}")
