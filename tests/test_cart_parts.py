"""One part, one place (issue 34, item 5): each cart part declares its model change, its coverage and its
label in its own class, and the model, the engine and the claims read them there.

The truths: the closed forms of each stage's bound (Delta = 2 pi / N, over i2 on the motor side; Delta/2 or
Delta; Delta/T; T/2 and tau_f + T/2), the compiled MuJoCo model's own fields, and the sum the claims take.
"""

from __future__ import annotations

import math

import pytest

from wmr_mj import C80
from wmr_mj.errors import ParameterError
from wmr_mj.hardware import Actuation, Coverage, Sensing, Transmission, measurement_error_bounds
from wmr_mj.hardware.sensing import _ROUNDING_PAD
from wmr_mj.plant import mjcf
from wmr_mj.sim.certify import measurement_errors_of
from wmr_mj.sim.config import RunConfig
from wmr_mj.sim.engine import plant_options

T = 1e-3  # s, the control period


@pytest.mark.parametrize("part", [Actuation(delay=0.002), Actuation(inductance=0.0005, current_limit=20.0),
                                  Transmission(backlash=0.003)])
def test_a_part_reads_back_its_model_options(part):
    options = part.model_options()
    assert options and type(part).from_model_options(**options) == part
    assert Actuation().model_options() == {} and Transmission().model_options() == {}
    assert Sensing(encoder_ticks=4096).model_options() == {}  # the sensor runs in the callback, not the model


def test_the_engine_and_the_model_take_the_parts_own_options():
    actuation, transmission = Actuation(delay=0.003, inductance=0.0005), Transmission(backlash=0.002)
    config = RunConfig(actuation=actuation, transmission=transmission, sensing=Sensing(encoder_ticks=4096))
    options = plant_options(config)
    assert {k: options[k] for k in ("actuation_delay_s", "inductance_H", "current_limit_A", "backlash_rad")} == {
        **actuation.model_options(), **transmission.model_options()}
    model = mjcf.compile_model(**options)[0]
    at = mjcf.steering_joint_addresses(model)
    # MuJoCo's own fields: 3 steps of delay, the inductance, the play's range +-b
    assert model.actuator_history[at.actuator, 0] == 3 and model.actuator_delay[at.actuator] == pytest.approx(0.003)
    assert at.current_act is not None and list(model.tendon_range[at.play_tendon]) == [-0.002, 0.002]
    ideal = RunConfig()
    assert set(plant_options(ideal)) == {"steering_friction", "tyre_contact"}  # an ideal cart: today's model


@pytest.mark.parametrize("options, culprit", [
    ({"inductance_H": -1.0}, "inductance_H = -1.0 is not accepted"),
    ({"current_limit_A": math.nan}, "current_limit_A = nan is not accepted"),
    ({"backlash_rad": -0.1}, "backlash_rad = -0.1 is not accepted"),
])
def test_the_model_refuses_a_bad_option_through_its_part_naming_the_keyword(options, culprit):
    with pytest.raises(ParameterError, match=culprit):
        mjcf.scene_spec(**options)


def test_each_sensing_stage_has_its_bound_beside_it():
    i2 = C80.i2
    motor = Sensing(encoder_ticks=8000, encoder_side="motor", encoder_rounding="floor", velocity="difference")
    delta = 2 * math.pi / 8000 / i2
    assert motor.encoder_step(i2) == pytest.approx(delta, rel=1e-15)
    assert motor.encoder_bound(i2) == pytest.approx(delta, rel=2e-9)  # floor: the error lies in [0, Delta)
    axis = Sensing(encoder_ticks=4096, noise_kind="uniform", noise=0.0005, velocity="filtered",
                   filter_tau=0.01)
    assert axis.encoder_bound(i2) == pytest.approx(math.pi / 4096, rel=2e-9)  # round: Delta/2, Delta at the axis
    assert axis.noise_bound() == 0.0005 and axis.velocity_noise_bound() == 0.0
    spread = axis.encoder_spread(i2) + 2 * 0.0005
    error, lag = axis.estimate_bound(T, angle_spread=spread)
    assert error == pytest.approx((2 * math.pi / 4096 + 0.001) / T, rel=2e-9) and lag == pytest.approx(0.01 + T / 2)
    tachometer = Sensing(velocity="tachometer", velocity_noise_kind="uniform", velocity_noise=0.2)
    assert tachometer.estimate_bound(T, angle_spread=1.0) == (0.2, 0.0)  # its noise, no lag
    assert Sensing(noise_kind="gaussian", noise=0.001).noise_bound() == math.inf
    # the sum the bounds function returns is the stages' sum, to the bit
    b = measurement_error_bounds(axis, control_period=T, gear_ratio=i2)
    assert b.alpha_error_max == axis.encoder_bound(i2) + 0.0005 and (b.alpha_dot_error_max, b.alpha_dot_lag) == (
        error, lag)


def test_each_part_declares_its_coverage():
    assert Actuation(delay=0.003).coverage(R_a=C80.R_a) == Coverage(delay=0.003)
    driven = Actuation(inductance=0.002, current_limit=5.0).coverage(R_a=2.0)
    # the inductance is bounded (its L_a/R_a, held by the sampled-data certificate), the current limit is not
    assert driven.electrical_time_constant == 0.002 / 2.0
    assert len(driven.why_not) == 1 and "current limit (5 A)" in driven.why_not[0]
    assert Transmission().coverage(encoder_on_motor=True) == Coverage()
    motor = Transmission(backlash=0.005).coverage(encoder_on_motor=True)
    axis = Transmission(backlash=0.005).coverage(encoder_on_motor=False)
    assert not motor.covered and "the play's stop is soft: its penetration is not bounded" in motor.why_not[0]
    assert motor.alpha_error == 0.005 and axis.alpha_error == 0.0 and "actuator's side" in axis.why_not[0]
    gauss = Sensing(noise_kind="gaussian", noise=0.001).coverage(control_period=T, gear_ratio=C80.i2)
    # an unbounded error is infinite (issue 35 item 7): a claim that reads only the numbers cannot cover it
    assert not gauss.covered and gauss.alpha_error == math.inf and gauss.why_not == ("Gaussian noise has no bound",)


def test_the_claims_take_the_parts_sum():
    sensing = Sensing(encoder_ticks=4096, velocity="difference", delay=0.003)
    config = RunConfig(sensing=sensing, actuation=Actuation(delay=0.002))
    m = measurement_errors_of(config, C80)
    assert m.covered and m.alpha_error_max == 2 * math.pi / 4096 * _ROUNDING_PAD * 0.5
    assert m.alpha_dot_error_max == 2 * math.pi / 4096 * _ROUNDING_PAD / T
    assert m.delay_s == 0.003 + 0.002 + T / 2  # sensing delay, actuation delay, the difference's lag T/2
    played = measurement_errors_of(RunConfig(sensing=Sensing(encoder_ticks=8000, encoder_side="motor"),
                                             transmission=Transmission(backlash=0.005)), C80)
    assert not played.covered and "the play's stop is soft" in str(played.why_not)
    assert played.alpha_error_max == pytest.approx(0.005 + math.pi / 8000 / C80.i2, rel=1e-8)
    assert measurement_errors_of(RunConfig(), C80).is_exact
