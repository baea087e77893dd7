"""How many of the Modelica Standard Library's Translational (or Rotational) examples
simulate with the bundled Modelica library.

Each example file of ``<msl>/Modelica/Mechanics/<package>/Examples`` is copied to a
temporary folder without its ``within`` clause, with imports of the package and its
subpackages added (the names it would find in its package), and simulated by the command
line for its experiment's stop time. Prints one line per example (the first line of
springc's output) and the count.

    PYTHONPATH=src python benchmarks/msl_translational.py [/work/ref/msl] [Rotational]
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path


def standalone(text: str, package: str) -> str:
    """The example without ``within``, with the imports after its icon ``extends``."""
    imports = " ".join(f"import Modelica.{name};" for name in (
        f"Mechanics.{package}", f"Mechanics.{package}.Components",
        f"Mechanics.{package}.Sources", f"Mechanics.{package}.Sensors", "Units.SI",
        "Blocks"))
    text = re.sub(r"^within [^;]*;\n", "", text, flags=re.M)
    return text.replace("extends Modelica.Icons.Example;",
                        f"extends Modelica.Icons.Example; {imports}", 1)


def main(msl: Path, package: str) -> None:
    examples = sorted((msl / f"Modelica/Mechanics/{package}/Examples").glob("*.mo"))
    examples = [p for p in examples if p.name != "package.mo"]
    passed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in examples:
            model = Path(tmp) / path.name
            model.write_text(standalone(path.read_text(encoding="utf-8"), package))
            run = subprocess.run(
                [sys.executable, "-m", "springc", "simulate", str(model), "-o",
                 str(Path(tmp) / f"{path.stem}.csv")], capture_output=True, text=True,
                timeout=300)
            first = (run.stderr or run.stdout).strip().splitlines()[0][:120]
            passed += run.returncode == 0
            print(f"{path.stem:22} {'ok  ' if run.returncode == 0 else 'fail'} {first}")
    print(f"{passed} of {len(examples)} examples simulate")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/work/ref/msl"),
         sys.argv[2] if len(sys.argv) > 2 else "Translational")
