"""The external functions springc evaluates itself instead of calling foreign code.

ModelicaStandardTables (the table blocks of the Modelica Standard Library) are external
objects built by C functions. The string functions of
``Modelica.Utilities.Strings`` (ModelicaStrings) are evaluated the same way. springc
recognises those functions by their C names, as
the library declares them (``external "C" y = ModelicaStandardTables_CombiTable1D_getValue
(tableID, icol, u)``), and evaluates them while flattening (``flatten/natives/tables.py``). Each
entry names the operation and the role of every argument of the external call, in the
order of the C function's parameters; ``None`` marks an argument springc does not need
(an array size the table already knows).
"""

from __future__ import annotations

_T1_INIT = ("fileName", "tableName", "table", None, None, "columns", None, "smoothness",
            "extrapolation", "verboseRead", "delimiter", "nHeaderLines")
_TT_INIT = ("fileName", "tableName", "table", None, None, "startTime", "columns", None,
            "smoothness", "extrapolation", "shiftTime", "timeEvents", "verboseRead",
            "delimiter", "nHeaderLines")
_T2_INIT = ("fileName", "tableName", "table", None, None, "smoothness", "extrapolation",
            "verboseRead", "delimiter", "nHeaderLines")
_PREFIX = "ModelicaStandardTables_"

NATIVE_EXTERNALS: dict[str, tuple[str, tuple[str | None, ...]]] = {
    _PREFIX + "CombiTable1D_init2": ("table1D", _T1_INIT[:10]),
    _PREFIX + "CombiTable1D_init3": ("table1D", _T1_INIT),
    _PREFIX + "CombiTimeTable_init2": ("timeTable", _TT_INIT[:13]),
    _PREFIX + "CombiTimeTable_init3": ("timeTable", _TT_INIT),
    _PREFIX + "CombiTable2D_init2": ("table2D", _T2_INIT[:8]),
    _PREFIX + "CombiTable2D_init3": ("table2D", _T2_INIT),
    _PREFIX + "CombiTable1D_close": ("close", ("tableID",)),
    _PREFIX + "CombiTimeTable_close": ("close", ("tableID",)),
    _PREFIX + "CombiTable2D_close": ("close", ("tableID",)),
    _PREFIX + "CombiTable1D_getValue": ("value1D", ("tableID", "icol", "u")),
    _PREFIX + "CombiTable1D_minimumAbscissa": ("min1D", ("tableID",)),
    _PREFIX + "CombiTable1D_maximumAbscissa": ("max1D", ("tableID",)),
    _PREFIX + "CombiTimeTable_getValue": ("valueTime", ("tableID", "icol", "t", None, None)),
    _PREFIX + "CombiTimeTable_minimumTime": ("minTime", ("tableID",)),
    _PREFIX + "CombiTimeTable_maximumTime": ("maxTime", ("tableID",)),
    _PREFIX + "CombiTimeTable_nextTimeEvent": ("nextEvent", ("tableID", "t")),
    _PREFIX + "CombiTable2D_getValue": ("value2D", ("tableID", "u1", "u2")),
}
"""C name -> (operation, the role of each argument of the external call)."""

_STRINGS = "ModelicaStrings_"
NATIVE_EXTERNALS.update({
    _STRINGS + "length": ("strings.length", ("string",)),
    _STRINGS + "substring": ("strings.substring", ("string", "startIndex", "endIndex")),
    _STRINGS + "compare": ("strings.compare", ("string", "string2", "caseSensitive")),
    _STRINGS + "skipWhiteSpace": ("strings.skipWhiteSpace", ("string", "startIndex")),
})
"""The string functions of ``Modelica.Utilities.Strings`` (``flatten/externals.py``)."""

FILES = "it writes or removes files, folders or the environment"
_CLOCK = "its result depends on when or where the translation runs"
READS = ("it reads files, folders or the environment, which the compiled model's cache "
          "key does not cover")
_STATE = "it keeps a state between calls, which a call while translating would not"
REFUSED_EXTERNALS: dict[str, str] = {
    **{f"ModelicaInternal_{name}": FILES for name in (
        "print", "removeFile", "copyFile", "rename", "mkdir", "rmdir", "chdir", "setenv")},
    "ModelicaIO_writeRealMatrix": FILES,
    "ModelicaStreams_closeFile": FILES,
    **{f"ModelicaInternal_{name}": _CLOCK for name in (
        "getTime", "getpid", "temporaryFileName")},
    "ModelicaRandom_automaticGlobalSeed": _CLOCK,
    **{f"ModelicaInternal_{name}": READS for name in (
        "countLines", "fullPathName", "getNumberOfFiles", "getcwd", "getenv",
        "readDirectory", "readFile", "readLine", "stat")},
    "ModelicaIO_readMatrixSizes": READS,
    "ModelicaIO_readRealMatrix": READS,
    "ModelicaRandom_impureRandom_xorshift1024star": _STATE,
    "ModelicaRandom_setInternalState_xorshift1024star": _STATE,
}
"""The MSL's C functions springc does not call although their sources compile: it calls
foreign functions while translating a model (once per compilation, not at the model's
events), so a function with effects outside its outputs would act at the wrong moment,
one that reads the clock, files or the environment would make the cached model depend
on what its key does not cover, and an impure one would be called once instead of at
each of the model's calls (``docs/msl.md``)."""
