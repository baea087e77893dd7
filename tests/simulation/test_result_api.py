"""The notebook face of a result: pandas, xarray, array variables, repr, HTML, plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import springc
from springc.simulation import SimulationResult
from springc.simulation.results import SimulationStats

OSC = """\
model Osc
  parameter Real k(unit = "N/m") = 4;
  parameter Real m(unit = "kg") = 1;
  Real p[2](each unit = "m", start = {1, 2}, each fixed = true);
  Real v[2](each unit = "m/s", start = {0, 0}, each fixed = true);
  Real e(unit = "J");
equation
  der(p) = v;
  m * der(v) = -k * p;
  e = 0.5 * m * (v[1]^2 + v[2]^2) + 0.5 * k * (p[1]^2 + p[2]^2);
end Osc;
"""
NAMES = ("p[1]", "p[2]", "v[1]", "v[2]", "e")
UNITS = {"p[1]": "m", "p[2]": "m", "v[1]": "m/s", "v[2]": "m/s", "e": "J"}


@pytest.fixture(scope="module")
def result(tmp_path_factory: pytest.TempPathFactory) -> SimulationResult:
    path = tmp_path_factory.mktemp("osc") / "Osc.mdl"
    path.write_text(OSC, encoding="utf-8")
    return springc.simulate(path, stop=1.0, interval=0.25, solver="rk4", step=0.01,
                            cache=False)


def test_array_variables_are_two_dimensional(result: SimulationResult) -> None:
    assert result.names == NAMES
    pos = result["p"]
    assert pos.shape == (5, 2)
    assert np.array_equal(pos, np.column_stack([result["p[1]"], result["p[2]"]]))
    assert result["p[2]"].shape == (5,)
    # against the closed form p(t) = p(0) cos(2 t), to the accuracy of rk4 at h = 0.01
    expected = np.outer(np.cos(2 * result.time), [1.0, 2.0])
    assert np.max(np.abs(pos - expected)) < 1e-8
    with pytest.raises(KeyError):
        result["q"]
    with pytest.raises(KeyError):
        result["e[1]"]


def test_to_pandas(result: SimulationResult) -> None:
    frame = result.to_pandas()
    assert list(frame.columns) == list(NAMES)
    assert frame.index.name == "time"
    assert np.array_equal(frame.index.to_numpy(), result.time)
    assert np.array_equal(frame.to_numpy(), result.values)
    assert frame.attrs["units"] == UNITS
    assert frame.attrs["model"] == "Osc"


def test_to_xarray_groups_arrays(result: SimulationResult) -> None:
    data = result.to_xarray()
    assert list(data.data_vars) == ["p", "v", "e"]
    assert data["p"].dims == ("time", "p_index")
    assert list(data["p_index"].values) == [1, 2]
    assert np.array_equal(data["p"].values,
                          np.column_stack([result["p[1]"], result["p[2]"]]))
    assert np.array_equal(data["e"].values, result["e"])
    assert np.array_equal(data["time"].values, result.time)
    assert {name: data[name].attrs["units"] for name in ("p", "v", "e", "time")} == {
        "p": "m", "v": "m/s", "e": "J", "time": "s"}
    assert data.attrs["model"] == "Osc"


def test_repr_and_html(result: SimulationResult) -> None:
    assert repr(result) == ("<SimulationResult Osc: rk4 (compiled), 100 steps, 5 times from 0 "
                            "to 1 s, variables p[2], v[2], e>")
    page = result._repr_html_()
    for row in ("<th style=\"text-align:left\">model</th><td style=\"text-align:left\">Osc",
                "<td style=\"text-align:left\">rk4 (compiled)</td>", ">100</td>",
                ">5 times from 0 to 1 s</td>",
                "<td style=\"text-align:left\">p</td><td>2</td>"
                "<td style=\"text-align:left\">m</td>",
                "<td style=\"text-align:left\">e</td><td></td>"
                "<td style=\"text-align:left\">J</td>"):
        assert row in page


def test_repr_escapes_and_shortens() -> None:
    names = tuple(f"<b>x{i}</b>" for i in range(25))
    result = SimulationResult("M&<i>", np.array([0.0, 1.0]), names, np.zeros((2, 25)),
                              ("",) * 25, SimulationStats("dop853", 7, 0, 0, 0.0, 0.0, 0.0,
                                                          False))
    assert repr(result) == ("<SimulationResult M&<i>: dop853 (scipy), 7 steps, 2 times from 0 "
                            "to 1 s, variables <b>x0</b>, <b>x1</b>, <b>x2</b>, <b>x3</b>, "
                            "... 21 more>")
    page = result._repr_html_()
    assert "<b>" not in page and "<i>" not in page
    assert "M&amp;&lt;i&gt;" in page and "&lt;b&gt;x19&lt;/b&gt;" in page
    assert "x20" not in page and "... 5 more" in page


def test_plot_returns_the_figure_without_writing(result: SimulationResult,
                                                 tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    from matplotlib.figure import Figure

    monkeypatch.chdir(tmp_path)
    figure = result.plot()
    assert isinstance(figure, Figure)
    assert [ax.get_title(loc="left") for ax in figure.axes] == [
        "position", "velocity", "energy"]
    assert [ax.get_ylabel() for ax in figure.axes] == [
        "position [m]", "velocity [m/s]", "energy [J]"]
    assert [line.get_label() for line in figure.axes[0].lines] == ["p[1]", "p[2]"]
    # 5 output times under-sample a turning curve: drawn from the same run on 10 times
    line = figure.axes[0].lines[1]
    assert figure.layout.note == "drawn on 10 times (the output grid has 5)"
    assert np.array_equal(line.get_ydata(), result.rerun(10)["p[2]"])
    assert line.get_xdata()[[0, -1]].tolist() == [0.0, 1.0] and len(result.time) == 5
    assert figure.get_suptitle() == "Osc"
    assert figure._repr_png_().startswith(b"\x89PNG\r\n\x1a\n")
    assert list(tmp_path.iterdir()) == []


def test_missing_optional_dependency_names_the_extra(result: SimulationResult,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "pandas", None)
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ImportError) as info:
        result.to_pandas()
    assert str(info.value) == ("pandas is needed for this (an optional dependency of "
                               "springc): pip install springc[analysis]")
    with pytest.raises(ImportError, match=r"^xarray is needed .*springc\[analysis\]$"):
        result.to_xarray()


def test_only_whole_arrays_of_one_unit_are_grouped() -> None:
    from springc.simulation.tables import ArrayVariable, array_variables

    names = ("a[1,1]", "a[1,2]", "a[2,1]", "a[2,2]", "gap[1]", "gap[3]", "u[1]", "u[2]",
             "w", "w[1]", "der(x[1])", "c[2].f[1]", "c[2].f[2]")
    units = ("m",) * 6 + ("m", "s", "", "", "", "N", "N")
    assert array_variables(names, units) == [
        ArrayVariable("a", (0, 1, 2, 3), (2, 2), "m"),
        ArrayVariable("gap[1]", (4,), (), "m"), ArrayVariable("gap[3]", (5,), (), "m"),
        ArrayVariable("u[1]", (6,), (), "m"), ArrayVariable("u[2]", (7,), (), "s"),
        ArrayVariable("w", (8,), (), ""), ArrayVariable("w[1]", (9,), (), ""),
        ArrayVariable("der(x[1])", (10,), (), ""),
        ArrayVariable("c[2].f", (11, 12), (2,), "N")]
    values = np.arange(26.0).reshape(2, 13)
    result = SimulationResult("M", np.array([0.0, 1.0]), names, values, units,
                              SimulationStats("rk4", 1, 0, 0, 0.0, 0.0, 0.0, False))
    assert np.array_equal(result["a"], [[[0, 1], [2, 3]], [[13, 14], [15, 16]]])
    data = result.to_xarray()
    assert data["a"].dims == ("time", "a_index1", "a_index2")
    assert np.array_equal(data["a"].values, result["a"])
    assert "u[2]" in data and data["u[2]"].attrs == {"units": "s"} and data["w"].attrs == {}


def test_the_csv_is_written_a_few_rows_at_a_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """``write_csv`` turns CSV_ROWS rows into text at a time (no copy of a large result):
    the text of the whole table at once, ``repr`` of each float, integers as floats."""
    import io

    from springc.simulation import results

    monkeypatch.setattr(results, "CSV_ROWS", 2)
    values = np.array([[0.1, -2.5e-300], [1 / 3, 7.0], [np.nan, np.inf], [4.0, -0.0],
                       [1e22, 5e-324]])
    run = SimulationResult("M", np.array([0, 1, 2, 3, 4]), ("a", "b,c"), values,
                           ("", ""), SimulationStats("rk4", 1, 0, 0, 0.0, 0.0, 0.0, False))
    text = io.StringIO()
    results.write_csv(run, text)
    assert text.getvalue() == (
        'time,a,"b,c"\n0.0,0.1,-2.5e-300\n1.0,0.3333333333333333,7.0\n2.0,nan,inf\n'
        "3.0,4.0,-0.0\n4.0,1e+22,5e-324\n")
    empty = io.StringIO()
    results.write_csv(SimulationResult("M", np.array([0.0, 0.5]), (), np.zeros((2, 0)), (),
                                       run.stats), empty)
    assert empty.getvalue() == "time\n0.0\n0.5\n"
