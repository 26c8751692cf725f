"""The softarm CLI the Python tests compare with: $SOFTARM_BIN, else
target/debug/softarm (built by `cargo test`), else target/release/softarm."""

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli():
    for p in [os.environ.get("SOFTARM_BIN"), ROOT / "target/debug/softarm",
              ROOT / "target/release/softarm"]:
        if p and Path(p).exists():
            return str(p)
    pytest.skip("no softarm binary: run cargo build first")
