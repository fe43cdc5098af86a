"""Shared fixtures for the Python tests: where the built `repose` is and where the real data is."""
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def bin_dir():
    path = pathlib.Path(os.environ.get("REPOSE_BIN_DIR", REPO / "build" / "bin"))
    if not (path / "repose").exists():
        pytest.fail(f"{path / 'repose'} is not built; run `make test`")
    return path


@pytest.fixture(scope="session")
def data_dir():
    path = pathlib.Path(os.environ.get("REPOSE_DATA_DIR", REPO.parent / "shared" / "data"))
    if not path.is_dir():
        pytest.fail(f"shared test data not found at {path}")
    return path


@pytest.fixture
def repose(bin_dir):
    """Runs `repose ARGS...`, returns the CompletedProcess (text mode)."""

    def run(*args, check=True):
        result = subprocess.run([str(bin_dir / "repose"), *map(str, args)],
                                capture_output=True, text=True)
        if check and result.returncode != 0:
            raise AssertionError(f"repose {' '.join(map(str, args))} failed: {result.stderr}")
        return result

    return run
