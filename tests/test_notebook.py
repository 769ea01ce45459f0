"""examples/first_look.ipynb runs from top to bottom in a fresh kernel (slow: ~40 s),
so the notebook a researcher opens first never rots."""

from __future__ import annotations

from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

NOTEBOOK = Path(__file__).resolve().parent.parent / "examples" / "first_look.ipynb"


def test_the_first_look_notebook_runs_and_shows_what_it_says():
    import nbformat
    from nbclient import NotebookClient

    notebook = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(notebook, timeout=600, kernel_name="python3").execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "stood up: True" in text
    assert all(name in text for name in ("advancement", "stiff", "compliant"))
    kinds = {kind for o in outputs for kind in o.get("data", {})}
    assert "image/png" in kinds  # the signals' figure
    html = "".join(o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {}))
    assert "<iframe srcdoc=" in html and len(html) > 500_000  # the recording, inline
