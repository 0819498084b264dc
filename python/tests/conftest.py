"""Shared fixtures: the repository's specs and the reachc CLI the results are compared with.

The CLI is ``$REACHC_BIN`` if set, else the repository's ``target/release/reachc`` or
``target/debug/reachc`` (``cargo build -p reachc``); CI runs this suite after ``cargo test``,
which builds the debug one.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path
from typing import List

import pytest

REPO = Path(__file__).resolve().parents[2]
SPECS = REPO / "specs"


def cli_path() -> Path:
    env = os.environ.get("REACHC_BIN")
    if env:
        return Path(env)
    for profile in ("release", "debug"):
        p = REPO / "target" / profile / "reachc"
        if p.exists():
            return p
    raise RuntimeError(
        "the reachc CLI is needed to compare results: build it (cargo build -p reachc) "
        "or set REACHC_BIN"
    )


@pytest.fixture(scope="session")
def cli() -> Path:
    return cli_path()


def run_cli(cli: Path, args: List[str]) -> "subprocess.CompletedProcess[str]":
    return subprocess.run(
        [str(cli), *args], capture_output=True, text=True, cwd=REPO, timeout=1800
    )
