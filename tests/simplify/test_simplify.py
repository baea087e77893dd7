"""Structural simplification: each pass on small models, and the issue's structural list
(matchings, BLT blocks and chosen states asserted as sets)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from springc.errors import BalanceError, SimplifyError
from springc.ir import ode
from springc.ir.expr import to_text
from springc.pipeline.files import flatten_files
from springc.simplify.alias import eliminate_aliases
from springc.simplify.causalize import causalize
from springc.simplify.index_reduction import index_reduce
from springc.simplify.lower import lower
from springc.simplify.ode_eval import OdeEvaluator, parameter_values
from springc.simplify.passes import simplify

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "models" / "Scenes.mdl"


def flat(tmp_path: Path, text: str, model: str | None = None):
    path = tmp_path / "m.mdl"
    path.write_text(text)
    return flatten_files([path], model)


def scene(name: str):
    return flatten_files([SCENES], f"Scenes.{name}")


def states(model: ode.ODE) -> set[str]:
    return {s.name for s in model.states}


def blocks(model: ode.ODE) -> list[tuple[str, frozenset[str]]]:
    """(kind, names) of every step, in evaluation order."""
    out = []
    for step in model.steps:
        if isinstance(step, ode.Assign):
            out.append(("assign", frozenset({step.name})))
        elif isinstance(step, ode.LinearBlock):
            out.append(("linear", frozenset(step.names)))
        else:
            out.append(("nonlinear", frozenset(step.tearing + tuple(a.name for a in step.inner))))
    return out


# ----------------------------------------------------------------- alias pass

ALIASES = """
model A
  Real a(start = 1, fixed = true);
  Real b;
  Real c;
  Real d;
  Real e;
  parameter Real p = 3;
  Real f;
equation
  der(a) = -a + e + f;
  b = a;
  c = -b;
  d + c = 0;
  e = 2.0;
  f = 2*p;
end A;
"""


def test_alias_chains_signs_and_constants(tmp_path: Path) -> None:
    result = eliminate_aliases(lower(flat(tmp_path, ALIASES)))
    values = {a.name: to_text(a.value) for a in result.aliases}
    assert values == {"b": "a", "c": "-a", "d": "a", "e": "2.0", "f": "2 * p"}
    assert [u.name for u in result.dae.unknowns] == ["a"]
    assert [to_text(r.expr) for r in result.dae.equations] == ["der(a) - (-a + 2.0 + 2 * p)"]


SECOND_ROUND = """
model B
  Real a(start = 1, fixed = true);
  Real s;
  Real f;
  Real z;
  Real w;
equation
  der(a) = -a + s + w;
  s = f - z;
  z = 0;
  f = 3*a;
  w = sin(a) + f*z;
end B;
"""


def test_alias_made_by_a_substitution_is_eliminated_in_a_second_round(
        tmp_path: Path) -> None:
    # ``s = f - z`` is an alias only once ``z = 0`` is substituted (the rewritten
    # equations are classified again); ``w``'s equation, rewritten too, is none
    result = eliminate_aliases(lower(flat(tmp_path, SECOND_ROUND)))
    assert {a.name: to_text(a.value) for a in result.aliases} == {"f": "s", "z": "0"}
    assert [u.name for u in result.dae.unknowns] == ["a", "s", "w"]
    assert [to_text(r.expr) for r in result.dae.equations] == [
        "der(a) - (-a + s + w)", "s - 3 * a", "w - sin(a)"]


def test_alias_keeps_fixed_start_then_state_select(tmp_path: Path) -> None:
    text = """
model P
  Real p;
  Real q(start = 2, fixed = true);
  Real r(stateSelect = StateSelect.prefer);
  Real s;
equation
  p = q;
  der(p) = -p;
  r = s;
  der(s) = -r;
end P;
"""
    result = eliminate_aliases(lower(flat(tmp_path, text)))
    assert {u.name for u in result.dae.unknowns} == {"q", "r"}
    assert {a.name: to_text(a.value) for a in result.aliases} == {"p": "q", "s": "r"}
    assert result.dae.differentiated == frozenset({"q", "r"})


def test_alias_conflicting_start_values_warn(tmp_path: Path) -> None:
    text = """
model W
  Real a(start = 1);
  Real b(start = 2);
equation
  a = b;
  der(a) = -a;
end W;
"""
    result = eliminate_aliases(lower(flat(tmp_path, text)))
    assert len(result.warnings) == 1
    assert "conflicting start values" in result.warnings[0].message
    assert "a = 1" in result.warnings[0].message and "b = 2" in result.warnings[0].message


def test_alias_negated_start_values_agree(tmp_path: Path) -> None:
    text = """
model N
  Real a(start = 1);
  Real b(start = -1);
equation
  a = -b;
  der(a) = -a;
end N;
"""
    assert eliminate_aliases(lower(flat(tmp_path, text))).warnings == ()


# ------------------------------------------------------ the structural list


def test_seed_states_and_observed() -> None:
    model = simplify(flatten_files([ROOT / "models" / "SpringMass.mdl"])).ode
    assert states(model) == {"mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]"}
    assert set(model.observed_names()) == {"spring.x", "spring.dir[1]", "spring.dir[2]"}
    # Matching: every step is one explicit assignment; BLT puts spring.x after dir.
    kinds = blocks(model)
    assert {k for k, _ in kinds} == {"assign"}
    order = [next(iter(names)) for _, names in kinds]
    assert set(order) == {"der(mass.pos[1])", "der(mass.pos[2])", "der(mass.v[1])",
                          "der(mass.v[2])", "spring.x", "spring.dir[1]", "spring.dir[2]"}
    assert order.index("spring.dir[1]") < order.index("spring.x") < order.index("der(mass.v[1])")


def test_connector_chain() -> None:
    model = simplify(scene("Chain")).ode
    assert states(model) == {f"m[{i}].{v}" for i in range(1, 11) for v in ("s", "v")}
    assert {k for k, _ in blocks(model)} == {"assign"}
    assert len(model.steps) + len(model.observed) + len(model.states) == len(
        scene("Chain").unknowns) + 20  # + the 20 derivatives


SERIES = """
model Series "fixed --s1-- n1 --s2-- n2 --s3-- mass: node positions from a linear system"
  import T = Translational;
  parameter Real c[3] = {10, 20, 30};
  T.Fixed fixed;
  T.Spring s[3](c = c, each s_rel0 = 1);
  T.Mass mass(m = 1, s0 = 3.5);
  Real n1 = s[1].flange_b.s;
  Real n2 = s[2].flange_b.s;
equation
  connect(fixed.flange, s[1].flange_a);
  connect(s[1].flange_b, s[2].flange_a);
  connect(s[2].flange_b, s[3].flange_a);
  connect(s[3].flange_b, mass.flange);
end Series;
"""


def test_springs_in_series_solve_a_linear_system(tmp_path: Path) -> None:
    model = simplify(flat(tmp_path, SERIES)).ode
    assert states(model) == {"mass.s", "mass.v"}
    linear = [names for kind, names in blocks(model) if kind == "linear"]
    assert len(linear) == 1 and len(linear[0]) >= 2
    # Numerically: equal tension in all springs, positions as for springs in series.
    params = parameter_values(model.parameters)
    env = OdeEvaluator(model, params).values(0.0, [3.5, 0.0])
    env.update(OdeEvaluator(model, params).observed(env))
    f = [env[f"s[{i}].f"] for i in (1, 2, 3)]
    total = 0.5 / (1 / 10 + 1 / 20 + 1 / 30)  # stretch 0.5 over three springs
    assert f == pytest.approx([total] * 3, rel=1e-12)
    assert env["n1"] == pytest.approx(1 + total / 10, rel=1e-12)


def test_pendulum_index_three() -> None:
    system = eliminate_aliases(lower(scene("Pendulum"))).dae
    reduced = index_reduce(system)
    constraint = next(i for i, r in enumerate(system.equations)
                      if "L" in to_text(r.expr) and "der" not in to_text(r.expr))
    orders = [o for s, o in zip(reduced.sources, reduced.orders)
              if s is system.equations[constraint]]
    assert sorted(orders) == [0, 1, 2]  # differentiated twice
    model = simplify(scene("Pendulum")).ode
    assert len(model.states) == 2
    assert states(model) in ({"x", "vx"}, {"y", "vy"})
    kinds = blocks(model)
    assert any(kind == "linear" and "lambda" in names for kind, names in kinds)


def test_rigid_pair_keeps_six_states_regular_at_start() -> None:
    model = simplify(scene("RigidPair")).ode
    # The rod starts horizontal: p2's vertical coordinate must remain a state.
    assert states(model) == {"p1.pos[1]", "p1.pos[2]", "p1.v[1]", "p1.v[2]",
                             "p2.pos[2]", "p2.v[2]"}


TORN = """
model Torn "a nonlinear loop in y and z that needs tearing"
  Real x(start = 1, fixed = true);
  Real y(start = 0.5);
  Real z;
  Real w;
equation
  der(x) = -y;
  y + z^3 = x;
  z = cos(y) + w;
  w = 0.1*y^2;
end Torn;
"""


def test_nonlinear_loop_is_torn(tmp_path: Path) -> None:
    model = simplify(flat(tmp_path, TORN)).ode
    assert states(model) == {"x"}
    torn = [s for s in model.steps if isinstance(s, ode.NonlinearBlock)]
    assert len(torn) == 1
    step = torn[0]
    assert len(step.tearing) == 1 and len(step.residuals) == 1
    assert set(step.tearing) | {a.name for a in step.inner} == {"y", "z", "w"}
    env = OdeEvaluator(model, {}).values(0.0, [1.0])
    assert env["y"] + env["z"] ** 3 == pytest.approx(1.0, abs=1e-10)
    assert env["z"] == pytest.approx(np.cos(env["y"]) + 0.1 * env["y"] ** 2, abs=1e-10)


def test_oscillator_der_of_algebraic_keeps_mass_positions() -> None:
    model = simplify(scene("Oscillator")).ode
    assert states(model) == {"mass1.s", "mass1.v", "mass2.s", "mass2.v"}


@pytest.mark.parametrize(("name", "count"), [
    ("SpringMassConnected", 4), ("DampedSpringMass", 4), ("Chain", 20), ("Cloth", 400),
    ("Pendulum", 2), ("RigidPair", 6), ("Oscillator", 4)])
def test_state_counts(name: str, count: int) -> None:
    assert len(simplify(scene(name)).ode.states) == count


def test_structurally_singular_names_equations(tmp_path: Path) -> None:
    text = """
model S
  Real x;
  Real y;
  Real z;
equation
  x^2 = 2;
  sin(x) = 0.1;
  y^2 + z^2 = 1;
end S;
"""
    model = flat(tmp_path, text)
    # Index reduction names them (simplify runs the balance check before, which does too).
    with pytest.raises(SimplifyError) as info:
        index_reduce(eliminate_aliases(lower(model)).dae)
    err = info.value
    assert err.message.startswith("the system is structurally singular")
    texts = " ".join(n.message for n in err.notes)
    assert "x ^ 2 = 2" in texts and "sin(x) = 0.1" in texts
    with pytest.raises(BalanceError) as balance:
        simplify(model)
    assert balance.value.message == ("model 'S' is structurally singular: 3 unknowns, "
                                     "3 equations, but they do not match")


def test_causalize_blocks_are_in_dependency_order(tmp_path: Path) -> None:
    reduced = index_reduce(eliminate_aliases(lower(flat(tmp_path, TORN))).dae)
    steps = causalize(reduced)
    known = {"x"}
    for step in steps:
        computed = ({step.name} if isinstance(step, ode.Assign) else
                    set(step.names) if isinstance(step, ode.LinearBlock) else
                    set(step.tearing) | {a.name for a in step.inner})
        assert computed.isdisjoint(known)
        known |= computed
    assert known == {"x", "y", "z", "w", "der(x)"}


def test_derivative_names_are_built_and_read_by_one_pair_of_functions() -> None:
    from springc.ir.dae import derivative_base, derivative_name, is_derivative

    assert derivative_name("mass.v[1]") == "der(mass.v[1])"
    assert derivative_base("der(mass.v[1])") == "mass.v[1]"
    assert derivative_base(derivative_name(derivative_name("x"))) == "der(x)"
    assert derivative_base("derivative") is None and derivative_base("der(x") is None
    assert is_derivative("der(x)") and not is_derivative("x")


def test_alias_classes_keep_the_member_that_index_reduction_ranks_highest(
        tmp_path: Path) -> None:
    # One policy (structure.state_priority): stateSelect = prefer outranks a fixed start
    # with the default stateSelect (2.0 against 1.5), as in the dummy-derivative choice.
    text = """
model P
  Real x(start = 1, fixed = true);
  Real y(stateSelect = StateSelect.prefer);
equation
  x = y;
  der(y) = -y;
end P;
"""
    result = eliminate_aliases(lower(flat(tmp_path, text)))
    assert [u.name for u in result.dae.unknowns] == ["y"]
    assert [(a.name, to_text(a.value)) for a in result.aliases] == [("x", "y")]
    kept = result.dae.unknowns[0]
    assert kept.fixed and to_text(kept.start) == "1"  # y inherits x's fixed start
