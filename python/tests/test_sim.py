"""Walks, designs, minimum torque and Table III: the CLI's JSON on the same inputs, the
README's numbers, dynamic similarity, and the GIL released while simulating."""

from __future__ import annotations

import threading
import time

import polars as pl
import pytest

import robot_survey as rs


def test_walk_metrics_equal_the_clis(cli):
    w = rs.walk("mugatu")
    assert w.to_dict() == cli.json("sim", "walk", "--design", "mugatu", "--format", "json")
    # README: mugatu walks at 0.1570 m/s, step frequency 2.481 Hz.
    assert w.walks and round(w.velocity_mps, 4) == 0.1570
    assert round(w.step_frequency_hz, 3) == 2.481


def test_scaled_seeded_walk_and_its_trajectory_equal_the_clis(cli, tmp_path):
    csv = tmp_path / "walk.csv"
    want = cli.json(
        "sim", "walk", "--design", "zippy", "--leg-length", "0.5", "--mass-law", "l3",
        "--contact", "fixed-material", "--duration", "6", "--seed", "3",
        "--trajectory", str(csv), "--format", "json",
    )
    w = rs.walk("zippy", leg_length_m=0.5, duration_s=6, seed=3, mass_law="l3",
                contact="fixed-material")
    assert w.metrics == want
    traj = pl.read_csv(csv, schema_overrides={"feet_in_contact": pl.UInt8})
    assert w.trajectory.columns == traj.columns
    assert w.trajectory.equals(traj)  # the CSV holds shortest round-trip floats: exact
    # Without the trajectory the metrics are the same.
    assert rs.walk("zippy", leg_length_m=0.5, duration_s=6, seed=3, mass_law="l3",
                   contact="fixed-material", trajectory=False).metrics == want


def test_a_modified_design_walks_as_its_toml_does_in_the_cli(cli, tmp_path):
    d = rs.Design("mugatu").with_values({"mass.total_mass_kg": 1.1, "ground.slope_deg": 0.5})
    d = d.with_effects({"hip_viscous_damping": 0.01})
    assert d.get("mass.total_mass_kg") == 1.1 and d["ground.slope_deg"] == 0.5
    path = tmp_path / "heavy.toml"
    d.save(path)
    assert rs.Design.load(path) == d
    want = cli.json("sim", "walk", "--design", str(path), "--duration", "8", "--format", "json")
    assert rs.walk(d, duration_s=8, trajectory=False).metrics == want
    assert d.walk(duration_s=8, trajectory=False).metrics == want
    # The original is unchanged (designs are immutable).
    assert rs.Design("mugatu").mass_kg == 0.9


def test_effects_in_a_walk_are_those_of_the_library():
    e = rs.gap.effect("hip_coulomb_friction").with_value(value=0.05)
    assert e.magnitude == 0.05
    by_object = rs.walk(effects=[e], duration_s=8, trajectory=False)
    by_mapping = rs.walk(
        effects={f"hip_coulomb_friction.{k}": v for k, v in e.values.items()},
        duration_s=8, trajectory=False,
    )
    assert by_object.metrics == by_mapping.metrics
    nominal = rs.walk(duration_s=8, trajectory=False)
    assert by_object.velocity_mps != nominal.velocity_mps


def test_bad_design_values_name_the_field_as_the_cli_does(cli, tmp_path):
    with pytest.raises(rs.SurveyError, match=r"field `mass.total_mass_kg` = -1: must be > 0"):
        rs.Design("mugatu").with_value("mass.total_mass_kg", -1)
    bad = tmp_path / "bad.toml"
    bad.write_text(
        rs.Design("mugatu").to_toml().replace("total_mass_kg = 0.9", "total_mass_kg = -0.9"),
        encoding="utf-8",
    )
    msg = cli.error("sim", "walk", "--design", str(bad))
    assert "mass.total_mass_kg" in msg
    with pytest.raises(rs.SurveyError) as e:
        rs.walk(str(bad))
    assert str(e.value) == msg
    with pytest.raises(rs.SurveyError) as e:
        rs.Design.load(bad)
    assert str(e.value) == msg
    with pytest.raises(rs.SurveyError, match="no field `nonesuch`"):
        rs.Design("zippy").get("mass.nonesuch")
    with pytest.raises(rs.SurveyError, match=r"invalid walk option"):
        rs.walk(duration_s=-1)
    with pytest.raises(rs.SurveyError, match="mass_law: unknown value `l4`"):
        rs.walk(mass_law="l4")
    with pytest.raises(TypeError):
        rs.walk(design=3)


def test_min_torque_equals_the_clis(cli):
    args = dict(duration_s=10, seeds=0, tolerance=0.1)
    want = cli.json("sim", "min-torque", "--design", "mugatu", "--duration", "10",
                    "--seeds", "0", "--tolerance", "0.1", "--format", "json")
    got = rs.min_torque("mugatu", **args)
    assert got.to_dict() == want
    assert got.walks and got.min_torque_nm > 0


def test_table3_equals_the_cli_and_similar_contact_gives_the_similarity_exponents(cli):
    calls = []
    t3 = rs.table3(
        ["mugatu"], ["l2"], "similar", leg_lengths_m=[0.1, 0.153, 0.3, 0.6], duration_s=10,
        seeds=0, tolerance=0.1, progress=lambda done, total, msg: calls.append((done, total)),
    )
    want = cli.json(
        "sim", "table3", "--designs", "mugatu", "--mass-laws", "l2", "--contact", "similar",
        "--leg-lengths", "0.1,0.153,0.3,0.6", "--duration", "10", "--seeds", "0",
        "--tolerance", "0.1", "--format", "json",
    )
    assert t3.to_dict() == want
    assert sorted(calls) == [(k, 4) for k in range(1, 5)]
    row = t3.rows.row(0, named=True)
    # Dynamic similarity (README): v ∝ L^0.5, τ ∝ m·L = L³ under m ∝ L², τ ∝ (m·L)^1.
    assert abs(row["velocity_exponent"] - 0.5) < 1e-6
    assert abs(row["torque_exponent"] - 3.0) < 1e-6
    assert abs(row["torque_vs_mass_length_exponent"] - 1.0) < 1e-6
    assert t3.points.height == 4


def test_simulations_release_the_gil():
    """While a long walk runs in a thread, the main thread keeps running Python."""
    done = threading.Event()

    def run():
        rs.walk(duration_s=150, trajectory=False)
        done.set()

    t = threading.Thread(target=run)
    start = time.perf_counter()
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - start
    assert elapsed > 0.05, "the walk was too short to tell"
    # Holding the GIL, the walk would block every tick until it ends.
    assert ticks > 10, (ticks, elapsed)


def test_designs_lists_the_builtins():
    assert {"mugatu", "zippy", "zippy-spherical"} <= set(rs.designs())
    u = rs.Design("zippy").uncertain()
    assert {"path", "nominal", "lo", "hi", "why"} <= set(u.columns)
