"""Type stubs of the extension module robot_survey._core (python/src/lib.rs).

Each function returns what the matching `survey … --format json` prints (a JSON string);
the Python modules around it build DataFrames and objects from it.
"""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

class SurveyError(ValueError): ...

class Design:
    def __init__(self, name_or_path: str = "mugatu") -> None: ...
    @staticmethod
    def from_toml(text: str, origin: str = "<string>") -> Design: ...
    @property
    def name(self) -> str: ...
    @property
    def leg_length_m(self) -> float: ...
    @property
    def mass_kg(self) -> float: ...
    def get(self, path: str) -> float: ...
    def with_values(self, values: Sequence[Tuple[str, float]]) -> Design: ...
    def with_effects(self, effects: Sequence[str]) -> Design: ...
    def to_toml(self) -> str: ...
    def to_json(self) -> str: ...
    def uncertain_json(self) -> str: ...

_DesignArg = Union[Design, str]

def dataset_parquet(
    release: Optional[str] = None, path: Optional[str] = None
) -> Tuple[bytes, str]: ...
def fit_json(
    release: Optional[str] = None,
    path: Optional[str] = None,
    method_name: str = "ols",
    confidence_level: float = 0.95,
    bootstrap: Optional[int] = None,
    seed: int = 1,
) -> str: ...
def predict_json(
    leg_length_m: Optional[float] = None,
    mass_budget_kg: Optional[float] = None,
    cls: str = "lower-biped",
    from_: Optional[str] = None,
    release: Optional[str] = None,
    path: Optional[str] = None,
    confidence_level: float = 0.95,
    torque_contact: str = "fixed-material",
    torque_margin: float = 2.0,
    table3_points: Optional[str] = None,
    speed_kind: str = "top",
) -> str: ...
def walk(
    design: _DesignArg,
    leg_length_m: Optional[float] = None,
    mass_law_name: str = "l2",
    contact_rule: str = "similar",
    duration_s: float = 25.0,
    seed: Optional[int] = None,
    torque_limit_nm: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    effects: Sequence[str] = ...,
    trajectory: bool = True,
) -> Tuple[str, Optional[Dict[str, List[Any]]]]: ...
def min_torque_json(
    design: _DesignArg,
    leg_length_m: Optional[float] = None,
    mass_law_name: str = "l2",
    contact_rule: str = "similar",
    duration_s: float = 25.0,
    seed: Optional[int] = None,
    seeds: int = 2,
    tolerance: float = 0.02,
    cap: float = 2.0,
    effects: Sequence[str] = ...,
) -> str: ...
def table3_json(
    designs: Sequence[_DesignArg],
    mass_laws: Sequence[str],
    contacts: Sequence[str],
    sizes: int = 36,
    leg_lengths_m: Optional[Sequence[float]] = None,
    duration_s: float = 25.0,
    seeds: int = 2,
    tolerance: float = 0.02,
    cap: float = 2.0,
    points: Optional[str] = None,
    progress: Optional[Callable[[int, int, str], Any]] = None,
) -> str: ...
def gap_effects_json(design: Optional[_DesignArg] = None) -> str: ...
def gap_synth_csv(
    design: str = "mugatu",
    effects: Sequence[str] = ...,
    set: Sequence[str] = ...,
    noise: float = 0.05,
    seed: int = 0,
    conditions_path: Optional[str] = None,
    conditions_text: Optional[str] = None,
    origin: str = "<DataFrame>",
    base_dir: Optional[str] = None,
) -> str: ...
def gap_diagnose_json(
    path: Optional[str] = None,
    text: Optional[str] = None,
    origin: str = "<DataFrame>",
    base_dir: Optional[str] = None,
    effects: Sequence[str] = ...,
    grid: int = 9,
    default_sd: float = 0.10,
    calibrate: bool = True,
    reference_path: Optional[str] = None,
    reference_text: Optional[str] = None,
    reference_origin: str = "<DataFrame>",
    undeclared: bool = True,
    criterion: Optional[str] = None,
) -> Tuple[str, str]: ...
def trial_columns() -> List[str]: ...
def builtin_designs() -> List[str]: ...
def version() -> str: ...
