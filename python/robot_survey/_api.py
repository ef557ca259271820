"""The dataset, Table 2 fits, predictions and walker simulations."""

from __future__ import annotations

import io
import json
import os
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Union

import polars as pl

from . import _core
from ._design import Design, EffectsArg, design_arg, effect_args
from ._results import PathLike, Result, fspath, frame

CLASSES = ("lower-biped", "full-biped", "quadruped", "hexapod", "all")


def dataset(release: Optional[str] = None, path: Optional[PathLike] = None) -> pl.DataFrame:
    """The survey table: one row per robot, with its class, whether it is fitted (and why
    not), every compiled field in SI units and its ``sources`` (URLs, ``" ; "``-separated).

    Columns are typed by ``dataset/vocabulary.toml`` (numbers f64, integers i64, flags bool),
    exactly as the frozen releases' ``robots.parquet``.

    Parameters
    ----------
    release:
        A frozen release, e.g. ``"1.0.0"`` (the table the paper used); ``None``: the live
        records.
    path:
        Dataset directory; ``None``: ``./dataset`` when present, else the copy bundled into
        the package (as the ``survey`` command).

    ``.to_pandas()`` on the result needs pandas and pyarrow (``pip install
    "./python[pandas]"``).
    """
    data, _ = _core.dataset_parquet(release, fspath(path))
    return pl.read_parquet(io.BytesIO(data))


def dataset_info(release: Optional[str] = None, path: Optional[PathLike] = None) -> Dict[str, Any]:
    """Which table ``dataset()`` reads: ``version``, ``sha256`` of its CSV form, ``frozen``
    (a release) and ``columns``."""
    _, meta = _core.dataset_parquet(release, fspath(path))
    return json.loads(meta)


def _classes(classes: Union[None, str, Iterable[str]]) -> Optional[List[str]]:
    if classes is None:
        return None
    if isinstance(classes, str):
        classes = [classes]
    out = []
    for c in classes:
        key = c.strip().lower().replace("_", "-").replace(" ", "-")
        if key not in CLASSES:
            raise _core.SurveyError(
                f"unknown class `{c}` (one of: {', '.join(CLASSES)})"
            )
        out.append(key)
    return out


def fit_report(
    release: Optional[str] = None,
    method: str = "ols",
    *,
    path: Optional[PathLike] = None,
    confidence: float = 0.95,
    bootstrap: Optional[int] = None,
    seed: int = 1,
) -> Dict[str, Any]:
    """``survey fit --format json`` as a dict: ``dataset`` (version, sha256), ``method`` and
    ``fits`` (every class × variable pair). See ``fit`` for the parameters."""
    return json.loads(
        _core.fit_json(release, fspath(path), method, confidence, bootstrap, seed)
    )


def fit(
    release: Optional[str] = None,
    method: str = "ols",
    classes: Union[None, str, Sequence[str]] = None,
    *,
    path: Optional[PathLike] = None,
    confidence: float = 0.95,
    bootstrap: Optional[int] = None,
    seed: int = 1,
) -> pl.DataFrame:
    """The paper's Table 2: power laws y = a·x^b in log–log space per class.

    One row per class and variable pair (L_B vs L, m vs L, m vs L_B): ``class``, ``x``,
    ``y``, ``a``, ``b``, ``r2``, ``n``, ``se_b``, the intervals ``b_ci_lo``/``b_ci_hi`` and
    ``a_ci_lo``/``a_ci_hi``, ``p_b_equals_0``, ``p_isometry``, ``confidence`` — the numbers
    of ``survey fit --format json``, bit for bit.

    Parameters
    ----------
    release:
        A frozen release (``"1.0.0"`` reproduces the published Table 2); ``None``: live
        records.
    method:
        ``"ols"`` (the paper's; use it to predict), ``"ma"`` or ``"sma"``.
    classes:
        Keep only these classes (``lower-biped``, ``full-biped``, ``quadruped``, ``hexapod``,
        ``all``); ``None``: all.
    path:
        Dataset directory (default as ``dataset()``).
    confidence:
        Level of the intervals.
    bootstrap, seed:
        ``bootstrap=N`` adds seeded case-resampling percentile and BCa intervals of b
        (``N`` ≥ 100; 2000 or more is usual).
    """
    report = fit_report(
        release, method, path=path, confidence=confidence, bootstrap=bootstrap, seed=seed
    )
    keep = _classes(classes)
    fits = [f for f in report["fits"] if keep is None or f["class"] in keep]
    return frame(fits)


class Prediction(Result):
    """``survey predict --format json``: mass and body length for a target leg length (or
    the leg length for a mass budget), with intervals; the isometric scaling of a reference;
    with a walker design as reference, the hip torque it needs (``torque``).

    ``quantities``, ``torques`` and ``actuators`` are DataFrames of its tables.
    """

    @property
    def quantities(self) -> pl.DataFrame:
        """Predicted quantities: mean (bias-corrected), median, CI of the median,
        prediction interval, and the law used (``law_a``, ``law_b``, …)."""
        return frame(self._data.get("quantities") or [])

    @property
    def torques(self) -> pl.DataFrame:
        """Required hip torque at each mass (fit, L² and L³ scaling of the design)."""
        t = self._data.get("torque")
        return frame(t["torques"]) if t else pl.DataFrame()

    @property
    def actuators(self) -> pl.DataFrame:
        """Catalogue actuators and whether each delivers the required torque with the
        margin."""
        t = self._data.get("torque")
        return frame(t["actuators"]) if t else pl.DataFrame()


def predict(
    leg_length_m: Optional[float] = None,
    *,
    cls: str = "lower-biped",
    from_: Optional[str] = None,
    mass_budget_kg: Optional[float] = None,
    release: Optional[str] = None,
    path: Optional[PathLike] = None,
    confidence: float = 0.95,
    torque_contact: str = "fixed-material",
    torque_margin: float = 2.0,
    table3_points: Optional[PathLike] = None,
    speed_kind: str = "top",
) -> Prediction:
    """Designer query: what a robot of leg length ``leg_length_m`` weighs, how long it is
    and how fast it goes.

    Parameters
    ----------
    leg_length_m:
        Target leg length [m] (hip height standing).
    cls:
        Class whose OLS fit predicts.
    from_:
        A reference scaled isometrically beside the fit: a record id (``"zippy"``) or a walker
        design (``"design:mugatu"``; then ``.torque`` has the hip torque that design needs at
        this size, from Table III, and the catalogue actuators that deliver it).
    mass_budget_kg:
        The inverse query: the leg length whose median mass is this budget.
    release, path:
        The dataset (as ``fit``).
    confidence:
        Level of the intervals.
    torque_contact, torque_margin, table3_points:
        With a design: Table III's contact rule (``"fixed-material"`` or ``"similar"``), the
        stall-torque margin actuators must have, and a Table III points file (default: the
        bundled one).
    speed_kind:
        The speed predicted (``"top"``, ``"typical"``, ``"walking"`` or ``"running"``), fitted
        on the class's robots with a speed of that kind; it is among ``quantities`` (with its
        Froude number in ``froude``) when the class has enough of them, else
        ``speed_unavailable`` says why.
    """
    text = _core.predict_json(
        None if leg_length_m is None else float(leg_length_m),
        None if mass_budget_kg is None else float(mass_budget_kg),
        cls,
        from_,
        release,
        fspath(path),
        confidence,
        torque_contact,
        torque_margin,
        fspath(table3_points),
        speed_kind,
    )
    return Prediction(json.loads(text))


class WalkResult(Result):
    """One simulated walk: the gait metrics of ``survey sim walk --format json``
    (``velocity_mps``, ``froude``, ``walks``, ``fall_reason``, ``roll_pp_deg``, ``cot``,
    ``peak_torque_nm`` …, as attributes or ``to_dict()``) and the trajectory.
    """

    def __init__(self, data: Dict[str, Any], trajectory: Optional[pl.DataFrame]) -> None:
        super().__init__(data)
        self._trajectory = trajectory

    @property
    def metrics(self) -> Dict[str, Any]:
        """The gait metrics (the CLI's JSON)."""
        return self.to_dict()

    @property
    def trajectory(self) -> Optional[pl.DataFrame]:
        """Time series (the columns of ``survey sim walk --trajectory``): time, base
        position, roll/pitch/yaw, hip angle and torque, work, feet in contact, normal forces.
        ``None`` when run with ``trajectory=False``."""
        return self._trajectory

    def __repr__(self) -> str:
        d = self._data
        state = "walks" if d.get("walks") else f"does not walk ({d.get('fall_reason')})"
        return (
            f"WalkResult({d.get('design')} at L = {d.get('leg_length_m')} m: {state}, "
            f"v = {d.get('velocity_mps')} m/s)"
        )


def walk(
    design: Union[str, "os.PathLike[str]", Design] = "mugatu",
    leg_length_m: Optional[float] = None,
    duration_s: float = 25.0,
    effects: EffectsArg = None,
    seed: Optional[int] = None,
    *,
    mass_law: str = "l2",
    contact: str = "similar",
    torque_limit_nm: Optional[float] = None,
    frequency_hz: Optional[float] = None,
    trajectory: bool = True,
) -> WalkResult:
    """Simulates one walk of a quasi-passive walker (``survey sim walk``).

    The GIL is released while it runs, so walks in threads run in parallel.

    Parameters
    ----------
    design:
        A built-in name (``robot_survey.designs()``), a path to a design TOML, or a
        ``Design``.
    leg_length_m:
        Scale the design to this leg length (dynamic similarity; ``None``: its own size).
    duration_s:
        Simulated time [s].
    effects:
        Unmodelled effects switched on: ``{"hip_coulomb_friction": 0.05}`` (SI, the design at
        1×; ``"name.param"`` keys set one parameter), ``gap.Effect`` objects, or
        ``"NAME=VALUE"`` strings.
    seed:
        Seed of a deterministic perturbation of the initial state.
    mass_law:
        ``"l2"`` (m ∝ L²) or ``"l3"`` (m ∝ L³) when scaling.
    contact:
        ``"similar"`` or ``"fixed-material"`` contact scaling.
    torque_limit_nm, frequency_hz:
        Servo torque limit (or bang-bang torque) and drive frequency (default: the design's,
        scaled).
    trajectory:
        Record the time series (``False`` is a little faster).
    """
    text, cols = _core.walk(
        design_arg(design),
        None if leg_length_m is None else float(leg_length_m),
        mass_law,
        contact,
        float(duration_s),
        seed,
        None if torque_limit_nm is None else float(torque_limit_nm),
        None if frequency_hz is None else float(frequency_hz),
        effect_args(effects),
        trajectory,
    )
    traj = None
    if cols is not None:
        traj = pl.DataFrame(cols, schema_overrides={"feet_in_contact": pl.UInt8})
    return WalkResult(json.loads(text), traj)


class MinTorque(Result):
    """``survey sim min-torque --format json``: ``min_torque_nm``, ``min_torque_over_mgl``,
    ``bracket_nm``, ``walks``, ``gait`` (the walk at the minimum torque), …"""


def min_torque(
    design: Union[str, "os.PathLike[str]", Design] = "mugatu",
    leg_length_m: Optional[float] = None,
    *,
    mass_law: str = "l2",
    contact: str = "similar",
    duration_s: float = 25.0,
    seed: Optional[int] = None,
    seeds: int = 2,
    tolerance: float = 0.02,
    cap: float = 2.0,
    effects: EffectsArg = None,
) -> MinTorque:
    """The smallest hip torque at which a design walks consistently at a size (from the
    unperturbed start and ``seeds`` perturbed ones), by bracketing and bisection to
    ``tolerance``; up to ``cap`` m·g·L. Runs with the GIL released."""
    text = _core.min_torque_json(
        design_arg(design),
        None if leg_length_m is None else float(leg_length_m),
        mass_law,
        contact,
        float(duration_s),
        seed,
        seeds,
        float(tolerance),
        float(cap),
        effect_args(effects),
    )
    return MinTorque(json.loads(text))


class Table3(Result):
    """``survey sim table3 --format json``: per design × mass law × contact rule the fitted
    exponents (v ∝ L^a, τ_min ∝ L^b, τ_min ∝ (m·L)^c) and every size's point."""

    @property
    def rows(self) -> pl.DataFrame:
        """One row per chain: exponents with intervals, attitudes, sizes walking."""
        return frame(
            {k: v for k, v in r.items() if k not in ("points", "sizes_not_walking_m")}
            for r in self._data["rows"]
        )

    @property
    def points(self) -> pl.DataFrame:
        """Every size of every chain: mass, minimum torque, gait at the reported torque."""
        return frame(p for r in self._data["rows"] for p in r["points"])


def _progress_callback(progress: Union[bool, Callable[[int, int, str], Any], None]):
    """(callback, closer): a tqdm.auto bar when tqdm is installed and ``progress`` is True."""
    if callable(progress):
        return progress, lambda: None
    if not progress:
        return None, lambda: None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None, lambda: None
    state: Dict[str, Any] = {}

    def update(done: int, total: int, message: str) -> None:
        bar = state.get("bar")
        if bar is None:
            bar = state["bar"] = tqdm(total=total, desc="table3", unit="size")
        bar.set_postfix_str(message, refresh=False)
        bar.update(done - bar.n)

    def close() -> None:
        if "bar" in state:
            state["bar"].close()

    return update, close


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
    points: Optional[PathLike] = None,
    progress: Union[bool, Callable[[int, int, str], Any]] = True,
) -> Table3:
    """The paper's Table III: each design's minimum hip torque and gait over leg lengths
    (default 36 sizes, 0.02–1.2 m) under each mass law and contact rule, with fitted power
    laws. Parallel on every core, with the GIL released.

    Parameters
    ----------
    designs, mass_laws:
        Designs (names, paths or ``Design``) and mass laws (``"l2"``, ``"l3"``).
    contact:
        ``"both"``, ``"similar"`` or ``"fixed-material"``.
    sizes, leg_lengths_m:
        Number of log-spaced sizes, or explicit leg lengths [m].
    duration_s, seeds, tolerance, cap:
        As ``min_torque`` (the duration at the design's own size, ∝ √L elsewhere).
    points:
        A points file: finished sizes are appended as they finish; a re-run resumes.
    progress:
        ``True``: a ``tqdm.auto`` progress bar (a widget in Jupyter) when tqdm is installed,
        else silent; ``False``: silent; a callable ``f(done, total, message)``: called after
        every size.
    """
    contacts = {
        "both": ["similar", "fixed-material"],
        "similar": ["similar"],
        "fixed-material": ["fixed-material"],
        "fixed_material": ["fixed-material"],
    }.get(contact)
    if contacts is None:
        raise _core.SurveyError(
            f"contact: unknown value `{contact}` (one of: both, similar, fixed-material)"
        )
    callback, close = _progress_callback(progress)
    try:
        text = _core.table3_json(
            [design_arg(d) for d in designs],
            list(mass_laws),
            contacts,
            sizes,
            None if leg_lengths_m is None else [float(x) for x in leg_lengths_m],
            float(duration_s),
            seeds,
            float(tolerance),
            float(cap),
            fspath(points),
            callback,
        )
    finally:
        close()
    return Table3(json.loads(text))
