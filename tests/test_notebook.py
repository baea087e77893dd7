"""docs/notebook.ipynb executed in a Jupyter kernel (nbclient): the DataFrame, the LaTeX
equations and the inline plot are checked in the outputs the notebook shows."""

from __future__ import annotations

import base64
import json
import sys
from pathlib import Path
from typing import Any

import pytest

NOTEBOOK = Path(__file__).resolve().parents[1] / "docs" / "notebook.ipynb"
KERNEL = "springc-test"


@pytest.fixture(scope="module")
def executed(tmp_path_factory: pytest.TempPathFactory) -> list[dict[str, Any]]:
    """The notebook's code cells after a run in a kernel of this interpreter (a kernel
    spec of its own, so that the kernel imports the springc under test)."""
    import nbclient
    import nbformat

    home = tmp_path_factory.mktemp("jupyter")
    spec = home / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "springc test", "language": "python"}))
    with pytest.MonkeyPatch.context() as env:
        env.setenv("JUPYTER_PATH", str(home))
        env.setenv("SPRINGC_CACHE_DIR", str(home / "cache"))
        env.setenv("MPLBACKEND", "agg")
        notebook = nbformat.read(NOTEBOOK, as_version=4)
        nbclient.NotebookClient(notebook, timeout=600, kernel_name=KERNEL,
                                resources={"metadata": {"path": str(home)}}).execute()
    return [cell for cell in notebook.cells if cell.cell_type == "code"]


def shown(cell: dict[str, Any]) -> dict[str, Any]:
    """The rich output of a cell's last expression (``execute_result``)."""
    (result,) = [o for o in cell["outputs"] if o["output_type"] == "execute_result"]
    return dict(result["data"])


def test_no_cell_fails_or_writes_to_stderr(executed: list[dict[str, Any]]) -> None:
    for cell in executed:
        assert [o for o in cell["outputs"] if o["output_type"] in ("error", "stream")] == []


def test_the_equations_are_latex(executed: list[dict[str, Any]]) -> None:
    latex = shown(executed[1])["text/latex"]
    assert latex == "$$\\begin{aligned}\n\\dot{x} &= - k x \\\\\ny &= 2 x\n\\end{aligned}$$"


def test_the_dataframe_has_the_columns_and_exp_minus_one(executed: list[dict[str, Any]]
                                                        ) -> None:
    html = shown(executed[2])["text/html"]
    assert "<th>x</th>\n      <th>y</th>" in html and "<th>time</th>" in html
    # x(1) = exp(-1) = 0.3678794 (rk4 at step 0.01 is within 1e-10), y = 2x
    assert ("<th>1.00</th>\n      <td>0.367879</td>\n      <td>0.735759</td>" in html)


def test_the_plot_is_an_inline_png(executed: list[dict[str, Any]]) -> None:
    data = shown(executed[3])
    png = base64.b64decode(data["image/png"])
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    # one panel (x and y are both positions, in m) at 100 dpi: 3.5 inches high, 10.465
    # wide (0.9 margin, 8.9 panel, its legend at the right: 0.6 + 0.065 per character)
    assert (width, height) == (1046, 350)
    assert data["text/plain"] == "<ResultFigure size 1046.5x350 with 1 Axes>"
