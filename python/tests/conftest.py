"""Shared by the Python tests: where the sources and the command line are (ctest sets
STACKBEAM_SOURCE_DIR and STACKBEAM_CLI; run by hand, the defaults are this checkout and its build/)."""
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("STACKBEAM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CLI = os.environ.get("STACKBEAM_CLI", str(SOURCE_DIR / "build" / "apps" / "cli" / "stackbeam"))


@pytest.fixture
def scenarios():
    return SOURCE_DIR / "scenarios"
