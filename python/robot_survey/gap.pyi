"""Type stubs of robot_survey.gap."""

import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import polars as pl

from . import Design, Result

_PathLike = Union[str, os.PathLike[str]]
_Trials = Union[_PathLike, pl.DataFrame, Any]
_Effects = Union[None, Mapping[str, float], Iterable[Union[str, "Effect"]]]

class EffectParam:
    name: str
    unit: str
    default: float
    min: float
    max: float
    off: float
    scale: str
    scale_value: float
    note: str
    def __init__(
        self,
        name: str,
        unit: str,
        default: float,
        min: float,
        max: float,
        off: float,
        scale: str,
        scale_value: float,
        note: str,
    ) -> None: ...

class Effect:
    name: str
    description: str
    models: str
    scaling: str
    design: str
    params: Tuple[EffectParam, ...]
    values: Mapping[str, float]
    def __init__(
        self,
        name: str,
        description: str,
        models: str,
        scaling: str,
        design: str,
        params: Tuple[EffectParam, ...],
        values: Mapping[str, float],
    ) -> None: ...
    @property
    def magnitude(self) -> float: ...
    def with_value(self, param: Optional[str] = None, value: float = 0.0) -> Effect: ...
    def args(self) -> List[str]: ...
    def table(self) -> pl.DataFrame: ...
    def to_dict(self) -> Dict[str, Any]: ...

class Diagnosis(Result):
    timing: Dict[str, Any]
    def __init__(self, data: Dict[str, Any], timing: Dict[str, Any]) -> None: ...
    @property
    def statement(self) -> str: ...
    @property
    def probabilities(self) -> Dict[str, float]: ...
    @property
    def posterior(self) -> pl.DataFrame: ...
    @property
    def explanations(self) -> pl.DataFrame: ...
    @property
    def where(self) -> pl.DataFrame: ...
    @property
    def regimes(self) -> pl.DataFrame: ...
    @property
    def detectable(self) -> pl.DataFrame: ...
    @property
    def residuals(self) -> pl.DataFrame: ...

def effects(design: Union[str, Design] = "mugatu") -> List[Effect]: ...
def effect(name: str, design: Union[str, Design] = "mugatu") -> Effect: ...
def trial_columns() -> List[str]: ...
def read_trials(text: str) -> pl.DataFrame: ...
def synth(
    design: str = "mugatu",
    effects: _Effects = None,
    *,
    set: Optional[Mapping[str, float]] = None,
    noise: float = 0.05,
    seed: int = 0,
    conditions: Optional[_Trials] = None,
    out: Optional[_PathLike] = None,
) -> pl.DataFrame: ...
def diagnose(
    trials: _Trials,
    *,
    effects: Optional[Sequence[str]] = None,
    grid: int = 9,
    default_sd: float = 0.10,
    calibrate: bool = True,
    reference: Optional[_Trials] = None,
    undeclared: bool = True,
    criterion: Optional[_PathLike] = None,
) -> Diagnosis: ...
