"""The steps of a system as C statements: linear blocks solved in C, torn nonlinear
blocks by Newton's method in C with the backtracking of :mod:`.newton_search` (the
tolerance and iteration limit of the Python module: :data:`.newton_search.NEWTON_TOLERANCE`,
:data:`.context.NEWTON_ITERATIONS`).

:class:`CContext` is the generator's :class:`.context.CodegenContext` whose blocks are
written with fixed-size local arrays and ``springc_solve`` (:data:`SOLVE`) instead of
numpy; everything else (loads, aliases, the event statements) is shared.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from ..ir import ode
from ..ir.expr import ZERO, Var
from .context import (
    NEWTON_ITERATIONS,
    CodegenBug,
    CodegenContext,
    block_names,
    newton_trial,
    scalar_newton_step,
)
from .newton_search import (
    search_accept,
    search_control,
    search_end,
    search_start,
    search_step,
)
from .statements import Block, Guard, Let, Load, Loop, Raw, Stmt, Store

SOLVE = """SPRINGC_FN void springc_solve(int n, int m, double *a, double *b, double *y)
{
    /* y = a^-1 b (a: n x n, b and y: n x m, by rows): Gaussian elimination with */
    /* partial pivoting; a and b are overwritten; y is NaN where an entry of a or b */
    /* is not finite or a is singular */
    int i, j, k, c;
    for (i = 0; i < n * n; i++) {
        if (!(a[i] - a[i] == 0.0)) goto fail;
    }
    for (i = 0; i < n * m; i++) {
        if (!(b[i] - b[i] == 0.0)) goto fail;
    }
    for (k = 0; k < n; k++) {
        int pivot = k;
        double best = fabs(a[k * n + k]);
        for (i = k + 1; i < n; i++) {
            if (fabs(a[i * n + k]) > best) {
                best = fabs(a[i * n + k]);
                pivot = i;
            }
        }
        if (best == 0.0) goto fail;
        if (pivot != k) {
            double swap;
            for (j = 0; j < n; j++) {
                swap = a[k * n + j];
                a[k * n + j] = a[pivot * n + j];
                a[pivot * n + j] = swap;
            }
            for (c = 0; c < m; c++) {
                swap = b[k * m + c];
                b[k * m + c] = b[pivot * m + c];
                b[pivot * m + c] = swap;
            }
        }
        for (i = k + 1; i < n; i++) {
            double f = a[i * n + k] / a[k * n + k];
            for (j = k + 1; j < n; j++) a[i * n + j] -= f * a[k * n + j];
            for (c = 0; c < m; c++) b[i * m + c] -= f * b[k * m + c];
        }
    }
    for (c = 0; c < m; c++) {
        for (i = n - 1; i >= 0; i--) {
            double s = b[i * m + c];
            for (j = i + 1; j < n; j++) s -= a[i * n + j] * y[j * m + c];
            y[i * m + c] = s / a[i * n + i];
        }
    }
    return;
    fail:
    for (i = 0; i < n * m; i++) y[i] = SPRINGC_NAN;
}"""


class CContext(CodegenContext):
    """The codegen context whose linear and nonlinear blocks are C statements; a
    function whose statements contain one declares ``int _code`` (0, or the failure
    code of the last torn system that did not converge) and defines ``springc_solve``
    where a block solves a linear system (``uses_solve``)."""

    uses_solve = False
    jacobian_size = 0  # non-zeros of springc_jacobian
    has_jacobian = False  # whether the C file computes the Jacobian (see c_model)
    work_doubles = 0  # the largest local work arrays of a function (see c_vector)
    code_chars = 0  # characters of the file's functions (the C compiler's work)

    def _linear(self, block: ode.LinearBlock, index: int, comment: str) -> Stmt:
        n = len(block.names)
        self.uses_solve = True
        body: list[Stmt] = [Raw(f"double _A{index}[{n * n}] = {{0.0}};")]
        body += [Store(f"_A{index}[{i * n + j}]", e) for i, j, e in block.matrix]
        body.append(Raw(f"double _b{index}[{n}];"))
        body += [Store(f"_b{index}[{i}]", e) for i, e in enumerate(block.rhs)]
        body.append(Raw(f"double _y{index}[{n}];\n" + _solve(f"_y{index}", f"_A{index}",
                                                               f"_b{index}", n, 1)))
        body += [Load(name, f"_y{index}[{k}]", name) for k, name in enumerate(block.names)]
        return Block(body, comment, {*block.names, f"_A{index}"})

    def _nonlinear(self, block: ode.NonlinearBlock, index: int, comment: str) -> Stmt:
        k = len(block.tearing)
        slots = [self.guess_slots[t] for t in block.tearing]
        body: list[Stmt] = [Load(t, f"z[{s}]", f"{t} (warm start)")
                            for t, s in zip(block.tearing, slots)]
        body += search_start(block.tearing, index)
        body.append(Raw(f"int _ok{index} = 0;\n_done{index} = 0.0;"))
        loop = newton_trial(block, index, guard=False)
        loop.append(search_control(index, c=True))
        loop += search_accept(block.tearing, index)
        loop += [Let(s.name, s.expr, "sensitivity") for s in block.sensitivities]
        entries = {(i, j): e for i, j, e in block.jacobian}
        if k == 1:
            loop += scalar_newton_step(block.tearing[0], entries.get((0, 0), ZERO), index)
        else:
            self.uses_solve = True
            loop.append(Raw(f"double _J{index}[{k * k}] = {{0.0}};"))
            loop += [Store(f"_J{index}[{i * k + j}]", e) for (i, j), e in entries.items()]
            loop.append(Raw(f"double _R{index}[{k}];"))
            loop += [Store(f"_R{index}[{i}]", Var(f"_r{index}_{i}")) for i in range(k)]
            loop.append(Raw(f"double _D{index}[{k}];\n"
                            f"springc_solve({k}, 1, _J{index}, _R{index}, _D{index});"))
            loop += [Load(f"_d{index}_{i}", f"_D{index}[{i}]") for i in range(k)]
        loop += search_step(block.tearing, index)
        body.append(Loop(f"for (int _it = 0; _it < {NEWTON_ITERATIONS}; _it++) {{", loop))
        body += search_end(block.tearing, index)
        body.append(Raw(f"if (!_ok{index}) {{\n    z[{self.flag_slot}] = {float(index + 1)!r};\n"
                        f"    _code = {index + 1};\n}}"))
        body += [Store(f"z[{s}]", Var(t)) for t, s in zip(block.tearing, slots)]
        return Block(body, comment, block_names(block))


def _solve(result: str, matrix: str, rhs: str, n: int, m: int) -> str:
    """C lines solving ``matrix result = rhs`` (``rhs`` overwritten, ``matrix`` kept:
    the Jacobian reads it again)."""
    return (f"{{\n    double _w[{n * n}];\n"
            f"    for (int _k = 0; _k < {n * n}; _k++) _w[_k] = {matrix}[_k];\n"
            f"    springc_solve({n}, {m}, _w, {rhs}, {result});\n}}")


_EMPTY = re.compile(r"(\w+) = np\.empty\((\d+)\)\Z")
_ZEROS = re.compile(r"(\w+) = np\.zeros\(\((\d+), (\d+)\)\)\Z")
_SOLVE = re.compile(r"(\w+) = np\.linalg\.solve\((\w+), (\w+)\) if ")
_ENTRY = re.compile(r"(-?)(\w+)\[(\d+), (\d+)\]\Z")


def c_jacobian(stmts: Sequence[Stmt]) -> list[Stmt]:
    """The Jacobian's statements (:mod:`.jacobian`) in C: its matrices (``_C3 =
    np.zeros((n, m))``) become arrays by rows, their entries ``_C3[i, j]`` flat
    indices, its solves ``springc_solve``; ``jv = np.empty(n)`` is the argument."""
    shapes: dict[str, tuple[int, int]] = {}

    def flat(text: str) -> str:
        found = _ENTRY.match(text)
        if found is None:
            return text
        sign, name, i, j = found.groups()
        return f"{sign}{name}[{int(i) * shapes[name][1] + int(j)}]"

    def walk(body: Sequence[Stmt]) -> list[Stmt]:
        out: list[Stmt] = []
        for s in body:
            if isinstance(s, Raw):
                out += _jacobian_raw(s.text, shapes)
            elif isinstance(s, Store):
                out.append(Store(flat(s.target), s.expr, s.comment))
            elif isinstance(s, Load):
                out.append(Load(s.name, flat(s.source), s.comment))
            elif isinstance(s, Block):
                out.append(Block(walk(s.body), s.comment, s.defines, s.uses))
            elif isinstance(s, Loop):
                out.append(Loop(s.header, walk(s.body)))
            elif isinstance(s, Guard):
                out.append(Guard(s.cond, walk(s.body)))
            else:
                out.append(s)
        return out

    return walk(stmts)


def _jacobian_raw(text: str, shapes: dict[str, tuple[int, int]]) -> list[Stmt]:
    if text.startswith("jv = np.empty("):
        return []
    zeros = _ZEROS.match(text)
    if zeros:
        name, rows, cols = zeros.group(1), int(zeros.group(2)), int(zeros.group(3))
        shapes[name] = (rows, cols)
        return [Raw(f"double {name}[{rows * cols}] = {{0.0}};")]
    solve = _SOLVE.match(text)
    if solve:  # the matrix is square, of the right-hand side's rows
        result, matrix, rhs = solve.groups()
        n, m = shapes[rhs]
        shapes[result] = (n, m)
        return [Raw(f"double {result}[{n * m}];\n" + _solve(result, matrix, rhs, n, m))]
    raise CodegenBug(f"no C for the statement {text!r}")


def c_statements(stmts: Sequence[Stmt], outputs: Sequence[str]) -> list[Stmt]:
    """The event functions' statements (:mod:`.events`) in C: their few lines of
    Python (``g = np.empty(n)``) become declarations, or nothing for an array the C
    function takes as its argument (``outputs``)."""
    out: list[Stmt] = []
    for s in stmts:
        if isinstance(s, Raw):
            found = _EMPTY.match(s.text)
            if found:
                name, size = found.group(1), int(found.group(2))
                if name not in outputs:
                    out.append(Raw(f"double {name}[{max(size, 1)}];"))
            elif s.text == "_zdone = 1.0":
                continue
            elif not s.text.startswith(("double ", "int ", "if (", "springc_")):
                raise CodegenBug(f"no C for the statement {s.text!r}")
            else:
                out.append(s)
        elif isinstance(s, Block):
            out.append(Block(c_statements(s.body, outputs), s.comment, s.defines, s.uses))
        elif isinstance(s, Loop):
            out.append(Loop(s.header, c_statements(s.body, outputs)))
        elif isinstance(s, Guard):
            out.append(Guard(s.cond, c_statements(s.body, outputs)))
        else:
            out.append(s)
    return out
