"""Shared fixtures of the Python tests (python/CMakeLists.txt runs them with the Python the module was built for).

Environment set by CTest: PYTHONPATH (build/python), SEAM_CLI (the seam executable), SEAM_SHARED_DATA_DIR
(../shared/data), SEAM_EXAMPLES_DIR (examples/)."""
import json
import os
import subprocess

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _env_path(name, default):
    return os.environ.get(name) or default


@pytest.fixture(scope="session")
def cli():
    path = _env_path("SEAM_CLI", os.path.join(REPO, "build", "bin", "seam"))
    if not os.path.exists(path):
        pytest.skip(f"the seam executable is not built ({path})")
    return path


@pytest.fixture(scope="session")
def shared_data():
    path = _env_path("SEAM_SHARED_DATA_DIR", os.path.join(REPO, "..", "shared", "data"))
    if not os.path.isdir(path):
        pytest.skip(f"no shared data at {path}")
    return path


@pytest.fixture(scope="session")
def examples():
    return _env_path("SEAM_EXAMPLES_DIR", os.path.join(REPO, "examples"))


@pytest.fixture(scope="session")
def run_cli(cli):
    """Runs the CLI; returns (exit code, parsed JSON or None, stderr)."""

    def run(*args):
        p = subprocess.run([cli, *args], capture_output=True, text=True, timeout=300)
        out = json.loads(p.stdout) if p.stdout.strip().startswith("{") else None
        return p.returncode, out, p.stderr

    return run
