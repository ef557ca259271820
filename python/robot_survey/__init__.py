"""robot_survey: allometric scaling of legged robots, from Python.

The Rust library of this repository (``robot-survey``) through a PyO3 binding; every
function returns the numbers the ``survey`` command prints with ``--format json``, bit for
bit, as polars DataFrames or result objects.

* ``dataset(release=None)``: the curated survey table (one row per robot, with sources).
* ``fit(release="1.0.0")``: the paper's Table 2 power laws; ``fit_report`` as a dict.
* ``predict(1.0, cls="lower-biped", from_="design:mugatu")``: mass and body length at a leg
  length, and the hip torque and actuators a walker design needs there.
* ``Design("mugatu")``: walker designs (read, ``with_value``, ``to_toml``);
  ``walk(...)``, ``min_torque(...)``, ``table3(...)``: the walker simulation and studies.
* ``gap``: the sim-to-real gap (``gap.effects``, ``gap.synth``, ``gap.diagnose``).

Bad input raises ``SurveyError`` (a ``ValueError``) with the CLI's message, naming the
file, line and field where it can. Simulations release the GIL.
"""

from ._core import SurveyError
from ._api import (
    MinTorque,
    Prediction,
    Table3,
    WalkResult,
    dataset,
    dataset_info,
    fit,
    fit_report,
    min_torque,
    predict,
    table3,
    walk,
)
from ._design import Design, designs
from ._results import Result
from . import gap

from ._core import version as _version

__version__: str = _version()

__all__ = [
    "SurveyError",
    "Design",
    "Result",
    "Prediction",
    "WalkResult",
    "MinTorque",
    "Table3",
    "dataset",
    "dataset_info",
    "fit",
    "fit_report",
    "predict",
    "walk",
    "min_torque",
    "table3",
    "designs",
    "gap",
]
