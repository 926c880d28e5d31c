"""Command-line start-up: ``wmr-mj --help`` and a bad option against ``import mujoco``, each a fresh process.

    .venv/bin/python bench/bench_cli_help.py [--repeats 9]

Each repeat runs, in turn (a slow spell of a shared machine hits all of them), in a new interpreter:

- ``python -m wmr_mj.cli --help``: the top-level page (every command listed, none registered);
- ``python -m wmr_mj.cli run --bogus``: run's parser built, its options and helps, then the one-line refusal;
- ``python -c "import mujoco"``: the floor, since ``main`` imports MuJoCo before parsing (its check that
  MuJoCo loads at all);
- ``python -c "pass"``: the interpreter alone.

Medians of the repeats' wall times (``time.perf_counter`` around ``subprocess.run``), in seconds. Target
(issue 41 item 6): ``--help`` and a bad option under 0.4 s, near ``import mujoco``. What building a parser
imports is checked by tests/test_cli_help.py.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

CASES = {
    "wmr-mj --help": [sys.executable, "-m", "wmr_mj.cli", "--help"],
    "wmr-mj run --bogus": [sys.executable, "-m", "wmr_mj.cli", "run", "--bogus"],
    'python -c "import mujoco"': [sys.executable, "-c", "import mujoco"],
    'python -c "pass"': [sys.executable, "-c", "pass"],
}
#: the exit status each must give: --help 0, a bad option 2 (one line), the imports 0
EXPECTED_STATUS = {"wmr-mj --help": 0, "wmr-mj run --bogus": 2, 'python -c "import mujoco"': 0,
                   'python -c "pass"': 0}
TARGET_S = 0.4


def _time(argv: list[str], status: int) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    wall = time.perf_counter() - t0
    if proc.returncode != status:
        raise SystemExit(f"{' '.join(argv)} exited {proc.returncode}, expected {status}: {proc.stderr.strip()}")
    return wall


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=9, help="processes per case (default 9)")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error("--repeats must be >= 1")
    for argv_ in CASES.values():  # warm the file cache and the bytecode once, untimed
        subprocess.run(argv_, capture_output=True, timeout=60)
    walls: dict[str, list[float]] = {name: [] for name in CASES}
    for _ in range(args.repeats):
        for name, argv_ in CASES.items():
            walls[name].append(_time(argv_, EXPECTED_STATUS[name]))
    print(f"median wall time of {args.repeats} fresh processes each (s); target for wmr-mj: < {TARGET_S} s")
    width = max(map(len, CASES))
    for name, ws in walls.items():
        print(f"  {name:<{width}}  {statistics.median(ws):.3f}  (min {min(ws):.3f}, max {max(ws):.3f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
