"""Generated code checked numerically: RHS and Jacobian against hand-written ones and
finite differences, sparsity patterns, parameters, outputs, standalone modules."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import springc
from springc.codegen.printer import function_lines
from springc.codegen.statements import Let, Namer, Raw, Store
from springc.ir.expr import BinOp, Call, Const, If, Var

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")
EVENT_SCENES = str(ROOT / "models" / "EventScenes.mdl")


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def seed_rhs(x: np.ndarray, k: float = 1e4, l0: float = 1.0, m: float = 1.0) -> np.ndarray:
    """The seed's 4-state ODE, derived by hand from LANGUAGE.md."""
    pos, v = x[:2], x[2:]
    length = math.hypot(*pos)
    acc = -k * pos * (length - l0) / length / m + np.array([0.0, -9.81])
    return np.concatenate([v, acc])


def seed_jacobian(x: np.ndarray, k: float = 1e4, l0: float = 1.0, m: float = 1.0
                  ) -> np.ndarray:
    pos = x[:2]
    length = math.hypot(*pos)
    outer = np.outer(pos, pos) / length**2
    block = -k / m * ((1 - l0 / length) * np.eye(2) + l0 / length * outer)
    jac = np.zeros((4, 4))
    jac[0:2, 2:4] = np.eye(2)
    jac[2:4, 0:2] = block
    return jac


def finite_differences(mod: object, x: np.ndarray, p: np.ndarray, z: np.ndarray
                       ) -> np.ndarray:
    n = len(x)
    out = np.zeros((n, n))
    for j in range(n):
        h = 1e-6 * max(1.0, abs(x[j]))
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        out[:, j] = (mod.rhs(0.0, up, p, z) - mod.rhs(0.0, down, p, z)) / (2 * h)
    return out


@pytest.fixture(scope="module", params=["python", "numba"])
def seed(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):
    if request.param == "numba":
        pytest.importorskip("numba")
    mp = pytest.MonkeyPatch()
    mp.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
    try:
        yield springc.compile_model(SEED, backend=request.param)
    finally:
        mp.undo()


def test_seed_rhs_and_jacobian_match_hand_written(seed) -> None:
    mod = seed.module
    p, z = mod.parameters(), mod.guesses(mod.parameters())
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = rng.uniform(-2, 2, 4)
        assert np.allclose(mod.rhs(0.3, x, p, z), seed_rhs(x), rtol=1e-13, atol=1e-9)
        jac = mod.jacobian_dense(0.3, x, p, z)
        assert np.allclose(jac, seed_jacobian(x), rtol=1e-12, atol=1e-8)
        assert np.allclose(jac, finite_differences(mod, x, p, z), rtol=1e-5, atol=1e-3)
        sparse = mod.jacobian(0.3, x, p, z)
        assert np.array_equal(sparse.toarray(), jac)


def test_seed_sparsity_pattern(seed) -> None:
    pattern = seed.module.sparsity().toarray() != 0
    expected = seed_jacobian(np.array([0.7, -0.4, 0.0, 0.0])) != 0
    assert np.array_equal(pattern, expected)


def test_seed_observed_and_names(seed) -> None:
    mod = seed.module
    assert mod.STATES == ("mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]")
    assert mod.OBSERVED == ("spring.dir[1]", "spring.dir[2]", "spring.x")
    p = mod.parameters()
    out = mod.observed(0.0, np.array([3.0, 4.0, 0.0, 0.0]), p, mod.guesses(p))
    assert out.tolist() == [3.0, 4.0, 5.0]


@pytest.mark.parametrize("name", ["Scenes.Pendulum", "Scenes.RigidPair", "Scenes.Oscillator",
                                  "Scenes.DampedSpringMass", "Scenes.Chain"])
def test_jacobian_matches_finite_differences(name: str) -> None:
    mod = springc.compile_model(SCENES, name).module
    p = mod.parameters()
    x0, z = mod.start(p), mod.guesses(p)
    rng = np.random.default_rng(2)
    for _ in range(3):
        x = x0 + 0.01 * rng.standard_normal(len(x0))
        jac = mod.jacobian_dense(0.0, x, p, z)
        fd = finite_differences(mod, x, p, z)
        scale = max(1.0, np.abs(fd).max())
        assert np.abs(jac - fd).max() < 1e-6 * scale
        # every non-zero of the true Jacobian lies inside the pattern
        pattern = mod.sparsity().toarray() != 0
        assert np.abs(fd[~pattern]).max(initial=0.0) < 1e-6 * scale


@pytest.mark.parametrize("backend", ["python", "numba"])
def test_chain_rhs_and_jacobian_match_hand_written(backend: str) -> None:
    if backend == "numba":
        pytest.importorskip("numba")
    mod = springc.compile_model(SCENES, "Scenes.Chain", backend=backend).module
    p = mod.parameters()
    n, k, length, mass = 10, 100.0, 1.0, 1.0
    assert mod.STATES[:4] == ("m[1].s", "m[1].v", "m[2].s", "m[2].v")
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 12, 2 * n)
    s, v = x[0::2], x[1::2]
    stretch = np.diff(np.concatenate([[0.0], s])) - length
    force = k * stretch
    acc = (np.append(force[1:], 0.0) - force) / mass
    expected = np.empty(2 * n)
    expected[0::2], expected[1::2] = v, acc
    assert np.allclose(mod.rhs(0.0, x, p, mod.guesses(p)), expected, rtol=1e-13)
    jac = np.zeros((2 * n, 2 * n))
    for i in range(n):
        jac[2 * i, 2 * i + 1] = 1.0
        jac[2 * i + 1, 2 * i] = -2 * k / mass if i < n - 1 else -k / mass
        if i > 0:
            jac[2 * i + 1, 2 * i - 2] = k / mass
        if i < n - 1:
            jac[2 * i + 1, 2 * i + 2] = k / mass
    assert np.array_equal(mod.jacobian_dense(0.0, x, p, mod.guesses(p)), jac)
    assert np.array_equal(mod.sparsity().toarray() != 0, jac != 0)


def test_parameters_follow_bindings_and_overrides() -> None:
    mod = springc.compile_model(SCENES, "Scenes.RigidPair").module
    names = list(mod.PARAMETERS)
    p = mod.parameters({"k_spring": 5.0})
    assert p[names.index("spring.k")] == 5.0  # spring.k = k_spring
    p = mod.parameters({"k_spring": 5.0, "spring.k": 7.0})
    assert p[names.index("spring.k")] == 7.0
    with pytest.raises(KeyError, match=r"spring\.kk"):
        mod.parameters({"spring.kk": 1.0})


def test_start_values_are_functions_of_parameters() -> None:
    mod = springc.compile_model(SEED).module
    x0 = mod.start(mod.parameters({"mass.xy[1]": 2.5}))
    assert x0.tolist() == [2.5, -1.0, 0.0, 0.0]


def test_structural_parameters() -> None:
    mod = springc.compile_model(SCENES, "Scenes.Chain").module
    assert "N" in mod.STRUCTURAL
    assert "k" not in mod.STRUCTURAL and "s[1].c" not in mod.STRUCTURAL


def test_only_requested_observed_variables_are_generated() -> None:
    import inspect

    model = springc.compile_model(SCENES, "Scenes.SpringMassConnected",
                                  outputs=["spring.f", "mass.pos*"])
    mod = model.module
    assert mod.OBSERVED == ("spring.f",)
    assert model.outputs == ("mass.pos[1]", "mass.pos[2]", "spring.f")
    source = inspect.getsource(mod.observed)
    assert "spring_len" in source and "mass_flange_f" not in source
    p = mod.parameters()
    (value,) = mod.observed(0.0, np.array([3.0, 4.0, 0.0, 0.0]), p, mod.guesses(p))
    assert value == pytest.approx(1e4 * (5.0 - 1.0))


def test_nonlinear_block_newton_and_failure_flag() -> None:
    mod = springc.compile_model(SCENES, "Scenes.Pendulum").module
    p = mod.parameters()
    z = mod.guesses(p)
    x = np.array([0.6, 0.0])  # x, vx; y = -sqrt(1 - x^2) on the lower branch
    mod.rhs(0.0, x, p, z)
    assert z[0] == pytest.approx(-0.8, abs=1e-12) and z[-1] == 0.0
    mod.rhs(0.0, np.array([1.5, 0.0]), p, z)  # no real solution: flagged
    assert z[-1] != 0.0 and mod.NEWTON_SYSTEMS[int(z[-1])] == ("y",)


def test_generated_module_runs_without_springc(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from springc.cli import main

    target = tmp_path / "seed_model.py"
    result = CliRunner().invoke(main, ["compile", SEED, "-o", str(target)])
    assert result.exit_code == 0, result.output
    script = (
        "import sys; sys.modules['springc'] = None\n"
        "import importlib.util, numpy as np\n"
        f"spec = importlib.util.spec_from_file_location('m', {str(target)!r})\n"
        "m = importlib.util.module_from_spec(spec); spec.loader.exec_module(m)\n"
        "p = m.parameters({'spring.k': 2.0}); x = m.start(p)\n"
        "print(m.rhs(0.0, x, p, m.guesses(p)).tolist(), m.jacobian(0.0, x, p, m.guesses(p)).nnz)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=tmp_path, check=True).stdout
    expected = seed_rhs(np.array([1.0, -1.0, 0.0, 0.0]), k=2.0)
    assert out.strip() == f"{expected.tolist()} 6"


# ------------------------------------------------------------------ printer units


def test_namer_sanitizes_and_keeps_names_distinct() -> None:
    namer = Namer()
    assert namer("mass.pos[1]") == "mass_pos_1"
    assert namer("der(mass.v[2])") == "der_mass_v_2"
    assert namer("mass_pos_1") == "mass_pos_1_2"
    assert namer("x") == "x_2"  # x is the state vector
    assert namer("lambda") == "lambda_2"
    assert namer("mass.pos[1]") == "mass_pos_1"


def _run(stmts: list, names: dict[str, float]) -> dict[str, float]:
    namer = Namer()
    lines = [f"    {namer(n)} = {v!r}" for n, v in names.items()]
    body = function_lines(namer, set(), stmts)
    source = "import math\ndef f():\n" + "\n".join(lines + body) + "\n    return locals()\n"
    env: dict[str, object] = {}
    exec(source, env)
    return env["f"](), source  # type: ignore[operator,return-value]


def test_common_subexpressions_are_computed_once() -> None:
    a, b = Var("a"), Var("b")
    shared = Call("sqrt", (BinOp("+", BinOp("*", a, a), BinOp("*", b, b)),))
    stmts = [Raw("out = [0.0, 0.0]"), Store("out[0]", BinOp("/", a, shared)),
             Store("out[1]", BinOp("/", b, shared))]
    values, source = _run(stmts, {"a": 3.0, "b": 4.0})
    assert values["out"] == [0.6, 0.8]
    assert source.count("math.sqrt") == 1


def test_if_branches_are_not_hoisted() -> None:
    x = Var("x")
    guarded = Call("sqrt", (x,))
    stmts = [Raw("out = [0.0, 0.0]"),
             Store("out[0]", If(BinOp(">", x, Const(0)), guarded, Const(0.0))),
             Store("out[1]", If(BinOp(">", x, Const(0)), BinOp("*", guarded, Const(2)),
                                Const(1.0)))]
    values, _ = _run(stmts, {"x": -4.0})  # math.sqrt(-4) must never run
    assert values["out"] == [0.0, 1.0]


def test_reassigned_variables_invalidate_shared_values() -> None:
    y = Var("y")
    twice = BinOp("*", Const(2), y)
    stmts = [Raw("out = [0.0, 0.0]"), Store("out[0]", BinOp("+", twice, Const(1))),
             Let("y", BinOp("+", y, Const(1))), Store("out[1]", BinOp("+", twice, Const(1)))]
    values, _ = _run(stmts, {"y": 1.0})
    assert values["out"] == [3.0, 5.0]


def test_unused_statements_are_dropped() -> None:
    writer_lines = function_lines(Namer(), set(), [
        Let("unused", BinOp("+", Var("a"), Const(1))), Raw("out = 0"),
        Store("out", Var("a"))])
    assert not any("unused" in line for line in writer_lines)


# ------------------------------------------------------------------ vector layout

CLOTH = """
model SmallCloth
  extends Scenes.Cloth(N = 3, M = 4);
end SmallCloth;
"""


def _generated(files: list[str], model: str, **options: object):
    from springc.codegen.generator import CodegenOptions, generate
    from springc.pipeline.files import flatten_files
    from springc.simplify.passes import simplify

    flat_model = flatten_files(files, model)
    system = simplify(flat_model).ode
    return generate(system, flat_model, CodegenOptions(**options))  # type: ignore[arg-type]


def _load(source: str, tmp_path: Path, name: str):
    import importlib.util

    path = tmp_path / f"{name}.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("backend", ["python", "numba"])
@pytest.mark.parametrize("scene", ["chain", "cloth"])
def test_vector_layout_matches_scalar_layout(tmp_path: Path, backend: str, scene: str) -> None:
    if backend == "numba":
        pytest.importorskip("numba")
    if scene == "cloth":
        (tmp_path / "cloth.mdl").write_text(CLOTH)
        files, model = [str(tmp_path / "cloth.mdl")], "SmallCloth"
    else:
        files, model = [SCENES], "Scenes.Chain"
    scalar = _load(_generated(files, model, vector=False).source, tmp_path,
                   f"scalar_{scene}_{backend}")
    vector_source = _generated(files, model, backend=backend, vector=True).source
    assert "for _q in range(" in vector_source or backend == "python"
    vector = _load(vector_source, tmp_path, f"vector_{scene}_{backend}")
    if backend == "numba":  # jitted with the model-function signature: the compiled loops
        from numba.core.dispatcher import Dispatcher  # call them through function pointers

        assert all(isinstance(getattr(vector, fn), Dispatcher)
                   for fn in ("rhs", "jacobian_values", "observed", "assertions"))
    assert vector.STATES == scalar.STATES and vector.OBSERVED == scalar.OBSERVED
    given = {"k": 50.0} if scene == "chain" else {"k_shear": 150.0}
    p = vector.parameters(given)
    assert np.array_equal(p, scalar.parameters(given))
    assert np.array_equal(vector.start(p), scalar.start(p))
    rng = np.random.default_rng(4)
    x = scalar.start(p) + 0.01 * rng.standard_normal(len(scalar.STATES))
    z = scalar.guesses(p)
    assert np.allclose(vector.rhs(0.1, x, p, z), scalar.rhs(0.1, x, p, z), rtol=1e-13,
                       atol=1e-11)
    assert np.array_equal(vector.sparsity().toarray(), scalar.sparsity().toarray())
    assert np.allclose(vector.jacobian_dense(0.1, x, p, z), scalar.jacobian_dense(0.1, x, p, z),
                       rtol=1e-12, atol=1e-9)
    assert np.allclose(vector.observed(0.1, x, p, z), scalar.observed(0.1, x, p, z),
                       rtol=1e-13, atol=1e-11)
    grid = np.array([0.0, 0.5])
    states = np.vstack([x, x])
    assert np.allclose(vector.observed_grid(grid, states, p, z)[1],
                       scalar.observed(0.5, x, p, z), rtol=1e-13, atol=1e-11)


def test_vector_layout_groups_a_chain_into_loops() -> None:
    source = _generated([SCENES], "Scenes.Chain", backend="numba", vector=True).source
    rhs = source[source.index("def rhs("):source.index("def jacobian_values(")]
    assert rhs.count("for _q in range(") <= 8  # a handful of loops, not 10 x 5 statements
    assert "# 9 x s[2].s_rel := m[2].s - m[1].s" in rhs


CHAIN_200 = """
model Chain200
  extends Scenes.Chain(N = 200);
end Chain200;
"""


def test_vector_parameters_lift_constant_operands(tmp_path: Path) -> None:
    """``m[i].s0 = L*i`` (+ ``ds`` for i = 1): the constants i are read from a table,
    so the 200 bindings are one numpy statement, not 200 lines, with the same values
    (``L * i`` exactly, here with L = 0.3 given)."""
    (tmp_path / "chain.mdl").write_text(CHAIN_200)
    source = _generated([SCENES, str(tmp_path / "chain.mdl")], "Chain200",
                        backend="numba").source
    body = source[source.index("def parameters("):source.index("def start(")]
    assert body.count("\n") < 40  # one line per binding was 400 lines
    module = _load(source, tmp_path, "chain200_lifted")
    p = module.parameters({"L": 0.3})
    s0 = [p[module.PARAMETERS.index(f"m[{i}].s0")] for i in range(1, 201)]
    assert s0 == [0.3 * 1 + 0.5] + [0.3 * i for i in range(2, 201)]
    x = module.start(p)
    assert [x[module.STATES.index(f"m[{i}].s")] for i in range(1, 201)] == s0


def test_a_parameter_read_only_by_event_code_can_be_changed() -> None:
    """The ball's restitution ``e`` is read only by its reinit: not structural, and a
    run with ``e = 0.5`` bounces as the closed form says (impact speed ``e**k * v1``)."""
    model = springc.compile_model(EVENT_SCENES, "EventScenes.BouncingBall", cache=False)
    assert "e" not in model.module.STRUCTURAL
    result = springc.simulate(model, parameters={"e": 0.5}, stop=1.0, interval=0.001,
                              rtol=1e-10, atol=1e-12)
    g, e = 9.81, 0.5
    t1 = (2.0 / g) ** 0.5
    v1 = g * t1
    t2 = t1 + 2 * e * v1 / g
    expected = e * e * v1 - g * (1.0 - t2)
    v_end = result.values[-1, list(result.names).index("v")]
    assert v_end == pytest.approx(expected, rel=1e-6)
