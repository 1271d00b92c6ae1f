"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import joulepath
from joulepath.description import preset_path

FIXTURES = Path(__file__).parent / "fixtures"


@pytest.fixture(scope="session")
def irb120() -> joulepath.Robot:
    return joulepath.load_robot("irb120")


@pytest.fixture(scope="session")
def irb120_urdf() -> joulepath.Robot:
    return joulepath.load_robot(preset_path("irb120", fmt="urdf"))


@pytest.fixture(scope="session")
def appendix_c_path() -> Path:
    return FIXTURES / "thesis_appendix_c.irml"


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20251125)
