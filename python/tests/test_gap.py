"""The gap module: the effect library, synthetic trials and the diagnosis, against the CLI on
the same inputs and against a cause known by construction."""

from __future__ import annotations

import shutil

import polars as pl
import pytest

import robot_survey as rs
from conftest import REPO
from robot_survey import gap

# A small diagnosis (6 conditions, one candidate, 4 grid points, no parameters among the
# suspects): seconds, not minutes, in the CI's dev build.
DIAG = dict(effects=["hip_viscous_damping"], grid=4, calibrate=False, undeclared=False)
DIAG_FLAGS = ["--effects", "hip_viscous_damping", "--grid", "4", "--no-calibration",
              "--no-undeclared"]


@pytest.fixture(scope="module")
def trials_file(cli, tmp_path_factory):
    """Trials with a hip viscous damping the nominal model lacks (the CLI's synth), cut to
    the first 6 conditions."""
    d = tmp_path_factory.mktemp("gap")
    full = d / "synth.csv"
    cli.run("gap", "synth", "--effect", "hip_viscous_damping=0.01", "--noise", "0.05",
            "--seed", "1", "--out", str(full))
    lines = full.read_text(encoding="utf-8").splitlines(keepends=True)
    header = [line for line in lines if not line.startswith("#")][:7]
    small = d / "trials.csv"
    small.write_text("".join(header), encoding="utf-8")
    return full, small


def test_effects_are_the_clis_library(cli):
    want = cli.json("gap", "effects", "--design", "zippy", "--format", "json")
    got = gap.effects("zippy")
    assert [e.name for e in got] == [w["name"] for w in want]
    for e, w in zip(got, want):
        assert [p.__dict__ for p in e.params] == w["params"]
        assert e.values == {p["name"]: p["default"] for p in w["params"]}
    with pytest.raises(rs.SurveyError, match="unknown effect `gremlins`"):
        gap.effect("gremlins")
    with pytest.raises(rs.SurveyError, match="has no parameter 'nonesuch'"):
        gap.effect("hip_backlash").with_value("nonesuch", 1.0)


def test_synth_writes_the_clis_file(cli, trials_file, tmp_path):
    full, _ = trials_file
    out = tmp_path / "py.csv"
    df = gap.synth(effects={"hip_viscous_damping": 0.01}, noise=0.05, seed=1, out=out)
    assert out.read_bytes() == full.read_bytes()
    assert df.height == 12
    assert set(gap.trial_columns()) <= set(df.columns)


def test_synth_with_wrong_parameters_and_conditions_from_a_dataframe(cli, trials_file, tmp_path):
    _, small = trials_file
    cond = gap.read_trials(small.read_text(encoding="utf-8")).head(3)
    out = tmp_path / "cond.csv"
    cond.write_csv(out)
    py = gap.synth(set={"mass.leg_com_height_over_l": 0.52}, noise=0.02, seed=4,
                   conditions=cond)
    cli_out = tmp_path / "cli.csv"
    cli.run("gap", "synth", "--set", "mass.leg_com_height_over_l=0.52", "--noise", "0.02",
            "--seed", "4", "--conditions", str(out), "--out", str(cli_out))
    want = gap.read_trials(cli_out.read_text(encoding="utf-8"))
    assert py.drop("source").equals(want.drop("source"))
    with pytest.raises(rs.SurveyError, match="--set mass.nonesuch=1.0"):
        gap.synth(set={"mass.nonesuch": 1.0})


@pytest.fixture(scope="module")
def diagnosis(trials_file):
    _, small = trials_file
    return gap.diagnose(small, **DIAG)


def test_diagnose_equals_the_clis_json(cli, trials_file, diagnosis):
    _, small = trials_file
    want = cli.json("gap", "diagnose", "--trials", str(small), *DIAG_FLAGS, "--format", "json")
    assert diagnosis.to_dict() == want


def test_diagnose_with_the_undeclared_numbers_equals_the_clis(cli, trials_file, diagnosis):
    """``undeclared=True`` (the default) weighs the design's undeclared numbers too: more
    explanations than without them, the same answer as the CLI's."""
    _, small = trials_file
    opts = {k: v for k, v in DIAG.items() if k != "undeclared"}
    got = gap.diagnose(small, **opts).to_dict()
    flags = [f for f in DIAG_FLAGS if f != "--no-undeclared"]
    want = cli.json("gap", "diagnose", "--trials", str(small), *flags, "--format", "json")
    assert got == want
    assert got["weighed"] > diagnosis.to_dict()["weighed"]


def test_diagnose_names_the_effect_that_made_the_trials(diagnosis):
    """The trials were made with hip viscous damping 0.01 N·m·s/rad: the answer names it,
    with a credible interval that holds the truth, and its probability is the posterior's
    largest."""
    a = diagnosis.answer
    assert a["kind"] == "effect_missing", diagnosis.statement
    assert a["explanation"] == "hip_viscous_damping"
    (named,) = a["named"]
    lo, hi = named["interval"]
    assert lo <= 0.01 <= hi
    probs = diagnosis.probabilities
    assert next(iter(probs)) == "hip_viscous_damping"
    assert probs["hip_viscous_damping"] >= diagnosis.to_dict()["criterion"]["decision"]["threshold"]
    assert abs(sum(probs.values()) - 1.0) < 1e-9
    assert diagnosis.where.height >= 1 and "rms_z" in diagnosis.where.columns
    assert diagnosis.explanations["explanation"][0] == "hip_viscous_damping"
    assert set(diagnosis.timing) >= {"grid_s", "walks"}


def test_diagnose_takes_a_dataframe(trials_file, diagnosis):
    _, small = trials_file
    df = gap.read_trials(small.read_text(encoding="utf-8"))
    from_df = gap.diagnose(df, **DIAG).to_dict()
    want = diagnosis.to_dict()
    assert from_df.pop("trials") == "<DataFrame>"
    want.pop("trials")
    assert from_df == want


def test_bad_trials_name_line_and_column(cli, trials_file, tmp_path):
    _, small = trials_file
    df = gap.read_trials(small.read_text(encoding="utf-8"))
    bad = df.with_columns(
        pl.when(pl.int_range(pl.len()) == 2).then(-1.0).otherwise(pl.col("leg_length_m"))
        .alias("leg_length_m")
    )
    with pytest.raises(rs.SurveyError, match=r"^<DataFrame>:4:3: leg_length_m: -1"):
        gap.diagnose(bad)
    path = tmp_path / "bad.csv"
    bad.write_csv(path)
    msg = cli.error("gap", "diagnose", "--trials", str(path))
    with pytest.raises(rs.SurveyError) as e:
        gap.diagnose(path)
    assert str(e.value) == msg and ":4:3: leg_length_m" in msg
    with pytest.raises(TypeError):
        gap.diagnose(42)


def test_diagnose_through_a_reference_equals_the_clis_json(cli, trials_file, tmp_path):
    """`reference=` is `--reference`; trials taken as their own reference change nothing,
    so every metric is carried onto the nominal itself and the answer is no gap."""
    _, small = trials_file
    ref = tmp_path / "ref.csv"
    cli.run("gap", "synth", "--conditions", str(small), "--noise", "0.05", "--seed", "2",
            "--out", str(ref))
    got = gap.diagnose(small, reference=ref, **DIAG)
    want = cli.json("gap", "diagnose", "--trials", str(small), "--reference", str(ref),
                    *DIAG_FLAGS, "--format", "json")
    assert got.to_dict() == want
    same = gap.diagnose(small, reference=gap.read_trials(small.read_text(encoding="utf-8")),
                        **DIAG)
    assert same.answer["kind"] == "no_gap", same.statement
    other = gap.read_trials(small.read_text(encoding="utf-8")).head(3)
    with pytest.raises(rs.SurveyError, match="reference"):
        gap.diagnose(small, reference=other, **DIAG)


def test_one_answer_in_python_json_and_text_on_trials_with_logs(cli, tmp_path):
    """Trials whose rows name robot logs (the CLI's synth with ``--logs``): the logged cycles
    enter the likelihood, and Python, the CLI's JSON and the CLI's text give one answer."""
    shutil.copy(REPO / "tests/data/gap/mugatu-two-uncertain.toml", tmp_path)
    trials, logs = tmp_path / "t.csv", tmp_path / "logs"
    cli.run("gap", "synth", "--conditions", str(REPO / "tests/data/gap/conditions-6.csv"),
            "--effect", "hip_coulomb_friction=0.02", "--noise", "0.03", "--seed", "7",
            "--out", str(trials), "--logs", str(logs))
    effects = ["hip_coulomb_friction", "hip_viscous_damping"]
    flags = ["--effects", ",".join(effects), "--no-undeclared"]
    got = gap.diagnose(trials, effects=effects, undeclared=False).to_dict()
    want = cli.json("gap", "diagnose", "--trials", str(trials), *flags, "--format", "json")
    assert got == want
    assert got["logged_trials"] == 6 and got["n_cycle_observations"] > 100
    text = cli.stdout("gap", "diagnose", "--trials", str(trials), *flags)
    assert got["answer"]["statement"] in text
    assert got["answer"]["explanation"] == "hip_coulomb_friction", got["answer"]["statement"]
