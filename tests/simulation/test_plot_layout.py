"""Plots that scale: which panels a result gets (quantities with legends, or families
with heat maps and colour bars), copies drawn once, the note, and the drawn figure."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import springc
from springc.cli import main
from springc.simulation import SimulationResult
from springc.simulation.plot_layout import (
    HEATMAP,
    LINES,
    MAX_LEGEND,
    MAX_PLOT_POINTS,
    SAMPLES_PER_PERIOD,
    Panel,
    choose_layout,
    copies_of,
    families,
    plot_points,
)

SCENES = str(Path(__file__).resolve().parents[2] / "models" / "Scenes.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def cloth(tmp_path_factory: pytest.TempPathFactory) -> SimulationResult:
    """The 4x4 cloth: 16 masses, 728 outputs, 411 of them copies of another."""
    import os

    os.environ.setdefault("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    return springc.simulate(SCENES, model_name="Scenes.Cloth", parameters={"N": 4, "M": 4},
                            stop=0.1, interval=0.01)


def test_copies_are_equal_or_negated_columns_found_exactly() -> None:
    t = np.linspace(0.0, 1.0, 7)
    a, b = np.sin(3 * t), np.cos(t)
    close = a.copy()
    close[3] += 1e-15  # one ulp-sized difference: not a copy
    values = np.column_stack([a, b, a, -a, close, np.zeros(7), -np.zeros(7), -b])
    assert copies_of(values) == {2: (0, 1), 3: (0, -1), 6: (5, 1), 7: (1, -1)}
    assert copies_of(values[:, :1]) == {}


def test_families_strip_subscripts_and_keep_vector_components_apart() -> None:
    names = ["p[1,1].pos[1]", "p[1,1].pos[2]", "p[1,2].pos[1]", "p[1,2].pos[2]",
             "x[1]", "x[2]", "x[3]", "x[4]", "s[1].f", "s[2].f", "mass.pos[1]",
             "mass.pos[2]"]
    units = ["m"] * 4 + [""] * 4 + ["N", "N", "m", "m"]
    assert families(names, units, range(len(names))) == [
        ("p[:].pos[1]", [0, 2]), ("p[:].pos[2]", [1, 3]), ("x[:]", [4, 5, 6, 7]),
        ("s[:].f", [8, 9]), ("mass.pos[:]", [10, 11])]


def test_a_small_result_gets_one_panel_per_quantity_with_copies_in_the_legend() -> None:
    t = np.linspace(0.0, 1.0, 5)
    x = np.column_stack([t, t * t, 2 * t, -t, t + 1, t * t])
    names = ["m.pos[1]", "m.pos[2]", "m.v[1]", "s.a.pos", "s.len", "s.b.pos"]
    layout = choose_layout(names, ["m", "m", "m/s", "m", "m", "m"], x)
    assert layout.panels == (
        Panel(LINES, "position", "position [m]", (0, 1, 4),
              ("m.pos[1] = -s.a.pos", "m.pos[2] = s.b.pos", "s.len")),
        Panel(LINES, "velocity", "velocity [m/s]", (2,), ("m.v[1]",)))
    assert layout.copies == {3: (0, -1), 5: (1, 1)}
    assert layout.note == "2 copies (equal to another variable or its negative) drawn once"


def test_a_quantity_of_more_than_a_legend_makes_family_panels() -> None:
    n = MAX_LEGEND + 1
    t = np.linspace(0.0, 1.0, 4)
    names = [f"c[{i}].s" for i in range(1, n + 1)] + ["e", "f"]
    values = np.column_stack([t * i for i in range(1, n + 1)] + [t ** 3, t ** 4])
    layout = choose_layout(names, ["m"] * n + ["J", "J"], values)
    assert layout.panels == (
        Panel(HEATMAP, f"c[:].s: {n} variables, c[1].s (top) to c[{n}].s (bottom)",
              "position [m]", tuple(range(n))),
        Panel(LINES, "e (energy)", "energy [J]", (n,), ("e",)),
        Panel(LINES, "f (energy)", "energy [J]", (n + 1,), ("f",)))
    assert layout.note == (f"{n + 2} variables in 3 families; drawn: c[:].s (heat map), "
                           "e (lines), f (lines)")


def test_the_cloth_gets_heat_maps_of_positions_and_velocities(cloth: SimulationResult
                                                             ) -> None:
    layout = choose_layout(cloth.names, cloth.units, cloth.values)
    assert [(p.kind, p.title, p.label) for p in layout.panels] == [
        (HEATMAP, f"p[:].{q}: 16 variables, p[1,1].{q} (top) to p[4,4].{q} (bottom)", label)
        for q, label in (("pos[1]", "position [m]"), ("pos[2]", "position [m]"),
                         ("v[1]", "velocity [m/s]"), ("v[2]", "velocity [m/s]"))]
    assert [cloth.names[c] for c in layout.panels[1].columns] == [
        f"p[{i},{j}].pos[2]" for i in range(1, 5) for j in range(1, 5)]
    assert layout.note == (
        "728 variables in 26 families; drawn: p[:].pos[1] (heat map), p[:].pos[2] "
        "(heat map), p[:].v[1] (heat map), p[:].v[2] (heat map); not drawn: 22 families "
        "(253 variables), select them with --vars; 411 copies of another variable left out")
    for copy, (original, sign) in layout.copies.items():
        assert np.array_equal(cloth.values[:, copy], sign * cloth.values[:, original])
    # an alias of a mass's position: the flange of the mass is the same point
    flange = cloth.names.index("p[2,3].flange.pos[1]")
    assert layout.copies[flange] == (cloth.names.index("p[2,3].pos[1]"), 1)


def test_the_cloth_figure_has_colour_bars_and_the_note(cloth: SimulationResult) -> None:
    figure = cloth.plot()
    maps = [ax for ax in figure.axes if ax.images]
    assert len(maps) == 4 and len(figure.axes) == 8  # a colour bar beside each map
    image = maps[1].images[0].get_array()
    assert image.shape == (16, len(cloth.time))
    assert image.dtype == np.float32  # (see figure._heat_map)
    assert np.array_equal(image[5], cloth["p[2,2].pos[2]"].astype(np.float32))
    bars = [ax for ax in figure.axes if not ax.images]
    assert [ax.get_ylabel() for ax in bars] == ["position [m]", "position [m]",
                                                "velocity [m/s]", "velocity [m/s]"]
    assert figure.layout.note in " ".join(t.get_text() for t in figure.texts).replace(
        "\n", " ")
    assert figure.get_suptitle() == "Scenes.Cloth"


def test_cli_plot_of_a_large_scene_says_what_it_drew(tmp_path: Path) -> None:
    out = CliRunner().invoke(main, ["simulate", SCENES, "--model", "Scenes.Cloth",
                                    "--set", "N=4", "--set", "M=4", "--stop", "0.1",
                                    "--interval", "0.01", "--plot",
                                    str(tmp_path / "cloth.png")])
    assert out.exit_code == 0, out.stderr
    assert out.stderr.splitlines()[0] == (
        f"note: plot {tmp_path / 'cloth.png'}: 728 variables in 26 families; drawn: "
        "p[:].pos[1] (heat map), p[:].pos[2] (heat map), p[:].v[1] (heat map), p[:].v[2] "
        "(heat map); not drawn: 22 families (253 variables), select them with --vars; "
        "411 copies of another variable left out")
    assert (tmp_path / "cloth.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_a_legend_entry_names_at_most_two_copies() -> None:
    t = np.linspace(0.0, 1.0, 3)
    values = np.column_stack([t, t, -t, t, t * t])
    layout = choose_layout(["a", "b", "c", "d", "e"], [""] * 5, values)
    assert layout.panels[0].labels == ("a = b = -c (+1 more)",)
    assert layout.copies == {1: (0, 1), 2: (0, -1), 3: (0, 1)}


SEED = str(Path(__file__).resolve().parents[2] / "models" / "SpringMass.mdl")


def test_the_seed_draws_direction_once_as_a_copy_of_position() -> None:
    result = springc.simulate(SEED)
    layout = choose_layout(result.names, result.units, result.values)
    assert [(p.title, p.labels) for p in layout.panels] == [
        ("position", ("mass.pos[1] = spring.dir[1]", "mass.pos[2] = spring.dir[2]")),
        ("velocity", ("mass.v[1]", "mass.v[2]")), ("x", ("spring.x",))]
    assert layout.copies == {4: (0, 1), 5: (1, 1)}


def test_copies_of_wide_random_columns_are_found_whatever_their_position() -> None:
    # a BLAS product may sum equal columns in different orders; the row-by-row sums do not
    values = np.random.default_rng(1).standard_normal((501, 40))
    values[:, 37] = values[:, 3]
    values[:, 38] = -values[:, 11]
    assert copies_of(values) == {37: (3, 1), 38: (11, -1)}


def test_an_under_sampled_oscillation_asks_for_a_finer_grid() -> None:
    t = np.linspace(0.0, 10.0, 501)  # the seed's grid: 3 rows per period of 16 Hz
    fast, slow = np.sin(2 * np.pi * 16 * t), np.sin(2 * np.pi * 0.5 * t)
    values = np.column_stack([slow, fast, np.floor(t)])
    assert plot_points(values, [0]) == 0  # 100 rows per period: enough
    assert plot_points(values, [0, 2]) == 0  # a staircase has no extrema
    points = plot_points(values, [0, 1])
    assert 2 * 501 <= points <= MAX_PLOT_POINTS
    fine = np.linspace(0.0, 10.0, MAX_PLOT_POINTS)
    assert plot_points(np.sin(2 * np.pi * 16 * fine)[:, None], [0]) == 0
    # 160 periods on the fine grid need 16 rows each: 2,560 <= 8,000
    assert 160 * SAMPLES_PER_PERIOD <= MAX_PLOT_POINTS


def test_discrete_variables_are_drawn_as_steps() -> None:
    t = np.linspace(0.0, 1.0, 5)
    values = np.column_stack([t, np.floor(4 * t), t * t])
    layout = choose_layout(["h", "n", "m.s"], ["m", "", "m"], values, discrete=("n",))
    assert layout.panels == (
        Panel(LINES, "position", "position [m]", (0, 2), ("h", "m.s")),
        Panel(LINES, "n", "n", (1,), ("n",), (1,)))


BOUNCE = """model Bounce
  parameter Real g(unit = "m/s2") = 9.81;
  Real h(start = 1, fixed = true, unit = "m");
  Real v(start = 0, fixed = true, unit = "m/s");
  Integer n(start = 0, fixed = true);
equation
  der(h) = v;
  der(v) = -g;
  when h < 0 then
    reinit(v, -0.8*pre(v));
    n = pre(n) + 1;
  end when;
end Bounce;
"""


def test_a_plot_is_drawn_from_a_finer_run_and_the_result_keeps_its_grid(tmp_path: Path
                                                                        ) -> None:
    path = tmp_path / "bounce.mo"
    path.write_text(BOUNCE)
    result = springc.simulate(str(path), stop=1.0, interval=0.1, rtol=1e-9)
    assert result.discrete == ("n",) and len(result.time) == 11
    figure = result.plot()
    assert len(result.time) == 11  # the result's grid is the user's
    lines = [ax.lines for ax in figure.axes]
    assert [[line.get_drawstyle() for line in group] for group in lines] == [
        ["default"], ["default"], ["steps-post"]]
    time = lines[0][0].get_xdata()
    # the first bounce, at sqrt(2/g): rows there from its left to its right limit
    bounce = np.sqrt(2 / 9.81)
    at = np.flatnonzero(np.abs(time - bounce) < 1e-6)
    assert len(at) >= 2 and len(time) > 11
    v = lines[1][0].get_ydata()
    assert abs(v[at[0]] + 9.81 * bounce) < 1e-6
    assert abs(v[at[-1]] - 0.8 * 9.81 * bounce) < 1e-6
    assert figure.layout.note == f"drawn on {len(time)} times (the output grid has 11)"


def test_a_heat_map_resampled_before_it_is_coloured_is_the_same_image() -> None:
    # many more variables than pixel rows: matplotlib picks the nearest value of each
    # pixel; colouring first (the rgba stage) made an RGBA array of every value
    from springc.simulation.figure import draw_layout

    n, t = 2_000, np.linspace(0.0, 1.0, 301)
    names = [f"c[{i}].s" for i in range(1, n + 1)]
    values = np.sin(np.outer(t, np.arange(1.0, n + 1.0)) * 0.37) * np.arange(1.0, n + 1.0)
    layout = choose_layout(names, ["m"] * n, values)
    assert [p.kind for p in layout.panels] == [HEATMAP]
    figure = draw_layout("M", t, values, layout, names)
    (image,) = [image for ax in figure.axes for image in ax.images]
    assert image.get_interpolation_stage() == "data"
    figure.canvas.draw()
    resampled = np.array(figure.canvas.buffer_rgba())
    image.set_interpolation_stage("rgba")
    figure.canvas.draw()
    assert np.array_equal(np.array(figure.canvas.buffer_rgba()), resampled)
