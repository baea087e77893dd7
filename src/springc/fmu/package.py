"""The files of an FMU -> the ``.fmu`` archive: the C sources (the wrapper of ``c/``, the
model and its glue), the binary for linux64 compiled with the C compiler that
:func:`springc.pipeline.find_compiler` finds (the one owner of that search), and
the model description; written through :mod:`springc.fileio` (all or nothing, the
file-safety rules of every output).

A machine without a C compiler gets a sources-only FMU: the caller reports the note
:data:`NO_COMPILER_NOTE`. The archive is byte-for-byte the same for the same model
(fixed entry dates, sorted entries), so no decision and no output reads the clock.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..fileio import atomic_write
from ..native import run_compiler
from ..pipeline import CCompilerMissing, find_compiler

WRAPPER = {
    3: ("springc_fmi3.c", "springc_fmi3_modes.c"),
    2: ("springc_fmi2.c",),
}
HEADERS = {3: ("springc_fmi3.h", "springc_fmi3_api.h"), 2: ("springc_fmi2.h",)}
COMMON = ("springc_fmu.c",)
COMMON_HEADERS = ("springc_fmu.h", "springc_glue.h")
PLATFORM = {3: "x86_64-linux", 2: "linux64"}
"""The binaries folder of the platform (FMI 3.0: platform tuple; FMI 2.0: linux64)."""

COMPILER_FLAGS = ("-std=c99", "-O2", "-g0", "-shared", "-fPIC", "-fvisibility=hidden",
                  "-ffp-contract=off")  # -g0: zig cc's debug information names the folder
NO_COMPILER_NOTE = ("no C compiler found (looked for $CC, cc, gcc, clang and the ziglang "
                    "package): the FMU holds the C sources only; compile them with a C "
                    "compiler (sources/buildDescription.xml lists them) to run it, or "
                    "pip install ziglang and export again")
ZIP_DATE = (1980, 1, 1, 0, 0, 0)


class BuildError(RuntimeError):
    """The system C compiler failed on the FMU's sources: a springc bug (exit code 3)."""


def wrapper_sources(version: int) -> dict[str, bytes]:
    """The wrapper's C files for FMI ``version``, by name."""
    folder = resources.files(__package__) / "c"
    names = COMMON + COMMON_HEADERS + WRAPPER[version] + HEADERS[version]
    return {name: (folder / name).read_bytes() for name in names}


def compile_sources(version: int) -> tuple[str, ...]:
    """The translation units the compiler is given (the model is included by the glue)."""
    return ("springc_glue.c",) + COMMON + WRAPPER[version]


def compiler_or_none() -> list[str] | None:
    """The C compiler's command (:func:`springc.pipeline.find_compiler`), or None where
    there is none: the FMU then holds its sources only."""
    try:
        return find_compiler()
    except CCompilerMissing:
        return None


def build_binary(sources: Mapping[str, bytes], version: int, identifier: str,
                 compiler: Sequence[str]) -> bytes:
    """The shared library of the FMU, compiled from ``sources`` by ``compiler``."""
    with tempfile.TemporaryDirectory(prefix="springc-fmu-") as folder:
        root = Path(folder)
        for name, data in sources.items():
            (root / name).write_bytes(data)
        target = root / f"{identifier}.so"
        argv = [*compiler, *COMPILER_FLAGS, "-I", str(root),
                *(str(root / name) for name in compile_sources(version)), "-lm",
                "-o", str(target)]
        code, messages = run_compiler(argv, None, "the FMU's sources")
        if code != 0:
            raise BuildError(f"the C compiler failed on the FMU's sources: "
                             f"{messages.strip()[:2000]}")
        return target.read_bytes()


def write_fmu(path: str | os.PathLike[str], entries: Mapping[str, bytes],
              protected: Iterable[str | os.PathLike[str]] = ()) -> None:
    """The archive ``path`` of ``entries`` (name -> bytes), deflated, written safely."""
    with atomic_write(path, "wb", protected) as f, \
            zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(entries):
            info = zipfile.ZipInfo(name, ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, entries[name])


@dataclass(frozen=True)
class Package:
    """What went into an FMU: its entries and whether it holds a binary."""

    entries: dict[str, bytes]
    binary: bool


def assemble(version: int, identifier: str, description: str, build_xml: str | None,
             model_c: str, glue_c: str, compiler: Sequence[str] | None) -> Package:
    """The FMU's entries: model description, sources, and the binary where a compiler
    is at hand."""
    sources = wrapper_sources(version)
    sources["model.c"] = model_c.encode()
    sources["springc_glue.c"] = glue_c.encode()
    entries = {f"sources/{name}": data for name, data in sources.items()}
    entries["modelDescription.xml"] = description.encode()
    if build_xml is not None:
        entries["sources/buildDescription.xml"] = build_xml.encode()
    if compiler is not None:
        binary = build_binary(sources, version, identifier, compiler)
        entries[f"binaries/{PLATFORM[version]}/{identifier}.so"] = binary
    return Package(entries, compiler is not None)
