"""The C model's text is the same in every process: nothing in it follows the
iteration order of a set of strings, which Python's hash seed changes between runs."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from pendulum_text import PENDULUM

SRC = Path(__file__).resolve().parents[2] / "src"

PRINT_C = """
import sys
from springc.codegen import generate_c
from springc.pipeline import derive_system, CompileOptions
derived = derive_system(CompileOptions(files=(sys.argv[1],), model="Pendulum"))
sys.stdout.write(generate_c(derived.system).text)
"""


def c_text(model: Path, seed: str, cache: Path) -> str:
    env = {**os.environ, "PYTHONHASHSEED": seed, "PYTHONPATH": str(SRC),
           "SPRINGC_CACHE_DIR": str(cache)}
    done = subprocess.run([sys.executable, "-c", PRINT_C, str(model)], env=env,
                          capture_output=True, text=True, check=True)
    return done.stdout


def test_the_c_text_does_not_depend_on_the_hash_seed(tmp_path: Path) -> None:
    model = tmp_path / "pendulum.mo"
    model.write_text(PENDULUM, encoding="utf-8")
    texts = {c_text(model, seed, tmp_path / "cache") for seed in ("1", "2", "3")}
    assert len(texts) == 1
    assert "springc_rhs" in texts.pop()
