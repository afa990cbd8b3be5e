"""Shared fixtures: the shared meshes, the elastic tool, and one plane -> cap map."""

import json
import os
import subprocess
from pathlib import Path

import pytest

import elastic

SOURCE_DIR = Path(os.environ.get("ELASTIC_SOURCE_DIR", Path(__file__).resolve().parents[3]))
SHARED = Path(os.environ.get("ELASTIC_SHARED_DIR", SOURCE_DIR.parent / "shared"))
MESHES = SHARED / "meshes"
TOOL = os.environ.get("ELASTIC_TOOL", "")

# The job the map fixture runs, in the tool's flags (the C++ results the bindings must match).
PLANE_CAP = {
    "source": str(MESHES / "grid.off"),
    "source-region": "disk:0.5,0.5,0,0.45",
    "target": str(MESHES / "hemisphere.off"),
    "target-region": "boundary",
    "particles": 1500,
}


def run_tool(*args, check=True):
    """Runs the elastic tool; returns the CompletedProcess."""
    assert TOOL, "ELASTIC_TOOL is not set (ctest sets it)"
    return subprocess.run([TOOL, *map(str, args)], capture_output=True, text=True, check=check)


def tool_report(command, job, tmp_path, *extra):
    """Runs `elastic COMMAND` with the job's flags and returns its JSON report."""
    report = tmp_path / f"{command}.json"
    flags = []
    for key, value in job.items():
        flags += [f"--{key}", str(value)]
    run_tool(command, *flags, "--threads", "2", "-q", "--report", report, *extra)
    return json.loads(report.read_text())


@pytest.fixture(scope="session")
def plane():
    return elastic.Surface(str(MESHES / "grid.off"))


@pytest.fixture(scope="session")
def cap():
    return elastic.Surface(str(MESHES / "hemisphere.off"))


@pytest.fixture(scope="session")
def plane_cap(plane, cap):
    return elastic.map_regions(
        plane.region(PLANE_CAP["source-region"]),
        cap.region(PLANE_CAP["target-region"]),
        particles=PLANE_CAP["particles"],
        threads=2,
    )


def pytest_configure(config):
    # Debian's tornado under distributed warns about its own event-loop API; not ours.
    config.addinivalue_line("filterwarnings",
                            "ignore:make_current is deprecated:DeprecationWarning")
