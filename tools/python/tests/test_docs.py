"""docs/python.md quotes docs/examples/map_plane_onto_cap.py verbatim, and the example runs."""

import os
import subprocess
import sys

from conftest import SOURCE_DIR


def test_the_python_doc_quotes_the_example_and_it_runs():
    example = SOURCE_DIR / "docs" / "examples" / "map_plane_onto_cap.py"
    doc = (SOURCE_DIR / "docs" / "python.md").read_text()
    assert example.read_text() in doc, "docs/python.md does not quote the example as it is"
    run = subprocess.run([sys.executable, str(example)], capture_output=True, text=True,
                         env=os.environ.copy(), timeout=300)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0].startswith("wrote ")
    assert lines[2].startswith("ElasticPaint") and lines[3].startswith("LSCM")
