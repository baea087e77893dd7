"""Load time of a model that uses 5 classes of a large library (issue 12).

    PYTHONPATH=src python benchmarks/bench_load.py [--repeat N] [--quick]

Generates, in a temporary folder, a library ``Big`` stored the Modelica way: 20 package
folders (``Big/P<i>/package.mo``) of 10 files each (200 files), each file a package of 10
models (2,000 classes); and a small library of 20 files holding 200 classes the same way.
A user model uses 5 classes of each library. For each library it prints the load +
flatten time (best of ``--repeat`` runs, each in a fresh process state: the parse cache
cleared) and the number of files parsed. Loading parses only the files lookup needs, so
the ratio of the two times stays near 1 however large the library is.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from springc.flatten import flatten
from springc.parse import clear_parse_cache, load


def make_library(root: Path, packages: int, files: int, classes: int) -> None:
    """Write ``Big`` with ``packages`` x ``files`` files of ``classes`` models each."""
    big = root / "Big"
    big.mkdir(parents=True)
    (big / "package.mo").write_text("within;\npackage Big\nend Big;\n")
    (big / "package.order").write_text("".join(f"P{i}\n" for i in range(packages)))
    for i in range(packages):
        folder = big / f"P{i}"
        folder.mkdir()
        (folder / "package.mo").write_text(f"within Big;\npackage P{i}\nend P{i};\n")
        for j in range(files):
            body = "".join(
                f"  model C{k}\n    parameter Real k = {k + 1};\n"
                f"    Real x(start = 1, fixed = true);\n  equation\n"
                f"    der(x) = -k * x;\n  end C{k};\n" for k in range(classes))
            (folder / f"F{j}.mo").write_text(
                f"within Big.P{i};\npackage F{j}\n{body}end F{j};\n")


USER = """model User
  Big.P0.F0.C0 a;
  Big.P0.F1.C3 b;
  Big.P1.F0.C5 c;
  Big.P1.F1.C7 d;
  Big.P1.F1.C9 e;
end User;
"""


def measure(library: Path, user: Path, repeat: int) -> tuple[float, int]:
    """Best wall time of load + flatten, and the number of files parsed."""
    best, parsed = float("inf"), 0
    for _ in range(repeat):
        clear_parse_cache()
        start = time.perf_counter()
        tree = load([user], [library])
        flatten(tree, "User")
        best = min(best, time.perf_counter() - start)
        parsed = len(tree.parsed_paths)
    return best, parsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="3 repeats")
    args = parser.parse_args()
    if args.quick:
        args.repeat = 3
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        make_library(root / "large", 20, 10, 10)
        make_library(root / "small", 2, 10, 10)
        user = root / "User.mo"
        user.write_text(USER)
        measure(root / "small", user, 1)  # warm up: the grammar, imports
        small_time, small_files = measure(root / "small", user, args.repeat)
        large_time, large_files = measure(root / "large", user, args.repeat)
    print(f"library of   200 classes in  20 files: {small_time * 1e3:7.1f} ms, "
          f"{small_files} files parsed")
    print(f"library of 2,000 classes in 200 files: {large_time * 1e3:7.1f} ms, "
          f"{large_files} files parsed")
    print(f"ratio large/small: {large_time / small_time:.2f}")


if __name__ == "__main__":
    main()
