"""The Python client's API reference (issue 24): generated from the docstrings by pdoc in every `make test`, into
build/api-docs (open build/api-docs/index.html). It must build without a warning, and every public method of
Client must be documented: a method without a docstring would leave an empty entry a user cannot tell from a
missing one."""
import inspect
import subprocess
import sys
from pathlib import Path

import graspsim

OUT = Path(__file__).resolve().parents[2] / "build" / "api-docs"


def test_the_api_reference_builds_without_warnings_and_documents_every_client_method():
    run = subprocess.run([sys.executable, "-m", "pdoc", "graspsim", "-o", str(OUT)], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert "warn" not in run.stderr.lower(), run.stderr
    page = (OUT / "graspsim.html").read_text()
    public = [name for name, member in inspect.getmembers(graspsim.Client, inspect.isfunction)
              if not name.startswith("_")]
    assert len(public) > 40  # the whole client, not an empty class
    undocumented = [name for name in public if not inspect.getdoc(getattr(graspsim.Client, name))]
    assert not undocumented, f"Client methods without a docstring: {undocumented}"
    missing = [name for name in public if f'id="Client.{name}"' not in page]
    assert not missing, f"Client methods missing from the generated reference: {missing}"
