"""The cart's spec (issue 36, "The cart's keys" and "Accepted though absurd"; issue 35 item 7's cart slips):
one key name per sensing quantity, ``encoder_bits`` in a spec, an empty file refused, a file taking changes,
the physical limits on inductance, play, delays and an encoder's resolution, an unbounded error as math.inf,
and the play's coverage following the sensor's side. Every refusal through the CLI is one line on stderr
naming the culprit and what is accepted, exit status 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from helpers import one_error_line

from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError, UnknownNameError
from wmr_mj.hardware import Actuation, Sensing, Transmission
from wmr_mj.hardware.assembly import MAX_ELECTRICAL_TIME_CONSTANT_S, smallest_encoder_ticks
from wmr_mj.hardware.sensing import SENSING_SPEC_KEYS, measurement_error_bounds
from wmr_mj.params import C80
from wmr_mj.searches.search_space import HARDWARE_AXES, with_hardware
from wmr_mj.sim.certify import certificate_for, measurement_errors_of
from wmr_mj.sim.config import RunConfig, build_reference, config_from_dict
from wmr_mj.sim.designs import design_changes

HERE = Path(__file__).resolve().parent.parent
#: a short run: the lane change reaches its manoeuvre in 6 s
SHORT = ["--preset", "certified", "--path", "lane-change", "--duration", "6", "--no-log"]



def _refused(capsys, argv: list[str], words: list[str]) -> str:
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert all(w in line for w in words), line
    return line


def _write(path: Path, text: str) -> str:
    path.write_text(text)
    return str(path)


# ---- 1. one key name per sensing quantity: spec, Python, files and axes


def test_every_sensing_axis_is_a_spec_key_and_every_spec_key_a_field_or_its_second_form():
    fields = set(Sensing.__dataclass_fields__)
    for key in SENSING_SPEC_KEYS:
        # a spec key is a field, or encoder_bits (2**bits ticks): the noise's kind rides in its value
        assert key in fields or key == "encoder_bits", key
    for axis in HARDWARE_AXES:
        part, _, key = axis.partition(".")
        if part == "sensing":
            assert key in SENSING_SPEC_KEYS, axis


def test_the_noise_has_one_name_in_python_the_spec_a_file_and_an_axis(tmp_path):
    python = Sensing(noise_kind="uniform", noise=0.0005)
    spec = Sensing.from_spec("noise=uniform:0.0005")
    file = Sensing.from_spec(_write(tmp_path / "s.toml", 'noise = "uniform:0.0005"\n'))
    axis = with_hardware(RunConfig(), {"sensing.noise": 0.0005}).sensing
    assert python == spec == file == axis
    assert python.noise == 0.0005 and python.to_dict()["noise"] == "uniform:0.0005"
    velocity = Sensing(velocity="tachometer", velocity_noise_kind="uniform", velocity_noise=0.2)
    assert Sensing.from_spec("velocity=tachometer,velocity_noise=uniform:0.2") == velocity
    assert with_hardware(RunConfig(sensing="velocity=tachometer"), {"sensing.velocity_noise": 0.2}).sensing == velocity
    with pytest.raises(UnknownNameError, match="noise"):
        Sensing.from_spec("noise_alpha=uniform:0.0005")  # the old Python name is not a second spelling
    with pytest.raises(UnknownNameError, match="sensing.noise"):
        with_hardware(RunConfig(), {"sensing.noise_alpha": 0.0005})


def test_a_logs_recorded_config_still_loads():
    """A log records RunConfig.to_dict(); its sensing is the spec form, whose keys did not change."""
    config = RunConfig.from_inputs(
        sensing="encoder_bits=12,velocity=tachometer,noise=uniform:0.0005,velocity_noise=gaussian:0.01")
    recorded = json.loads(json.dumps(config.to_dict()))
    assert recorded["sensing"]["noise"] == "uniform:0.0005" and recorded["sensing"]["encoder_ticks"] == 4096
    assert config_from_dict(recorded).sensing == config.sensing
    # the form written before this change (main's efa4efa) reads back the same
    written = {"encoder_ticks": 4096, "encoder_side": "axis", "encoder_rounding": "round", "velocity": "tachometer",
               "filter_tau": None, "noise": "uniform:0.0005", "velocity_noise": "gaussian:0.01", "delay": 0.0,
               "seed": 0}
    assert Sensing.from_spec(written) == config.sensing


# ---- 2. encoder_bits in a spec


def test_encoder_bits_is_two_to_the_bits_ticks():
    assert Sensing.from_spec("encoder_bits=13") == Sensing(encoder_ticks=8192)
    assert Sensing.from_spec({"encoder_bits": 0}).encoder_ticks == 1
    # a preset's resolution changed by bits, as by ticks
    assert Sensing.from_spec("preset=magnetic-12bit-axis,encoder_bits=14") == Sensing.from_spec(
        "preset=magnetic-12bit-axis,encoder_ticks=16384")
    for bad in ("-1", "49", "12.5", "twelve"):
        with pytest.raises(ParameterError, match="encoder_bits"):
            Sensing.from_spec(f"encoder_bits={bad}")


@pytest.mark.parametrize("spec", ["encoder_bits=13,encoder_ticks=8192", "encoder_ticks=8192,encoder_bits=13"])
def test_encoder_bits_and_ticks_together_are_refused(capsys, spec):
    _refused(capsys, ["run", *SHORT, "--sensing", spec], ["encoder_bits", "encoder_ticks", "give one"])


def test_encoder_bits_runs_as_its_ticks(capsys):
    assert main(["run", *SHORT, "--json", "--sensing", "encoder_bits=13"]) == 0
    assert json.loads(capsys.readouterr().out)["sensing"]["encoder_ticks"] == 2 ** 13


# ---- 3. an empty or unknown-only file refused


@pytest.mark.parametrize("name, text", [("empty.toml", ""), ("comments.toml", "# nothing set\n"),
                                        ("empty.json", "{}")])
def test_an_empty_file_is_refused_not_read_as_ideal(tmp_path, capsys, name, text):
    path = _write(tmp_path / name, text)
    with pytest.raises(ParameterError, match="sets no key"):
        Sensing.from_spec(path)
    with pytest.raises(ParameterError, match="sets no key"):
        Actuation.from_spec(path)
    line = _refused(capsys, ["run", *SHORT, "--sensing", path], [name, "sets no key", "encoder_ticks", "noise"])
    assert "preset" in line  # the accepted keys, the preset among them


def test_a_file_of_unknown_keys_is_refused_naming_the_key_and_the_file(tmp_path, capsys):
    path = _write(tmp_path / "typo.toml", "encoder_tick = 4096\n")
    _refused(capsys, ["run", *SHORT, "--sensing", path], ["encoder_tick", "typo.toml", "encoder_ticks"])
    nested = _write(tmp_path / "nested.toml", "[sensing]\nencoder_ticks = 4096\n")
    _refused(capsys, ["run", *SHORT, "--sensing", nested], ["'sensing'", "nested.toml", "encoder_ticks"])


# ---- 4. a file takes changes


def test_a_file_takes_changes_as_a_preset_does(tmp_path, capsys):
    toml = _write(tmp_path / "my.toml", 'encoder_bits = 13\nvelocity = "tachometer"\nnoise = "uniform:0.0005"\n')
    mine = Sensing(encoder_ticks=8192, velocity="tachometer", noise_kind="uniform", noise=0.0005)
    assert Sensing.from_spec(toml) == mine
    assert Sensing.from_spec(f"preset={toml},delay=0.003") == Sensing(
        encoder_ticks=8192, velocity="tachometer", noise_kind="uniform", noise=0.0005, delay=0.003)
    assert Sensing.from_spec(f"preset={toml},encoder_ticks=4096").encoder_ticks == 4096  # the change wins
    as_json = _write(tmp_path / "my.json", json.dumps(mine.to_dict()))
    assert Sensing.from_spec({"preset": as_json, "delay": 0.003}) == Sensing.from_spec(f"preset={toml},delay=0.003")
    # a file may itself start from a named preset
    based = _write(tmp_path / "based.toml", 'preset = "magnetic-12bit-axis"\ndelay = 0.002\n')
    assert Sensing.from_spec(f"preset={based},encoder_bits=14") == Sensing.from_spec(
        "preset=magnetic-12bit-axis,delay=0.002,encoder_bits=14")
    # but not from another file (no chains)
    chained = _write(tmp_path / "chained.toml", f'preset = "{toml}"\n')
    with pytest.raises(ParameterError, match="names another file"):
        Sensing.from_spec(chained)
    act = _write(tmp_path / "act.json", '{"inductance": 0.0005}')
    assert Actuation.from_spec(f"preset={act},delay=0.002") == Actuation(delay=0.002, inductance=0.0005)
    # through the CLI: the run's JSON carries the changed file's cart
    assert main(["run", *SHORT, "--json", "--sensing", f"preset={toml},delay=0.003"]) == 0
    assert Sensing.from_spec(json.loads(capsys.readouterr().out)["sensing"]) == Sensing.from_spec(
        f"preset={toml},delay=0.003")
    _refused(capsys, ["run", *SHORT, "--sensing", f"preset={tmp_path / 'none.toml'},delay=0.003"],
             ["none.toml", "cannot read"])


# ---- 5. the hardware guide shows the syntax, in blocks tests/test_docs.py runs


def test_the_hardware_guide_shows_the_noise_syntax_and_a_file_in_run_blocks():
    import mktestdocs

    text = (HERE / "docs" / "guides" / "hardware.md").read_text()
    run = [b for lang in ("sh", "python") for b in mktestdocs.grab_code_blocks(text, lang=lang)]
    assert any("noise=uniform:" in b for b in run)  # the uniform:BOUND form in a spec
    assert any(".toml <<" in b and "preset=" in b and ".toml," in b for b in run)  # a file, and a file changed


# ---- 6. physical limits on inductance and play, with their reason


def test_the_inductance_limit_is_the_electrical_time_constant_against_its_datasheet_range(capsys):
    limit = MAX_ELECTRICAL_TIME_CONSTANT_S * C80.R_a  # tau_e = L_a / R_a <= 0.1 s
    assert limit == pytest.approx(0.1)
    RunConfig.from_inputs(actuation=Actuation(inductance=limit))  # the limit itself is accepted
    with pytest.raises(ParameterError, match="L_a/R_a"):  # checked where the config is coerced (on the plant)
        RunConfig.from_inputs(actuation=Actuation(inductance=limit * (1 + 1e-12)))
    # R_a read from the plant's parameter set: twice the resistance, twice the inductance
    RunConfig.from_inputs(actuation=Actuation(inductance=2 * limit), plant_overrides={"R_a": 2 * C80.R_a})
    _refused(capsys, ["run", *SHORT, "--actuation", "inductance=1e6"],
             ["inductance = 1e+06 H", "L_a/R_a", "0.1 s", "datasheet", "inductance <= 0.1 H"])


@pytest.mark.parametrize("backlash", ["10", "2", "0.9"])
def test_play_beyond_the_steering_stops_is_refused(capsys, backlash):
    _refused(capsys, ["run", *SHORT, "--backlash", backlash],
             [f"backlash = {backlash} rad", "0.9 rad stops", "cannot be", "backlash < 0.9 rad"])


def test_the_play_limit_is_read_from_the_parameter_set():
    stops = C80.steering_range
    RunConfig(transmission=Transmission(backlash=math.nextafter(stops, 0.0)))
    with pytest.raises(ParameterError, match="cannot be"):
        RunConfig(transmission=Transmission(backlash=stops))
    RunConfig(transmission=Transmission(backlash=1.0), plant_overrides={"steering_range": 1.2})  # wider stops


# ---- 7. a delay longer than the run, and an encoder too coarse for the claim's arithmetic, refused up front


@pytest.mark.parametrize("argv, words", [
    (["--sensing", "delay=7"], ["sensing: delay = 7 s", "not shorter than the run", "duration = 6 s",
                                "accepted: a delay below the duration"]),
    (["--sensing", "delay=6"], ["sensing: delay = 6 s", "not shorter than the run"]),
    (["--actuation", "delay=6"], ["actuation: delay = 6 s", "not shorter than the run"]),
])
def test_a_delay_not_shorter_than_the_run_is_refused(capsys, argv, words):
    _refused(capsys, ["run", *SHORT, *argv], words)


def test_a_delay_within_the_run_reaches_the_claim_without_a_division_by_zero():
    """A 5 s delay on a 10 s run is refused by nothing; the claim's measured angle then reaches pi/2 at
    E_max = 0, which used to raise ZeroDivisionError (an invalid claim's terms divided by cos^2 = 0)."""
    config = RunConfig(**design_changes("certified"), duration=10.0, sensing="delay=5")
    cert = certificate_for(config, build_reference(config.path, C80, dt=1e-3, duration=10.0)[0])
    assert cert is not None and not cert.valid and "reaches pi/2" in cert.reason
    assert math.isfinite(cert.gyro_term) and math.isfinite(cert.K_term)


def _smallest_by_loop(side: str, rounding: str, i2: float, stops: float) -> int:
    """The fewest ticks N whose bound (Delta/2 rounding, Delta truncation; Delta = 2 pi / N, / i2 on the motor)
    keeps the measured angle below pi/2 from the stops: a plain search."""
    n = 1
    while (2 * math.pi / n / (i2 if side == "motor" else 1.0)) * (0.5 if rounding == "round" else 1.0) >= \
            math.pi / 2 - stops:
        n += 1
    return n


@pytest.mark.parametrize("side, rounding, expected", [("axis", "round", 5), ("axis", "floor", 10),
                                                      ("motor", "round", 1), ("motor", "floor", 1)])
def test_the_smallest_encoder_is_the_one_whose_reading_stays_below_pi_over_2(side, rounding, expected):
    n = smallest_encoder_ticks(side=side, rounding=rounding, gear_ratio=C80.i2, steering_range=C80.steering_range)
    assert n == expected == _smallest_by_loop(side, rounding, C80.i2, C80.steering_range)
    for stops in (0.3, 0.9, 1.2, 1.5):
        assert smallest_encoder_ticks(side=side, rounding=rounding, gear_ratio=7.0, steering_range=stops) == \
            _smallest_by_loop(side, rounding, 7.0, stops)
    spec = f"encoder_ticks={n},encoder_side={side},encoder_rounding={rounding}"
    config = RunConfig(**design_changes("certified"), duration=10.0, sensing=spec)  # accepted
    # at the smallest encoder the claim's arithmetic is defined: a certificate (valid or not), no exception
    certificate_for(config, build_reference(config.path, C80, dt=1e-3, duration=10.0)[0])
    if n > 1:
        with pytest.raises(ParameterError, match=f"encoder_ticks >= {n}"):
            RunConfig(sensing=f"encoder_ticks={n - 1},encoder_side={side},encoder_rounding={rounding}")


@pytest.mark.parametrize("argv, words", [
    (["run", *SHORT, "--sensing", "encoder_ticks=2"], ["encoder_ticks = 2", "too coarse", "pi/2",
                                                       "encoder_ticks >= 5", "encoder_bits >= 3"]),
    (["run", *SHORT, "--sensing", "encoder_bits=2"], ["encoder_ticks = 4", "encoder_bits >= 3"]),
    (["run", *SHORT, "--sensing", "encoder_ticks=9,encoder_rounding=floor"], ["Delta = ", "encoder_ticks >= 10",
                                                                              "encoder_bits >= 4"]),
    (["run", *SHORT, "--sensing", "noise=uniform:0.7"], ["noise = uniform:0.7", "pi/2", "below 0.6708"]),
    (["sweep", "--n", "2", "--range", "sensing.encoder_bits=0:4", *SHORT[:-1]],
     ["sensing.encoder_bits", "at 0", "encoder_bits >= 3"]),
    (["falsify", "--budget", "4", "--range", "sensing.encoder_bits=0:4", *SHORT[:-1]],
     ["sensing.encoder_bits", "at 0", "encoder_bits >= 3"]),
], ids=["ticks-2", "bits-2", "floor-9", "noise-0.7", "sweep-bits-0-4", "falsify-bits-0-4"])
def test_a_reading_that_can_reach_pi_over_2_is_refused_up_front(tmp_path, capsys, argv, words):
    if argv[0] != "run":
        argv = [*argv, "--out", str(tmp_path / "out")]
    line = _refused(capsys, argv, words)
    assert "ZeroDivisionError" not in line and "claim()" not in line


def test_the_noise_limit_stands_beside_the_encoder():
    margin = math.pi / 2 - C80.steering_range
    encoder = Sensing(encoder_ticks=4096).encoder_bound(C80.i2)
    RunConfig(sensing=Sensing(encoder_ticks=4096, noise_kind="uniform", noise=(margin - encoder) * (1 - 1e-9)))
    with pytest.raises(ParameterError, match="noise = uniform"):
        RunConfig(sensing=Sensing(encoder_ticks=4096, noise_kind="uniform", noise=margin - encoder))
    RunConfig(sensing=Sensing(noise_kind="gaussian", noise=1.0))  # no bound to check: not covered instead


# ---- 8. an unbounded error is infinite


def test_gaussian_noise_reaches_a_claim_as_an_infinite_error():
    T = 0.001
    on_alpha = measurement_errors_of(RunConfig(sensing="noise=gaussian:0.0005"), C80)
    assert on_alpha.alpha_error_max == math.inf and on_alpha.alpha_dot_error_max == 0.0  # alpha' exact
    assert not on_alpha.covered and on_alpha.why_not == "Gaussian noise has no bound"
    on_rate = measurement_errors_of(RunConfig(sensing="velocity=tachometer,velocity_noise=gaussian:0.01"), C80)
    assert on_rate.alpha_error_max == 0.0 and on_rate.alpha_dot_error_max == math.inf and not on_rate.covered
    differenced = measurement_errors_of(RunConfig(sensing="velocity=difference,noise=gaussian:0.0005"), C80)
    assert differenced.alpha_error_max == differenced.alpha_dot_error_max == math.inf  # the difference spreads it
    bounds = measurement_error_bounds(Sensing(noise_kind="gaussian", noise=0.0005), control_period=T, gear_ratio=60.0)
    assert on_alpha.alpha_error_max == bounds.alpha_error_max  # the part's bound, carried as it is
    # a uniform noise of the same size stays a number, covered
    uniform = measurement_errors_of(RunConfig(sensing="noise=uniform:0.0005"), C80)
    assert uniform.covered and uniform.alpha_error_max == 0.0005


def test_a_gaussian_run_prints_no_inf_and_its_json_writes_null(capsys):
    assert main(["run", *SHORT, "--json", "--sensing", "noise=gaussian:0.0005"]) == 0
    text = capsys.readouterr().out
    assert "Infinity" not in text and "NaN" not in text
    report = json.loads(text)
    # the run is judged by the sampled-data certificate (issue 44), which records the cart's measurement with the cart
    assert report["certificate"]["claimant"] == "sampled-data"
    measurement = report["certificate"]["inputs"]["cart"]["measurement"]
    assert measurement["alpha_error_max"] is None and measurement["covered"] is False
    assert report["certificate"]["valid"] is False
    assert main(["run", *SHORT, "--sensing", "noise=gaussian:0.0005"]) == 0
    printed = capsys.readouterr().out
    assert "Gaussian noise has no bound" in printed
    assert not any(word in printed.split() for word in ("inf", "inf,", "-inf", "nan"))


@pytest.mark.parametrize("controller", ["computed-torque", "sliding-mode"])
def test_robustness_prints_an_unbounded_error_as_unbounded_not_inf(capsys, controller):
    """Before, the Gaussian cart printed 'alpha_error_max 0'; its error is now infinite, and shown as such."""
    assert main(["robustness", "--certificate", "--controller", controller, "--sensing", "noise=gaussian:0.0005"]) == 0
    printed = capsys.readouterr().out
    assert "e_alpha is unbounded (no bound derived)" in printed
    words = printed.replace(",", " ").split()
    assert "inf" not in words and "nan" not in words, printed
    if controller == "sliding-mode":
        assert "alpha_error_max unbounded" in printed


# ---- 9. the play's coverage follows the sensor's side, with or without ticks


@pytest.mark.parametrize("sensing", ["encoder_side=motor", "encoder_side=motor,encoder_ticks=120000"])
def test_play_with_a_motor_side_sensor_gives_the_motor_side_reason(sensing):
    m = measurement_errors_of(RunConfig(sensing=sensing, transmission=0.004), C80)
    assert not m.covered and "the play's stop is soft" in m.why_not and "steering axis" not in m.why_not
    side = Sensing.from_spec(sensing)
    assert side.reads_motor_side
    # the rigid stop's b rides in the reading's bound, as for any motor-side reading
    assert m.alpha_error_max == side.encoder_bound(C80.i2) + 0.004


def test_play_with_an_axis_sensor_keeps_the_axis_reason():
    m = measurement_errors_of(RunConfig(sensing="velocity=difference", transmission=0.004), C80)
    assert not m.covered and "steering axis" in m.why_not and "soft" not in m.why_not


def test_the_run_names_the_motor_side_reason_for_an_exact_motor_angle(capsys):
    assert main(["run", *SHORT, "--sensing", "encoder_side=motor", "--backlash", "0.004"]) == 0
    out = capsys.readouterr().out
    assert "the play's stop is soft" in out and "encoder on the steering axis" not in out



def test_the_modules_old_name_warns_and_hands_the_same_objects():
    """``wmr_mj.hardware.cart`` (beside the cart files' ``wmr_mj.carts``) is ``wmr_mj.hardware.assembly`` now; the old
    name is kept one release, each name warning and the very object of the new module."""
    import wmr_mj.hardware.cart as old
    from wmr_mj.hardware import assembly

    for name in assembly.__all__:
        with pytest.warns(DeprecationWarning, match=rf"hardware\.cart\.{name} is deprecated: use "
                                                    rf"wmr_mj\.hardware\.assembly\.{name}"):
            assert getattr(old, name) is getattr(assembly, name)
    with pytest.raises(AttributeError):
        old.no_such_name  # noqa: B018
