"""The notebooks run from top to bottom (at small N), so they never rot."""

import os
import shutil
from pathlib import Path

import nbformat
import pytest

nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = sorted((Path(__file__).parent.parent / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_runs(path, tmp_path):
    nb = nbformat.read(path, as_version=4)
    os.environ.setdefault("MPLBACKEND", "Agg")
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
    # nothing is written into the current directory: every file goes to the directory the
    # notebook says it made (tempfile.mkdtemp()), where each notebook draws figures
    assert not list(tmp_path.iterdir()), sorted(p.name for p in tmp_path.iterdir())
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
                   if o.output_type == "stream")
    said = [line.split("files of this notebook go to", 1)[1].strip() for line in text.splitlines()
            if "files of this notebook go to" in line]
    assert len(said) == 1, text[:500]
    out = Path(said[0])
    try:
        assert out.is_dir() and out.resolve() != tmp_path.resolve()
        assert any(p.suffix == ".png" for p in out.iterdir())
    finally:
        shutil.rmtree(out, ignore_errors=True)
