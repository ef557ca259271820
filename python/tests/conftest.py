"""Shared fixtures: the repository root as working directory and the `survey` binary.

The tests compare the package with the `survey` command line on the same inputs. The binary
is `$SURVEY_BIN`, else `target/debug/survey` or `target/release/survey` (built by
`cargo test` / `cargo build`), else `cargo run --quiet --`.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any, List

import pytest

REPO = Path(__file__).resolve().parents[2]
SHARED = REPO.parent / "shared"


def _survey_command() -> List[str]:
    env = os.environ.get("SURVEY_BIN")
    if env:
        return [env]
    for profile in ("debug", "release"):
        p = REPO / "target" / profile / "survey"
        if p.is_file():
            return [str(p)]
    cargo = shutil.which("cargo")
    if cargo:
        return [cargo, "run", "--quiet", "--bin", "survey", "--"]
    pytest.exit("no `survey` binary: run `cargo build` first or set SURVEY_BIN", 2)
    return []


@pytest.fixture(autouse=True, scope="session")
def _at_repo_root():
    """Both the package and the CLI read ./dataset, as from the repository root."""
    old = os.getcwd()
    os.chdir(REPO)
    yield
    os.chdir(old)


class Cli:
    def __init__(self) -> None:
        self.command = _survey_command()

    def run(self, *args: str, check: bool = True) -> subprocess.CompletedProcess:
        out = subprocess.run(
            self.command + list(args),
            cwd=REPO,
            capture_output=True,
            text=True,
            encoding="utf-8",
        )
        if check and out.returncode != 0:
            raise AssertionError(f"survey {' '.join(args)} failed:\n{out.stderr}")
        return out

    def stdout(self, *args: str) -> str:
        return self.run(*args).stdout

    def json(self, *args: str) -> Any:
        return json.loads(self.stdout(*args))

    def error(self, *args: str) -> str:
        """The message of a failing command (stderr without `survey: error: `)."""
        out = self.run(*args, check=False)
        assert out.returncode == 2, f"expected exit 2, got {out.returncode}: {out.stderr}"
        line = out.stderr.strip()
        prefix = "survey: error: "
        assert line.startswith(prefix), line
        return line[len(prefix) :]


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli()
