"""Both reduced steering models of the C80, derived with sympy from the geometry.

Equation numbers are the paper's (Hendzel, ``../shared/seed/``, section 2).
Everything here is built from the positions of the seven bodies; nothing is
copied from the printed formulas, which are kept separately (``PRINTED_*``)
to document where the print departs from the derivation.

Geometry (top view; x forward, y left, z up; ``e`` = heading, ``n`` = left)::

    A = (x_A, y_A)            rear-axle midpoint, heading theta, V_A = e . A'
    chassis (a)   CoM at A + l3 e           mass m1, yaw inertia I_z1 (CoM)
    rear beam (b) at A                      m_b2, I_b2
    rear wheels   at A +- l2 n              m_w2, I_y2 (spin), I_z2 (diametral), r2
    pivot O = A + l1 e; unit c turned by alpha, heading theta + alpha
    front beam    at O                      m_b3, I_b3 (about O)
    front wheels  at O +- l4 n_c            m_w3, I_y3, I_z3, r3

Masses and inertias are per body (per wheel, per beam), as in
:mod:`wmr_mj.params`: m2 = m_b2 + 2 m_w2, m3 = m_b3 + 2 m_w3.
``PAPER_SYMBOL_MAPPING`` gives the per-side reading of the paper's (2.3).

Constraints (no slip of the four contact points)::

    rear:  A' = V_A e,  r2 phi_+-' = V_A -+ l2 theta'
    front: O' || e_c    => theta' = V_A tan(alpha)/l1,   |O'| = V_A / cos(alpha)
           r3 psi_+-' = V_A/cos(alpha) -+ l4 (theta' + alpha')

Results (``J = 2D`` = yaw inertia of unit c about O + 2 I_y3 (l4/r3)^2)::

    (2.2)  E = A V^2 + B V^2 tan^2 a + C V a' tan a + D a'^2
           A = (m1 + m2 + m3)/2 + I_y2/r2^2 + I_y3/r3^2
           B = [m1 l3^2/2 + I_z1/2 + I_b2/2 + m_w2 l2^2 + I_z2 + I_y2 l2^2/r2^2 + J/2]/l1^2
               + m_b3/2 + m_w3 + I_y3/r3^2
           C = J/l1,   D = J/2
    (2.4)  Lagrange on (2.2) with (S_A, alpha) as if independent:
           [2A + 2B tan^2 a   C tan a] [V' ]   [4B a' tan a/cos^2 a   C a'/cos^2 a] [V ]   [Q1]
           [C tan a           2D     ] [a''] + [-2B V sin a/cos^3 a   0           ] [a'] = [Q2]
    (2.6)  V' = 0:  2D a'' - 2B V^2 sin a/cos^3 a + tau_f sgn a' = i2 M2
    non-holonomic (Kane, generalized speeds V_A, alpha'): the same mass matrix,
           velocity matrix [[2B a' sin a/cos^3 a, 0], [C a'/cos^2 a, 0]]; alpha row
           J (a'' + V' tan a/l1 + V a'/(l1 cos^2 a)) + tau_f sgn a' = i2 M2
           = J d/dt(theta' + alpha'): the yaw acceleration of unit c times its inertia.
    Lagrange-on-(2.2) minus Kane (alpha row) = -sum_z p_z d(z')/d(alpha)
           = -2B V^2 sin a/cos^3 a - J V a'/(l1 cos^2 a)   (Chaplygin/Maggi pitfall);
           with the V_A-row difference it does no work, so energy balances agree.
    DC motor (2.9)-(2.10): u = (R_a/k_i) M2 + k_b i2 a'
           P a'' + C_V a' + F sgn a' + K sin a/cos^3 a + gyro V a'/cos^2 a = u
           P = (R_a/k_i) J/i2, C_V = k_b i2, F = (R_a/k_i) tau_f/i2,
           paper (2.7): K = (R_a/k_i) 2B V^2/i2, gyro = 0
           nonholonomic: K = 0, gyro = P/l1

API (sympy expressions unless said otherwise; all cached)::

    bodies()                             the seven bodies (position, yaw, spin)
    constraint_velocities()              q' of every coordinate in (V_A, alpha')
    kinetic_energy_full()                T(q, q') before the constraints
    kinetic_energy(in_abcd=False)        E of (2.2)
    paper_coefficients_symbolic()        {A, B, C, D} (per-body symbols)
    printed_coefficients_symbolic()      (2.3) as printed (per-side symbols)
    corrected_printed_coefficients_symbolic(), PAPER_SYMBOL_MAPPING
    lagrange_equations_paper(in_abcd=True)     (2.4): mass/velocity matrices
    paper_steering_equation(sign=...)    (2.6) ('lagrange') or (2.7)'s sign
    nonholonomic_equations(in_abcd=True) Kane's rows in the form of (2.4)
    nonholonomic_equations_maggi()       the same from T by Maggi's form
    nonholonomic_steering_equation(constant_speed=False, in_J=True)
    spurious_terms(), spurious_terms_from_momenta()   Lagrange minus Kane
    steering_torque(model), reduced_model_symbolic(model)   H, V, F, P, K, G
    voltage_equation(model), voltage_coefficients_symbolic(model)
    coefficients_from_derivation(params, model) -> params.Coefficients (floats)
    kinetic_energy_coefficients_from_derivation(params) -> {A, B, C, D} (floats)
    is_zero(expr)                        exact zero test (sin/cos of the angles)
    PRINTED_DEPARTURES                   [(equation, printed, derived, note)]

Usage::

    from wmr_mj import C80
    from wmr_mj.plant import derivation as d
    d.paper_coefficients_symbolic()["C"]          # J/l1 in body symbols
    d.nonholonomic_steering_equation()            # sympy Eq, general V_A(t)
    d.coefficients_from_derivation(C80, "nonholonomic")   # Coefficients in V
    for eq, printed, derived, note in d.PRINTED_DEPARTURES: ...

The sympy work (about 10 s in all) runs on first use and is cached
(``functools.lru_cache``); importing this module does none of it, and
``coefficients_from_derivation`` is lambdified arithmetic after its first call.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cache
from types import MappingProxyType
from typing import Any

import sympy as sp

from wmr_mj.errors import UnknownNameError
from wmr_mj.params import C80Parameters, Coefficients

__all__ = [
    "SYMBOLS",
    "MODELS",
    "PRINTED_DEPARTURES",
    "PAPER_SYMBOL_MAPPING",
    "LagrangeEquations",
    "NonholonomicEquations",
    "bodies",
    "constraint_velocities",
    "kinetic_energy_full",
    "kinetic_energy",
    "paper_coefficients_symbolic",
    "printed_coefficients_symbolic",
    "corrected_printed_coefficients_symbolic",
    "lagrange_equations_paper",
    "paper_steering_equation",
    "nonholonomic_equations",
    "nonholonomic_equations_maggi",
    "nonholonomic_steering_equation",
    "spurious_terms",
    "spurious_terms_from_momenta",
    "steering_torque",
    "reduced_model_symbolic",
    "steering_inertia_symbolic",
    "is_zero",
    "J_SYMBOL",
    "TAU_F",
    "PAPER_SYMBOLS",
    "kinetic_energy_coefficients_from_derivation",
    "voltage_equation",
    "voltage_coefficients_symbolic",
    "symbol_values",
    "coefficients_from_derivation",
]

MODELS = ("paper", "paper-lagrange", "nonholonomic")

_pos = dict(positive=True)

# --------------------------------------------------------------------------
# symbols
# --------------------------------------------------------------------------
#: Named sympy symbols. Body/geometry, motor and motion symbols.
SYMBOLS: Mapping[str, sp.Symbol] = MappingProxyType(
    {
        # geometry
        "l1": sp.Symbol("l1", **_pos),
        "l2": sp.Symbol("l2", **_pos),
        "l3": sp.Symbol("l3", **_pos),
        "l4": sp.Symbol("l4", **_pos),
        "r2": sp.Symbol("r2", **_pos),
        "r3": sp.Symbol("r3", **_pos),
        # unit a
        "m1": sp.Symbol("m1", **_pos),
        "I_z1": sp.Symbol("I_z1", **_pos),
        # unit b: beam and per-wheel values
        "m_b2": sp.Symbol("m_b2", **_pos),
        "I_b2": sp.Symbol("I_b2", **_pos),
        "m_w2": sp.Symbol("m_w2", **_pos),
        "I_y2": sp.Symbol("I_y2", **_pos),
        "I_z2": sp.Symbol("I_z2", **_pos),
        # unit c
        "m_b3": sp.Symbol("m_b3", **_pos),
        "I_b3": sp.Symbol("I_b3", **_pos),
        "m_w3": sp.Symbol("m_w3", **_pos),
        "I_y3": sp.Symbol("I_y3", **_pos),
        "I_z3": sp.Symbol("I_z3", **_pos),
        # friction (2.5), motor (2.9)-(2.10)
        "mu": sp.Symbol("mu", **_pos),
        "Q": sp.Symbol("Q", **_pos),
        "R_a": sp.Symbol("R_a", **_pos),
        "k_i": sp.Symbol("k_i", **_pos),
        "k_b": sp.Symbol("k_b", **_pos),
        "i2": sp.Symbol("i2", **_pos),
        # motion (plain symbols; primes are time derivatives)
        "V": sp.Symbol("V_A", real=True),  # V_A = S_A'
        "V_d": sp.Symbol("V_A'", real=True),  # V_A'
        "alpha": sp.Symbol("alpha", real=True),
        "alpha_d": sp.Symbol("alpha'", real=True),
        "alpha_dd": sp.Symbol("alpha''", real=True),
        # generalized forces
        "Q1": sp.Symbol("Q1", real=True),  # force on S_A, (2.5)
        "M2": sp.Symbol("M2", real=True),  # steering motor torque, (2.5)
        "u": sp.Symbol("u", real=True),  # armature voltage, (2.12)
    }
)

_S = SYMBOLS
l1, l2, l3, l4, r2, r3 = (_S[k] for k in ("l1", "l2", "l3", "l4", "r2", "r3"))
V, Vd, al, ad, add = (_S[k] for k in ("V", "V_d", "alpha", "alpha_d", "alpha_dd"))

#: Coulomb friction torque at the pivot, (2.5): tau_f = (l3 l4/l1) mu Q.
TAU_F = _S["l3"] * _S["l4"] / _S["l1"] * _S["mu"] * _S["Q"]

# configuration coordinates and their rates (plain symbols)
_x, _y, _th = sp.symbols("x_A y_A theta", real=True)
_phiL, _phiR, _psiL, _psiR = sp.symbols("phi_L phi_R psi_L psi_R", real=True)
_Q = (_x, _y, _th, al, _phiL, _phiR, _psiL, _psiR)
_QD = sp.symbols("x_A' y_A' theta' alpha'_q phi_L' phi_R' psi_L' psi_R'", real=True)
_QD_OF = dict(zip(_Q, _QD))


# trigonometric canonical form: sin/cos of theta and alpha as symbols, the
# numerator reduced modulo s^2 + c^2 - 1 (exact zero test, fast)
_sa, _ca, _st, _ct = sp.symbols("s_alpha c_alpha s_theta c_theta", real=True)


def _to_sc(expr: sp.Expr) -> sp.Expr:
    expr = sp.expand_trig(sp.sympify(expr))
    expr = expr.subs({sp.tan(al): _sa / _ca, sp.tan(_th): _st / _ct})
    return expr.subs({sp.sin(al): _sa, sp.cos(al): _ca, sp.sin(_th): _st, sp.cos(_th): _ct})


def _reduce(poly: sp.Expr) -> sp.Expr:
    poly = sp.expand(poly)
    poly = sp.rem(poly, _sa**2 + _ca**2 - 1, _sa) if poly.has(_sa) else poly
    poly = sp.rem(poly, _st**2 + _ct**2 - 1, _st) if poly.has(_st) else poly
    return sp.expand(poly)


def _sc_fraction(expr: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(numerator, denominator) in s_alpha, c_alpha, ...; numerator reduced."""
    num, den = sp.fraction(sp.together(_to_sc(expr)))
    return _reduce(num), _reduce(den)


def _from_sc(expr: sp.Expr) -> sp.Expr:
    return expr.subs({_sa: sp.sin(al), _ca: sp.cos(al), _st: sp.sin(_th), _ct: sp.cos(_th)})


def is_zero(expr: sp.Expr) -> bool:
    """Exact zero test for expressions rational in sin/cos/tan of alpha and theta.

    sin and cos become symbols s, c; the numerator is reduced modulo
    s^2 + c^2 - 1 (a Groebner basis for both angles): zero iff it vanishes.
    """
    return _sc_fraction(expr)[0] == 0




def _angle_free(expr: sp.Expr) -> bool:
    return is_zero(sp.diff(expr, al)) and is_zero(sp.diff(expr, _th))


def _const_value(expr: sp.Expr) -> sp.Expr:
    """The value of an angle-free expression, read at the rational point
    (sin a, cos a) = (3/5, 4/5), theta = 0; raises if it depends on an angle."""
    if not _angle_free(expr):
        raise RuntimeError(f"expression depends on alpha or theta: {expr}")
    val = _to_sc(expr).subs({_sa: sp.Rational(3, 5), _ca: sp.Rational(4, 5), _st: 0, _ct: 1})
    return sp.factor(sp.cancel(val))


_MOTION = (add, Vd, V, ad)
_TRIG_BASIS = (
    sp.Integer(1),
    sp.tan(al),
    sp.tan(al) ** 2,
    1 / sp.cos(al),
    1 / sp.cos(al) ** 2,
    sp.sin(al) / sp.cos(al) ** 3,
)


def _motion_terms(expr: sp.Expr) -> dict[tuple[int, ...], sp.Expr]:
    """{exponents of (a'', V', V, a'): coefficient} of an expression polynomial in them."""
    num, den = _sc_fraction(expr)
    if num == 0:
        return {}
    out = {}
    for monom, coeff in sp.Poly(num, *_MOTION).terms():
        c = _from_sc(coeff / den)
        if not is_zero(c):
            out[monom] = c
    return out


def _trig_term(c: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """c(alpha) = k f(alpha) with f from a small basis (1, tan, tan^2, 1/cos,
    1/cos^2, sin/cos^3) and k angle-free; raises if no basis function fits."""
    for f in _TRIG_BASIS:
        q = c / f
        if _angle_free(q):
            return _const_value(q), f
    raise RuntimeError(f"no single-term trigonometric form for {c}")


def _monomial(m: tuple[int, ...]) -> sp.Expr:
    return sp.Mul(*(s**k for s, k in zip(_MOTION, m)))


def _in_abcd(k: sp.Expr) -> sp.Expr:
    """An angle-free coefficient as a rational multiple of one of A, B, C, D."""
    if k.free_symbols & set(_abcd_symbols()):
        return k
    for sym, name in zip(_abcd_symbols(), "ABCD"):
        r = sp.cancel(k / _abcd()[name])
        if r.is_number:
            return r * sym
    raise RuntimeError(f"coefficient {k} is not a multiple of A, B, C or D")


def _split_rows(rows: sp.Matrix) -> tuple[sp.Matrix, sp.Matrix]:
    """rows = M [V', a''] + Vm [V, a']: M the Jacobian, Vm found term by term.

    Convention of the printed (2.4): V^2 and V a' terms go to column 1 (as
    coefficient * V resp. coefficient * a'), a'^2 terms to column 2.
    """
    qdd = sp.Matrix([Vd, add])
    M = rows.jacobian(qdd)
    Vm = sp.zeros(2, 2)
    for i in range(2):
        rest = rows[i] - (M[i, :] * qdd)[0]
        for m, c in _motion_terms(rest).items():
            k, f = _trig_term(c)
            k = _in_abcd(k)
            if m == (0, 0, 2, 0):
                Vm[i, 0] += k * f * V
            elif m == (0, 0, 1, 1):
                Vm[i, 0] += k * f * ad
            elif m == (0, 0, 0, 2):
                Vm[i, 1] += k * f * ad
            else:
                raise RuntimeError(f"row {i}: term {c} * {_monomial(m)} is not a velocity term")
    check = (M * qdd + Vm * sp.Matrix([V, ad]) - rows).subs(_abcd_subs())
    if not all(is_zero(x) for x in check):
        raise RuntimeError("velocity-matrix split does not reproduce the rows")
    return M, Vm


def _vec(a: Any, b: Any) -> sp.Matrix:
    return sp.Matrix([a, b])


def _dt_q(expr: sp.Expr) -> sp.Expr:
    """Time derivative of f(q) with the free rates _QD."""
    return sum((sp.diff(expr, q) * qd for q, qd in zip(_Q, _QD)), sp.Integer(0))


# --------------------------------------------------------------------------
# bodies and constraints
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Body:
    """A planar rigid body: CoM position, yaw angle, optional spin angle."""

    name: str
    position: sp.Matrix  # 2x1, function of the coordinates
    mass: sp.Symbol
    yaw: sp.Expr
    yaw_inertia: sp.Symbol  # about the vertical through the CoM
    spin: sp.Symbol | None = None
    spin_inertia: sp.Symbol | None = None
    radius: sp.Symbol | None = None  # wheels only


def bodies() -> tuple[Body, ...]:
    """The seven bodies of the C80 as functions of (x_A, y_A, theta, alpha, spins)."""
    th = _th
    e = _vec(sp.cos(th), sp.sin(th))
    n = _vec(-sp.sin(th), sp.cos(th))
    nc = _vec(-sp.sin(th + al), sp.cos(th + al))
    A = _vec(_x, _y)
    O = A + l1 * e
    s = _S
    return (
        Body("chassis", A + l3 * e, s["m1"], th, s["I_z1"]),
        Body("rear_beam", A, s["m_b2"], th, s["I_b2"]),
        Body("rear_wheel_L", A + l2 * n, s["m_w2"], th, s["I_z2"], _phiL, s["I_y2"], r2),
        Body("rear_wheel_R", A - l2 * n, s["m_w2"], th, s["I_z2"], _phiR, s["I_y2"], r2),
        Body("front_beam", O, s["m_b3"], th + al, s["I_b3"]),
        Body("front_wheel_L", O + l4 * nc, s["m_w3"], th + al, s["I_z3"], _psiL, s["I_y3"], r3),
        Body("front_wheel_R", O - l4 * nc, s["m_w3"], th + al, s["I_z3"], _psiR, s["I_y3"], r3),
    )


def _contact_velocity(b: Body) -> sp.Matrix:
    """Velocity of a wheel's contact point: v_centre - r spin' e_w.

    Spin about the axle n_w (pointing left): omega x (-r z) = -r spin' (n_w x z)
    = -r spin' e_w, e_w the wheel's heading.
    """
    e_w = _vec(sp.cos(b.yaw), sp.sin(b.yaw))
    return b.position.applyfunc(_dt_q) - b.radius * _QD_OF[b.spin] * e_w


@cache
def constraint_velocities() -> Mapping[sp.Symbol, sp.Expr]:
    """q' of every coordinate in terms of the generalized speeds (V_A, alpha').

    With A' = V_A e + w n (w the side-slip speed of A, unknown), the contact
    point velocities are projected on each wheel's heading and axle; six
    conditions (both projections at the left wheels, the rolling projection
    at the right wheels) are solved for w, theta' and the four spin rates,
    and the two lateral conditions left out (redundant on a rigid axle) are
    checked to hold.
    """
    w = sp.Symbol("w", real=True)
    unknowns = (w, _QD[2]) + tuple(_QD[4:])
    e = _vec(sp.cos(_th), sp.sin(_th))
    n = _vec(-sp.sin(_th), sp.cos(_th))
    base = {_QD[0]: V * e[0] + w * n[0], _QD[1]: V * e[1] + w * n[1], _QD[3]: ad}
    proj = {}
    for b in bodies():
        if b.spin is None:
            continue
        cv = _contact_velocity(b).subs(base)
        e_w = _vec(sp.cos(b.yaw), sp.sin(b.yaw))
        n_w = _vec(-sp.sin(b.yaw), sp.cos(b.yaw))
        proj[b.name] = (_simplify_sc(e_w.dot(cv)), _simplify_sc(n_w.dot(cv)))
    eqs = [
        *proj["rear_wheel_L"], proj["rear_wheel_R"][0],
        *proj["front_wheel_L"], proj["front_wheel_R"][0],
    ]
    sol = sp.solve(eqs, unknowns, dict=True)
    if len(sol) != 1:
        raise RuntimeError("the rolling constraints have no unique solution")
    sol = {k: sp.simplify(v) for k, v in sol[0].items()}
    for name in ("rear_wheel_R", "front_wheel_R"):
        if not is_zero(proj[name][1].subs(sol)):
            raise RuntimeError(f"the lateral no-slip condition of {name} does not hold")
    out = {
        _x: sp.simplify(base[_QD[0]].subs(sol)),
        _y: sp.simplify(base[_QD[1]].subs(sol)),
        _th: sol[_QD[2]],
        al: ad,
    }
    for q, qd in zip(_Q[4:], _QD[4:]):
        out[q] = sol[qd]
    return MappingProxyType({q: out[q] for q in _Q})


def _simplify_sc(expr: sp.Expr) -> sp.Expr:
    """Projections: expand sin/cos of sums, then trigsimp (small expressions)."""
    return sp.trigsimp(sp.expand(sp.expand_trig(expr)))


def _qdot_map() -> dict[sp.Symbol, sp.Expr]:
    cvel = constraint_velocities()
    return {_QD_OF[q]: cvel[q] for q in _Q}


def _total_dt(expr: sp.Expr) -> sp.Expr:
    """d/dt along the constrained motion: q' from the constraints, (V, a')' = (V', a'')."""
    cvel = constraint_velocities()
    out = sum((sp.diff(expr, q) * cvel[q] for q in _Q if q is not al), sp.Integer(0))
    return out + sp.diff(expr, al) * ad + sp.diff(expr, V) * Vd + sp.diff(expr, ad) * add


# --------------------------------------------------------------------------
# kinetic energy (2.2)-(2.3)
# --------------------------------------------------------------------------
@cache
def kinetic_energy_full() -> sp.Expr:
    """T(q, q') of the unconstrained bodies; the rates are the symbols ``x_A'``, ... .

    Planar rigid bodies: (m/2)|r'|^2 + (I_z/2) yaw'^2 + (I_y/2) spin'^2. For an
    axisymmetric wheel this is exact in 3D (spin about the axle, yaw about a
    diameter).
    """
    T = sp.Integer(0)
    for b in bodies():
        v = b.position.applyfunc(_dt_q)
        T += b.mass * v.dot(v) / 2 + b.yaw_inertia * _dt_q(b.yaw) ** 2 / 2
        if b.spin is not None:
            T += b.spin_inertia * _QD_OF[b.spin] ** 2 / 2
    return sp.expand(T)


@cache
def _abcd() -> dict[str, sp.Expr]:
    E = kinetic_energy_full().subs(_qdot_map())
    if not is_zero(sp.diff(E, _th)):
        raise RuntimeError("the constrained kinetic energy depends on the heading")
    terms = _motion_terms(E)
    if set(terms) - {(0, 0, 2, 0), (0, 0, 1, 1), (0, 0, 0, 2)}:
        raise RuntimeError("the constrained kinetic energy is not quadratic in (V_A, alpha')")
    cVV, cVa, caa = (terms.get(m, sp.Integer(0)) for m in ((0, 0, 2, 0), (0, 0, 1, 1), (0, 0, 0, 2)))
    t = sp.tan(al)
    A = sp.factor(sp.cancel(_to_sc(cVV).subs({_sa: 0, _ca: 1})))
    B = _const_value((cVV - A) / t**2)
    C = _const_value(cVa / t)
    D = _const_value(caa)
    form = A * V**2 + B * V**2 * t**2 + C * V * ad * t + D * ad**2
    if not is_zero(E - form):
        raise RuntimeError("the constrained kinetic energy is not of the form (2.2)")
    return {"A": sp.expand(A), "B": sp.expand(B), "C": sp.expand(C), "D": sp.expand(D)}


def kinetic_energy(*, in_abcd: bool = False) -> sp.Expr:
    """E(alpha, V_A, alpha') of (2.2): T with the rolling constraints substituted.

    Returned as A V^2 + B V^2 tan^2 a + C V a' tan a + D a'^2 with the derived
    coefficients (or the symbols A, B, C, D with ``in_abcd``). The
    coefficients are read off the substituted T, which is checked to equal
    this form exactly (and to be independent of the heading).
    """
    A, B, C, D = _abcd_symbols() if in_abcd else (_abcd()[k] for k in "ABCD")
    t = sp.tan(al)
    return A * V**2 + B * V**2 * t**2 + C * V * ad * t + D * ad**2


def paper_coefficients_symbolic() -> dict[str, sp.Expr]:
    """A, B, C, D of (2.2) derived from the geometry (per-body symbols)."""
    return dict(_abcd())


def steering_inertia_symbolic() -> sp.Expr:
    """J = I_b3 + 2 (I_z3 + m_w3 l4^2) + 2 I_y3 (l4/r3)^2 (= 2D = params.steering_inertia)."""
    s = _S
    return s["I_b3"] + 2 * (s["I_z3"] + s["m_w3"] * l4**2) + 2 * s["I_y3"] * (l4 / r3) ** 2


# -- the printed (2.3), in the paper's per-side symbols -------------------
#: Symbols of the printed (2.3); the paper's m2, m3, I_z2, I_z3 are per side.
PAPER_SYMBOLS: Mapping[str, sp.Symbol] = MappingProxyType(
    {k: sp.Symbol(k + "^p", **_pos) for k in ("m2", "m3", "I_y2", "I_z2", "I_y3", "I_z3")}
)

#: Per-side reading of the paper's symbols, in this module's per-body symbols.
PAPER_SYMBOL_MAPPING: Mapping[sp.Symbol, sp.Expr] = MappingProxyType(
    {
        PAPER_SYMBOLS["m2"]: (_S["m_b2"] + 2 * _S["m_w2"]) / 2,  # half of unit b
        PAPER_SYMBOLS["m3"]: (_S["m_b3"] + 2 * _S["m_w3"]) / 2,  # half of unit c
        PAPER_SYMBOLS["I_y2"]: _S["I_y2"],  # one wheel
        PAPER_SYMBOLS["I_y3"]: _S["I_y3"],  # one wheel
        # half the yaw inertia of unit b about A (beam + wheel + wheel offset)
        PAPER_SYMBOLS["I_z2"]: _S["I_b2"] / 2 + _S["I_z2"] + _S["m_w2"] * l2**2,
        # half the yaw inertia of unit c about O (params.steering_yaw_inertia / 2)
        PAPER_SYMBOLS["I_z3"]: _S["I_b3"] / 2 + _S["I_z3"] + _S["m_w3"] * l4**2,
    }
)


def printed_coefficients_symbolic() -> dict[str, sp.Expr]:
    """(2.3) exactly as printed (the paper's per-side symbols ``m2^p``, ...)."""
    p = PAPER_SYMBOLS
    m1, Iz1 = _S["m1"], _S["I_z1"]
    A = m1 / 2 + p["m2"] + p["m3"] + p["I_y2"] / r2**2 + p["I_y3"] * (l4 / (l3 * r3)) ** 2
    B = (
        m1 / 2 * (l3 / l1) ** 2
        + p["m3"]
        + (Iz1 / 2 + p["I_z2"]) / l1**2
        + p["I_y2"] * (l2 / (l1 * r2)) ** 2
        + p["I_y3"] * (l4 / l3) ** 2 * (1 / r3**2 + 1 / l1**2)
        + p["I_z3"] / l1**2
    )
    C = 2 * p["I_z3"] / l1 + 2 * p["I_y3"] * (l4 / l3) / l1
    D = p["I_z3"] + p["I_y3"] * (l4 / l3) ** 2
    return {"A": A, "B": B, "C": C, "D": D}


def corrected_printed_coefficients_symbolic() -> dict[str, sp.Expr]:
    """(2.3) with the departures of ``PRINTED_DEPARTURES`` fixed (per-side symbols).

    l3 -> r3 in every front-wheel spin term, the (l4/r3)^2 factor only on the
    steering part of the front-wheel spin, and the square in C. Substituting
    ``PAPER_SYMBOL_MAPPING`` gives ``paper_coefficients_symbolic()``.
    """
    p = PAPER_SYMBOLS
    m1, Iz1 = _S["m1"], _S["I_z1"]
    A = m1 / 2 + p["m2"] + p["m3"] + p["I_y2"] / r2**2 + p["I_y3"] / r3**2
    B = (
        m1 / 2 * (l3 / l1) ** 2
        + p["m3"]
        + (Iz1 / 2 + p["I_z2"]) / l1**2
        + p["I_y2"] * (l2 / (l1 * r2)) ** 2
        + p["I_y3"] * (1 / r3**2 + (l4 / r3) ** 2 / l1**2)
        + p["I_z3"] / l1**2
    )
    C = 2 * p["I_z3"] / l1 + 2 * p["I_y3"] * (l4 / r3) ** 2 / l1
    D = p["I_z3"] + p["I_y3"] * (l4 / r3) ** 2
    return {"A": A, "B": B, "C": C, "D": D}


def _abcd_symbols() -> tuple[sp.Symbol, ...]:
    return sp.symbols("A B C D", positive=True)


def _abcd_subs() -> dict[sp.Symbol, sp.Expr]:
    return dict(zip(_abcd_symbols(), (_abcd()[k] for k in "ABCD")))


def _forces() -> sp.Matrix:
    """(Q1, Q2) of (2.5): Q2 = i2 M2 - tau_f sgn(alpha'); Q1 left symbolic."""
    return sp.Matrix([_S["Q1"], _S["i2"] * _S["M2"] - TAU_F * sp.sign(ad)])


# --------------------------------------------------------------------------
# (2.4)-(2.8): Lagrange on (2.2) with (S_A, alpha) as independent coordinates
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class LagrangeEquations:
    """mass_matrix [V', a''] + velocity_matrix [V, a'] = forces, (2.4).

    ``lhs``: the two Lagrange expressions d/dt dE/dq' - dE/dq (q = S_A, alpha)
    as computed; the matrices are found from it and checked to reproduce it.
    """

    mass_matrix: sp.Matrix
    velocity_matrix: sp.Matrix
    forces: sp.Matrix  # (Q1, Q2), Q2 = i2 M2 - tau_f sgn a'   (2.5)
    lhs: sp.Matrix

    @property
    def equations(self) -> list[sp.Eq]:
        return [sp.Eq(self.lhs[i], self.forces[i]) for i in range(2)]


def _sub_abcd(m: sp.Matrix | sp.Expr, in_abcd: bool) -> Any:
    return m if in_abcd else m.subs(_abcd_subs())


@cache
def lagrange_equations_paper(*, in_abcd: bool = True) -> LagrangeEquations:
    """(2.4): Lagrange's equations (2.1) applied to E of (2.2), q = (S_A, alpha).

    ``in_abcd``: in the symbols A, B, C, D (as the paper writes it); else with
    the derived coefficients substituted.
    """
    E = kinetic_energy(in_abcd=True)

    def dt(f: sp.Expr) -> sp.Expr:  # E has no S_A; alpha, V, alpha' vary
        return sp.diff(f, al) * ad + sp.diff(f, V) * Vd + sp.diff(f, ad) * add

    lhs = sp.Matrix([dt(sp.diff(E, V)), dt(sp.diff(E, ad)) - sp.diff(E, al)])
    lhs = lhs.applyfunc(sp.simplify)
    M, Vm = _split_rows(lhs)
    M = M.applyfunc(sp.simplify)
    return LagrangeEquations(_sub_abcd(M, in_abcd), _sub_abcd(Vm, in_abcd), _forces(), _sub_abcd(lhs, in_abcd))


def paper_steering_equation(*, sign: str = "lagrange", in_abcd: bool = True) -> sp.Eq:
    """(2.6) at constant V_A, in pivot-torque units: lhs = i2 M2.

    sign='lagrange': the alpha row of (2.4) at V_A' = 0, as (2.6) prints it,
    2D a'' - 2BV^2 sin a/cos^3 a + tau_f sgn a'. sign='printed-2.7': with
    V(alpha) = +2BV^2 sin/cos^3 as (2.7) defines it.
    """
    if sign not in ("lagrange", "printed-2.7"):
        raise UnknownNameError("sign convention", sign, ("lagrange", "printed-2.7"))
    eqs = lagrange_equations_paper(in_abcd=True)
    row = (eqs.mass_matrix[1, 1] * add + (eqs.velocity_matrix[1, :] * sp.Matrix([V, ad]))[0])
    if sign == "printed-2.7":
        row = row - 2 * eqs.velocity_matrix[1, 0] * V
    return sp.Eq(_sub_abcd(row, in_abcd) + TAU_F * sp.sign(ad), _S["i2"] * _S["M2"])


# --------------------------------------------------------------------------
# the non-holonomic model: Kane's method with generalized speeds (V_A, alpha')
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class NonholonomicEquations:
    """Kane's equations F_r + F_r* = 0 for the generalized speeds u = (V_A, alpha').

    ``lhs[r]`` = -F_r* (the generalized inertia force, sign turned) in the form
    of (2.4), mass_matrix [V', a''] + velocity_matrix [V, a'] (found from the
    raw Kane rows ``inertia`` and checked to reproduce them); ``forces[r]`` = F_r.
    """

    mass_matrix: sp.Matrix
    velocity_matrix: sp.Matrix
    forces: sp.Matrix
    lhs: sp.Matrix
    inertia: sp.Matrix = field(repr=False)  # raw Kane rows, in the body symbols

    @property
    def equations(self) -> list[sp.Eq]:
        return [sp.Eq(self.lhs[i], self.forces[i]) for i in range(2)]


@cache
def _kane_rows() -> sp.Matrix:
    """-F_r* = sum over bodies of m a . dv/du_r + I_z yaw'' dyaw'/du_r + I_y spin'' dspin'/du_r."""
    qmap = _qdot_map()
    rows = [sp.Integer(0), sp.Integer(0)]
    for b in bodies():
        v = b.position.applyfunc(_dt_q).subs(qmap)
        a = v.applyfunc(_total_dt)
        w = _dt_q(b.yaw).subs(qmap)
        wd = _total_dt(w)
        for r, u in enumerate((V, ad)):
            rows[r] += b.mass * a.dot(v.diff(u)) + b.yaw_inertia * wd * sp.diff(w, u)
        if b.spin is not None:
            s = qmap[_QD_OF[b.spin]]
            sd = _total_dt(s)
            for r, u in enumerate((V, ad)):
                rows[r] += b.spin_inertia * sd * sp.diff(s, u)
    return sp.Matrix(rows)


@cache
def nonholonomic_equations(*, in_abcd: bool = True) -> NonholonomicEquations:
    """Kane's equations of the constrained C80 (rolling without slip, no side slip).

    Body velocities follow from ``constraint_velocities``; the partial
    velocities are their derivatives by (V_A, alpha'), the accelerations their
    total time derivatives along the constrained motion.

    Active forces: the steering torque i2 M2 between chassis and unit c and the
    pivot friction -tau_f sgn(alpha') (2.5) on the alpha row (the chassis'
    partial angular velocity for alpha' is zero); the drive's generalized force
    Q1 on the V_A row. The contact forces do no work under rolling without slip.

    Result: the mass matrix of (2.4) (the Hessian of (2.2) in the speeds) and
    velocity_matrix = [[2B a' sin a/cos^3 a, 0], [C a'/cos^2 a, 0]].
    """
    raw = _kane_rows()
    M, Vm = _split_rows(raw)
    M_abcd = lagrange_equations_paper(in_abcd=True).mass_matrix
    if not all(is_zero(x) for x in (M - M_abcd.subs(_abcd_subs()))):
        raise RuntimeError("the Kane mass matrix is not the Hessian of (2.2)")
    lhs = M_abcd * sp.Matrix([Vd, add]) + Vm * sp.Matrix([V, ad])
    return NonholonomicEquations(
        _sub_abcd(M_abcd, in_abcd), _sub_abcd(Vm, in_abcd), _forces(), _sub_abcd(lhs, in_abcd), raw
    )


@cache
def nonholonomic_equations_maggi() -> sp.Matrix:
    """The Kane rows again, from T(q, q') by Maggi's form: sum_i (dq_i'/du_r) E_i(T).

    E_i(T) = d/dt dT/dq_i' - dT/dq_i of the unconstrained kinetic energy,
    evaluated on the constrained motion: an independent route to
    ``nonholonomic_equations().inertia`` (compare with ``is_zero``).
    """
    T = kinetic_energy_full()
    qmap = _qdot_map()
    cvel = constraint_velocities()
    rows = [sp.Integer(0), sp.Integer(0)]
    for q in _Q:
        p = sp.diff(T, _QD_OF[q]).subs(qmap)
        Ei = _total_dt(p) - sp.diff(T, q).subs(qmap)
        for r, u in enumerate((V, ad)):
            rows[r] += sp.diff(cvel[q], u) * Ei
    return sp.Matrix(rows)


J_SYMBOL = sp.Symbol("J", positive=True)


def nonholonomic_steering_equation(*, constant_speed: bool = False, in_J: bool = True) -> sp.Eq:
    """Kane's alpha row: J (a'' + V' tan a/l1 + V a'/(l1 cos^2 a)) + tau_f sgn a' = i2 M2.

    Read term by term off the raw Kane row. ``constant_speed``: V_A' = 0.
    ``in_J``: with the symbol ``J_SYMBOL`` (checked to divide every term:
    J = ``steering_inertia_symbolic()`` = 2D); else in the body symbols.
    """
    row = _kane_rows()[1]
    if constant_speed:
        row = row.subs(Vd, 0)
    J = steering_inertia_symbolic()
    inertia_syms = {_S[k] for k in ("I_b3", "I_z3", "I_y3", "m_w3", "m1", "m_b3", "I_z1")}
    terms = []
    for m, c in _motion_terms(row).items():
        k, f = _trig_term(c)
        if in_J:
            k = sp.factor(sp.cancel(k / J))
            if k.free_symbols & inertia_syms:
                raise RuntimeError(f"J does not factor out of the steering row: {k}")
        terms.append(k * f * _monomial(m))
    lhs = sp.Add(*terms)
    if in_J:
        lhs = J_SYMBOL * lhs
    return sp.Eq(lhs + TAU_F * sp.sign(ad), _S["i2"] * _S["M2"])


@cache
def spurious_terms(*, in_abcd: bool = True) -> sp.Expr:
    """alpha row of Lagrange-on-(2.2) minus Kane's alpha row, read term by term.

    = -2B V^2 sin a/cos^3 a - C V a'/cos^2 a (C = J/l1): the V(alpha) of
    (2.6), and the gyroscopic term that Lagrange on (2.2) loses. (The V_A rows
    differ by 2B V a' sin a/cos^3 a + C a'^2/cos^2 a; the pair does no work,
    V dQ1 + a' dQ2 = 0, so an energy balance cannot see it.)
    """
    diff = lagrange_equations_paper(in_abcd=False).lhs[1] - _kane_rows()[1]
    terms = []
    for m, c in _motion_terms(diff).items():
        k, f = _trig_term(c)
        terms.append((_in_abcd(k) if in_abcd else k) * f * _monomial(m))
    return sp.Add(*terms)


@cache
def spurious_terms_from_momenta() -> sp.Expr:
    """The same difference from its origin: -sum_z p_z d(z')/d(alpha) at fixed speeds.

    With z' = b_z(q) (V, a') the dependent rates, Lagrange on T* = T(q, b u)
    differs from Maggi's form by sum_z p_z [d/dt(dz'/da') - dz'/da]
    + sum_z (dT/dz)(dz'/da'). Here dz'/da' is constant (front-wheel spins,
    -+l4/r3) and T does not depend on the spin angles, so only
    -sum_z p_z dz'/da survives: the alpha-dependence of the constraints
    (theta' = V tan a/l1, |O'| = V/cos a) is taken for a configuration
    dependence of the kinetic energy: the Chaplygin/Maggi pitfall.
    Returned raw (body symbols); ``is_zero(it - spurious_terms(in_abcd=False))``.
    """
    T = kinetic_energy_full()
    qmap = _qdot_map()
    cvel = constraint_velocities()
    out = sp.Integer(0)
    for q in _Q:
        if q is al:
            continue
        p = sp.diff(T, _QD_OF[q]).subs(qmap)
        out += p * (_total_dt(sp.diff(cvel[q], ad)) - sp.diff(cvel[q], al))
        out += sp.diff(T, q).subs(qmap) * sp.diff(cvel[q], ad)
    return out


# --------------------------------------------------------------------------
# voltage form (2.9)-(2.13)
# --------------------------------------------------------------------------
def steering_torque(model: str, *, constant_speed: bool = True, in_abcd: bool = False) -> sp.Expr:
    """Pivot torque i2 M2 that ``model`` requires (friction included).

    model: 'paper' ((2.7)'s sign of V(alpha)), 'paper-lagrange' ((2.6), what
    Lagrange on (2.2) gives) or 'nonholonomic' (Kane). ``constant_speed``:
    V_A' = 0 (the paper states (2.6) only for that case; otherwise the paper
    models give the alpha row of (2.4)). ``in_abcd``: in the symbols A..D,
    else in the body symbols.
    """
    if model not in MODELS:
        raise UnknownNameError("model", model, MODELS)
    if model == "nonholonomic":
        row = nonholonomic_equations(in_abcd=True).lhs[1]
    else:
        eqs = lagrange_equations_paper(in_abcd=True)  # lhs = M qdd + Vm u, checked
        Vm = eqs.velocity_matrix
        if model == "paper":  # V(alpha) with (2.7)'s sign
            Vm = Vm.copy()
            Vm[1, 0] = -Vm[1, 0]
        row = (eqs.mass_matrix[1, :] * sp.Matrix([Vd, add]))[0] + (Vm[1, :] * sp.Matrix([V, ad]))[0]
    if constant_speed:
        row = row.subs(Vd, 0)
    return _sub_abcd(row, in_abcd) + TAU_F * sp.sign(ad)


def reduced_model_symbolic(model: str, *, in_abcd: bool = True) -> dict[str, sp.Expr]:
    """The scalar model of ``model`` in the paper's notation, (2.7)-(2.8), (2.12)-(2.13).

    H a'' + F(a') + V(alpha) = M  and  P a'' + G(a') + K(alpha) = u, constant V_A:
    H = coefficient of a'' in M2, V(alpha) = M2 at a' = a'' = 0, F(a') = the rest
    of M2 (for 'nonholonomic' this includes the gyroscopic term
    (J/i2) V_A a'/(l1 cos^2 a)), P = (R_a/k_i) H, K(alpha) = (R_a/k_i) V(alpha),
    G(a') = (R_a/k_i) F(a') + k_b i2 a'.
    """
    s = _S
    M2 = steering_torque(model, constant_speed=True, in_abcd=in_abcd) / s["i2"]
    H = sp.diff(M2, add)
    Va = M2.subs({ad: 0, add: 0})  # sign(0) = 0
    F = sp.expand(M2 - H * add - Va)
    r = s["R_a"] / s["k_i"]
    return {
        "H": H, "V": Va, "F": F, "M": s["M2"],
        "P": r * H, "K": r * Va, "G": r * F + s["k_b"] * s["i2"] * ad,
    }


def voltage_equation(model: str) -> sp.Expr:
    """Armature voltage u of ``model`` at constant V_A, (2.9)-(2.10) with M = M2.

    u = R_a I_a + k_b alpha_m' = (R_a/k_i) M2 + k_b i2 alpha'  (alpha_m = i2 alpha).
    (2.11) prints k_b i2 alpha_m', which would be k_b i2^2 alpha'.
    """
    s = _S
    M2 = steering_torque(model, constant_speed=True) / s["i2"]
    return s["R_a"] / s["k_i"] * M2 + s["k_b"] * s["i2"] * ad


@cache
def voltage_coefficients_symbolic(model: str) -> dict[str, sp.Expr]:
    """P, C_V, F, K, gyro of ``model``, read off its voltage equation.

    u = P a'' + C_V a' + F sgn a' + K sin a/cos^3 a + gyro V_A a'/cos^2 a;
    raises if the equation has a term outside that form.
    """
    u = voltage_equation(model)
    sgn = sp.Symbol("sgn")
    u = u.subs(sp.sign(ad), sgn)
    P = _const_value(sp.diff(u, add))
    F = _const_value(sp.diff(u, sgn))
    r = u - P * add - F * sgn
    slope = sp.diff(r, ad)
    C_V = _const_value(slope.subs(V, 0))
    gyro = _const_value((slope - C_V) * sp.cos(al) ** 2 / V)
    K = _const_value(r.subs(ad, 0) * sp.cos(al) ** 3 / sp.sin(al))
    out = {"P": P, "C_V": C_V, "F": F, "K": K, "gyro": gyro}
    for name, c in out.items():
        if c.has(ad, add, sgn) or (name != "K" and c.has(V)):
            raise RuntimeError(f"{model}: coefficient {name} = {c} is not a constant")
    form = (P * add + C_V * ad + F * sgn + K * sp.sin(al) / sp.cos(al) ** 3
            + gyro * V * ad / sp.cos(al) ** 2)
    if not is_zero(u - form):
        raise RuntimeError(f"{model}: the voltage equation has terms outside (2.12)")
    return out


# --------------------------------------------------------------------------
# numeric evaluation
# --------------------------------------------------------------------------
_PARAM_SYMBOLS = (
    "l1", "l2", "l3", "l4", "r2", "r3", "m1", "I_z1", "m_b2", "I_b2", "m_w2", "I_y2",
    "I_z2", "m_b3", "I_b3", "m_w3", "I_y3", "I_z3", "mu", "Q", "R_a", "k_i", "k_b", "i2", "V",
)


def symbol_values(params: C80Parameters) -> dict[sp.Symbol, float]:
    """Numeric value of every parameter symbol for a C80 parameter set.

    Per-body values from :mod:`wmr_mj.params` (wheel discs, slender-rod beams,
    box chassis); V is params.V_A and Q the total weight.
    """
    p = params
    values = {
        "l1": p.l1, "l2": p.l2, "l3": p.l3, "l4": p.l4, "r2": p.r2, "r3": p.r3,
        "m1": p.m1, "I_z1": p.I_z1,
        "m_b2": p.rear_axle_mass, "I_b2": p.rear_axle_yaw_inertia,
        "m_w2": p.rear_wheel_mass, "I_y2": p.I_y2, "I_z2": p.I_z2,
        "m_b3": p.front_axle_mass, "I_b3": p.front_axle_yaw_inertia,
        "m_w3": p.front_wheel_mass, "I_y3": p.I_y3, "I_z3": p.I_z3,
        "mu": p.mu, "Q": p.Q, "R_a": p.R_a, "k_i": p.k_i, "k_b": p.k_b, "i2": p.i2,
        "V": p.V_A,
    }
    return {_S[k]: float(v) for k, v in values.items()}


@cache
def _lambdified(model: str) -> dict[str, Callable[..., float]]:
    args = [_S[k] for k in _PARAM_SYMBOLS]
    exprs = _abcd() if model == "kinetic" else voltage_coefficients_symbolic(model)
    return {k: sp.lambdify(args, e, modules="math") for k, e in exprs.items()}


def _values(params: C80Parameters) -> list[float]:
    vals = symbol_values(params)
    return [vals[_S[k]] for k in _PARAM_SYMBOLS]


def kinetic_energy_coefficients_from_derivation(params: C80Parameters) -> dict[str, float]:
    """Numeric A, B, C, D of (2.2) from the derivation (cf. params.kinetic_energy_coefficients)."""
    x = _values(params)
    return {k: float(f(*x)) for k, f in _lambdified("kinetic").items()}


def coefficients_from_derivation(params: C80Parameters, model: str = "paper") -> Coefficients:
    """Voltage-form coefficients of ``model`` (one of MODELS) from the derivation.

    'paper' and 'nonholonomic' match ``params.coefficients(model)``;
    'paper-lagrange' is 'paper' with K -> -K (wmr_mj.plant.reduced's model of that name).
    The first call per model runs the sympy derivation (seconds); later calls
    are lambdified arithmetic.
    """
    if model not in MODELS:
        raise UnknownNameError("model", model, MODELS)
    x = _values(params)
    return Coefficients(**{k: float(f(*x)) for k, f in _lambdified(model).items()})


# --------------------------------------------------------------------------
# where the print departs from the derivation
# --------------------------------------------------------------------------
#: (equation, printed, derived, note). Per-side symbols m2', m3', I_z2', I_z3'
#: are those of PAPER_SYMBOL_MAPPING; I_y2, I_y3 are per wheel.
PRINTED_DEPARTURES: list[tuple[str, str, str, str]] = [
    (
        "(2.2)",
        "E = A V_A + B V_A^2 + tan^2 alpha + C V_A alpha' tan alpha + D alpha'^2",
        "E = A V_A^2 + B V_A^2 tan^2 alpha + C V_A alpha' tan alpha + D alpha'^2",
        "extraction error: a kinetic energy is quadratic in (V_A, alpha'); "
        "the (2.4) printed from it needs exactly this form",
    ),
    (
        "(2.3) masses",
        "m2, m3, I_z2, I_z3 (A = m1/2 + m2 + m3 + ...)",
        "per side: m2' = m2/2, m3' = m3/2, I_z2' = I_b2/2 + I_z2 + m_w2 l2^2, "
        "I_z3' = I_b3/2 + I_z3 + m_w3 l4^2 (half the unit's yaw inertia about A resp. O); "
        "I_y2, I_y3 per wheel",
        "with per-unit masses A = (m1 + m2 + m3)/2 + ...; the print reads as if m2, m3 "
        "(or lost parentheses around m1 + m2 + m3) and I_z2, I_z3 were per side of the cart",
    ),
    (
        "(2.3) A",
        "I_y3 (l4/(l3 r3))^2",
        "I_y3 / r3^2",
        "forward rolling of the front wheels (|O'| = V_A/cos alpha) gives "
        "I_y3 V_A^2 (1 + tan^2 alpha)/r3^2; l4 enters only the spin from steering",
    ),
    (
        "(2.3) B",
        "I_y3 (l4/l3)^2 (1/r3^2 + 1/l1^2)",
        "I_y3 (1/r3^2 + (l4/r3)^2/l1^2)",
        "first part from V_A^2 tan^2 alpha/r3^2 of the forward rolling, second from the "
        "yaw rate theta' = V_A tan alpha/l1 rolling the wheels by -+l4 theta'/r3",
    ),
    (
        "(2.3) B, C, D",
        "(l4/l3) in the front-wheel spin terms",
        "(l4/r3)",
        "l3 (A to the chassis CoM) printed where r3 (front wheel radius) belongs: "
        "r3 psi' = -+l4 (theta' + alpha')",
    ),
    (
        "(2.3) C",
        "C = 2 I_z3/l1 + 2 I_y3 (l4/l3)/l1",
        "C = 2 I_z3'/l1 + 2 I_y3 (l4/r3)^2/l1 = J/l1 = 2D/l1",
        "C V alpha' tan alpha is the cross term of (J/2)(theta' + alpha')^2 with "
        "theta' = V_A tan alpha/l1, so C = 2D/l1: the square is missing",
    ),
    (
        "(2.3) D",
        "D = I_z3 + I_y3 (l4/l3)^2",
        "D = I_z3' + I_y3 (l4/r3)^2 = J/2",
        "l3 for r3; with I_z3' half the yaw inertia of unit c about O",
    ),
    (
        "(2.4) velocity matrix, row 1",
        "[4B q2 tan q2,  C q' 1/cos q2]",
        "[4B q2' tan q2/cos^2 q2,  C q2'/cos^2 q2]",
        "from d/dt dE/dV_A; row 2 [-2B q1' sin q2/cos^3 q2, 0] is right "
        "(the factorization of the velocity terms is not unique; this one keeps the printed row 2)",
    ),
    (
        "(2.6)/(2.7)",
        "(2.6): - 2B V_A^2/i2 sin/cos^3;  (2.7): V(alpha) = + 2B V_A^2/i2 sin/cos^3",
        "Lagrange on (2.2): 2D a'' - 2B V_A^2 sin a/cos^3 a = Q2, i.e. (2.6)'s minus",
        "(2.6) and (2.7)-(2.8) cannot both hold; wmr_mj.plant.reduced: 'paper' uses (2.7), "
        "'paper-lagrange' (2.6)",
    ),
    (
        "(2.11)",
        "u_a = R_a I_a + k_b i2 alpha_m'",
        "u_a = R_a I_a + k_b alpha_m' = R_a I_a + k_b i2 alpha'",
        "with alpha_m = i2 alpha (2.10) the print counts i2 twice (k_b i2^2 alpha'); "
        "(2.13)'s G = (R_a/k_i) F + k_b i2 alpha' is consistent: C_V = k_b i2",
    ),
    (
        "(2.6)-(2.8) physics",
        "H a'' + F(a') + V(alpha) = M, V(alpha) = 2B V_A^2/i2 sin a/cos^3 a",
        "(J/i2)(a'' + V_A' tan a/l1 + V_A a'/(l1 cos^2 a)) + F(a') = M, J = 2D",
        "rolling without side slip is non-holonomic; Lagrange's equations on the "
        "constrained energy (2.2) add -sum_z p_z dz'/dalpha = -2BV^2 sin/cos^3 - J V a'/(l1 cos^2): "
        "voltage form K = 0, gyro = P/l1 (Kane / Maggi)",
    ),
]
