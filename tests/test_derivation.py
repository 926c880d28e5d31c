"""wmr_mj.plant.derivation: the symbolic derivation of both reduced steering models.

Checks the derived (2.2) coefficients against params' closed forms
(symbolically and numerically), the printed-departure bookkeeping, the
Lagrange-on-(2.2) equations (2.4)-(2.6), the non-holonomic (Kane) row, and
finally the non-holonomic steering equation against an independent numeric
planar multibody simulation (Newton-Euler bodies, Lagrange multipliers for
the joints and the rolling constraints; numpy/scipy only).
"""

from __future__ import annotations

import math
import random
from dataclasses import fields

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from wmr_mj import C80, with_params
from wmr_mj.errors import UnknownNameError
from wmr_mj.params import C80Parameters
from wmr_mj.plant import derivation as d
from wmr_mj.plant.reduced import steering_model

pytestmark = pytest.mark.slow  # symbolic derivations (sympy): seconds each, even cached

S = d.SYMBOLS
V, Vd, al, ad, add = S["V"], S["V_d"], S["alpha"], S["alpha_d"], S["alpha_dd"]
A_, B_, C_, D_ = sp.symbols("A B C D", positive=True)


# ---------------------------------------------------------------------------
# params evaluated with sympy symbols (its closed forms, symbolically)
# ---------------------------------------------------------------------------
def _symbolic_params():
    """An object carrying C80Parameters' properties and methods, fields as symbols."""
    attrs = {
        name: value
        for name, value in vars(C80Parameters).items()
        if isinstance(value, (property, staticmethod))
    }
    attrs["kinetic_energy_coefficients"] = C80Parameters.kinetic_energy_coefficients
    attrs["coefficients"] = C80Parameters.coefficients
    cls = type("SymbolicC80", (), attrs)
    obj = cls()
    for f in fields(C80Parameters):
        setattr(obj, f.name, sp.Symbol(f.name, positive=True))
    return obj


def _body_substitution(p) -> dict:
    """derivation's per-body symbols -> params' expressions (the same map as symbol_values)."""
    return {
        S["l1"]: p.l1, S["l2"]: p.l2, S["l3"]: p.l3, S["l4"]: p.l4, S["r2"]: p.r2, S["r3"]: p.r3,
        S["m1"]: p.m1, S["I_z1"]: p.I_z1,
        S["m_b2"]: p.rear_axle_mass, S["I_b2"]: p.rear_axle_yaw_inertia,
        S["m_w2"]: p.rear_wheel_mass, S["I_y2"]: p.I_y2, S["I_z2"]: p.I_z2,
        S["m_b3"]: p.front_axle_mass, S["I_b3"]: p.front_axle_yaw_inertia,
        S["m_w3"]: p.front_wheel_mass, S["I_y3"]: p.I_y3, S["I_z3"]: p.I_z3,
        S["mu"]: p.mu, S["Q"]: p.Q, S["R_a"]: p.R_a, S["k_i"]: p.k_i, S["k_b"]: p.k_b,
        S["i2"]: p.i2, V: p.V_A,
    }


def _exact_equal(a, b) -> bool:
    diff = sp.nsimplify(sp.sympify(a) - sp.sympify(b), rational=True)
    return sp.simplify(diff) == 0


def _random_params(seed: int) -> C80Parameters:
    rng = random.Random(seed)
    u = rng.uniform
    l1 = u(0.3, 1.5)
    return with_params(
        C80,
        V_A=u(0.05, 2.0), m1=u(100, 1500), chassis_length=u(0.5, 3.0),
        chassis_width=u(0.3, 1.5), chassis_height=u(0.1, 0.6), chassis_inertia_mass=u(100, 1500),
        l1=l1, l2=u(0.1, 0.8), l3=u(0.05, 0.95) * l1, l4=u(0.1, 0.6),
        rear_axle_mass=u(5, 80), rear_wheel_mass=u(1, 30), r2=u(0.05, 0.4),
        rear_wheel_width=u(0.02, 0.2), front_axle_mass=u(2, 40), front_wheel_mass=u(1, 20),
        r3=u(0.05, 0.3), front_wheel_width=u(0.02, 0.15), R_a=u(0.1, 5), k_i=u(0.01, 0.5),
        k_b=u(0.01, 0.5), i2=u(5, 200), mu=u(0.001, 0.1),
    )


PARAM_SETS = [C80] + [_random_params(s) for s in range(5)]


# ---------------------------------------------------------------------------
# kinematics and the kinetic energy (2.2)-(2.3)
# ---------------------------------------------------------------------------
def test_constraint_velocities():
    cv = d.constraint_velocities()
    q = {s.name: s for s in cv}
    l1, l2, l4, r2, r3 = S["l1"], S["l2"], S["l4"], S["r2"], S["r3"]
    th = q["theta"]
    assert d.is_zero(cv[q["x_A"]] - V * sp.cos(th))
    assert d.is_zero(cv[q["y_A"]] - V * sp.sin(th))
    assert d.is_zero(cv[th] - V * sp.tan(al) / l1)
    assert d.is_zero(cv[q["phi_L"]] - (V - l2 * V * sp.tan(al) / l1) / r2)
    w_c = V * sp.tan(al) / l1 + ad
    assert d.is_zero(cv[q["psi_R"]] - (V / sp.cos(al) + l4 * w_c) / r3)
    assert d.is_zero(cv[q["psi_L"]] - (V / sp.cos(al) - l4 * w_c) / r3)


def test_kinetic_energy_coefficients_match_params_closed_forms_symbolically():
    p = _symbolic_params()
    sub = _body_substitution(p)
    derived = d.paper_coefficients_symbolic()
    closed = C80Parameters.kinetic_energy_coefficients(p)
    for k in "ABCD":
        assert _exact_equal(derived[k].subs(sub), closed[k]), k
    # and the docstring form in per-body symbols
    J = d.steering_inertia_symbolic()
    assert _exact_equal(derived["C"], J / S["l1"])
    assert _exact_equal(derived["D"], J / 2)
    assert _exact_equal(J.subs(sub), p.steering_inertia)


@pytest.mark.slow
def test_voltage_coefficients_match_params_symbolically():
    p = _symbolic_params()
    sub = _body_substitution(p)
    for model in ("paper", "nonholonomic"):
        derived = d.voltage_coefficients_symbolic(model)
        closed = C80Parameters.coefficients(p, model).to_dict()
        for k, v in closed.items():
            assert _exact_equal(derived[k].subs(sub), v), (model, k)


@pytest.mark.parametrize("params", PARAM_SETS, ids=lambda p: f"l1={p.l1:.3f}")
def test_coefficients_from_derivation_numeric(params):
    ke = params.kinetic_energy_coefficients()
    ke_d = d.kinetic_energy_coefficients_from_derivation(params)
    for k in "ABCD":
        assert math.isclose(ke_d[k], ke[k], rel_tol=1e-12), k
    for model in ("paper", "nonholonomic"):
        got = d.coefficients_from_derivation(params, model).to_dict()
        want = params.coefficients(model).to_dict()
        for k in want:
            if want[k] == 0.0:
                assert got[k] == 0.0, (model, k)
            else:
                assert math.isclose(got[k], want[k], rel_tol=1e-12), (model, k, got[k], want[k])
    lag = d.coefficients_from_derivation(params, "paper-lagrange")
    ref = steering_model("paper-lagrange", params)
    assert math.isclose(lag.K, ref.K, rel_tol=1e-12) and lag.K < 0
    assert math.isclose(lag.P, ref.P, rel_tol=1e-12)


def test_unknown_model_rejected():
    with pytest.raises(UnknownNameError):
        d.coefficients_from_derivation(C80, "lagrange")
    with pytest.raises(UnknownNameError):
        d.steering_torque("nope")


# ---------------------------------------------------------------------------
# the printed (2.3) and the departures
# ---------------------------------------------------------------------------
def test_corrected_print_equals_derivation_and_print_does_not():
    derived = d.paper_coefficients_symbolic()
    corrected = d.corrected_printed_coefficients_symbolic()
    printed = d.printed_coefficients_symbolic()
    mapping = dict(d.PAPER_SYMBOL_MAPPING)
    vals = d.symbol_values(C80)
    for k in "ABCD":
        assert _exact_equal(corrected[k].subs(mapping), derived[k]), k
        pv = float(printed[k].subs(mapping).subs(vals))
        dv = float(derived[k].subs(vals))
        assert abs(pv - dv) > 1e-3 * abs(dv), k  # the print is off for every coefficient


def test_printed_departures_table():
    table = d.PRINTED_DEPARTURES
    assert len(table) >= 8
    for row in table:
        assert len(row) == 4 and all(isinstance(x, str) and x for x in row)
    eqs = " ".join(r[0] for r in table)
    for eq in ("(2.2)", "(2.3)", "(2.4)", "(2.6)", "(2.7)", "(2.11)"):
        assert eq in eqs
    assert any("l3" in r[1] and "r3" in r[2] for r in table)


# ---------------------------------------------------------------------------
# (2.4)-(2.6): Lagrange on (2.2)
# ---------------------------------------------------------------------------
def test_lagrange_mass_and_velocity_matrices():
    eqs = d.lagrange_equations_paper()
    t, c, s = sp.tan(al), sp.cos(al), sp.sin(al)
    M = sp.Matrix([[2 * A_ + 2 * B_ * t**2, C_ * t], [C_ * t, 2 * D_]])
    Vm = sp.Matrix([[4 * B_ * ad * t / c**2, C_ * ad / c**2], [-2 * B_ * V * s / c**3, 0]])
    assert all(d.is_zero(x) for x in eqs.mass_matrix - M)  # as printed
    assert all(d.is_zero(x) for x in eqs.velocity_matrix - Vm)  # row 1 differs from the print
    lhs = M * sp.Matrix([Vd, add]) + Vm * sp.Matrix([V, ad])
    assert all(d.is_zero(x) for x in eqs.lhs - lhs)


def test_lagrange_steering_row_has_sin_cos3_and_no_alpha_dot_term():
    row = d.lagrange_equations_paper().lhs[1].subs(Vd, 0)
    assert d.is_zero(row - (2 * D_ * add - 2 * B_ * V**2 * sp.sin(al) / sp.cos(al) ** 3))
    assert d.is_zero(sp.diff(row, ad))
    eq26 = d.paper_steering_equation()
    eq27 = d.paper_steering_equation(sign="printed-2.7")
    tau_f = S["l3"] * S["l4"] / S["l1"] * S["mu"] * S["Q"]
    assert d.is_zero((eq26.lhs - tau_f * sp.sign(ad)) - row)
    assert d.is_zero(eq27.lhs - eq26.lhs - 4 * B_ * V**2 * sp.sin(al) / sp.cos(al) ** 3)


# ---------------------------------------------------------------------------
# the non-holonomic model
# ---------------------------------------------------------------------------
@pytest.mark.slow
def test_nonholonomic_row_no_sin_cos3_and_gyro_J_over_l1():
    J = d.steering_inertia_symbolic()
    l1 = S["l1"]
    row = d.nonholonomic_equations(in_abcd=False).lhs[1]
    expected = J * (add + Vd * sp.tan(al) / l1 + V * ad / (l1 * sp.cos(al) ** 2))
    assert d.is_zero(row - expected)
    assert d.is_zero(d.nonholonomic_equations().inertia[1] - expected)  # raw Kane row
    assert d.is_zero(row.subs({ad: 0, add: 0, Vd: 0}))  # no sin/cos^3 (or any alpha) term
    gyro = sp.diff(row.subs(Vd, 0), ad) * sp.cos(al) ** 2 / V
    assert d.is_zero(gyro - J / l1)
    eq = d.nonholonomic_steering_equation()
    Jsym = d.J_SYMBOL
    tau_f = S["l3"] * S["l4"] / l1 * S["mu"] * S["Q"]
    assert d.is_zero(eq.lhs.subs(Jsym, J) - expected - tau_f * sp.sign(ad))


@pytest.mark.slow
def test_kane_equals_maggi_and_spurious_terms():
    kane = d.nonholonomic_equations()
    maggi = d.nonholonomic_equations_maggi()
    assert all(d.is_zero(x) for x in maggi - kane.inertia)
    # the same mass matrix as (2.4); only the velocity terms differ
    assert kane.mass_matrix == d.lagrange_equations_paper().mass_matrix
    c, s = sp.cos(al), sp.sin(al)
    assert all(
        d.is_zero(x)
        for x in kane.velocity_matrix - sp.Matrix([[2 * B_ * ad * s / c**3, 0], [C_ * ad / c**2, 0]])
    )
    spur = d.spurious_terms()
    assert d.is_zero(spur - (-2 * B_ * V**2 * s / c**3 - C_ * V * ad / c**2))
    assert d.is_zero(d.spurious_terms_from_momenta() - d.spurious_terms(in_abcd=False))


def test_both_models_balance_power():
    """V Q1 + a' Q2 = dE/dt for both: the spurious pair does no work."""
    E = d.kinetic_energy(in_abcd=True)
    dE = sp.diff(E, al) * ad + sp.diff(E, V) * Vd + sp.diff(E, ad) * add
    for lhs in (d.lagrange_equations_paper().lhs, d.nonholonomic_equations().lhs):
        assert d.is_zero(V * lhs[0] + ad * lhs[1] - dE)


def test_reduced_models_in_paper_notation():
    sc3 = sp.sin(al) / sp.cos(al) ** 3
    i2 = S["i2"]
    paper = d.reduced_model_symbolic("paper")
    lag = d.reduced_model_symbolic("paper-lagrange")
    nh = d.reduced_model_symbolic("nonholonomic")
    assert d.is_zero(paper["V"] - 2 * B_ * V**2 / i2 * sc3)  # (2.7)
    assert d.is_zero(lag["V"] + 2 * B_ * V**2 / i2 * sc3)  # (2.6): the sign clash
    assert nh["V"] == 0 and nh["K"] == 0
    for m in (paper, lag, nh):
        assert m["H"] == 2 * D_ / i2
    assert d.is_zero(nh["F"] - paper["F"] - C_ * V * ad / (i2 * sp.cos(al) ** 2))


def test_voltage_forms():
    s = S
    P = s["R_a"] / s["k_i"] * d.steering_inertia_symbolic() / s["i2"]
    nh = d.voltage_coefficients_symbolic("nonholonomic")
    assert nh["K"] == 0
    assert _exact_equal(nh["gyro"], P / s["l1"])
    assert _exact_equal(nh["P"], P)
    pa = d.voltage_coefficients_symbolic("paper")
    assert pa["gyro"] == 0
    assert _exact_equal(pa["C_V"], s["k_b"] * s["i2"])
    B = d.paper_coefficients_symbolic()["B"]
    assert _exact_equal(pa["K"], s["R_a"] / s["k_i"] * 2 * B * V**2 / s["i2"])
    assert _exact_equal(d.voltage_coefficients_symbolic("paper-lagrange")["K"], -pa["K"])


# ---------------------------------------------------------------------------
# independent check: planar multibody with Lagrange multipliers
# ---------------------------------------------------------------------------
def _R(th):
    c, s = math.cos(th), math.sin(th)
    return np.array([[c, -s], [s, c]])


def _Rp(th):  # dR/dth
    c, s = math.cos(th), math.sin(th)
    return np.array([[-s, -c], [c, -s]])


class PlanarC80:
    """Seven planar bodies + four wheel spins, maximal coordinates.

    z = [x, y, yaw] of chassis(0), rear beam(1), rear wheels(2, 3), front
    beam(4), front wheels(5, 6), then spins of wheels 2, 3, 5, 6.
    Joints (welds, the steering pin) and no-slip conditions are constraint
    rows G z' = 0; M z'' = G^T lam + tau b_tau + F b_F; the steering torque
    tau (front beam +, chassis -) and the drive force F (on the rear beam,
    along its heading) are solved so that alpha'' and V_A' follow given
    functions of time.
    """

    def __init__(self, p: C80Parameters):
        self.p = p
        nb = 7
        self.n = 3 * nb + 4
        m = [p.m1, p.rear_axle_mass, p.rear_wheel_mass, p.rear_wheel_mass,
             p.front_axle_mass, p.front_wheel_mass, p.front_wheel_mass]
        Iz = [p.I_z1, p.rear_axle_yaw_inertia, p.I_z2, p.I_z2,
              p.front_axle_yaw_inertia, p.I_z3, p.I_z3]
        diag = []
        for mi, Ii in zip(m, Iz):
            diag += [mi, mi, Ii]
        diag += [p.I_y2, p.I_y2, p.I_y3, p.I_y3]
        self.M = np.diag(diag)
        l1, l2, l3, l4 = p.l1, p.l2, p.l3, p.l4
        # (body i, point in i, body j, point in j, weld?)
        self.joints = [
            (1, (0.0, 0.0), 0, (-l3, 0.0), True),
            (2, (0.0, 0.0), 1, (0.0, l2), True),
            (3, (0.0, 0.0), 1, (0.0, -l2), True),
            (4, (0.0, 0.0), 0, (l1 - l3, 0.0), False),  # steering pin
            (5, (0.0, 0.0), 4, (0.0, l4), True),
            (6, (0.0, 0.0), 4, (0.0, -l4), True),
        ]
        # (wheel body, spin index, radius, lateral condition?)
        self.wheels = [(2, 21, p.r2, True), (3, 22, p.r2, False),
                       (5, 23, p.r3, True), (6, 24, p.r3, False)]

    def constraints(self, z, zd):
        rows, gam = [], []
        n = self.n
        for i, si, j, sj, weld in self.joints:
            si, sj = np.array(si), np.array(sj)
            thi, thj = z[3 * i + 2], z[3 * j + 2]
            wi, wj = zd[3 * i + 2], zd[3 * j + 2]
            G = np.zeros((2, n))
            G[:, 3 * i:3 * i + 2] = np.eye(2)
            G[:, 3 * i + 2] = _Rp(thi) @ si
            G[:, 3 * j:3 * j + 2] = -np.eye(2)
            G[:, 3 * j + 2] = -_Rp(thj) @ sj
            rows.append(G)
            gam.append(wi**2 * _R(thi) @ si - wj**2 * _R(thj) @ sj)
            if weld:
                g = np.zeros((1, n))
                g[0, 3 * i + 2], g[0, 3 * j + 2] = 1.0, -1.0
                rows.append(g)
                gam.append(np.zeros(1))
        for w, k, r, lateral in self.wheels:
            th, om = z[3 * w + 2], zd[3 * w + 2]
            e, nrm = np.array([math.cos(th), math.sin(th)]), np.array([-math.sin(th), math.cos(th)])
            v = zd[3 * w:3 * w + 2]
            g = np.zeros((1, n))
            g[0, 3 * w:3 * w + 2] = e
            g[0, k] = -r
            rows.append(g)
            gam.append(np.array([-om * nrm @ v]))
            if lateral:
                g = np.zeros((1, n))
                g[0, 3 * w:3 * w + 2] = nrm
                rows.append(g)
                gam.append(np.array([om * e @ v]))
        return np.vstack(rows), np.concatenate(gam)

    def solve(self, z, zd, alpha_dd, V_d):
        """(z'', tau, F) for prescribed alpha'' and V_A'."""
        n = self.n
        G, gam = self.constraints(z, zd)
        nc = G.shape[0]
        b_tau = np.zeros(n)
        b_tau[3 * 4 + 2], b_tau[2] = 1.0, -1.0
        th1 = z[5]
        e1 = np.array([math.cos(th1), math.sin(th1)])
        n1 = np.array([-math.sin(th1), math.cos(th1)])
        b_F = np.zeros(n)
        b_F[3:5] = e1
        K = np.zeros((n + nc + 2, n + nc + 2))
        rhs = np.zeros(n + nc + 2)
        K[:n, :n] = self.M
        K[:n, n:n + nc] = -G.T
        K[:n, n + nc] = -b_tau
        K[:n, n + nc + 1] = -b_F
        K[n:n + nc, :n] = G
        rhs[n:n + nc] = gam
        K[n + nc, 3 * 4 + 2], K[n + nc, 2] = 1.0, -1.0  # alpha'' = th4'' - th0''
        rhs[n + nc] = alpha_dd
        K[n + nc + 1, 3:5] = e1  # V' = e1 . r1'' + th1' n1 . r1'
        rhs[n + nc + 1] = V_d - zd[5] * n1 @ zd[3:5]
        sol = np.linalg.solve(K, rhs)
        return sol[:n], sol[n + nc], sol[n + nc + 1]

    def initial_state(self, alpha, alpha_d, V_A):
        p = self.p
        th, thd = 0.0, V_A * math.tan(alpha) / p.l1
        A = np.zeros(2)
        e, nrm = np.array([1.0, 0.0]), np.array([0.0, 1.0])
        vA = V_A * e
        z, zd = np.zeros(self.n), np.zeros(self.n)

        def put(i, pos, vel, yaw, yawd):
            z[3 * i:3 * i + 2], zd[3 * i:3 * i + 2] = pos, vel
            z[3 * i + 2], zd[3 * i + 2] = yaw, yawd

        put(0, A + p.l3 * e, vA + p.l3 * thd * nrm, th, thd)
        put(1, A, vA, th, thd)
        for i, sgn in ((2, 1.0), (3, -1.0)):
            put(i, A + sgn * p.l2 * nrm, vA - sgn * p.l2 * thd * e, th, thd)
            zd[21 + i - 2] = (V_A - sgn * p.l2 * thd) / p.r2
        O, vO = A + p.l1 * e, vA + p.l1 * thd * nrm
        yc, wc = th + alpha, thd + alpha_d
        ec, nc = np.array([math.cos(yc), math.sin(yc)]), np.array([-math.sin(yc), math.cos(yc)])
        put(4, O, vO, yc, wc)
        for i, k, sgn in ((5, 23, 1.0), (6, 24, -1.0)):
            v = vO - sgn * p.l4 * wc * ec
            put(i, O + sgn * p.l4 * nc, v, yc, wc)
            zd[k] = ec @ v / p.r3
        return z, zd


def _alpha_ref(t):
    a = 0.45 * np.sin(1.1 * t) + 0.15 * np.sin(2.3 * t + 0.4)
    a_d = 0.45 * 1.1 * np.cos(1.1 * t) + 0.15 * 2.3 * np.cos(2.3 * t + 0.4)
    a_dd = -0.45 * 1.21 * np.sin(1.1 * t) - 0.15 * 2.3**2 * np.sin(2.3 * t + 0.4)
    return a, a_d, a_dd


def _simulate(p, V_of_t, T=4.0, n_eval=81):
    """Integrate the constrained bodies with alpha(t), V_A(t) prescribed; sample tau."""
    sim = PlanarC80(p)
    a0, ad0, _ = _alpha_ref(0.0)
    z0, zd0 = sim.initial_state(a0, ad0, V_of_t(0.0)[0])
    G, _ = sim.constraints(z0, zd0)
    assert np.abs(G @ zd0).max() < 1e-12  # consistent initial velocities (a linear solve: rounding)

    def rhs(t, y):
        z, zd = y[:sim.n], y[sim.n:]
        zdd, _, _ = sim.solve(z, zd, _alpha_ref(t)[2], V_of_t(t)[1])
        return np.concatenate([zd, zdd])

    ts = np.linspace(0.0, T, n_eval)
    out = solve_ivp(rhs, (0.0, T), np.concatenate([z0, zd0]), method="DOP853",
                    t_eval=ts, rtol=1e-11, atol=1e-12)
    assert out.success
    rows = []
    for t, y in zip(out.t, out.y.T):
        z, zd = y[:sim.n], y[sim.n:]
        _, tau, _ = sim.solve(z, zd, _alpha_ref(t)[2], V_of_t(t)[1])
        alpha, alpha_d = z[14] - z[2], zd[14] - zd[2]
        VA = math.cos(z[5]) * zd[3] + math.sin(z[5]) * zd[4]
        rows.append((t, alpha, alpha_d, _alpha_ref(t)[2], VA, V_of_t(t)[1], tau))
    return np.array(rows)


@pytest.mark.parametrize("V_A", [C80.V_A, 1.0])
def test_multibody_steering_torque_constant_speed(V_A):
    p = C80
    rows = _simulate(p, lambda t: (V_A, 0.0))
    t, a, a_d, a_dd, VA, _, tau = rows.T
    assert np.abs(VA - V_A).max() < 1e-8
    assert np.abs(a - _alpha_ref(t)[0]).max() < 1e-8  # the motion followed the reference
    J = p.steering_inertia
    nh = J * (a_dd + VA * a_d / (p.l1 * np.cos(a) ** 2))
    scale = np.abs(tau).max()
    assert np.abs(tau - nh).max() < 1e-6 * scale
    # the gyroscopic term is resolved, not just tolerated
    gyro = J * VA * a_d / (p.l1 * np.cos(a) ** 2)
    assert np.abs(gyro).max() > 1e3 * np.abs(tau - nh).max()
    # the paper's row (2.6) (either sign of V(alpha)) is far off
    ke = p.kinetic_energy_coefficients()
    for sgn in (-1.0, 1.0):
        paper = 2 * ke["D"] * a_dd + sgn * 2 * ke["B"] * VA**2 * np.sin(a) / np.cos(a) ** 3
        assert np.abs(tau - paper).max() > 0.2 * scale
    # and the symbolic row, evaluated numerically, agrees as well
    expr = d.steering_torque("nonholonomic", constant_speed=False).subs(sp.sign(ad), 0)
    values = {k: v for k, v in d.symbol_values(p).items() if k != V}
    f = sp.lambdify((al, ad, add, V, Vd), expr.subs(values), "numpy")
    assert np.abs(tau - f(a, a_d, a_dd, VA, 0.0)).max() < 1e-6 * scale


def test_multibody_steering_torque_varying_speed():
    p = with_params(C80, l1=0.8, l4=0.3)
    rows = _simulate(p, lambda t: (0.5 + 0.3 * math.sin(0.9 * t), 0.27 * math.cos(0.9 * t)), T=3.0)
    t, a, a_d, a_dd, VA, V_d, tau = rows.T
    J = p.steering_inertia
    nh = J * (a_dd + V_d * np.tan(a) / p.l1 + VA * a_d / (p.l1 * np.cos(a) ** 2))
    assert np.abs(tau - nh).max() < 1e-6 * np.abs(tau).max()


def test_torque_form_h_v_f_match_voltage_form():
    """(2.13): P = (R_a/k_i) H, K = (R_a/k_i) V, F_V = (R_a/k_i) F_tau, from the torque form (2.7)."""
    from wmr_mj.params import C80

    tf = C80.steering_model_torque_form()
    c = C80.coefficients("paper")
    r = C80.R_a / C80.k_i
    assert c.P == pytest.approx(r * tf["H"], rel=1e-14)
    assert c.K == pytest.approx(r * tf["V"], rel=1e-14)
    assert c.F == pytest.approx(r * tf["F"], rel=1e-14)
