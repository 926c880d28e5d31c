"""The cart file (issue 37 items 1 and 3): the C80's file gives today's numbers to the bit, a wrong file is
one line and exit 2, a scaled cart follows the closed-form scaling, and ``wmr-mj cart check`` passes on the
C80 and fails where MuJoCo warns."""

from __future__ import annotations

import json
import struct
import tomllib
from pathlib import Path

import jsonschema
import pytest
from helpers import refused_line

from wmr_mj.carts import CARTS_DIR, SCHEMA_PATH, cart_names, load_cart, load_schema
from wmr_mj.carts.schema import SUPPORTED_KEYWORDS, resolve_ref, schema_table
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.params import (
    C80,
    C80_CART,
    M1_NOMINAL,
    M1_RANGE,
    PARAMETER_SOURCES,
    UNCERTAINTY_SOURCES,
    parameter_names,
    parameters_of_cart,
    uncertainty_ranges,
)

ROOT = Path(__file__).resolve().parents[1]

# The C80 parameter set as params.py wrote it before the cart file (main at 0577203): the independent truth; L_a
# (issue 42, the armature inductance) is 0 H, the paper's motor, which had none.
TODAY = dict(V_A=0.2, g=9.81, m1=650.0, chassis_length=1.75, chassis_width=0.85, chassis_height=0.30,
             chassis_inertia_mass=650.0, l1=0.612, l2=0.30, l3=0.142, l4=0.25, rear_axle_mass=40.0,
             rear_wheel_mass=10.0, r2=0.15, rear_wheel_width=0.08, i1=20.0, front_axle_mass=14.0,
             front_wheel_mass=8.0, r3=0.10, front_wheel_width=0.06, R_a=1.0, L_a=0.0, k_i=0.0795, k_b=0.0795, i2=60.0,
             voltage_limit=24.0, steering_range=0.9, mu=0.0172, f2=0.0005, f3=0.0005, ground_friction=1.0)
TODAY_FULL_BOX = {"m1": (550.0, 750.0), "mu": (0.0129, 0.0215), "ground_friction": (0.6, 1.0), "R_a": (1.0, 1.3),
                  "V_A": (0.15, 0.25)}


def _bits(x: float) -> bytes:
    return struct.pack("<d", x)


# -- a TOML writer for the tests' carts (the standard library reads TOML but does not write it) -----------------
def _toml_value(value: object) -> str:
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return repr(value)  # float or int: repr round-trips the double


def _toml(document: dict, path: tuple[str, ...] = ()) -> str:
    lines = []
    scalars = {k: v for k, v in document.items() if not isinstance(v, dict)}
    if scalars and path:
        lines.append(f"[{'.'.join(path)}]")
    lines += [f"{k} = {_toml_value(v)}" for k, v in scalars.items()]
    for key, value in document.items():
        if isinstance(value, dict):
            lines.append(_toml(value, (*path, key)))
    return "\n".join(lines)


def _c80_document() -> dict:
    with (CARTS_DIR / "c80.toml").open("rb") as f:
        return tomllib.load(f)


def _write(tmp_path: Path, document: dict, name: str = "cart.toml") -> Path:
    path = tmp_path / name
    path.write_text(_toml(document) + "\n", encoding="utf-8")
    return path


# -- the C80 to the bit ---------------------------------------------------------------------------------------
def test_c80_file_gives_todays_parameter_set_bit_for_bit():
    from_file = parameters_of_cart(load_cart("c80")).to_dict()
    for params in (from_file, C80.to_dict()):
        assert list(params) == list(TODAY)
        for name, value in TODAY.items():
            assert type(params[name]) is float and _bits(params[name]) == _bits(value), name
    assert _bits(M1_NOMINAL) == _bits(650.0)
    assert M1_RANGE == (550.0, 750.0) and all(type(x) is float for x in M1_RANGE)
    assert uncertainty_ranges("m1") == {"m1": (550.0, 750.0)}
    full = uncertainty_ranges("full")
    assert list(full) == list(TODAY_FULL_BOX)  # the order: the falsifier's search dimensions follow it
    assert all(_bits(a) == _bits(b) for k in full for a, b in zip(full[k], TODAY_FULL_BOX[k]))


def test_c80_sources_are_the_model_cards():
    """models/README.md was rendered from params.py's source texts before the file: every one is still there."""
    card = (ROOT / "models" / "README.md").read_text(encoding="utf-8")
    for name in parameter_names():
        assert f"| {PARAMETER_SOURCES[name]} |" in card, name
    assert list(UNCERTAINTY_SOURCES) == list(TODAY_FULL_BOX)
    assert UNCERTAINTY_SOURCES["m1"] == "(5.1): chassis mass 550-750 kg"


def test_c80_file_found_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    cart = load_cart("c80")
    assert cart.path == CARTS_DIR / "c80.toml" and cart_names() == ("c80", "c80-magmotor")
    assert cart.parameters == C80_CART.parameters


def test_c80_file_carries_version_changelog_units_and_sections():
    cart = C80_CART
    assert cart.name == "C80" and cart.changelog[0].startswith(cart.version)
    assert set(cart.parameters) == set(parameter_names())
    assert cart.units["steering_range"] == "rad" and cart.units["m1"] == "kg" and cart.units["k_b"] == "V s/rad"
    assert set(cart.sections) == {"operation", "chassis", "wheels", "steering_axle", "motor", "supply"}
    assert cart.defaults == {"sensing": "ideal", "actuation": "ideal", "backlash": 0.0}


# -- the schema -----------------------------------------------------------------------------------------------
def _schema_keywords(schema: object, out: set[str]) -> set[str]:
    """Every keyword used in ``schema`` (the names under properties and $defs are not keywords)."""
    if isinstance(schema, dict):
        for key, value in schema.items():
            if key in ("properties", "$defs"):
                for sub in value.values():
                    _schema_keywords(sub, out)
            else:
                out.add(key)
                _schema_keywords(value, out)
    elif isinstance(schema, list):
        for item in schema:
            _schema_keywords(item, out)
    return out


def test_schema_uses_only_the_keywords_the_checks_enforce():
    jsonschema.Draft202012Validator.check_schema(load_schema())
    used = _schema_keywords(load_schema(), set())
    assert used <= SUPPORTED_KEYWORDS, used - SUPPORTED_KEYWORDS


def test_schema_names_every_parameter_once_with_its_unit():
    schema = load_schema()
    names = [n for s in C80_CART.sections for n in schema["properties"][s]["properties"]]
    assert sorted(names) == sorted(parameter_names())
    for section, params in C80_CART.sections.items():
        for name in params:
            entry = resolve_ref(schema["properties"][section]["properties"][name], schema)
            assert entry["properties"]["unit"]["const"] == C80_CART.units[name]


def test_jsonschema_accepts_the_c80_file():
    jsonschema.Draft202012Validator(load_schema()).validate(_c80_document())


def test_schema_is_published_in_the_docs():
    """docs/reference/cart.md carries the table rendered from the schema, every parameter in it."""
    page = (ROOT / "docs" / "reference" / "cart.md").read_text(encoding="utf-8")
    table = page.split("<!-- schema-table: start -->\n")[1].split("<!-- schema-table: end -->")[0]
    assert table == schema_table()
    for section, names in C80_CART.sections.items():
        for name in names:
            assert f"| `{section}.{name}` | {C80_CART.units[name]} |" in table, name
    assert json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))["title"] in page


# -- a wrong file: one line, exit 2 -----------------------------------------------------------------------------
def _missing_key(d):
    del d["chassis"]["l1"]


def _unknown_key(d):
    d["chassis"]["wheelbase"] = {"value": 0.612, "unit": "m", "source": "a typo of l1"}


def _negative_mass(d):
    d["chassis"]["m1"]["value"] = -650.0


def _stop_beyond_half_pi(d):
    d["supply"]["steering_range"]["value"] = 2.0


def _zero_wheelbase(d):
    d["chassis"]["l1"]["value"] = 0.0


def _degrees(d):
    d["supply"]["steering_range"]["value"] = 51.6
    d["supply"]["steering_range"]["unit"] = "deg"


def _text_for_number(d):
    d["motor"]["i2"]["value"] = "60"


# (mutation, what the one line must say): the key, the value, the unit, what is accepted
SCHEMA_CASES = {
    "missing key": (_missing_key, ["chassis.l1 is missing", "wheelbase", "required in [chassis]", "l1"]),
    "unknown key": (_unknown_key, ["chassis.wheelbase", "is not a known key", "accepted in [chassis]: m1,"]),
    "negative mass": (_negative_mass, ["chassis.m1.value = -650.0 kg is not accepted", "accepted: a number > 0 kg"]),
    "stop beyond pi/2": (_stop_beyond_half_pi, ["supply.steering_range.value = 2.0 rad is not accepted",
                                                "accepted: a number > 0 and < pi/2 rad"]),
    "zero wheelbase": (_zero_wheelbase, ["chassis.l1.value = 0.0 m is not accepted", "accepted: a number > 0 m"]),
    "degrees": (_degrees, ["supply.steering_range.unit = 'deg' is not accepted", "accepted: 'rad' only",
                           "SI units"]),
    "text for a number": (_text_for_number, ["motor.i2.value = '60' is not accepted", "accepted: a number > 0"]),
}



@pytest.mark.parametrize("case", list(SCHEMA_CASES))
def test_wrong_file_is_one_line_and_exit_2(case, tmp_path, capsys):
    mutate, expected = SCHEMA_CASES[case]
    document = _c80_document()
    mutate(document)
    path = _write(tmp_path, document)
    line = refused_line(capsys, ["cart", "check", str(path)])
    assert line.startswith(f"wmr-mj: error: cart file {str(path)!r}: ")
    for text in expected:
        assert text in line, (text, line)
    # the second method: jsonschema refuses the same file with the same schema
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.Draft202012Validator(load_schema()).validate(document)


def _centre_behind_rear_axle_rule(d):
    d["chassis"]["l3"]["value"] = 0.7


def _range_upside_down(d):
    d["uncertainty"]["full"]["mu"]["range"] = [0.0215, 0.0129]


def _changelog_of_another_version(d):
    d["version"] = "1.2.0"


def _two_motor_constants(d):
    d["motor"]["k_b"]["value"] = 0.08745


def _unknown_sensing(d):
    d["defaults"]["sensing"]["value"] = "laser-99bit"


RULE_CASES = {
    "l3 beyond l1": (_centre_behind_rear_axle_rule, ["chassis.l3.value = 0.7 m", "below the wheelbase",
                                                    "chassis.l1.value = 0.612 m"]),
    "lo above hi": (_range_upside_down, ["uncertainty.full.mu.range = [0.0215, 0.0129]", "lo < hi"]),
    "changelog": (_changelog_of_another_version, ["changelog[0]", "beginning with the version '1.2.0'"]),
    "k_b other than k_i": (_two_motor_constants, ["motor.k_b.value = 0.08745 V s/rad is not accepted",
                                                  "equal to motor.k_i.value = 0.0795 N m/A"]),
    "sensing preset": (_unknown_sensing, ["defaults.sensing.value = 'laser-99bit'", "magnetic-12bit-axis"]),
}


@pytest.mark.parametrize("case", list(RULE_CASES))
def test_rules_beside_the_schema_are_one_line_and_exit_2(case, tmp_path, capsys):
    mutate, expected = RULE_CASES[case]
    document = _c80_document()
    mutate(document)
    line = refused_line(capsys, ["cart", "check", str(_write(tmp_path, document))])
    for text in expected:
        assert text in line, (text, line)


def test_unreadable_files_are_one_line_and_exit_2(tmp_path, capsys):
    line = refused_line(capsys, ["cart", "check", str(tmp_path / "nope.toml")])
    assert "is neither a file nor a shipped cart" in line and "c80" in line
    bad = tmp_path / "bad.toml"
    bad.write_text("name = \n", encoding="utf-8")
    assert "is not valid TOML" in refused_line(capsys, ["cart", "check", str(bad)])


def test_load_cart_raises_parameter_error():
    with pytest.raises(ParameterError, match="neither a file nor a shipped cart"):
        load_cart("c81")


# -- a scaled cart follows the closed-form scaling -----------------------------------------------------------
MASS, LENGTH, RESISTANCE, MOTOR_CONSTANT = 1.5, 1.2, 1.3, 1.1


def _scaled_document() -> dict:
    """The C80 with every mass x MASS, every length x LENGTH (the units in the file say which), R_a x RESISTANCE
    and k_i = k_b x MOTOR_CONSTANT; speeds, ratios, angles, the supply and gravity unchanged."""
    document = _c80_document()
    for section in C80_CART.sections:
        for entry in document[section].values():
            entry["value"] *= {"kg": MASS, "m": LENGTH}.get(entry["unit"], 1.0)
    document["motor"]["R_a"]["value"] *= RESISTANCE
    document["motor"]["k_i"]["value"] *= MOTOR_CONSTANT
    document["motor"]["k_b"]["value"] *= MOTOR_CONSTANT
    for box in document["uncertainty"].values():
        box["m1"]["range"] = [MASS * x for x in box["m1"]["range"]]
    document["name"] = "C80 scaled"
    return document


def test_scaled_cart_coefficients_follow_the_closed_form_scaling(tmp_path):
    """(2.13): P = (R_a/k_i) 2D/i2 with D a mass times a length squared; C_V = k_b i2; F = (R_a/k_i)
    (l3 l4/l1) mu Q / i2; K = (R_a/k_i) 2 B V_A^2/i2 with B a mass (lengths cancel); gyro = P / l1."""
    cart = load_cart(_write(tmp_path, _scaled_document()))
    scaled = parameters_of_cart(cart)
    assert scaled.m1 == MASS * 650.0 and scaled.l1 == LENGTH * 0.612
    per_volt = RESISTANCE / MOTOR_CONSTANT  # R_a / k_i
    factor = {"P": MASS * LENGTH**2 * per_volt, "C_V": MOTOR_CONSTANT, "F": MASS * LENGTH * per_volt,
              "K": MASS * per_volt}
    for model in ("paper", "nonholonomic"):
        base, new = C80.coefficients(model), scaled.coefficients(model)
        for name, f in factor.items():
            # a few dozen roundings of doubles: relative 1e-12 is far above them and far below any slip
            assert getattr(new, name) == pytest.approx(f * getattr(base, name), rel=1e-12, abs=0.0), (model, name)
    assert scaled.coefficients("nonholonomic").gyro == pytest.approx(
        MASS * LENGTH * per_volt * C80.coefficients("nonholonomic").gyro, rel=1e-12)


# -- cart check ---------------------------------------------------------------------------------------------
# about 1 s each on the 2-core machine (1 s stepped, 20 s identified): not 'slow'
@pytest.mark.parametrize("name", cart_names())
def test_every_shipped_cart_passes_cart_check(name, capsys):
    cart = load_cart(name)
    assert main(["cart", "check", name]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"cart {cart.name} {cart.version} ({CARTS_DIR / f'{name}.toml'}): passes: ")
    assert "no MuJoCo warning" in out[0]
    assert out[1].startswith("certified design on this cart: ")  # its second line (tests/test_cart_commands.py)
    assert out[2].startswith("design certifies it: ")  # its third line (tests/test_cart_check_design.py)
    assert out[4].startswith("steps: 1000 steps (1 s)") and "0 MuJoCo warnings" in out[4]


def test_cart_check_passes_on_a_scaled_cart_json(tmp_path, capsys):
    """The identification follows the file, not the C80: the scaled cart's implied P is 2.5 times the C80's."""
    path = _write(tmp_path, _scaled_document())
    assert main(["cart", "check", str(path), "--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert obj["passed"] and obj["steps"]["warnings"] == {} and obj["identification"]["mujoco_warnings"] == 0
    rows = obj["identification"]["coefficients"]
    factor = MASS * LENGTH**2 * RESISTANCE / MOTOR_CONSTANT
    assert rows["P"]["implied"] == pytest.approx(factor * C80.coefficients().P, rel=1e-12)
    for name, row in rows.items():
        assert abs(row["identified"] - row["implied"]) <= row["allowed"], name


def test_cart_check_fails_where_mujoco_warns(tmp_path, capsys):
    """A 1 GV supply on a 1 uOhm armature: the random voltages make the steering's acceleration blow up."""
    document = _c80_document()
    document["supply"]["voltage_limit"]["value"] = 1e9
    document["motor"]["R_a"]["value"] = 1e-6
    assert main(["cart", "check", str(_write(tmp_path, document))]) == 1
    first = capsys.readouterr().out.splitlines()[0]
    assert ": FAILS: 1 s of random controls: mjWARN_BADQACC x" in first
