"""Requirements in Signal Temporal Logic, monitored by rtamt on a run's signals.

A requirement is an STL formula over the run's signals (:data:`SIGNALS`), e.g.
``always[8,35](abs(E) <= 0.05)``: from 8 s to 35 s the tracking error stays within
0.05 rad. Its robustness is rtamt's quantitative semantics at t = 0 (discrete time, one
sample per control step): > 0 satisfied with that margin, < 0 violated by that much
(for ``always[a,b](abs(x) <= c)``, min over the window of c - |x|). Time bounds are in
seconds and must be whole multiples of the control period.

Presets (:data:`PRESETS`) name the regions the testbed judges runs by:

- ``certificate``: the rectangle |E| <= E_max, |E'| <= Edot_max of the run's certificate,
  for the whole run (the certificate's region (4.21) lies inside it);
- ``paper``: the paper's claim, |E| <= E_max and |E'| <= Edot_max of its (4.21)-(4.23).

The monitor is rtamt's offline discrete-time STL interpreter (parser, predicates, Boolean
and temporal operators). Its bounded operators (always[a,b], eventually[a,b],
historically[a,b], once[a,b]) take the min/max of a list slice per sample, O(n w): 12 s
for always[8,35] over a 35 s run at 1 ms. :class:`_WindowedVisitor` overrides those four
with the same semantics (the same padding at the ends of the trace) computed as a sliding
min/max in O(n log w); a test holds them equal, to the bit, to rtamt's own on random
signals.

Usage::

    from wmr_mj.analysis.requirements import parse_requirement, evaluate
    req = parse_requirement("always[0,2](abs(x) <= 1)", period=1.0, signals=("x",))
    result = evaluate(req, {"x": [0.1, -0.5, 0.3, 0.9]}, period=1.0)
    result.robustness  # 0.5: min(1 - |x|) over samples 0..2
"""

from __future__ import annotations

import contextlib
import logging
import math
import re
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from wmr_mj.errors import ParameterError, UnknownNameError

__all__ = [
    "SIGNALS",
    "PRESETS",
    "Requirement",
    "RequirementResult",
    "parse_requirement",
    "evaluate",
    "evaluate_run",
    "preset_formula",
    "stl_number",
]

#: Signals a requirement may name (a run's rows: wmr_mj.sim.closed_loop.ROW_FIELDS), t in s; cross_track
#: is C's signed distance from its desired path [m] at every control step (computed when a formula names it).
SIGNALS = ("t", "E", "E_dot", "alpha", "alpha_dot", "alpha0", "voltage", "voltage_cmd", "cross_track")
#: Named requirements, resolved against a run's bounds (see :func:`preset_formula`).
PRESETS = {
    "certificate": "the certificate's rectangle for the whole run: always((abs(E) <= E_max) and "
                   "(abs(E_dot) <= Edot_max)) with the run's certificate",
    "paper": "the paper's claim for the whole run: always((abs(E) <= E_max) and (abs(E_dot) <= Edot_max)) "
             "with (4.21)-(4.23) as the paper bounds them",
    "cross-track": "C on its path: always[settle_s, end](abs(cross_track) <= bound) with the steady-state "
                   "cross-track bound the certificate implies (wmr_mj.analysis.path_bound), from the run's "
                   "settling time; none where the path has no Cartesian guarantee",
}


def stl_number(x: float) -> str:
    """A float as rtamt's grammar reads it (no exponent), shortest digits that round-trip."""
    return np.format_float_positional(float(x), unique=True, trim="-")


def preset_formula(name: str, E_max: float | None, Edot_max: float | None) -> str | None:
    """The formula of preset ``name`` for the bounds (None when there is no finite bound)."""
    if name not in PRESETS:
        raise UnknownNameError("requirement preset", name, PRESETS)
    if name == "cross-track":  # E_max carries the cross-track bound [m]; the window is evaluate()'s
        return None if E_max is None or not math.isfinite(E_max) else f"always(abs(cross_track) <= {stl_number(E_max)})"
    if E_max is None or Edot_max is None or not (math.isfinite(E_max) and math.isfinite(Edot_max)):
        return None
    return f"always((abs(E) <= {stl_number(E_max)}) and (abs(E_dot) <= {stl_number(Edot_max)}))"


# -- rtamt with windowed operators in O(n log w) ---------------------------------------------

def _sliding(y: np.ndarray, w: int, op) -> np.ndarray:
    """out[k] = op(y[k:k+w]) for k in 0 .. len(y)-w (sparse table: windows of 1, 2, 4, ...)."""
    m, p = y, 1
    while 2 * p <= w:
        m = op(m[:-p], m[p:])  # m[k] = op over y[k:k+2p]
        p *= 2
    count = len(y) - w + 1
    return op(m[:count], m[w - p:w - p + count])


def _window(sample: Sequence[float], lo: int, hi: int, op, fill: float) -> np.ndarray:
    """r[i] = op(sample[i+lo .. i+hi]) over the samples that exist, ``fill`` where none does."""
    x = np.asarray(sample, dtype=float)
    n = len(x)
    front, back = max(0, -lo), max(0, hi)
    y = np.concatenate([np.full(front, fill), x, np.full(back, fill)])
    s = _sliding(y, hi - lo + 1, op)
    return s[lo + front:lo + front + n]


def _reverse_accumulate(sample: Sequence[float], op, start: float) -> list[float]:
    """rtamt's unbounded always/eventually as it loops: out[i] = op(sample[i], out[i+1]), Python's min/max."""
    out, prev = [], start
    for v in reversed(sample):
        prev = op(v, prev)
        out.append(prev)
    out.reverse()
    return out


def _import_rtamt() -> None:
    """Import rtamt quietly. Its ANTLR-generated parsers import ``typing.io`` (deprecated; gone
    in Python 3.12): where it is missing, an alias module carries the one name they use."""
    import importlib
    import sys
    import types
    import typing
    import warnings

    if "rtamt" in sys.modules:
        return
    try:
        importlib.import_module("typing.io")
    except ImportError:
        alias = types.ModuleType("typing.io")
        alias.__dict__["TextIO"] = typing.TextIO
        sys.modules["typing.io"] = alias
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import rtamt  # noqa: F401


def _visitor_class():
    _import_rtamt()
    from rtamt.semantics.enumerations.comp_oper import StlComparisonOperator as Op
    from rtamt.semantics.stl.discrete_time.offline.ast_visitor import StlDiscreteTimeOfflineAstVisitor

    class _WindowedVisitor(StlDiscreteTimeOfflineAstVisitor):
        """rtamt's offline discrete-time visitor; the bounded operators as sliding windows, and abs, the
        comparisons and the unbounded always/eventually element by element in NumPy: the same IEEE
        operations as rtamt's Python loops (a test holds them equal to the bit). With a NaN in the
        samples the unbounded operators keep rtamt's loop: Python's min/max and NumPy's treat NaN apart.
        Its operators pass arrays among themselves (:meth:`visit_array`); rtamt's own operators, where they
        run, get the lists they were written for (:meth:`visit`).
        """

        def visit(self, node, *args, **kwargs):  # what rtamt's own operators call: lists
            result = self.visit_array(node, *args, **kwargs)
            return result.tolist() if isinstance(result, np.ndarray) else result

        def visit_array(self, node, *args, **kwargs):  # what ours call: arrays where ours computed them
            return super().visit(node, *args, **kwargs)

        def visitAbs(self, node, *args, **kwargs):
            return np.abs(np.asarray(self.visit_array(node.children[0], *args, **kwargs), dtype=float))

        def visitPredicate(self, node, *args, **kwargs):
            left = np.asarray(self.visit_array(node.children[0], *args, **kwargs), dtype=float)
            right = np.asarray(self.visit_array(node.children[1], *args, **kwargs), dtype=float)
            op = node.operator.value
            if op in (Op.LEQ.value, Op.LESS.value):
                return right - left
            if op in (Op.GEQ.value, Op.GREATER.value):
                return left - right
            if op == Op.EQ.value:
                return -np.abs(left - right)
            if op == Op.NEQ.value:
                return np.abs(left - right)
            return super().visitPredicate(node, *args, **kwargs)

        def visitAlways(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            x = np.asarray(sample, dtype=float)
            if np.isnan(x).any():
                return _reverse_accumulate(sample, min, math.inf)
            return np.minimum.accumulate(x[::-1])[::-1]

        def visitEventually(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            x = np.asarray(sample, dtype=float)
            if np.isnan(x).any():
                return _reverse_accumulate(sample, max, -math.inf)
            return np.maximum.accumulate(x[::-1])[::-1]

        def visitTimedAlways(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            if np.isnan(np.asarray(sample, dtype=float)).any():  # rtamt's own loop: its min/max of a NaN
                return super().visitTimedAlways(node, *args, **kwargs)
            begin, end = self.time_unit_transformer(node)
            return _window(sample, begin, end, np.minimum, math.inf)

        def visitTimedEventually(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            if np.isnan(np.asarray(sample, dtype=float)).any():  # rtamt's own loop: its min/max of a NaN
                return super().visitTimedEventually(node, *args, **kwargs)
            begin, end = self.time_unit_transformer(node)
            return _window(sample, begin, end, np.maximum, -math.inf)

        def visitTimedHistorically(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            if np.isnan(np.asarray(sample, dtype=float)).any():  # rtamt's own loop: its min/max of a NaN
                return super().visitTimedHistorically(node, *args, **kwargs)
            begin, end = self.time_unit_transformer(node)
            return _window(sample, -end, -begin, np.minimum, math.inf)

        def visitTimedOnce(self, node, *args, **kwargs):
            sample = self.visit_array(node.children[0], *args, **kwargs)
            if np.isnan(np.asarray(sample, dtype=float)).any():  # rtamt's own loop: its min/max of a NaN
                return super().visitTimedOnce(node, *args, **kwargs)
            begin, end = self.time_unit_transformer(node)
            return _window(sample, -end, -begin, np.maximum, -math.inf)

    return _WindowedVisitor


@contextlib.contextmanager
def _quiet_rtamt():
    """rtamt logs a warning on the root logger for an undeclared name before it raises."""
    previous = logging.root.manager.disable
    logging.disable(logging.WARNING)
    try:
        yield
    finally:
        logging.disable(previous)


def _spec(formula: str, period: float, signals: Sequence[str], *, stock: bool = False):
    """A parsed rtamt specification of ``formula`` (ParameterError / UnknownNameError on bad input).

    stock: rtamt's own visitor, windowed operators included (tests compare the two)."""
    _import_rtamt()
    from rtamt.exception.exception import RTAMTException
    from rtamt.explanation.stl.discrete_time.explainer import STLExplainer
    from rtamt.semantics.abstract_discrete_time_offline_interpreter import discrete_time_offline_interpreter_factory
    from rtamt.spec.abstract_specification import AbstractOfflineSpecification
    from rtamt.syntax.ast.parser.stl.specification_parser import StlAst

    if stock:
        from rtamt.semantics.stl.discrete_time.offline.ast_visitor import StlDiscreteTimeOfflineAstVisitor as visitor
    else:
        visitor = _visitor_class()
    spec = AbstractOfflineSpecification(StlAst(), discrete_time_offline_interpreter_factory(visitor)(),
                                        explainer=STLExplainer())
    spec.stock = stock
    for name in signals:
        spec.declare_var(name, "float")
    spec.set_sampling_period(int(round(period * 1e9)), "ns", 0.1)
    spec.spec = formula
    with _quiet_rtamt():
        try:
            spec.parse()
        except KeyError as exc:
            raise UnknownNameError("signal", str(exc.args[0]) if exc.args else "?", signals) from None
        except RTAMTException as exc:
            message = str(exc).replace("RTAMT Exception:", "").strip().split(" expecting ")[0]
            raise ParameterError(f"requirement {formula!r} is not an STL formula rtamt reads ({message}); "
                                 f"e.g. 'always[8,35](abs(E) <= 0.05)', signals: {', '.join(signals)}") from None
        except Exception as exc:  # noqa: BLE001  (the parser's own errors: one line, the formula named)
            raise ParameterError(f"requirement {formula!r} is not an STL formula rtamt reads "
                                 f"({type(exc).__name__}: {exc}); signals: {', '.join(signals)}") from None
    return spec


_PARSED = threading.local()  # each thread's parsed specifications: a spec holds its last run's signals
_PARSED_KEPT = 16


def _parsed(formula: str, period: float, signals: Sequence[str]):
    """:func:`_spec`, parsed once per thread and kept (the last :data:`_PARSED_KEPT`): a run's requirements
    are the same formulas run after run, and rtamt's ANTLR parser takes 0.7-4 ms a formula, as long as
    monitoring it over a 35 s run at 1 ms (2-3 ms; measured on the standard suite's four requirements)."""
    kept = getattr(_PARSED, "specs", None)
    if kept is None:
        kept = _PARSED.specs = {}
    key = (formula, float(period), tuple(signals))
    spec = kept.get(key)
    if spec is None:
        if len(kept) >= _PARSED_KEPT:
            kept.pop(next(iter(kept)))
        spec = kept[key] = _spec(formula, period, signals)
    return spec


def _robustness(spec, formula: str, signals: Mapping[str, Any], period: float) -> float:
    from rtamt.exception.exception import RTAMTException

    windowed = not getattr(spec, "stock", False)
    # our visitor takes arrays; rtamt's own takes the lists it was written for
    columns = {name: np.asarray(v, dtype=float) if windowed else np.asarray(v, dtype=float).tolist()
               for name, v in signals.items()}
    n = len(next(iter(columns.values()))) if columns else 0
    if n < 2:
        raise ParameterError(f"requirement {formula!r}: {n} sample(s) to monitor; rtamt needs at least 2")
    try:
        with _quiet_rtamt():
            if windowed:
                return float(_robustness_at_zero(spec, columns, n))
            out = spec.evaluate({"time": (np.arange(n) * period).tolist(), **columns})
    except RTAMTException as exc:
        message = str(exc).replace("RTAMT Exception:", "").strip()
        raise ParameterError(f"requirement {formula!r}: {message} ({period:g} s); give time bounds in s that are "
                             f"whole multiples of it") from None
    return float(out[0][1])


def _robustness_at_zero(spec, columns: Mapping[str, np.ndarray], n: int) -> float:
    """The robustness at t = 0 as rtamt's offline discrete-time ``evaluate`` computes it: the signals set on
    the syntax tree, the tree visited, the last formula's first sample; without rtamt's formatting of every
    sample into a [time, value] pair and its sampling-period check (the samples here are uniform by
    construction), which cost more than the monitor itself over a 35 s run."""
    interpreter = spec.offline_interpreter
    if spec.set_ast_flag is not True:
        interpreter.set_ast(spec.ast)
        spec.set_ast_flag = True
    interpreter.set_variable_to_ast_from_dataset(columns)
    interpreter.ast.offline_results["time"] = None  # read by rtamt's dense-time visitors only
    try:
        return interpreter.visit_array(interpreter.ast.specs[-1], n)[0]  # visitAst visits every spec: the last counts
    finally:
        interpreter.ast.offline_results.clear()  # each node's samples: a kept spec does not hold the run's


# -- requirements -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Requirement:
    """A requirement as given: a preset's name (:data:`PRESETS`) or an STL formula."""

    text: str
    signals: tuple[str, ...] = SIGNALS

    @property
    def preset(self) -> str | None:
        return self.text if self.text in PRESETS else None

    def names(self, signal: str) -> bool:
        """Whether the requirement reads ``signal`` (a preset: the signals of its formula)."""
        if self.preset is not None:
            return signal == "cross_track" if self.preset == "cross-track" else signal in ("E", "E_dot")
        return re.search(rf"(?<![A-Za-z0-9_]){re.escape(signal)}(?![A-Za-z0-9_])", self.text) is not None


@dataclass(frozen=True)
class RequirementResult:
    """One requirement judged on one run: the formula monitored (a preset resolved), its
    robustness at t = 0 (None: a preset with no finite bound; inf: vacuous, every window past
    the run's end) and whether it holds (robustness >= 0)."""

    requirement: str
    formula: str | None
    robustness: float | None
    satisfied: bool
    note: str = ""

    def to_dict(self) -> dict[str, Any]:
        d = {"formula": self.formula if self.formula is not None else self.requirement,
             "robustness": self.robustness, "satisfied": self.satisfied}
        if self.formula != self.requirement:
            d["requirement"] = self.requirement
        if self.note:
            d["note"] = self.note
        return d

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RequirementResult:
        """The result of its JSON ``d`` (what :meth:`to_dict` wrote): ``requirement`` is written only where it is
        not the formula, and a formula that is None (a preset with no finite bound) is written as the requirement."""
        if "requirement" not in d:
            return cls(requirement=d["formula"], formula=d["formula"], robustness=d["robustness"],
                       satisfied=d["satisfied"], note=d.get("note", ""))
        formula = None if d["formula"] == d["requirement"] else d["formula"]
        return cls(requirement=d["requirement"], formula=formula, robustness=d["robustness"],
                   satisfied=d["satisfied"], note=d.get("note", ""))


def parse_requirement(text: str, *, period: float, signals: Sequence[str] = SIGNALS) -> Requirement:
    """Check ``text`` (a preset or a formula over ``signals``) before any run: it parses, names
    known signals only, and its time bounds are multiples of ``period`` (s)."""
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"requirement {text!r} is empty; give an STL formula (e.g. 'always[8,35](abs(E) <= "
                             f"0.05)') or a preset: {', '.join(PRESETS)}")
    text = text.strip()
    signals = tuple(signals)
    if text not in PRESETS:
        spec = _spec(text, period, signals)
        _robustness(spec, text, dict.fromkeys(signals, np.zeros(2)), period)  # time bounds vs the period
    return Requirement(text, signals)


def evaluate(requirement: Requirement, signals: Mapping[str, Any], *, period: float,
             bounds: Mapping[str, tuple[float | None, float | None]] | None = None) -> RequirementResult:
    """Monitor ``requirement`` on ``signals`` (name -> samples, one per ``period`` s from t = 0).

    bounds: {preset: (E_max, Edot_max)} for the presets (see :func:`evaluate_run`)."""
    preset = requirement.preset
    formula = requirement.text
    if preset is not None:
        E_max, Edot_max = (bounds or {}).get(preset, (None, None))
        resolved = preset_formula(preset, E_max, Edot_max)
        if resolved is None:
            return RequirementResult(requirement.text, None, None, False,
                                     note=f"no {preset} region for this run: nothing to satisfy")
        formula = resolved
        window = (bounds or {}).get("cross-track window")
        if preset == "cross-track" and window is not None and window[0]:
            # the bound holds in steady state: from the path verdict's settling time, on the control grid
            n = len(next(iter(signals.values()))) if signals else 0
            start = math.ceil(float(window[0]) / period - 1e-9)
            if start < n - 1:
                window_s = f"{stl_number(start * period)},{stl_number((n - 1) * period)}"
                formula = formula.replace("always(", f"always[{window_s}](", 1)
    missing = [s for s in requirement.signals if s not in signals and requirement.names(s)]
    if missing:
        raise UnknownNameError("signal", missing[0], tuple(signals))
    n = len(next(iter(signals.values()))) if signals else 0
    # a signal the formula does not read is declared but never evaluated: it is left out of the data (two
    # zeros stand in where the formula reads none, for the length)
    read = [s for s in requirement.signals if requirement.names(s) or s in formula]
    columns = {s: signals[s] for s in read if s in signals} or {requirement.signals[0]: np.zeros(n)}
    spec = _parsed(formula, period, requirement.signals)
    rob = _robustness(spec, formula, columns, period)
    note = "vacuous: every window lies past the run's end" if math.isinf(rob) and rob > 0 else ""
    return RequirementResult(requirement.text, formula, rob, bool(rob >= 0.0), note=note)


def evaluate_run(requirements: Sequence[Requirement], rows: Mapping[str, Any], summary: Mapping[str, Any], *,
                 period: float) -> list[RequirementResult]:
    """Every requirement on a run's rows (wmr_mj.sim.closed_loop.RunResult.rows), the presets
    resolved against its summary's certificate and paper region."""

    def pair(region: Any) -> tuple[float | None, float | None]:
        if not isinstance(region, Mapping):
            return None, None
        e, ed = region.get("E_max"), region.get("Edot_max")
        return (None if e is None else float(e)), (None if ed is None else float(ed))

    verdict = summary.get("path_verdict")
    cross = verdict.get("cross_track_bound") if isinstance(verdict, Mapping) else None
    bounds = {"certificate": pair(summary.get("certificate")),
              "paper": pair(summary.get("paper_region") or {"E_max": summary.get("E_max"),
                                                            "Edot_max": summary.get("Edot_max")}),
              "cross-track": (None if cross is None else float(cross), None),
              "cross-track window": (summary.get("settle_s"), None)}
    return [evaluate(r, rows, period=period, bounds=bounds) for r in requirements]
