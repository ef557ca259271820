"""Type stubs of robot_survey (the public API; see the docstrings in the .py files)."""

import os
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Union

import polars as pl

from . import gap as gap
from .gap import Effect

__version__: str

_PathLike = Union[str, os.PathLike[str]]
_Effects = Union[None, Mapping[str, float], Iterable[Union[str, Effect]]]

class SurveyError(ValueError):
    """Bad input or data; the message is the `survey` CLI's (file:line:field where known)."""

class Result:
    def __init__(self, data: Dict[str, Any]) -> None: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_json(self) -> str: ...
    def keys(self) -> List[str]: ...
    def __getitem__(self, key: str) -> Any: ...
    def __getattr__(self, key: str) -> Any: ...

class Prediction(Result):
    @property
    def quantities(self) -> pl.DataFrame: ...
    @property
    def torques(self) -> pl.DataFrame: ...
    @property
    def actuators(self) -> pl.DataFrame: ...

class WalkResult(Result):
    def __init__(self, data: Dict[str, Any], trajectory: Optional[pl.DataFrame]) -> None: ...
    @property
    def metrics(self) -> Dict[str, Any]: ...
    @property
    def trajectory(self) -> Optional[pl.DataFrame]: ...

class MinTorque(Result): ...

class Table3(Result):
    @property
    def rows(self) -> pl.DataFrame: ...
    @property
    def points(self) -> pl.DataFrame: ...

class Design:
    def __init__(self, name_or_path: _PathLike = "mugatu") -> None: ...
    @classmethod
    def from_toml(cls, text: str, origin: str = "<string>") -> Design: ...
    @classmethod
    def load(cls, path: _PathLike) -> Design: ...
    @property
    def name(self) -> str: ...
    @property
    def leg_length_m(self) -> float: ...
    @property
    def mass_kg(self) -> float: ...
    def get(self, path: str) -> float: ...
    def __getitem__(self, path: str) -> float: ...
    def with_value(self, path: str, value: float) -> Design: ...
    def with_values(self, values: Mapping[str, float]) -> Design: ...
    def with_effects(self, effects: _Effects) -> Design: ...
    def to_toml(self) -> str: ...
    def save(self, path: _PathLike) -> None: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def uncertain(self) -> pl.DataFrame: ...
    def walk(self, **kwargs: Any) -> WalkResult: ...
    def min_torque(self, **kwargs: Any) -> MinTorque: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

def designs() -> List[str]: ...
def dataset(release: Optional[str] = None, path: Optional[_PathLike] = None) -> pl.DataFrame: ...
def dataset_info(
    release: Optional[str] = None, path: Optional[_PathLike] = None
) -> Dict[str, Any]: ...
def fit_report(
    release: Optional[str] = None,
    method: str = "ols",
    *,
    path: Optional[_PathLike] = None,
    confidence: float = 0.95,
    bootstrap: Optional[int] = None,
    seed: int = 1,
) -> Dict[str, Any]: ...
def fit(
    release: Optional[str] = None,
    method: str = "ols",
    classes: Union[None, str, Sequence[str]] = None,
    *,
    path: Optional[_PathLike] = None,
    confidence: float = 0.95,
    bootstrap: Optional[int] = None,
    seed: int = 1,
) -> pl.DataFrame: ...
def predict(
    leg_length_m: Optional[float] = None,
    *,
    cls: str = "lower-biped",
    from_: Optional[str] = None,
    mass_budget_kg: Optional[float] = None,
    release: Optional[str] = None,
    path: Optional[_PathLike] = None,
    confidence: float = 0.95,
    torque_contact: str = "fixed-material",
    torque_margin: float = 2.0,
    table3_points: Optional[_PathLike] = None,
    speed_kind: str = "top",
) -> Prediction: ...
def walk(
    design: Union[_PathLike, Design] = "mugatu",
    leg_length_m: Optional[float] = None,
    duration_s: float = 25.0,
    effects: _Effects = None,
    seed: Optional[int] = None,
    *,
    mass_law: str = "l2",
    contact: str = "similar",
    torque_limit_nm: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    trajectory: bool = True,
) -> WalkResult: ...
def min_torque(
    design: Union[_PathLike, Design] = "mugatu",
    leg_length_m: Optional[float] = None,
    *,
    mass_law: str = "l2",
    contact: str = "similar",
    duration_s: float = 25.0,
    seed: Optional[int] = None,
    seeds: int = 2,
    tolerance: float = 0.02,
    cap: float = 2.0,
    effects: _Effects = None,
) -> MinTorque: ...
def table3(
    designs: Sequence[Union[str, Design]] = ("zippy", "zippy-spherical", "mugatu"),
    mass_laws: Sequence[str] = ("l2", "l3"),
    contact: str = "both",
    *,
    sizes: int = 36,
    leg_lengths_m: Optional[Sequence[float]] = None,
    duration_s: float = 25.0,
    seeds: int = 2,
    tolerance: float = 0.02,
    cap: float = 2.0,
    points: Optional[_PathLike] = None,
    progress: Union[bool, Callable[[int, int, str], Any]] = True,
) -> Table3: ...
