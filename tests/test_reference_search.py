"""Declared reference bounds and the search over C's paths: the certificate for every reference within
the bounds, the run's own checked against them, knot paths that stay inside them, and a worst path
that reproduces to the bit."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import signal

from wmr_mj.errors import ParameterError
from wmr_mj.params import C80
from wmr_mj.reference.bounds import ReferenceBounds, reference_bounds_from
from wmr_mj.searches.falsify import FalsifySpec, falsify, search_worst, worst_config
from wmr_mj.searches.search_space import config_for
from wmr_mj.sim.certify import certificate_for
from wmr_mj.sim.closed_loop import run_closed_loop
from wmr_mj.sim.config import RunConfig, build_reference, coerce, estimate_parameters
from wmr_mj.sim.designs import CERTIFIED

BASE = RunConfig(**{**CERTIFIED.config_changes(), "duration": 12.0})


def _reference(config: RunConfig):
    return build_reference(config.path, estimate_parameters(), dt=1e-3, duration=config.duration)[0]


def test_declared_bounds_equal_to_the_paths_own_give_the_paths_certificate():
    """A second route to the same numbers: declaring exactly the bounds the path measures gives the
    per-path certificate's E_max and Edot_max; declaring wider bounds gives a larger E_max."""
    config = BASE.replace(path="lane-change")
    reference = _reference(config)
    own = certificate_for(config, reference)
    declared = certificate_for(config.replace(reference_bounds=reference.bounds()), reference)
    assert (declared.E_max, declared.Edot_max) == (own.E_max, own.Edot_max)
    assert declared.valid
    wider = certificate_for(config.replace(reference_bounds="paper"), reference)
    assert wider.E_max > own.E_max and wider.valid


def test_a_reference_beyond_the_declared_bounds_is_uncertified():
    """The paper circle's entry reaches max|alpha0'| = 0.23 rad/s: declared 0.2, its run fails the
    assumption (with the ratio named) and cannot be certified-anything-but-uncertified."""
    config = BASE.replace(path="paper-circle", duration=20.0, reference_bounds="alpha_dot_max=0.2")
    summary = run_closed_loop(config, progress=False).summary
    (failed,) = [a for a in summary.certificate.assumptions if not a.met]
    assert failed.name == "reference within the declared bounds"
    assert failed.value == pytest.approx(0.23 / 0.2, rel=1e-6) and "max|alpha0'|" in failed.note
    assert summary.verdict.startswith("uncertified")
    ok = run_closed_loop(config.replace(reference_bounds="paper"), progress=False).summary
    assert all(a.met for a in ok.certificate.assumptions if a.name == "reference within the declared bounds")


def test_reference_bounds_round_trip_through_the_config_json():
    config = BASE.replace(reference_bounds="paper")
    d = config.to_dict()
    assert d["reference_bounds"] == reference_bounds_from("paper").to_dict()
    from wmr_mj.experiments.sweep import config_from_dict

    assert config_from_dict(json.loads(json.dumps(d))) == coerce(config)  # the record is of the coerced config
    assert "reference_bounds" not in BASE.to_dict()  # configs without them keep the keys they had
    with pytest.raises(ParameterError, match="alpha_dot_max"):
        BASE.replace(reference_bounds="alpha_dot=0.2")


def test_path_axes_give_knot_paths_inside_the_declared_bounds():
    config = config_for(BASE.replace(reference_bounds="paper"), ["m1", "path.k1", "path.k2", "path.hold"],
                        [700.0, 0.9, -0.6, 1.0])
    assert config.m1 == 700.0 and config.path.startswith("{")
    measured = _reference(config).bounds()
    declared = config.reference_bounds
    assert isinstance(declared, ReferenceBounds)
    assert measured.alpha_dot_max <= declared.alpha_dot_max and measured.alpha_ddot_max <= declared.alpha_ddot_max
    assert measured.alpha_max <= declared.angle_max
    # held at knot 1's angle, a stable equilibrium of the reference's integration (rtol 1e-10): 10x that
    assert measured.alpha_max == pytest.approx(np.arcsin(C80.l1 * 0.9), rel=1e-9)
    with pytest.raises(ParameterError, match="--reference-bounds"):
        config_for(BASE, ["path.k1"], [0.5])


def test_search_finds_the_known_worst_pulse_of_a_synthetic_plant():
    """The error loop E'' + K_D E' + K_P E = d/J under a pulse d of amplitude a in [-1, 1] and width
    w in [0.05, 0.4] s: |E| peaks highest at |a| = 1 and the widest pulse (the loop is critically
    damped, its step response monotone), at the value a brute-force grid gives."""
    kp, kd, J = 100.0, 20.0, 2.0
    system = signal.lti([1.0 / J], [1.0, kd, kp])
    t = np.arange(0.0, 2.0, 1e-3)

    def peak(points: np.ndarray) -> np.ndarray:
        out = []
        for a, w in points:
            d = np.where(t < w, a, 0.0)
            out.append(np.max(np.abs(signal.lsim(system, d, t)[1])))
        return np.array(out)

    bounds = np.array([[-1.0, 1.0], [0.05, 0.4]])
    trace = search_worst(peak, bounds, budget=12, seed=3)
    best = trace.points[trace.best]
    grid = np.array([(a, w) for a in np.linspace(-1, 1, 9) for w in np.linspace(0.05, 0.4, 15)])
    brute = peak(grid).max()
    assert abs(best[0]) == 1.0 and best[1] == 0.4
    assert trace.values[trace.best] == pytest.approx(brute, rel=1e-12)


@pytest.mark.slow
def test_falsify_over_paths_reports_a_worst_path_that_reproduces_to_the_bit(tmp_path, capsys):
    from wmr_mj.cli.app import main

    argv = ["falsify", "--preset", "certified", "--uncertainty", "m1", "--duration", "12", "--budget", "8",
            "--path-knots", "2", "--out", str(tmp_path / "f"), "--json"]
    assert main(argv) == 0
    found = json.loads(capsys.readouterr().out)
    assert found["reproduced"] is True and found["reference_bounds"] == reference_bounds_from("paper").to_dict()
    assert set(found["box"]) == {"m1", "path.k1", "path.k2", "path.hold"}
    worst = found["worst"]
    assert worst["verdict"] == "certified-inside"  # every searched path within the declared bounds
    path_file = tmp_path / "f" / "worst-path.json"
    assert main(["run", "--preset", "certified", "--duration", "12", "--path", str(path_file), "--m1",
                 repr(worst["params"]["m1"]), "--reference-bounds", "paper", "--no-log", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert (again["sup_E"], again["sup_Edot"]) == (worst["sup_E"], worst["sup_Edot"])
    assert again["certificate"]["E_ratio"] == worst["objective"]


def test_falsify_spec_over_paths_keeps_its_certificate_fixed():
    """One E_max for every searched path: the certificate is for the declared bounds, not the path."""
    base = BASE.replace(reference_bounds="paper", path="lane-change", duration=8.0)
    spec = FalsifySpec(base=base, box={"m1": (550.0, 750.0), "path.k1": (-1.0, 1.0), "path.hold": (0.0, 2.0)},
                       budget=6, seed=1, method="vertices-polish")  # 6 runs: below a CMA-ES generation in 3-D
    result = falsify(spec)
    e_max = {e.summary["certificate"]["E_max"] for e in result.search + result.random}
    assert len(e_max) == 1
    assert worst_config(result).path != base.path
