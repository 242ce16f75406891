"""The API in notebooks (issue 20, item 3): examples/quickstart.ipynb runs top to bottom on a
real Jupyter kernel (nbclient + ipykernel) and shows the scene as HTML and both renders as
PNG images."""

from __future__ import annotations

import base64
import io
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "quickstart.ipynb"


@pytest.mark.gl
@pytest.mark.slow
def test_quickstart_notebook_runs_and_shows_its_images(tmp_path, gl_ctx):
    from PIL import Image

    nb = nbformat.read(NOTEBOOK, as_version=4)
    assert all(not cell.get("outputs") for cell in nb.cells if cell.cell_type == "code")
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()                       # raises CellExecutionError on any error
    outputs = [out for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs]
    assert not [out for out in outputs if out.output_type == "error"]
    html = [out.data["text/html"] for out in outputs if "text/html" in out.get("data", {})]
    assert any(html_text.startswith("<b>Scene lecture</b>") and "<table>" in html_text
               for html_text in html)
    assert any("kd" in t and "0.35" in t for t in html)            # the edited material
    pngs = [out.data["image/png"] for out in outputs if "image/png" in out.get("data", {})]
    assert len(pngs) == 2                  # the raster and the Whitted image
    for data in pngs:
        with Image.open(io.BytesIO(base64.b64decode(data))) as image:
            assert image.size == (240, 180) and image.mode == "RGB"
            assert max(image.getextrema()[0]) > 0                  # not a black frame
    assert (tmp_path / "lecture-raster.png").is_file()
    assert (tmp_path / "lecture-whitted.exr").is_file()
