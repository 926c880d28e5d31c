"""``wmr-mj identify``'s parser."""

from __future__ import annotations

import argparse

from wmr_mj.cli.options import add_json, add_out, add_seed, positive_float
from wmr_mj.cli.run_options import add_option
from wmr_mj.params import M1_NOMINAL

#: the command's line in ``wmr-mj --help`` (read without registering the command: wmr_mj/cli/app.py)
HELP = ("fit the steering model: the simulated plant excited (P, C_V, F, K, gyro by least squares), or a cart's "
        "recordings (--data) into a cart file with intervals")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("identify", help=HELP)
    p.add_argument("--m1", type=positive_float, default=M1_NOMINAL,
                   help="chassis mass of the plant, kg (default: the cart's, 650 on the C80)")
    p.add_argument("--duration", type=positive_float, default=60.0, help="excitation length, s (default 60)")
    add_seed(p, help="seed of the excitation signal (default 0)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE", help="override a plant parameter (repeatable)")
    add_out(p, metavar="PATH", help="also write the result as JSON (used by --model identified); with --data: the "
            "identified cart file NEW.toml")
    p.add_argument("--data", action="append", metavar="FILE[:m1=KG]",
                   help="a recording of the cart (CSV with the header t_s,u_V,alpha_rad[,speed_m_per_s], or a "
                        "wmr-mj run's MCAP log); :m1= gives the chassis mass during it (default: the cart's); "
                        "repeatable. Identifies P, C_V, F (as front_axle_mass, k_i = k_b, mu), the delay, the "
                        "encoder and the noise, and writes --out NEW.toml")
    p.add_argument("--holdout", metavar="FILE[:m1=KG]",
                   help="a recording the fit never sees: the identified model must predict it (normalised RMS error "
                        "at most 0.1, else exit 1)")
    p.add_argument("--report", metavar="DIR",
                   help="with --data: write identify.html and identify.png (recorded against simulated angle on the "
                        "hold-out, or the first recording; residuals; the table of intervals) into DIR")
    p.add_argument("--topics", metavar="u=/T,alpha=/T[,speed=/T]",
                   help="with --data BAG.mcap: a ROS 2 bag's topics of the voltage, the angle and the speed (a topic "
                        "with .field or .field[i]; default field data), read through mcap-ros2-support")
    p.add_argument("--columns", metavar="KEY=NAME,...",
                   help="CSV column names of another header: t_s=...,u_V=...,alpha_rad=...,speed_m_per_s=...")
    p.add_argument("--sysid", action="store_true",
                   help="with --data: also roll out the identified cart file's MJCF with mujoco.sysid on each segment "
                        "of the hold-out (else of each recording) against the recorded angle and report its normalised "
                        "RMS error (the hold-out's limit applies); needs the sysid extra: pip install 'wmr-mj[sysid]'")
    add_json(p, help="print one JSON object")

    add_option(p, "--cart")
