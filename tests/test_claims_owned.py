"""Each law owns its claim (issue 41 item 3): the sampled-data certificate is the law's, chosen by its class, not by
its name; a subclass gets its parent's; a plug-in cannot take a built-in's name.

Independent truths: the built-in law's own certificate at the same numbers (a subclass that changes nothing of the
law must be judged as the law), and the registry's list of built-in names.
"""

from __future__ import annotations

import pytest

from tests.helpers import one_error_line
from wmr_mj.analysis.measurement import MeasurementErrors
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.sim.certify import certificate_for
from wmr_mj.sim.config import RunConfig, build_reference, estimate_parameters
from wmr_mj.sim.parts import resolve_run

#: the sliding-mode parameters where the sampled layer certifies on the 12-bit axis encoder (test_sliding_sampled.py)
CERTIFYING = {"lam": 20.0, "phi": 6.0, "k": 24.0}
BASE = dict(model="nonholonomic", path="paper-circle", m1=750.0, reference_bounds="paper", duration=35.0,
            sensing="magnetic-12bit-axis", controller_params=CERTIFYING)

PLUG_INS = '''
from controllers.sliding_mode import SlidingMode
from controllers.computed_torque import ComputedTorque

class MySMC(SlidingMode):
    name = "my-smc"

class MyCT(ComputedTorque):
    name = "my-ct"

    @classmethod
    def from_context(cls, context, **params):
        return cls(context.model, kp=context.kp, kd=context.kd, **params)

class Impostor(SlidingMode):
    name = "sliding-mode"

class Inherits(SlidingMode):
    """Takes sliding mode's name by not naming itself."""
'''


@pytest.fixture
def plug_ins(tmp_path):
    path = tmp_path / "my_laws.py"
    path.write_text(PLUG_INS)
    return path


def test_a_subclass_gets_its_parents_sampled_data_claim_on_the_12bit_cart(plug_ins):
    """Truth: the built-in at the same numbers; on main the plug-in got its boundary layer alone, uncertified
    (E_max 0.397 rad) where the built-in is certified by the sampled-data certificate (0.0526 rad)."""
    builtin = resolve_run(RunConfig(controller="sliding-mode", **BASE)).claim
    mine = resolve_run(RunConfig(controller=f"{plug_ins}:MySMC", **BASE)).claim
    assert builtin.certified and builtin.inputs["certificate"] == "sampled-data"
    assert mine.certified and mine.inputs["certificate"] == "sampled-data"
    assert mine.E_max == builtin.E_max and mine.Edot_max == builtin.Edot_max
    assert mine.inputs["certificates"] == builtin.inputs["certificates"]
    assert mine.inputs["controller"] == "my-smc"


def test_a_computed_torque_subclass_gets_the_sampled_data_certificate_too(plug_ins):
    base = {**BASE, "model": "paper", "controller_params": {}, "kp": 100.0, "kd": 20.0}
    builtin = resolve_run(RunConfig(controller="computed-torque", **{k: v for k, v in base.items()
                                                                     if k != "controller_params"})).claim
    mine = resolve_run(RunConfig(controller=f"{plug_ins}:MyCT", **base)).claim
    assert "certificates" in builtin.inputs and "sampled-data" in builtin.inputs["certificates"]
    assert mine.inputs["certificate"] == builtin.inputs["certificate"]
    assert mine.inputs["certificates"] == builtin.inputs["certificates"]
    assert mine.E_max == builtin.E_max


@pytest.mark.parametrize("cls", ["Impostor", "Inherits"])
def test_a_plug_in_cannot_take_a_built_ins_name(plug_ins, cls):
    # refused where the plug-in is imported: the coercer (a config's construction imports nothing)
    with pytest.raises(ParameterError, match="takes the built-in name 'sliding-mode'"):
        RunConfig.from_inputs(controller=f"{plug_ins}:{cls}", **BASE)
    with pytest.raises(ParameterError, match="takes the built-in name 'sliding-mode'"):
        resolve_run(RunConfig(controller=f"{plug_ins}:{cls}", **BASE))


def test_a_plug_in_object_with_a_built_ins_name_is_refused(plug_ins):
    from controllers.sliding_mode import SlidingMode
    from wmr_mj import C80
    from wmr_mj.plant.reduced import steering_model

    class Impostor(SlidingMode):
        name = "sliding-mode"

    law = Impostor(steering_model("nonholonomic", C80))
    with pytest.raises(ParameterError, match="takes the built-in name"):
        resolve_run(RunConfig(controller=law, path="paper-circle", duration=10.0, model="nonholonomic"))
    builtin = SlidingMode(steering_model("nonholonomic", C80))  # the built-in's own class, as an object: its name
    resolve_run(RunConfig(controller=builtin, path="paper-circle", duration=10.0, model="nonholonomic"))


def test_the_cli_refuses_a_plug_in_with_a_built_ins_name_in_one_line_exit_2(plug_ins, capsys):
    assert main(["run", "--controller", f"{plug_ins}:Impostor", "--duration", "10", "--no-log"]) == 2
    line = one_error_line(capsys)
    assert "takes the built-in name 'sliding-mode'" in line and "name = " in line


#: section 4's keys: the gains of (4.14), (4.18), the condition (4.23) and the terms of delta1
SECTION_4_KEYS = ("condition", "gamma1", "gamma2", "delta1", "delta2", "delta3", "friction_term", "gyro_term", "K_term",
                  "P_term", "C_V_term", "gyro_Edot_term", "dead_band", "kp", "kd", "friction_width", "friction_sign",
                  "regime")


def test_each_claimant_writes_only_its_own_terms():
    """The sampled-data certificate (the certified design on the 12-bit cart) and sliding mode's boundary
    layer write none of section 4's keys (on main: kp 0.0, kd 0.0, friction_sign 'none' beside the law's K_P);
    section 4's certificate writes all of them, with the law's gains."""
    from wmr_mj.sim.designs import CERTIFIED

    design = RunConfig(**CERTIFIED.config_changes()).replace(m1=750.0, reference_bounds="paper", duration=12.0)
    sampled = resolve_run(design.replace(sensing="magnetic-12bit-axis")).claim
    assert sampled.inputs["certificate"] == "sampled-data"
    out = sampled.to_dict()
    assert not set(SECTION_4_KEYS) & set(out), sorted(set(SECTION_4_KEYS) & set(out))
    assert out["inputs"]["kp"] == design.kp and "terms" in out["inputs"]  # its own record: the gains, its terms
    exact = MeasurementErrors.exact()  # the what-if 'exact measurement': the law's continuous claim alone
    reference = build_reference(design.path, estimate_parameters(), dt=1e-3, duration=design.duration)[0]
    layer = certificate_for(RunConfig(controller="sliding-mode", **{**BASE, "sensing": "ideal"}), reference,
                            measurement=exact)
    assert layer.analysis == "boundary-layer" and not set(SECTION_4_KEYS) & set(layer.to_dict())
    section4 = certificate_for(design, reference, measurement=exact)
    out = section4.to_dict()
    assert section4.analysis == "section-4" and set(SECTION_4_KEYS) <= set(out)
    assert out["kp"] == design.kp and out["kd"] == design.kd
