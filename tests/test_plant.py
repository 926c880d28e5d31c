"""The compiled C80 model equals its parameter set, and the scene runs clean."""

from __future__ import annotations

import math
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from wmr_mj import C80, ModelFileError, ParameterError, UnknownNameError, with_params
from wmr_mj.plant import MODELS_DIR, Plant, compile_model, load_model_file, robot_xml, scene_file_xml


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
    assert model.body("chassis").mass[0] == params.m1
    rear = ["drive_unit", "rear_left_wheel", "rear_right_wheel"]
    front = ["steering_unit", "front_left_wheel", "front_right_wheel"]
    assert sum(model.body(n).mass[0] for n in rear) == pytest.approx(params.m2, rel=1e-12)
    assert sum(model.body(n).mass[0] for n in front) == pytest.approx(params.m3, rel=1e-12)
    # chassis inertia and CoM
    assert np.allclose(model.body("chassis").inertia, params.chassis_inertia, rtol=1e-12)
    assert np.allclose(data.xipos[model.body("chassis").id][:2], [params.l3, 0.0])
    # steering unit yaw inertia about the pivot, computed from the compiled bodies
    pivot = data.xanchor[model.joint("steer").id]
    _, J_yaw = _mass_and_inertia_about(model, data, front, pivot, z)
    assert J_yaw == pytest.approx(params.steering_yaw_inertia, rel=1e-9)
    # wheel spin inertia and radii
    assert model.body("front_left_wheel").inertia[1] == pytest.approx(params.I_y3)
    assert model.body("rear_left_wheel").inertia[1] == pytest.approx(params.I_y2)
    assert model.geom("front_left_contact").size[0] == params.r3
    assert model.geom("rear_left_contact").size[0] == params.r2
    # geometry: wheelbase and tracks
    A = data.site_xpos[model.site("A").id]
    C = data.site_xpos[model.site("C").id]
    assert np.linalg.norm((C - A)[:2]) == pytest.approx(params.l1, abs=1e-12)
    for side, half in (("rear_left", params.l2), ("front_left", params.l4)):
        y = data.xpos[model.body(f"{side}_wheel").id][1]
        assert y == pytest.approx(half, abs=1e-12)
    # motor, gear, friction, limits
    act = model.actuator("steering_motor").id
    assert model.actuator_gear[act][0] == params.i2
    assert np.allclose(model.actuator_ctrlrange[act], [-params.voltage_limit, params.voltage_limit])
    j = model.joint("steer").id
    assert model.dof_frictionloss[model.jnt_dofadr[j]] == pytest.approx(params.l3 * params.l4 / params.l1 * params.mu * params.Q)
    assert np.allclose(model.jnt_range[j], [-params.steering_range, params.steering_range])
    assert model.opt.timestep == 1e-3


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
        assert plant.steer_torque() == pytest.approx(expected, rel=1e-9)
        assert plant.motor_current() == pytest.approx((u - C80.k_b * C80.i2 * rate) / C80.R_a, rel=1e-9)


def test_committed_model_files_match_parameter_set():
    assert (MODELS_DIR / "c80.xml").read_text() == robot_xml(C80), "run: wmr-mj model write"
    assert (MODELS_DIR / "scene.xml").read_text() == scene_file_xml(C80), "run: wmr-mj model write"


def test_scene_file_compiles_and_has_home_keyframe():
    model = load_model_file(MODELS_DIR / "scene.xml")
    assert model.key("home").id == 0
    assert model.geom("floor").id >= 0


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
    from wmr_mj.plant import measure_side_slip

    slip = measure_side_slip(C80, duration=15.0, settle=8.0)
    assert abs(slip["alpha"] - slip["alpha_target"]) < 0.02  # it was on the circle
    assert slip["max_slip_fraction"] < 0.01
    assert slip["max_slip_m_s"] > 0.0  # soft contacts do slip a little: the measurement is live


def test_model_card_is_a_fresh_rendering():
    from wmr_mj.modelcard import render_model_card

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
    assert all(w.number == 0 for w in data.warning), [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number]
    assert np.all(np.isfinite(data.qpos))
