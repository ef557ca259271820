"""The sim-to-real gap: candidate unmodelled effects, synthetic trials, the diagnosis.

* ``effects(design)``: the effect library (``dataset/effects/``) as ``Effect`` objects.
* ``synth(...)``: "real" trials simulated with effects the nominal model lacks, or wrong
  parameters, plus measurement noise (``survey gap synth``).
* ``diagnose(trials)``: where the simulation misses the trials, which effect or parameter
  explains it, how far the gap shrinks (``survey gap diagnose``).
"""

from __future__ import annotations

import dataclasses
import io
import json
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import polars as pl

from . import _core
from ._design import Design, EffectsArg, design_arg, effect_args
from ._results import PathLike, Result, fspath, frame

__all__ = [
    "Effect",
    "EffectParam",
    "Diagnosis",
    "effects",
    "effect",
    "synth",
    "diagnose",
    "trial_columns",
    "read_trials",
]


@dataclasses.dataclass(frozen=True)
class EffectParam:
    """One parameter of an effect, in SI for the design the library was read for."""

    name: str
    unit: str
    default: float
    min: float
    max: float
    off: float
    scale: str
    scale_value: float
    note: str


@dataclasses.dataclass(frozen=True)
class Effect:
    """A candidate unmodelled effect (``dataset/effects/NAME.toml``) with parameter values.

    ``values`` are SI at ``design``'s 1× size (defaults: the library's). ``with_value``
    returns a copy with one parameter changed; pass effects to ``robot_survey.walk(...,
    effects=[e])``, ``Design.with_effects([e])`` or ``synth(effects=[e])``.
    """

    name: str
    description: str
    models: str
    scaling: str
    design: str
    params: Tuple[EffectParam, ...]
    values: Mapping[str, float]

    @property
    def magnitude(self) -> float:
        """The first parameter's value (what ``NAME=VALUE`` sets)."""
        return self.values[self.params[0].name]

    def with_value(self, param: Optional[str] = None, value: float = 0.0) -> "Effect":
        """A copy with ``param`` (default: the magnitude, the first parameter) set."""
        name = self.params[0].name if param is None else param
        if name not in self.values:
            raise _core.SurveyError(
                f"effect {self.name} has no parameter {name!r}; it has "
                f"{', '.join(p.name for p in self.params)}"
            )
        values = dict(self.values)
        values[name] = float(value)
        return dataclasses.replace(self, values=values)

    def args(self) -> List[str]:
        """The ``NAME.PARAM=VALUE`` arguments of ``survey gap synth --effect`` for it."""
        return [f"{self.name}.{p}={float(v)!r}" for p, v in self.values.items()]

    def table(self) -> pl.DataFrame:
        """The parameters: unit, default, plausible range, off value, current value."""
        rows = [dict(dataclasses.asdict(p), value=self.values[p.name]) for p in self.params]
        return pl.DataFrame(rows)

    def to_dict(self) -> Dict[str, Any]:
        """The effect as a dict (what ``survey gap effects --format json`` lists, plus the
        values)."""
        d = dataclasses.asdict(self)
        d["params"] = [dataclasses.asdict(p) for p in self.params]
        d["values"] = dict(self.values)
        return d


def effects(design: Union[str, Design] = "mugatu") -> List[Effect]:
    """The effect library with each parameter in SI for ``design`` at its 1× size
    (``survey gap effects``)."""
    lib = json.loads(_core.gap_effects_json(design_arg(design)))
    name = design.name if isinstance(design, Design) else os.fspath(design)
    out = []
    for e in lib:
        params = tuple(EffectParam(**p) for p in e["params"])
        out.append(
            Effect(
                name=e["name"],
                description=e["description"],
                models=e["models"],
                scaling=e["scaling"],
                design=name,
                params=params,
                values={p.name: p.default for p in params},
            )
        )
    return out


def effect(name: str, design: Union[str, Design] = "mugatu") -> Effect:
    """One effect of the library by name (see ``effects``)."""
    for e in effects(design):
        if e.name == name:
            return e
    raise _core.SurveyError(
        f"unknown effect `{name}` (one of: {', '.join(e.name for e in effects(design))})"
    )


def trial_columns() -> List[str]:
    """The columns of a trials CSV, in order (``dataset/trials/README.md``)."""
    return list(_core.trial_columns())


TrialsArg = Union[str, "os.PathLike[str]", pl.DataFrame, Any]


def _trials_text(trials: Any) -> Optional[str]:
    """CSV text of a polars or pandas DataFrame of trials (None: not a DataFrame)."""
    if isinstance(trials, pl.DataFrame):
        return trials.write_csv()
    if type(trials).__module__.startswith("pandas") and hasattr(trials, "to_csv"):
        return trials.to_csv(index=False)
    return None


def _trials_args(trials: Any) -> Dict[str, Any]:
    text = _trials_text(trials)
    if text is not None:
        return {"path": None, "text": text, "origin": "<DataFrame>", "base_dir": os.getcwd()}
    if isinstance(trials, (str, os.PathLike)):
        return {"path": os.fspath(trials), "text": None, "origin": "", "base_dir": None}
    raise TypeError(
        f"trials: expected a path to a trials CSV or a polars/pandas DataFrame, got {type(trials)!r}"
    )


def read_trials(text: str) -> pl.DataFrame:
    """A trials CSV (text, ``#`` comment lines allowed) as a DataFrame."""
    return pl.read_csv(
        io.StringIO(text), comment_prefix="#", infer_schema_length=None
    )


def synth(
    design: str = "mugatu",
    effects: EffectsArg = None,
    *,
    set: Optional[Mapping[str, float]] = None,
    noise: float = 0.05,
    seed: int = 0,
    conditions: Optional[TrialsArg] = None,
    out: Optional[PathLike] = None,
) -> pl.DataFrame:
    """Synthetic "real" trials (``survey gap synth``): the design's default conditions (or
    those of ``conditions``, a trials file or DataFrame) simulated with ``effects`` the
    nominal model lacks and design values ``set`` differently (``{"mass.leg_com_height_over_l":
    0.52}``), plus Gaussian measurement noise of relative sd ``noise`` (seeded).

    Returns the trials as a DataFrame; ``out`` also writes the CSV the CLI writes.
    """
    set_args = [f"{k}={float(v)!r}" for k, v in (set or {}).items()]
    cond: Dict[str, Any] = {"path": None, "text": None, "origin": "<DataFrame>", "base_dir": None}
    if conditions is not None:
        cond = _trials_args(conditions)
    text = _core.gap_synth_csv(
        design,
        effect_args(effects),
        set_args,
        float(noise),
        seed,
        cond["path"],
        cond["text"],
        cond["origin"] or "<DataFrame>",
        cond["base_dir"],
    )
    if out is not None:
        with open(os.fspath(out), "w", encoding="utf-8") as f:
            f.write(text)
    return read_trials(text)


class Diagnosis(Result):
    """``survey gap diagnose --format json`` as an object.

    * ``statement``, ``answer``: the verdict (``answer["kind"]``: no_gap, parameters_off,
      effect_missing, both, ambiguous, unexplained), the explanation named with its values'
      credible intervals, the leading explanations, P(something outside these).
    * ``posterior``: every explanation weighed and its posterior probability.
    * ``explanations``: the most probable explanations with prior, evidence, values and
      intervals, χ² at the mode and the posterior-predictive p.
    * ``where``: per metric, how large the gap is and its trends; ``regimes``: per metric,
      design and size.
    * ``detectable``, ``spread``, ``residuals``: the other tables.
    * ``timing``: wall-clock seconds per phase (not part of the deterministic result).
    """

    def __init__(self, data: Dict[str, Any], timing: Dict[str, Any]) -> None:
        super().__init__(data)
        self.timing = timing

    @property
    def statement(self) -> str:
        """The answer in one sentence."""
        return self._data["answer"]["statement"]

    @property
    def probabilities(self) -> Dict[str, float]:
        """Every explanation's posterior probability, most probable first."""
        return {p["explanation"]: p["probability"] for p in self._data["posterior"]}

    @property
    def posterior(self) -> pl.DataFrame:
        """Every explanation and its posterior probability."""
        return frame(self._data["posterior"])

    @property
    def explanations(self) -> pl.DataFrame:
        """The most probable explanations: prior, probability, evidence, fit."""
        return frame(
            {k: v for k, v in e.items() if k != "knobs"} for e in self._data["explanations"]
        )

    @property
    def where(self) -> pl.DataFrame:
        """Where the gap lies: one row per metric."""
        return frame(
            {k: v for k, v in m.items() if k != "regimes"} for m in self._data["where"]
        )

    @property
    def regimes(self) -> pl.DataFrame:
        """The gap per metric, design and size."""
        return frame(r for m in self._data["where"] for r in m["regimes"])

    @property
    def detectable(self) -> pl.DataFrame:
        """Per suspect, the smallest change these trials can tell from nothing."""
        return frame(self._data["detectable"])

    @property
    def residuals(self) -> pl.DataFrame:
        """Every measurement: simulated, z before and after."""
        return frame(self._data["residuals"])

    def __repr__(self) -> str:
        return f"Diagnosis({self._data['answer']['kind']}: {self.statement})"


def diagnose(
    trials: TrialsArg,
    *,
    effects: Optional[Sequence[str]] = None,
    grid: int = 9,
    default_sd: float = 0.10,
    calibrate: bool = True,
    reference: Optional[TrialsArg] = None,
    undeclared: bool = True,
    criterion: Optional[PathLike] = None,
) -> Diagnosis:
    """Diagnoses trials against the simulator (``survey gap diagnose``): the posterior
    probability of every explanation and the answer drawn from it; runs with the GIL
    released.

    Parameters
    ----------
    trials:
        A trials CSV path (``dataset/trials/published.csv``) or a polars/pandas DataFrame with
        its columns (``trial_columns()``; relative trajectory files are then resolved
        against the working directory, and error lines count the header as line 1).
    effects:
        Candidate effects (names; default: the whole library).
    grid:
        Walks per suspect across its range before its curve is refined.
    default_sd:
        Relative sd assumed where a measurement states none.
    calibrate:
        The designs' ``[[uncertain]]`` parameters are suspects (False: only effects and
        undeclared numbers are).
    reference:
        Trials of the same conditions without the change (``survey gap diagnose
        --reference``): a path or a DataFrame. Each metric is then carried onto the model as
        nominal + (trial − reference), so a discrepancy the model has everywhere (another
        engine, an unmodelled property of the robot) is not blamed on an effect.
    undeclared:
        The designs' undeclared numbers are suspects too (False is ``--no-undeclared``).
    criterion:
        A criterion file in place of the bundled ``dataset/gap/criterion.toml``.
    """
    a = _trials_args(trials)
    r = _trials_args(reference) if reference is not None else None
    text, timing = _core.gap_diagnose_json(
        a["path"],
        a["text"],
        a["origin"] or "<DataFrame>",
        a["base_dir"],
        list(effects or []),
        grid,
        float(default_sd),
        calibrate,
        r["path"] if r else None,
        r["text"] if r else None,
        (r["origin"] or "<DataFrame>") if r else "<DataFrame>",
        bool(undeclared),
        fspath(criterion) if criterion is not None else None,
    )
    return Diagnosis(json.loads(text), json.loads(timing))
