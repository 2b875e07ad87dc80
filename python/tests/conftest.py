"""Shared fixtures of the pytest suite."""

from __future__ import annotations

import json
import pathlib
from typing import Any

import pytest

HERE = pathlib.Path(__file__).parent


@pytest.fixture(scope="session")
def golden() -> Any:
    """The golden values the crate's paper functions give (see rust_tests/golden.rs)."""
    return json.loads((HERE / "golden.json").read_text())
