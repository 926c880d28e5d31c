"""The steering-law interface: steering state, reference and time in, armature voltage out.

A steering law is a :class:`SteeringController`. The testbed calls it once per control period
with the steering state and the reference, and applies the voltage it returns (clipped to the
supply by :func:`saturate`; NaN applies 0 V)::

    law.reset(control_period=0.001)                      # before every run: clear any state
    u = law.step(t, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)   # floats, V

A stateless law writes only :meth:`voltage_scalar` (floats) or :meth:`voltage` (arrays, a
leading batch axis): each is derived from the other, and :meth:`step` calls
:meth:`voltage_scalar`. A law with state (an adaptive law's estimates, an integrator) overrides
:meth:`reset` and :meth:`step`. :meth:`batch_law` is the vectorised form a batch of runs may use
(the default derives it from :meth:`voltage`; a stateful law that has no batch form runs its
simulations one by one on the engine).

A law may log its own signals beside the rows: it names them in :attr:`signal_names` and returns
their values of the step just taken from :meth:`signals` (``{"alpha_dot_est": ...}``); the rows
gain ``law_alpha_dot_est``, and an MCAP log the channel ``/law``.

A law may state a claim (:meth:`claim`): a bound on |E| and |E'| with its assumptions
(:mod:`wmr_mj.analysis.claim`), which every run of it is judged against. Without one the run
is judged by its requirements only (``--require``), never as a pass.

A law of one's own, in a file of one's own (``wmr-mj run --controller my_law.py:MyLaw
--controller-param k=2``)::

    from controllers import SteeringController

    class MyPD(SteeringController):
        name = "my-pd"
        def __init__(self, kp=50.0, kd=15.0):
            self.kp, self.kd = kp, kd
        def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
            return 0.1 * (self.kp * (alpha0 - alpha) + self.kd * (alpha0_dot - alpha_dot))

The built-in computed-torque and PD laws also run compiled in MuJoCo's control callback
(:mod:`wmr_mj.sim.compiled_law`). So does a stateless law of one's own that offers its law as a
pure function of floats, which numba (``pip install 'wmr-mj[fast]'``) compiles to C::

    class FastPD(SteeringController):
        name = "fast-pd"
        def __init__(self, kp=50.0, kd=15.0):
            self.kp, self.kd = kp, kd
        def law_parameters(self):                  # p, the law's constants (floats)
            return [0.1, self.kp, self.kd]
        @staticmethod
        def law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):   # floats in, V out
            return p[0] * (p[1] * (alpha0 - alpha) + p[2] * (alpha0_dot - alpha_dot))

``law`` sees ``p`` as a float64 array (``law_parameters()``, fixed for the run) and the state as
floats; it may use arithmetic, ``math`` and ``if``, nothing of the object. Its Python path
(:meth:`voltage_scalar`, derived from it) gives the same bits as the compiled one where it keeps
to IEEE operations and ``math`` functions (``x * x`` rather than ``x ** 2``). Any other law runs
in Python in the same engine, one call per control step, and the run says so and why
(``RunResult.law_note``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from wmr_mj.analysis.certificate import Certificate
    from wmr_mj.analysis.claim import ClaimContext
    from wmr_mj.plant.reduced import SteeringModel

__all__ = ["SteeringController", "BatchLaw", "saturate", "BuildContext", "law_methods_missing", "DesignParameter"]

#: law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u) -> u: alpha, alpha_dot (n,) arrays
#: (rad, rad/s; strided views are fine); the reference as floats; E = alpha0 - alpha and
#: E_dot = alpha0_dot - alpha_dot are written into the (n,) arrays E, E_dot; the unsaturated
#: voltage (V) into u, which is returned.
BatchLaw = Callable[[np.ndarray, np.ndarray, float, float, float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]


class DesignParameter(NamedTuple):
    """One of a law's own parameters that a design search varies (``wmr-mj design``; in log, as the law's
    ``controller_params``): its name (a keyword of the law and a range of ``DesignProblem``), its unit and the format
    a design prints it with."""

    name: str
    unit: str
    format: str = ".6g"


class BuildContext:
    """What the testbed knows when it builds a law from a name and parameters (``from_context``).

    Attributes:
        model: the reduced model of the run's model source on the estimate (P^, C_V^, F^, K^, gyro^).
        estimate: the controller's belief, the nominal parameter set (:class:`wmr_mj.params.C80Parameters`).
        voltage_limit: the supply [V].
        kp, kd: the run's K_P [1/s^2], K_D [1/s] (a law with a PD servo of its own may take them).
    """

    #: the attributes that carry a run's settings (``--model``, ``--kp``, ``--kd``); reading one is recorded
    SETTINGS = ("model", "kp", "kd")

    def __init__(self, *, model: SteeringModel, estimate: Any, voltage_limit: float, kp: float, kd: float) -> None:
        self.estimate, self.voltage_limit = estimate, voltage_limit
        self._settings = {"model": model, "kp": kp, "kd": kd}
        #: the settings the law read while it was built (names of :data:`SETTINGS`): the run's options that
        #: reach it, and the only ones its outputs report as the law's
        self.read: set[str] = set()

    def _setting(self, name: str) -> Any:
        self.read.add(name)
        return self._settings[name]

    @property
    def model(self) -> SteeringModel:
        return self._setting("model")

    @property
    def kp(self) -> float:
        return self._setting("kp")

    @property
    def kd(self) -> float:
        return self._setting("kd")


class SteeringController:
    """Steering state and reference in (rad, rad/s, rad/s^2), armature voltage out (V).

    Override :meth:`voltage_scalar` or :meth:`voltage` (at least one); :meth:`reset` and
    :meth:`step` for a law with state; :meth:`claim` to state a guarantee; ``name`` to be named
    as yourself in every output.
    """

    name: str = "controller"
    #: optional, for the compiled callback: ``law(p, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot) -> V``,
    #: a staticmethod of floats with ``p = law_parameters()`` (see the module's docstring)
    law: Callable[..., float] | None = None
    #: the reduced model the law stands on (its estimate P^, C_V^, F^, K^), where it has one
    model: SteeringModel | None = None
    #: the model source of that estimate where the run names none (``RunConfig(model=None)``, ``wmr-mj run``
    #: without --model or --preset): one of controllers.computed_torque.MODEL_SOURCES under which the law's
    #: claim can hold at its default parameters
    default_model: str = "paper"
    #: whether the law reads alpha_dot; a law that estimates alpha' from the angle alone sets False, and only
    #: such a law runs with ``--sensing velocity=none`` (alpha_dot is then NaN; the run refuses the others)
    reads_velocity: bool = True
    #: the names of the law's own signals (its alpha' estimate, an observer's state), logged beside the rows as
    #: ``law_NAME`` (:meth:`signals`); a law that logs any runs in Python on the engine, one call per step
    signal_names: tuple[str, ...] = ()
    #: the law's own parameters a design search varies (:class:`DesignParameter`, in order); (): the run's gains K_P,
    #: K_D (searched as omega_n, zeta), as for the computed-torque law
    design_parameters: tuple[DesignParameter, ...] = ()
    #: whether a design search grades an uncertified point by how far its unmet assumptions are from their limits
    #: (a law whose default start sits on a flat plateau of one unmet assumption, as sliding mode's saturated layer)
    design_graded: bool = False

    @classmethod
    def from_context(cls, context: BuildContext, **params: Any) -> SteeringController:
        """The law built by name (``--controller NAME --controller-param k=v``): ``cls(**params)``.

        A law that stands on the run's model (its P^ etc.) overrides this to take ``context.model``.
        """
        return cls(**params)

    def voltage(self, alpha: ArrayLike, alpha_dot: ArrayLike, alpha0: ArrayLike, alpha0_dot: ArrayLike,
                alpha0_ddot: ArrayLike) -> np.ndarray:
        """Unsaturated armature voltage [V] for each simulation of a batch (arrays (B,) -> (B,))."""
        if type(self).voltage_scalar is SteeringController.voltage_scalar and type(self).law is None:
            raise TypeError(f"{type(self).__name__} defines neither voltage nor voltage_scalar")
        a, ad, a0, a0d, a0dd = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in
                                                    (alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)))
        return np.array([self.voltage_scalar(*map(float, row)) for row in zip(a.ravel(), ad.ravel(), a0.ravel(),
                                                                              a0d.ravel(), a0dd.ravel())],
                        dtype=float).reshape(a.shape)

    def voltage_scalar(self, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
                       alpha0_ddot: float) -> float:
        """The same law on floats [V] (override for speed); a law that offers ``law`` gets ``law(p, ...)``."""
        fn = type(self).law
        if fn is not None:
            return float(fn(np.asarray(self.law_parameters(), dtype=np.float64), alpha, alpha_dot, alpha0,
                            alpha0_dot, alpha0_ddot))
        if type(self).voltage is SteeringController.voltage:
            raise TypeError(f"{type(self).__name__} defines neither voltage nor voltage_scalar")
        return float(self.voltage(np.array([alpha]), np.array([alpha_dot]), np.array([alpha0]),
                                  np.array([alpha0_dot]), np.array([alpha0_ddot]))[0])

    def law_parameters(self) -> ArrayLike:
        """The constants ``p`` of :attr:`law` (a sequence of floats; read once per run by the compiled law)."""
        return ()

    def reset(self, *, control_period: float) -> None:
        """Before each run: clear the law's state; ``control_period`` [s] is the time between steps."""

    def step(self, t: float, alpha: float, alpha_dot: float, alpha0: float, alpha0_dot: float,
             alpha0_ddot: float) -> float:
        """One control step at time ``t`` [s]: the voltage to apply [V]; a law with state updates it here."""
        return self.voltage_scalar(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)

    def signals(self) -> Mapping[str, float]:
        """After each :meth:`step`: the law's own signals of that step, a float per name of :attr:`signal_names`
        (units the law's own), recorded in the rows as ``law_NAME`` and in the log's ``/law`` channel."""
        return {}

    @property
    def stateful(self) -> bool:
        """Whether the law keeps state between steps (it overrides :meth:`step` or :meth:`reset`)."""
        cls = type(self)
        return cls.step is not SteeringController.step or cls.reset is not SteeringController.reset

    def batch_law(self, n: int) -> BatchLaw:
        """The law for a batch of ``n`` simulations, writing into the caller's buffers.

        This default calls :meth:`voltage` (which allocates); controllers override it
        with a law that allocates nothing per call.
        """

        def law(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot, E, E_dot, u):
            np.subtract(alpha0, alpha, out=E)
            np.subtract(alpha0_dot, alpha_dot, out=E_dot)
            u[...] = self.voltage(alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot)
            return u

        return law

    def claim(self, context: ClaimContext) -> Certificate | None:
        """The law's guarantee for the run of ``context`` (:mod:`wmr_mj.analysis.claim`); None: it claims nothing."""
        return None

    def describe(self) -> dict:
        """JSON-able description for logs and reports (``controller`` is the law's name)."""
        return {"controller": self.name}

    def label(self) -> str:
        """One line naming the law and its parameters, for a report's heading."""
        params = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                           for k, v in self.describe().items()
                           if k != "controller" and not isinstance(v, (dict, list, tuple)))
        return f"controller {self.name}" + (f" ({params})" if params else "")


def law_methods_missing(cls: Any) -> str | None:
    """Why ``cls`` cannot run as a steering law (one line), or None where it can."""
    if not (isinstance(cls, type) and issubclass(cls, SteeringController)):
        return (f"{getattr(cls, '__name__', cls)!r} is not a steering law: subclass controllers.SteeringController "
                "and define voltage_scalar (or voltage, or step)")
    if (cls.voltage_scalar is SteeringController.voltage_scalar and cls.voltage is SteeringController.voltage
            and cls.step is SteeringController.step and cls.law is None):
        return f"{cls.__name__} defines none of voltage_scalar, voltage, step, law: a steering law needs one"
    return None


def saturate(u: ArrayLike, limit: float) -> tuple[np.ndarray, np.ndarray]:
    """(clip(u, -limit, limit), mask of saturated entries)."""
    u = np.asarray(u, dtype=float)
    clipped = np.clip(u, -limit, limit)
    return clipped, clipped != u


def describe_params(params: Mapping[str, Any]) -> dict[str, Any]:
    """Parameters as JSON-able values (numbers and strings kept, anything else as its repr)."""
    return {str(k): (v if isinstance(v, (int, float, str, bool)) or v is None else repr(v)) for k, v in params.items()}
