"""The gap module: the effect library, synthetic trials and the diagnosis, against the CLI on
the same inputs and against a cause known by construction."""

from __future__ import annotations

import polars as pl
import pytest

import robot_survey as rs
from robot_survey import gap

# A small diagnosis (6 conditions, one candidate, 4 grid points, no calibration): seconds,
# not minutes, in the CI's dev build.
DIAG = dict(effects=["hip_viscous_damping"], grid=4, calibrate=False)
DIAG_FLAGS = ["--effects", "hip_viscous_damping", "--grid", "4", "--no-calibration"]


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


def test_diagnose_without_the_audit_equals_the_clis(cli, trials_file, diagnosis):
    """``audit_undeclared=False`` is ``--no-audit-undeclared``; the default audits."""
    _, small = trials_file
    got = gap.diagnose(small, audit_undeclared=False, **DIAG).to_dict()
    want = cli.json("gap", "diagnose", "--trials", str(small), *DIAG_FLAGS,
                    "--no-audit-undeclared", "--format", "json")
    assert got == want
    assert not any(n.startswith("undeclared-parameter audit") for n in got["notes"])
    assert any(n.startswith("undeclared-parameter audit") for n in diagnosis.to_dict()["notes"])


def test_diagnose_names_the_effect_that_made_the_trials(diagnosis):
    """The trials were made with hip viscous damping 0.01 N·m·s/rad: the answer names it,
    with an interval that holds the truth, and the gap shrinks on held-out conditions."""
    a = diagnosis.answer
    assert a["kind"] == "effect_missing", diagnosis.statement
    (named,) = a["effects"]
    assert named["knob"] == "hip_viscous_damping"
    lo, hi = named["interval"]
    assert lo <= 0.01 <= hi
    how_far = diagnosis.how_far
    answer = how_far.filter(pl.col("model") == "the chain (the answer)").row(0, named=True)
    assert answer["within_noise"] and answer["shrink_pct"] > 50
    assert diagnosis.where.height >= 1 and "rms_z" in diagnosis.where.columns
    assert diagnosis.which["knob"].to_list() == ["hip_viscous_damping"]
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
    so every metric is carried onto the nominal itself and the answer is within noise."""
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
    assert same.answer["kind"] == "within_noise", same.statement
    other = gap.read_trials(small.read_text(encoding="utf-8")).head(3)
    with pytest.raises(rs.SurveyError, match="reference"):
        gap.diagnose(small, reference=other, **DIAG)
