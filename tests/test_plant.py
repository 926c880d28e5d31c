"""The compiled C80 model equals its parameter set, and the scene runs clean."""

from __future__ import annotations

import math
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from wmr_mj import C80, ModelFileError, ParameterError, UnknownNameError, with_params
from wmr_mj.plant.mjcf import (
    MODELS_DIR,
    STEERING_FRICTION_MODELS,
    TYRE_CONTACT_MODELS,
    Plant,
    compile_model,
    load_model_file,
    robot_spec,
    robot_xml,
    scene_file_xml,
    scene_spec,
    scene_xml,
)


def _mass_and_inertia_about(model, data, body_names, point, axis):
    """Total mass and inertia of bodies about a world axis through point (parallel axis theorem)."""
    mass, inertia = 0.0, 0.0
    for name in body_names:
        b = model.body(name).id
        m = model.body_mass[b]
        R = data.ximat[b].reshape(3, 3)
        I_world = R @ np.diag(model.body_inertia[b]) @ R.T
        r = data.xipos[b] - point
        r_perp = r - axis * (r @ axis)
        mass += m
        inertia += axis @ I_world @ axis + m * (r_perp @ r_perp)
    return mass, inertia


@pytest.mark.parametrize("params", [C80, with_params(C80, m1=550.0), with_params(C80, m1=750.0, m1_inertia="scale"),
                                    with_params(C80, l4=0.3, r3=0.12, mu=0.03, i2=45.0)])
def test_compiled_model_equals_parameter_set(params):
    model, _ = compile_model(params)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    z = np.array([0.0, 0.0, 1.0])
    # masses
    # every number enters the MJCF with 6 significant digits: relative error <= 5e-6
    rel = 5e-6
    assert model.body("chassis").mass[0] == pytest.approx(params.m1, rel=rel)
    rear = ["drive_unit", "rear_left_wheel", "rear_right_wheel"]
    front = ["steering_unit", "front_left_wheel", "front_right_wheel"]
    assert sum(model.body(n).mass[0] for n in rear) == pytest.approx(params.m2, rel=rel)
    assert sum(model.body(n).mass[0] for n in front) == pytest.approx(params.m3, rel=rel)
    # chassis inertia and CoM
    assert np.allclose(model.body("chassis").inertia, params.chassis_inertia, rtol=rel)
    assert np.allclose(data.xipos[model.body("chassis").id][:2], [params.l3, 0.0])
    # steering unit yaw inertia about the pivot, computed from the compiled bodies
    pivot = data.xanchor[model.joint("steer").id]
    _, J_yaw = _mass_and_inertia_about(model, data, front, pivot, z)
    assert J_yaw == pytest.approx(params.steering_yaw_inertia, rel=rel)
    # wheel spin inertia and radii
    assert model.body("front_left_wheel").inertia[1] == pytest.approx(params.I_y3, rel=rel)
    assert model.body("rear_left_wheel").inertia[1] == pytest.approx(params.I_y2, rel=rel)
    assert model.geom("front_left_contact").size[0] == pytest.approx(params.r3, rel=rel)
    assert model.geom("rear_left_contact").size[0] == pytest.approx(params.r2, rel=rel)
    # geometry: wheelbase and tracks
    A = data.site_xpos[model.site("A").id]
    C = data.site_xpos[model.site("C").id]
    assert np.linalg.norm((C - A)[:2]) == pytest.approx(params.l1, rel=rel)
    for side, half in (("rear_left", params.l2), ("front_left", params.l4)):
        y = data.xpos[model.body(f"{side}_wheel").id][1]
        assert y == pytest.approx(half, rel=rel)
    # motor, gear, friction, limits
    act = model.actuator("steering_motor").id
    assert model.actuator_gear[act][0] == pytest.approx(params.i2, rel=rel)
    assert model.actuator_dyntype[act] == mujoco.mjtDyn.mjDYN_DCMOTOR
    assert np.allclose(model.actuator_ctrlrange[act], [-params.voltage_limit, params.voltage_limit])
    j = model.joint("steer").id
    assert model.dof_frictionloss[model.jnt_dofadr[j]] == pytest.approx(
        params.l3 * params.l4 / params.l1 * params.mu * params.Q, rel=rel)
    assert np.allclose(model.jnt_range[j], [-params.steering_range, params.steering_range], rtol=rel)
    assert model.opt.timestep == 1e-3


def _model_arrays(model: mujoco.MjModel) -> dict[str, object]:
    """Every array and scalar of an MjModel and its options, by name."""
    out = {}
    for owner, prefix in ((model, ""), (model.opt, "opt.")):
        for name in dir(owner):
            if name.startswith("_"):
                continue
            try:
                value = getattr(owner, name)
            except Exception:  # noqa: BLE001  (some properties need a context)
                continue
            if isinstance(value, (np.ndarray, int, float)):
                out[prefix + name] = value
    return out


def _differing(a: mujoco.MjModel, b: mujoco.MjModel) -> list[str]:
    fa, fb = _model_arrays(a), _model_arrays(b)
    assert fa.keys() == fb.keys()
    return [k for k in fa if not np.array_equal(fa[k], fb[k])]


@pytest.mark.parametrize("steering_friction", STEERING_FRICTION_MODELS)
@pytest.mark.parametrize("params", [C80, with_params(C80, m1=613.7, mu=0.0213, l1=0.6531)])
def test_mjspec_xml_round_trips(params, steering_friction):
    """The model compiled from the written XML is the one compiled from the MjSpec, field for field."""
    from_spec = scene_spec(params, steering_friction=steering_friction).compile()
    from_xml, xml = compile_model(params, steering_friction=steering_friction)
    assert xml == scene_xml(params, steering_friction=steering_friction)
    assert _differing(from_spec, from_xml) == []
    assert _differing(robot_spec(params).compile(), mujoco.MjModel.from_xml_string(robot_xml(params))) == []
    # the first of the mass changes is visible (the test can fail)
    assert _differing(from_xml, compile_model(C80 if params is not C80 else with_params(C80, m1=651.0))[0])


def test_scene_file_with_include_compiles_to_the_simulated_model(tmp_path):
    """models/scene.xml (which includes c80.xml) == the one-string scene that runs simulate."""
    (tmp_path / "c80.xml").write_text(robot_xml(C80))
    (tmp_path / "scene.xml").write_text(scene_file_xml(C80))
    assert _differing(load_model_file(tmp_path / "scene.xml"), compile_model(C80)[0]) == []


def _significant_digits(text: str) -> dict[str, int]:
    """Every number in the attribute values of an XML text -> its count of significant digits."""
    import re

    numbers = re.findall(r'(?<=[" ])-?\d+\.?\d*(?:e[-+]?\d+)?(?=[" ])', text)
    return {n: len(n.lstrip("-").split("e")[0].replace(".", "").lstrip("0").rstrip("0") or "0") for n in numbers}


def test_xml_numbers_have_at_most_7_significant_digits():
    # the check sees the old f-string model's 17-digit numbers
    assert max(_significant_digits('diaginertia="44.01041666666666 170.76 205.021"').values()) == 16
    params = with_params(C80, m1=613.7, mu=0.0213, l1=0.6531)  # numbers with long expansions
    for text in (robot_xml(params), scene_file_xml(params), scene_xml(params, steering_friction="soft")):
        digits = _significant_digits(text)
        assert len(digits) > 10  # distinct numbers
        assert max(digits.values()) <= 7, {n: k for n, k in digits.items() if k > 7}


def test_names_other_code_uses_are_in_the_model():
    model, _ = compile_model(C80)
    for kind, names in {
        "body": ("chassis", "drive_unit", "steering_unit", "rear_left_wheel", "rear_right_wheel", "front_left_wheel",
                 "front_right_wheel"),
        "joint": ("chassis_free", "steer", "rear_left_spin", "rear_right_spin", "front_left_spin", "front_right_spin"),
        "site": ("A", "C"),
        "actuator": ("steering_motor", "drive"),
        "tendon": ("differential",),
        "sensor": ("steer_angle", "steer_rate", "steer_motor_torque", "steer_joint_torque", "A_pos", "C_pos",
                   "chassis_quat", "A_vel"),
        "key": ("home",),
    }.items():
        for name in names:
            getattr(model, kind)(name)  # raises KeyError when missing
    assert model.actuator_trntype[model.actuator("drive").id] == mujoco.mjtTrn.mjTRN_TENDON
    assert model.actuator_dyntype[model.actuator("steering_motor").id] == mujoco.mjtDyn.mjDYN_DCMOTOR
    xml = robot_xml(C80)
    for cls in ("wheel", "steer", "visual", "collision"):
        assert f'<default class="{cls}">' in xml
    assert xml.index("<default>") < xml.index("<worldbody>")


@pytest.mark.parametrize("name,option", [("steering_friction", "bogus"), ("tyre_contact", "rubber")])
def test_unknown_friction_or_contact_model_is_an_unknown_name(name, option):
    with pytest.raises(UnknownNameError, match="valid") as info:
        Plant(C80, **{name: option})
    valid = STEERING_FRICTION_MODELS if name == "steering_friction" else TYRE_CONTACT_MODELS
    assert all(v in str(info.value) for v in valid)
    with pytest.raises(UnknownNameError):
        compile_model(C80, **{name: option})


def test_friction_models_differ_only_in_the_steering_joints_solver_parameters():
    stiff, _ = compile_model(C80, steering_friction="stiction")
    soft, _ = compile_model(C80, steering_friction="soft")
    assert sorted(_differing(stiff, soft)) == ["dof_solimp", "dof_solref"]
    dof = stiff.jnt_dofadr[stiff.joint("steer").id]
    changed = np.flatnonzero(np.any(stiff.dof_solref != soft.dof_solref, axis=1))
    assert changed.tolist() == [dof]


def test_dcmotor_torque_is_equation_2_9():
    """Joint torque = i2 k_i (u - k_b i2 alpha')/R_a, checked against MuJoCo's actuator output."""
    plant = Plant(C80)
    m, d = plant.model, plant.data
    rng = np.random.default_rng(0)
    for _ in range(5):
        u = rng.uniform(-20, 20)
        d.ctrl[plant.steer_actuator] = u
        for _ in range(50):
            mujoco.mj_step(m, d)
        mujoco.mj_forward(m, d)
        rate = d.qvel[plant.steer_dof]
        expected = C80.i2 * C80.k_i * (u - C80.k_b * C80.i2 * rate) / C80.R_a
        # MuJoCo's actuator force at the state it stepped to, against (2.9) at that same state: the
        # arithmetic of its gain and bias terms, rounding only (no integration error enters)
        assert plant.steer_torque() == pytest.approx(expected, rel=1e-9)
        assert plant.motor_current() == pytest.approx((u - C80.k_b * C80.i2 * rate) / C80.R_a, rel=1e-9)


def test_committed_model_files_match_parameter_set():
    assert (MODELS_DIR / "c80.xml").read_text() == robot_xml(C80), "run: wmr-mj model write"
    assert (MODELS_DIR / "scene.xml").read_text() == scene_file_xml(C80), "run: wmr-mj model write"


def test_scene_file_compiles_and_has_home_keyframe():
    model = load_model_file(MODELS_DIR / "scene.xml")
    assert model.key("home").id == 0
    assert model.geom("floor").id >= 0


@pytest.mark.slow
def test_scene_drives_circle_for_60_s_without_warnings():
    """Hold the steady-circle steering angle with a PD on the dcmotor for 60 s; no MuJoCo warning."""
    plant = Plant(C80)
    m, d = plant.model, plant.data
    alpha_ss = math.asin(C80.l1 / 1.0)
    for _ in range(60_000):
        a, ad = d.qpos[plant.steer_qpos], d.qvel[plant.steer_dof]
        d.ctrl[plant.steer_actuator] = np.clip(80.0 * (alpha_ss - a) - 5.0 * ad, -24, 24)
        mujoco.mj_step(m, d)
    assert all(w.number == 0 for w in d.warning), [(i, w.number) for i, w in enumerate(d.warning) if w.number]
    assert np.all(np.isfinite(d.qpos))
    # point C ran on a circle of radius close to l1/sin(alpha) (PD leaves a small offset)
    a = d.qpos[plant.steer_qpos]
    assert abs(a - alpha_ss) < 0.05


def test_bad_model_file_is_one_line(tmp_path):
    with pytest.raises(ModelFileError, match="does not exist"):
        load_model_file(tmp_path / "nope.xml")
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body><geom type='sphere'/></body>")
    with pytest.raises(ModelFileError, match="not a valid MJCF"):
        load_model_file(bad)


@pytest.mark.parametrize("changes,error", [({"m1": -1.0}, ParameterError), ({"m1": float("nan")}, ParameterError),
                                            ({"mu": 0.0}, ParameterError), ({"bogus": 1.0}, UnknownNameError)])
def test_bad_parameters_raise(changes, error):
    with pytest.raises(error):
        with_params(C80, **changes)


@pytest.mark.slow
@pytest.mark.parametrize("argv,needle", [
    (["model", "params", "--param", "m1=-5"], "m1"),
    (["model", "params", "--param", "m1=inf"], "m1"),
    (["model", "params", "--param", "wheelbase=1"], "valid parameters"),
    (["model", "params", "--param", "m1"], "NAME=VALUE"),
])
def test_cli_bad_parameter_exits_2_with_one_line(argv, needle):
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", *argv], capture_output=True, text=True)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr


def test_wheels_roll_without_side_slip_at_paper_speed():
    """On the 1 m circle at 0.2 m/s the contact points slide sideways by < 1% of V_A."""
    from wmr_mj.plant.mjcf import measure_side_slip

    slip = measure_side_slip(C80, duration=15.0, settle=8.0)
    assert abs(slip["alpha"] - slip["alpha_target"]) < 0.02  # it was on the circle
    assert slip["max_slip_fraction"] < 0.01
    assert slip["max_slip_m_s"] > 0.0  # soft contacts do slip a little: the measurement is live


@pytest.mark.slow
def test_model_card_is_a_fresh_rendering():
    from wmr_mj.plant.modelcard import render_model_card

    assert (MODELS_DIR / "README.md").read_text() == render_model_card(C80), "run: wmr-mj model card"


@pytest.mark.parametrize("path", sorted(MODELS_DIR.glob("*.xml")), ids=lambda p: p.name)
def test_every_model_file_steps_without_warnings(path):
    """Each MJCF in models/ compiles and runs 10 s from its home keyframe with no MuJoCo warning."""
    model = load_model_file(path)
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    for _ in range(10_000):
        mujoco.mj_step(model, data)
    raised = [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number]
    assert not raised, raised
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("options", [dict(), dict(steering_friction="soft"), dict(tyre_contact="soft")])
def test_scene_xml_is_to_xml_without_the_sky_pixels(options):
    """scene_xml writes the spec with a 1x6 sky and puts the size back: to_xml's text, to the character."""
    from wmr_mj.plant import mjcf

    params = with_params(C80, m1=612.5)
    assert mjcf.scene_xml(params, **options) == mjcf.scene_spec(params, **options).to_xml()


def test_the_model_folder_has_its_picture_changelog_and_one_compiler():
    png = (MODELS_DIR / "c80.png").read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and 10_000 < len(png) < 300_000
    assert 'src="c80.png"' in (MODELS_DIR / "README.md").read_text()
    assert (MODELS_DIR / "CHANGELOG.md").read_text().startswith("# Changelog")
    scene = (MODELS_DIR / "scene.xml").read_text()
    assert "<compiler" not in scene and "<compiler" in (MODELS_DIR / "c80.xml").read_text()
    assert "physics, not rendering" in scene


@pytest.mark.slow
def test_model_image_renders_the_home_keyframe_or_says_why(tmp_path):
    from wmr_mj.errors import NoRenderBackendError
    from wmr_mj.plant.image import IMAGE_SIZE, write_model_image

    try:
        path = write_model_image(tmp_path)
    except NoRenderBackendError as exc:
        pytest.skip(f"no offscreen OpenGL here: {exc}")
    png = path.read_bytes()
    assert png.startswith(b"\x89PNG") and int.from_bytes(png[16:20], "big") == IMAGE_SIZE[0]
    assert len(png) < 300_000
