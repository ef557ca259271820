"""Walker designs as Python objects."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Union

import polars as pl

from . import _core
from ._results import PathLike

EffectsArg = Union[None, Mapping[str, float], Iterable[Any]]


def effect_args(effects: EffectsArg) -> List[str]:
    """``NAME=VALUE`` / ``NAME.PARAM=VALUE`` strings (as ``survey gap synth --effect``).

    Accepts a mapping ``{"hip_coulomb_friction": 0.05}`` (a name sets the magnitude,
    ``name.param`` one parameter), ``gap.Effect`` objects, or such strings.
    """
    if effects is None:
        return []
    if isinstance(effects, str):
        return [effects]
    if isinstance(effects, Mapping):
        return [f"{k}={float(v)!r}" for k, v in effects.items()]
    out: List[str] = []
    for e in effects:
        if isinstance(e, str):
            out.append(e)
        elif hasattr(e, "args"):
            out.extend(e.args())
        else:
            raise TypeError(
                f"effects: expected NAME=VALUE strings, gap.Effect objects or a mapping, got {e!r}"
            )
    return out


class Design:
    """A walker design (``dataset/walkers/*.toml``): read it, change a number, simulate it.

    ``Design("mugatu")`` is a built-in design (see ``robot_survey.designs()``);
    ``Design("my-walker.toml")`` reads a file of the same shape. Designs are immutable:
    ``with_value`` returns a changed copy, validated as a file would be (a bad value raises
    ``SurveyError`` naming the field).

    >>> d = Design("mugatu").with_value("mass.total_mass_kg", 1.0)
    >>> d.walk(duration_s=10).velocity_mps  # doctest: +SKIP
    """

    __slots__ = ("_d",)

    def __init__(self, name_or_path: Union[str, "os.PathLike[str]"] = "mugatu") -> None:
        self._d = _core.Design(os.fspath(name_or_path))

    @classmethod
    def _wrap(cls, core: Any) -> "Design":
        d = cls.__new__(cls)
        d._d = core
        return d

    @classmethod
    def from_toml(cls, text: str, origin: str = "<string>") -> "Design":
        """A design from TOML text; ``origin`` names it in error messages."""
        return cls._wrap(_core.Design.from_toml(text, origin))

    @classmethod
    def load(cls, path: PathLike) -> "Design":
        """A design from a TOML file."""
        p = os.fspath(path)
        with open(p, encoding="utf-8") as f:
            return cls.from_toml(f.read(), p)

    @property
    def name(self) -> str:
        """The design's name."""
        return self._d.name

    @property
    def leg_length_m(self) -> float:
        """Leg length (hip height) at 1× [m]."""
        return self._d.leg_length_m

    @property
    def mass_kg(self) -> float:
        """Total mass at 1× [kg]."""
        return self._d.mass_kg

    def get(self, path: str) -> float:
        """The number at a dotted path, e.g. ``mass.total_mass_kg`` or
        ``mass.leg_inertia_box_over_l[0]``."""
        return self._d.get(path)

    def __getitem__(self, path: str) -> float:
        return self.get(path)

    def with_value(self, path: str, value: float) -> "Design":
        """A copy with the number at ``path`` set to ``value`` (validated)."""
        return self.with_values({path: value})

    def with_values(self, values: Mapping[str, float]) -> "Design":
        """A copy with several numbers set at once (validated)."""
        return Design._wrap(self._d.with_values([(k, float(v)) for k, v in values.items()]))

    def with_effects(self, effects: EffectsArg) -> "Design":
        """A copy with effects of the library switched on (SI values at this design's 1×
        size; see ``robot_survey.gap.effects()``)."""
        return Design._wrap(self._d.with_effects(effect_args(effects)))

    def to_toml(self) -> str:
        """The design as TOML, readable by ``survey sim walk --design FILE``."""
        return self._d.to_toml()

    def save(self, path: PathLike) -> None:
        """Writes the design as a TOML file."""
        with open(os.fspath(path), "w", encoding="utf-8") as f:
            f.write(self.to_toml())

    def to_dict(self) -> Dict[str, Any]:
        """The design as a nested dict (the TOML's tables)."""
        return json.loads(self._d.to_json())

    def uncertain(self) -> pl.DataFrame:
        """The ``[[uncertain]]`` parameters: path, file value, plausible range, prior, why."""
        rows = json.loads(self._d.uncertain_json())
        from ._results import frame

        return frame(rows)

    def walk(self, **kwargs: Any) -> Any:
        """Simulates this design: ``robot_survey.walk(design=self, **kwargs)``."""
        from ._api import walk

        return walk(self, **kwargs)

    def min_torque(self, **kwargs: Any) -> Any:
        """``robot_survey.min_torque(design=self, **kwargs)``."""
        from ._api import min_torque

        return min_torque(self, **kwargs)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Design) and self._d == other._d

    def __hash__(self) -> int:
        return hash(self.to_toml())

    def __repr__(self) -> str:
        return f"Design({self.name!r}: L = {self.leg_length_m} m, m = {self.mass_kg} kg)"


def design_arg(design: Union[str, "os.PathLike[str]", Design]) -> Any:
    """What ``_core`` accepts: its Design, or a name/path string."""
    if isinstance(design, Design):
        return design._d
    if isinstance(design, (str, os.PathLike)):
        return os.fspath(design)
    raise TypeError(f"design: expected a Design, a design name or a path, got {design!r}")


def designs() -> List[str]:
    """The names of the built-in walker designs."""
    return list(_core.builtin_designs())


def _optional(v: Optional[float]) -> Optional[float]:
    return None if v is None else float(v)
