"""What a claim is: a region, the assumptions it rests on, its terms and its inputs; and a run judged by it.

Every claim a run is judged by, section 4's certificate (:mod:`wmr_mj.analysis.small_gain`) and a law's
own (:func:`wmr_mj.analysis.claim.box_claim`) alike, is a :class:`Certificate` (also named
:data:`Claim`): a :class:`~wmr_mj.analysis.regions.Region` object, its :class:`Assumption` records, section
4's :class:`SmallGainTerms` where it has them, and its :class:`ClaimInputs`. :func:`judge` gives the
run's verdict against it; a run may carry several claims by name (:class:`Claims`, :func:`claim_set`).

Usage::

    from wmr_mj.analysis.claim_types import Certificate, judge
    from wmr_mj.analysis.regions import BoxRegion
    cert = Certificate(region=BoxRegion(E_max=0.04, Edot_max=0.4), valid=True, assumptions=(),
                       alpha_max=0.7, voltage_max=9.0, claimant="my-law")
    judge(cert, 0.02, 0.1).verdict      # 'certified-inside'
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol, get_args

from wmr_mj.analysis.regions import BoxRegion, Region, SmallGainRegion, check_region
from wmr_mj.analysis.robustness import damping_regime
from wmr_mj.errors import ParameterError

__all__ = [
    "Verdict",
    "VERDICTS",
    "Assumption",
    "SmallGainTerms",
    "ClaimInputs",
    "Certificate",
    "Claim",
    "Claims",
    "LAW_CLAIM",
    "claim_set",
    "CertificateJudgement",
    "judge",
    "finite_or_none",
    "MeasurementCause",
]

#: A run's verdict against its certificate; only 'certified-inside' is a pass.
Verdict = Literal["certified-inside", "certified-outside", "uncertified-inside", "uncertified-outside"]
VERDICTS: tuple[str, ...] = get_args(Verdict)


def finite_or_none(x: float) -> float | None:
    """``x`` as a float, None when it is not finite (the JSON's way to write inf and NaN)."""
    x = float(x)
    return x if math.isfinite(x) else None


def _inf_if_none(x: float | None) -> float:
    """A bound as :func:`finite_or_none` wrote it: null (not finite) is inf."""
    return math.inf if x is None else x


def _nan_if_none(x: float | None) -> float:
    """A value as :func:`finite_or_none` wrote it: null (not finite) is NaN."""
    return math.nan if x is None else x


@dataclass(frozen=True)
class Assumption:
    """One assumption of the certificate: ``met`` when ``value`` is within ``limit``.

    kind: 'checked' (computed from the certificate's numbers) or 'stated' (a modelling
    choice with its source in ``note``; ``value``/``limit`` compare the measurements
    behind it with the band chosen).
    """

    name: str
    equation: str
    met: bool
    value: float
    limit: float
    note: str = ""
    kind: str = "checked"

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "equation": self.equation, "met": bool(self.met),
                "value": finite_or_none(self.value), "limit": finite_or_none(self.limit),
                "note": self.note, "kind": self.kind}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Assumption:
        """The assumption of its JSON ``d`` (:meth:`to_dict`); a value or limit that is null (not finite) is NaN."""
        return cls(name=d["name"], equation=d["equation"], met=d["met"], value=_nan_if_none(d["value"]),
                   limit=_nan_if_none(d["limit"]), note=d.get("note", ""), kind=d.get("kind", "checked"))


@dataclass(frozen=True, kw_only=True)
class MeasurementCause:
    """The measurement errors a section-4 certificate assumed, and which of them keeps its fixed point from
    closing (:func:`wmr_mj.analysis.small_gain.certify` with a ``measurement`` that is not exact).

    Attributes:
        e_a: the bound on |alpha_m - alpha| the claim assumed [rad] (inf: none derived).
        e_v: the bound on |alpha_m' - alpha'| [rad/s].
        tau: the delay [s] (sensing plus actuation; a differenced velocity's T/2 lag is counted by the sensing).
        E_max_without: for each error that is not 0, ('e_a', 'e_v' or 'tau', E_max [rad] with it set to 0
            and the others kept; inf: still no fixed point); empty when the certificate has a fixed point.
        E_max_exact: E_max with no measurement error at all [rad] (inf: no fixed point without them either);
            None when the certificate has a fixed point.
    """

    e_a: float
    e_v: float
    tau: float
    E_max_without: tuple[tuple[str, float], ...] = ()
    E_max_exact: float | None = None

    @property
    def binding(self) -> tuple[str, ...]:
        """The errors each of which alone keeps the fixed point from closing: set to 0, it closes."""
        return tuple(name for name, E in self.E_max_without if math.isfinite(E))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (inf -> None): e_a [rad], e_v [rad/s], tau [s], binding, E_max_without, E_max_exact."""
        return {"e_a": finite_or_none(self.e_a), "e_v": finite_or_none(self.e_v), "tau": finite_or_none(self.tau),
                "binding": list(self.binding),
                "E_max_without": {name: finite_or_none(E) for name, E in self.E_max_without},
                "E_max_exact": None if self.E_max_exact is None else finite_or_none(self.E_max_exact)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> MeasurementCause:
        """The cause of its JSON ``d`` (:meth:`to_dict`; ``binding`` is derived). A null error or E_max is inf (the
        writer's null of inf); E_max_exact null is None where E_max_without is empty (a fixed point), else inf."""
        without = tuple((name, _inf_if_none(E)) for name, E in d["E_max_without"].items())
        exact = d["E_max_exact"]
        return cls(e_a=_inf_if_none(d["e_a"]), e_v=_inf_if_none(d["e_v"]), tau=_inf_if_none(d["tau"]),
                   E_max_without=without,
                   E_max_exact=(None if not without else math.inf) if exact is None else exact)


@dataclass(frozen=True, kw_only=True)
class SmallGainTerms:
    """Section 4's breakdown of delta1 and the law it is for (:func:`wmr_mj.analysis.small_gain.certify`).

    Attributes:
        friction_term, gyro_term, K_term, P_term, C_V_term [rad/s^2]: the parts of delta1 (each at P_min).
        gyro_Edot_term [1/s]: the gyro part of delta3.
        dead_band [rad]: F_max/(P^ K_P).
        disturbance_term [rad/s^2]: d_V,max/P_min, the disturbance's part of delta1 (JSON only when not 0).
        measurement_term [rad/s^2]: the measurement errors' and delay's part of delta1 (JSON only when not 0).
        kp [1/s^2], kd [1/s]: the law's gains.
        friction_sign: the law's Coulomb sign ('measured', 'reference', 'none'); friction_width [rad/s]:
            its smoothing.
        delta1_parts: every term of delta1 [rad/s^2] as (name, value), at the plant corner P where delta1 is
            reached, so that they add up to delta1 (to rounding); the measurement's terms, with a delay's loop
            gain 1/(1 - tau c_v) as the part it adds. Not in :meth:`Certificate.to_dict` (whose keys stay as
            they were); ``robustness --certificate`` prints and writes them.
        measurement_cause: the measurement errors assumed and which binds (:class:`MeasurementCause`); None
            for a law that reads the true state at once.
    """

    friction_term: float
    gyro_term: float
    K_term: float = 0.0
    P_term: float = 0.0
    C_V_term: float = 0.0
    gyro_Edot_term: float = 0.0
    dead_band: float = 0.0
    disturbance_term: float = 0.0
    measurement_term: float = 0.0
    kp: float = 0.0
    kd: float = 0.0
    friction_sign: str = "measured"
    friction_width: float = 0.0
    delta1_parts: tuple[tuple[str, float], ...] = ()
    measurement_cause: MeasurementCause | None = None

    def json_items(self) -> dict[str, Any]:
        """The terms as :meth:`Certificate.to_dict` writes them (inf -> None): :data:`_TERM_KEYS` in order, then
        disturbance_term and measurement_term where not 0, then friction_sign."""
        out: dict[str, Any] = {name: finite_or_none(getattr(self, name)) for name in _TERM_KEYS}
        if self.disturbance_term:
            out["disturbance_term"] = finite_or_none(self.disturbance_term)
        if self.measurement_term:
            out["measurement_term"] = finite_or_none(self.measurement_term)
        out["friction_sign"] = self.friction_sign
        return out

    @classmethod
    def from_json_items(cls, d: Mapping[str, Any], *, measurement_cause: MeasurementCause | None = None
                        ) -> SmallGainTerms:
        """The terms of a certificate's JSON ``d`` (what :meth:`json_items` wrote there; a null term is inf).

        ``delta1_parts`` is not in that JSON and is () here; ``measurement_cause`` is the run JSON's
        ``measurement_errors`` (:meth:`MeasurementCause.from_dict`), given by the caller that has it."""
        terms: dict[str, Any] = {name: _inf_if_none(d[name]) for name in _TERM_KEYS}
        return cls(**terms, disturbance_term=_inf_if_none(d.get("disturbance_term", 0.0)),
                   measurement_term=_inf_if_none(d.get("measurement_term", 0.0)), friction_sign=d["friction_sign"],
                   measurement_cause=measurement_cause)


#: What the term properties of a claim without section 4's terms read (a law's box claim, the sampled-data
#: certificate): placeholders, no claim of the law's; its JSON writes none of them (:meth:`Certificate.to_dict`).
_NO_TERMS = SmallGainTerms(friction_term=math.nan, gyro_term=math.nan, friction_sign="none")

#: Section 4's region's numbers in the JSON beside its corner (E_max, Edot_max).
_REGION_KEYS = ("gamma1", "gamma2", "delta1", "delta2", "delta3")

#: The terms' keys in the JSON, in order (disturbance_term, measurement_term and friction_sign follow).
_TERM_KEYS = ("friction_term", "gyro_term", "K_term", "P_term", "C_V_term", "gyro_Edot_term", "dead_band", "kp", "kd",
              "friction_width")


class _Record(Protocol):
    def to_dict(self) -> dict[str, Any]: ...


@dataclass(frozen=True)
class ClaimInputs(Mapping[str, Any]):
    """What a claim rests on: the analysis's own inputs, then the run's record (as the JSON's ``inputs``).

    Read by attribute (``law``, ``run``); it is also the read-only mapping the JSON writes, the law's keys
    first, then the run's (a run key of the same name replaces the law's value in place).

    Attributes:
        law: the analysis's inputs: a typed record with ``to_dict()`` (section 4's
            :class:`~wmr_mj.analysis.small_gain.SmallGainInputs`), or a law's own mapping (a box claim's).
        run: what the run adds (:func:`wmr_mj.sim.certify.certificate_of`: model, controller, box rule, ...).
    """

    law: _Record | Mapping[str, Any] = field(default_factory=dict)
    run: Mapping[str, Any] = field(default_factory=dict)

    @functools.cached_property
    def _law_dict(self) -> dict[str, Any]:
        return self.law.to_dict() if hasattr(self.law, "to_dict") else dict(self.law)

    @functools.cached_property
    def _merged(self) -> dict[str, Any]:
        return {**self._law_dict, **self.run}

    def __getitem__(self, key: str) -> Any:
        return self._merged[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._merged)

    def __len__(self) -> int:
        return len(self._merged)

    def to_dict(self) -> dict[str, Any]:
        """A new dict of every input (the law's, then the run's)."""
        return dict(self._merged)

    def with_record(self, record: Mapping[str, Any]) -> ClaimInputs:
        """These inputs with ``record``, a copy of this mapping updated, as the whole: its keys that are new,
        or whose value is not the very object the law's inputs hold, become the run's."""
        law = self._law_dict
        return ClaimInputs(law=self.law, run={k: v for k, v in record.items() if k not in law or law[k] is not v})


def _regime(terms: SmallGainTerms | None) -> str | None:
    return damping_regime(terms.kp, terms.kd) if terms is not None else None


def _small_gain_value(name: str, doc: str) -> property:
    def get(self: Certificate) -> float:
        region = self.region
        return getattr(region, name) if isinstance(region, SmallGainRegion) else math.nan
    return property(get, doc=doc + " (NaN for a region other than section 4's).")


def _term(name: str) -> property:
    def get(self: Certificate) -> Any:
        return getattr(self.terms if self.terms is not None else _NO_TERMS, name)
    return property(get, doc=f"``terms.{name}`` (:class:`SmallGainTerms`; a placeholder for a claim without them, "
                             "which its JSON does not write).")


@dataclass(frozen=True, kw_only=True)
class Certificate:
    """A claim: the certified region for one controller on one plant box, and what it rests on.

    Attributes:
        region: the :class:`~wmr_mj.analysis.regions.Region` the run's (sup|E|, sup|E'|) must lie in.
        valid: the bound exists (a finite region); False with ``reason``.
        assumptions: every assumption, checked and stated, with its value and limit.
        alpha_max [rad]: max|a0| + E_max, the reachable angle. voltage_max [V]: the law's |u| bound in the
            region.
        terms: section 4's breakdown of delta1 (:class:`SmallGainTerms`); None for a claim without them.
        reason: why there is no bound ('' when there is). iterations: the fixed point's iterations.
        inputs: what the claim rests on (:class:`ClaimInputs`; a mapping is taken as the law's inputs).
        claimant: whose claim it is (the controller's name; '' for the section-4 analysis of the run's law).
        analysis: which analysis gave it, as the law names it ('section-4', 'boundary-layer', 'sampled-data';
            '' where the law names none); not in the JSON, whose ``inputs['certificate']`` names the one a run
            took where it computed two.

    ``E_max``, ``Edot_max`` and, for section 4's region, ``condition``, ``gamma1`` ... ``delta3`` read the
    region; ``friction_term`` ... ``friction_width`` read the terms.

    Raises:
        TypeError: a region that is not a :class:`~wmr_mj.analysis.regions.Region` (a name such as 'box').
    """

    region: Region
    valid: bool
    assumptions: tuple[Assumption, ...]
    alpha_max: float
    voltage_max: float
    terms: SmallGainTerms | None = None
    reason: str = ""
    iterations: int = 0
    inputs: ClaimInputs = field(default_factory=ClaimInputs, compare=False, hash=False)
    claimant: str = ""
    analysis: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        check_region(self.region)
        if not isinstance(self.inputs, ClaimInputs):
            object.__setattr__(self, "inputs", ClaimInputs(law=dict(self.inputs or {})))

    @property
    def E_max(self) -> float:
        """The region's bound on |E| [rad]; inf when not ``valid``."""
        return self.region.E_max

    @property
    def Edot_max(self) -> float:
        """The region's bound on |E'| [rad/s]; inf when not ``valid`` or not bounded."""
        return self.region.Edot_max

    condition = _small_gain_value("condition", "The left side of (4.23) [-]")
    gamma1 = _small_gain_value("gamma1", "gamma1 of (4.14) [s^2]")
    gamma2 = _small_gain_value("gamma2", "gamma2 of (4.14) [s]")
    delta1 = _small_gain_value("delta1", "delta1 of (4.18) [rad/s^2]")
    delta2 = _small_gain_value("delta2", "delta2, the coefficient of ||E|| [1/s^2]")
    delta3 = _small_gain_value("delta3", "delta3, the coefficient of ||E'|| [1/s]")
    friction_term = _term("friction_term")
    gyro_term = _term("gyro_term")
    K_term = _term("K_term")
    P_term = _term("P_term")
    C_V_term = _term("C_V_term")
    gyro_Edot_term = _term("gyro_Edot_term")
    dead_band = _term("dead_band")
    disturbance_term = _term("disturbance_term")
    measurement_term = _term("measurement_term")
    kp = _term("kp")
    kd = _term("kd")
    friction_sign = _term("friction_sign")
    friction_width = _term("friction_width")

    @property
    def certified(self) -> bool:
        """True when the bound exists and every assumption is met."""
        return bool(self.valid and all(a.met for a in self.assumptions))

    @property
    def unmet(self) -> tuple[str, ...]:
        """Names of the assumptions that are not met."""
        return tuple(a.name for a in self.assumptions if not a.met)

    @property
    def vertices(self) -> tuple[tuple[float, float], ...]:
        """The region's polygon in the (||E||, ||E'||) plane; () when not valid."""
        return self.region.vertices if self.valid else ()

    def region_ratio(self, sup_E: float, sup_Edot: float) -> float:
        """The region's ratio at (sup|E|, sup|E'|) (:meth:`Region.ratio`): <= 1 inside; inf when not valid."""
        return self.region.ratio(sup_E, sup_Edot) if self.valid else math.inf

    def inside(self, sup_E: float, sup_Edot: float) -> bool:
        """The run's sup|E|, sup|E'| lie in the certified region (so also below E_max, Edot_max).

        A diverged run (inf or NaN sup) is outside; a negative sup is refused.
        """
        for name, v in (("sup_E", sup_E), ("sup_Edot", sup_Edot)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v < 0:
                raise ParameterError(f"{name} = {v!r} is not accepted: a number >= 0 (inf or NaN: diverged) "
                                     "is required")
            if not math.isfinite(v):
                return False
        return bool(self.valid and self.region.contains(sup_E, sup_Edot))

    def verdict(self, sup_E: float, sup_Edot: float) -> str:
        """One of VERDICTS: 'certified-*' only when every assumption is met."""
        where = "inside" if self.inside(sup_E, sup_Edot) else "outside"
        return f"{'certified' if self.certified else 'uncertified'}-{where}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (inf -> None): the Interface keys E_max, Edot_max, valid, assumptions [{name, met, value,
        limit, ...}], and what the claimant itself has: section 4's region writes condition and gamma1 ... delta3,
        section 4's terms (:meth:`SmallGainTerms.json_items`) their keys and the regime; a claim without them (a box
        claim, the sampled-data certificate, whose own terms are in its ``inputs``) writes none of them."""
        small_gain = isinstance(self.region, SmallGainRegion)
        out: dict[str, Any] = {"E_max": finite_or_none(self.E_max), "Edot_max": finite_or_none(self.Edot_max)}
        if small_gain:  # section 4's region: (4.23) and the gains of (4.14), (4.18); no other claim has them
            out["condition"] = finite_or_none(self.condition)
        out.update(valid=bool(self.valid), certified=self.certified, reason=self.reason,
                   assumptions=[a.to_dict() for a in self.assumptions], unmet=list(self.unmet))
        for name in _REGION_KEYS if small_gain else ():
            out[name] = finite_or_none(getattr(self, name))
        out.update(alpha_max=finite_or_none(self.alpha_max), voltage_max=finite_or_none(self.voltage_max))
        if self.terms is not None:  # section 4's terms; a claim without them writes none
            out.update(self.terms.json_items())
            out["regime"] = _regime(self.terms)
        out["iterations"] = int(self.iterations)
        out["vertices"] = [list(v) for v in self.vertices]
        out["inputs"] = _clean_inputs(self.inputs)
        if not isinstance(self.region, SmallGainRegion):  # the section-4 certificate's keys, as they have always been
            out["region"] = self.region.kind
        if self.claimant:
            out["claimant"] = self.claimant
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, measurement_cause: MeasurementCause | None = None) -> Certificate:
        """The claim of its JSON ``d`` (what :meth:`to_dict` wrote), such that ``to_dict()`` writes ``d`` again.

        The region is rebuilt from its numbers (section 4's from gamma1 ... delta3 and its corner; a box from
        E_max, Edot_max); a null number (not finite) is inf. Not in the JSON, so not restored: the terms'
        ``delta1_parts`` (()), their ``measurement_cause`` (``measurement_cause``: the run JSON's
        ``measurement_errors``, given by the caller), ``analysis`` (''); the ``inputs`` are the law's inputs as
        a mapping (not the typed record they were).

        Raises:
            ParameterError: a region kind this module does not know (a plug-in's own region): one line.
        """
        E_max, Edot_max = _inf_if_none(d["E_max"]), _inf_if_none(d["Edot_max"])
        kind = d.get("region", SmallGainRegion.kind)
        region: Region
        if kind == SmallGainRegion.kind:
            region = SmallGainRegion(**{name: _inf_if_none(d[name]) for name in _REGION_KEYS},
                                     E_max=E_max, Edot_max=Edot_max)
        elif kind == BoxRegion.kind:
            region = BoxRegion(E_max=E_max, Edot_max=Edot_max)
        else:
            raise ParameterError(f"region {kind!r} is not read back: a certificate's JSON is read for the regions "
                                 f"{SmallGainRegion.kind!r} and {BoxRegion.kind!r}")
        terms = (SmallGainTerms.from_json_items(d, measurement_cause=measurement_cause)
                 if "friction_term" in d else None)
        assumptions = tuple(Assumption.from_dict(a) for a in d["assumptions"])
        return cls(region=region, valid=d["valid"], assumptions=assumptions,
                   alpha_max=_inf_if_none(d["alpha_max"]), voltage_max=_inf_if_none(d["voltage_max"]), terms=terms,
                   reason=d["reason"], iterations=d["iterations"], inputs=ClaimInputs(law=dict(d["inputs"])),
                   claimant=d.get("claimant", ""))


#: The claim type (section 4's certificate and a law's own claim alike).
Claim = Certificate

#: The name of the run's law's own claim in :class:`Claims` (section 4's certificate, or a box claim).
LAW_CLAIM = "law"


class Claims(Mapping[str, Certificate]):
    """The claims a run is judged by, by name, read-only (and picklable, for a batch's workers): the law's
    own under :data:`LAW_CLAIM`, any further analysis (a sampled-data certificate) as one more entry.

    Raises:
        TypeError: a value that is not a :class:`Certificate`.
    """

    def __init__(self, claims: Mapping[str, Certificate] | None = None) -> None:
        for name, c in (claims or {}).items():
            if not isinstance(c, Certificate):
                raise TypeError(f"claim {name!r} must be a Certificate, got {type(c).__name__}")
        self._claims: dict[str, Certificate] = dict(claims or {})

    def __getitem__(self, name: str) -> Certificate:
        return self._claims[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._claims)

    def __len__(self) -> int:
        return len(self._claims)

    def __repr__(self) -> str:
        return f"Claims({self._claims!r})"


def claim_set(**claims: Certificate | None) -> Claims:
    """:class:`Claims` of the claims given by name (None: that analysis states none, left out).

    Raises:
        TypeError: a value that is not a :class:`Certificate`.
    """
    return Claims({k: c for k, c in claims.items() if c is not None})


def _clean_inputs(obj: Any) -> Any:
    if isinstance(obj, Mapping):
        return {str(k): _clean_inputs(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean_inputs(v) for v in obj]
    if isinstance(obj, float):
        return finite_or_none(obj)
    return obj


@dataclass(frozen=True)
class CertificateJudgement:
    """The certificate with one run judged against it (:func:`judge`); read by attribute.

    Attributes:
        certificate: the certificate the run is judged by.
        inside: the run's (sup|E|, sup|E'|) lies in the region (4.21).
        E_ratio: sup|E| / E_max [-]; None when there is no finite bound.
        Edot_ratio: sup|E'| / Edot_max [-]; None when there is no finite bound.
        region_ratio: max of the two sides of (4.21) [-], <= 1 inside; None when not valid.
        verdict: one of :data:`VERDICTS`.
        sup_E: the run's sup|E| [rad]; None when not finite (a diverged run).
        sup_Edot: the run's sup|E'| [rad/s]; None when not finite.
    """

    certificate: Certificate
    inside: bool
    E_ratio: float | None
    Edot_ratio: float | None
    region_ratio: float | None
    verdict: str
    sup_E: float | None
    sup_Edot: float | None

    @property
    def E_max(self) -> float | None:
        """The certificate's bound on |E| [rad]; None when there is none (as the JSON writes it)."""
        return finite_or_none(self.certificate.E_max)

    @property
    def Edot_max(self) -> float | None:
        """The certificate's bound on |E'| [rad/s]; None when there is none."""
        return finite_or_none(self.certificate.Edot_max)

    @property
    def condition(self) -> float | None:
        """The left side of (4.23) [-]; None when not finite."""
        return finite_or_none(self.certificate.condition)

    @property
    def valid(self) -> bool:
        """The bound exists (fixed point found, (4.23) < 1)."""
        return bool(self.certificate.valid)

    @property
    def certified(self) -> bool:
        """The bound exists and every assumption is met."""
        return self.certificate.certified

    @property
    def assumptions(self) -> tuple[Assumption, ...]:
        """Every assumption, checked and stated, with its value and limit."""
        return self.certificate.assumptions

    @property
    def unmet(self) -> tuple[str, ...]:
        """Names of the assumptions that are not met."""
        return self.certificate.unmet

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the certificate's :meth:`Certificate.to_dict` with inside, E_ratio, Edot_ratio,
        region_ratio, verdict, sup_E and sup_Edot added (the keys of the run summary's certificate)."""
        out = self.certificate.to_dict()
        out.update(inside=self.inside, E_ratio=self.E_ratio, Edot_ratio=self.Edot_ratio,
                   region_ratio=self.region_ratio, verdict=self.verdict, sup_E=self.sup_E, sup_Edot=self.sup_Edot)
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, measurement_cause: MeasurementCause | None = None
                  ) -> CertificateJudgement:
        """The judgement of its JSON ``d`` (:meth:`to_dict`): the certificate as :meth:`Certificate.from_dict`
        restores it (``measurement_cause`` goes to its terms), and the run's numbers as written."""
        return cls(certificate=Certificate.from_dict(d, measurement_cause=measurement_cause), inside=d["inside"],
                   E_ratio=d["E_ratio"], Edot_ratio=d["Edot_ratio"], region_ratio=d["region_ratio"],
                   verdict=d["verdict"], sup_E=d["sup_E"], sup_Edot=d["sup_Edot"])


def judge(cert: Certificate, sup_E: float, sup_Edot: float) -> CertificateJudgement:
    """The certificate with the run judged against it.

    Args:
        cert: the certificate.
        sup_E: the run's sup|E| [rad] (inf or NaN: diverged).
        sup_Edot: the run's sup|E'| [rad/s].

    Returns:
        CertificateJudgement: inside (the claim's region), E_ratio = sup|E|/E_max, Edot_ratio =
        sup|E'|/Edot_max (None when the bound is infinite), region_ratio (<= 1 inside) and verdict.

    Raises:
        ParameterError: a negative sup.
    """
    inside = cert.inside(sup_E, sup_Edot)
    ok = cert.valid and cert.E_max > 0 and cert.Edot_max > 0
    return CertificateJudgement(
        certificate=cert,
        inside=inside,
        E_ratio=finite_or_none(float(sup_E) / cert.E_max) if ok else None,
        Edot_ratio=finite_or_none(float(sup_Edot) / cert.Edot_max) if ok else None,
        region_ratio=finite_or_none(cert.region_ratio(sup_E, sup_Edot)),
        verdict=cert.verdict(sup_E, sup_Edot),
        sup_E=finite_or_none(sup_E),
        sup_Edot=finite_or_none(sup_Edot),
    )
