"""``--param k_b`` (or ``k_i``) that leaves k_b different from k_i is refused in one line, exit status 2, as a cart
file giving them different is (wmr_mj/carts/cartfile.py): MuJoCo's dcmotor has one motor constant, so the plant
would silently run with their geometric mean while the analysis used each. Given equal, they are accepted and the
run's numbers are those of a cart file with that constant (the independent truth: the same numbers through
``--cart``)."""

from __future__ import annotations

import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR
from wmr_mj.sim.config import RunConfig, plant_parameters

RUN = ["run", "--duration", "10", "--no-log"]


@pytest.mark.parametrize("params, k_b, k_i", [(["k_b=0.09"], 0.09, 0.0795), (["k_i=0.09"], 0.0795, 0.09),
                                              (["k_i=0.09", "k_b=0.091"], 0.091, 0.09)])
def test_different_motor_constants_are_one_line_and_exit_2(params, k_b, k_i, capsys):
    argv = [*RUN, *(w for p in params for w in ("--param", p))]
    line = refused_line(capsys, argv)
    assert line == (f"wmr-mj: error: --param: k_b = {k_b!r} V s/rad and k_i = {k_i!r} N m/A differ; accepted: k_b "
                    "equal to k_i (one flux in SI units; MuJoCo's dcmotor has one constant), e.g. --param "
                    f"k_i={k_i!r} --param k_b={k_i!r}")


def test_on_a_cart_the_carts_constant_is_the_one_compared(capsys):
    """c80-magmotor's k_i = k_b = 0.1270...: --param k_b=0.0795 (the C80's) on it is refused, naming its k_i."""
    line = refused_line(capsys, [*RUN, "--cart", "c80-magmotor", "--param", "k_b=0.0795"])
    assert "k_i = 0.1270056445873325 N m/A differ" in line


def test_equal_motor_constants_are_accepted_and_are_a_carts(tmp_path):
    text = (CARTS_DIR / "c80.toml").read_text(encoding="utf-8")
    assert text.count("value = 0.0795\n") == 2  # k_i and k_b
    mine = tmp_path / "k.toml"
    mine.write_text(text.replace("value = 0.0795\n", "value = 0.09\n"), encoding="utf-8")
    by_param = plant_parameters(RunConfig(plant_overrides={"k_i": 0.09, "k_b": 0.09}))
    assert by_param == plant_parameters(RunConfig(cart=str(mine)))


@pytest.mark.parametrize("command", [["model", "params"], ["identify", "--duration", "5"]])
def test_model_params_and_identify_refuse_them_too(command, capsys):
    """The commands that apply --param to the parameter set directly (not through RunConfig) check it as well."""
    line = refused_line(capsys, [*command, "--param", "k_b=0.09"])
    assert "k_b = 0.09 V s/rad and k_i = 0.0795 N m/A differ" in line


def test_model_params_accepts_equal_constants(capsys):
    from wmr_mj.cli.app import main

    assert main(["model", "params", "--param", "k_i=0.09", "--param", "k_b=0.09", "--json"]) == 0
    capsys.readouterr()
