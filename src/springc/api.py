"""The Python API: files -> CompiledModel (``compile_model``) -> SimulationResult
(``simulate``), for notebooks and scripts.

    >>> import springc
    >>> model = springc.compile_model("models/SpringMass.mdl")
    >>> result = springc.simulate(model, stop=2.0, parameters={"spring.k": 1e5})
    >>> result.time, result["mass.pos[1]"]
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, TextIO

from .errors import CodegenError, OutputError, UsageError
from .ir.expr import recursion_room
from .native.foreign_calls import RunTimeCallRefused, calls_foreign
from .pipeline import (
    CompiledModel,
    CompileOptions,
    Derived,
    ModuleKind,
    check_parameter_names,
    collector_paused,
    compile_files,
    modification_value,
)
from .simulation import (
    AUTO,
    DEFAULT_ENGINE,
    DEFAULT_ERROR_CONTROL,
    DEFAULT_SOLVER,
    RunSettings,
    SimulationResult,
    c_loop_runs,
    check_run_values,
    choose_engine,
    default_backend,
    estimate_deprecation,
    numba_available,
    run_settings,
    simulate_model,
)

if TYPE_CHECKING:
    from .fmu import FmuExport

Files = str | os.PathLike[str] | Sequence[str | os.PathLike[str]]

INTEGER_LIMIT = 2**31 - 1
"""The largest magnitude of a value given to an Integer parameter (32-bit, as Modelica
tools use)."""


def _check_integers(model: CompiledModel, values: Mapping[str, float]) -> None:
    """Integer parameters take whole numbers of at most :data:`INTEGER_LIMIT`."""
    types = dict(zip(model.module.PARAMETERS, getattr(model.module, "PARAMETER_TYPES", ())))
    for name, value in values.items():
        if types.get(name) == "Integer" and not (
                abs(value) <= INTEGER_LIMIT and float(value) == int(value)):
            raise UsageError(f"'{name}' is an Integer parameter: {value!r} is not a whole "
                             f"number of magnitude at most {INTEGER_LIMIT}",
                             option="parameters")


def _files(files: Files) -> tuple[str, ...]:
    """The file names of ``files`` (one name or a sequence of names)."""
    if isinstance(files, (str, os.PathLike)):
        return (os.fspath(files),)
    if isinstance(files, (list, tuple)) and all(isinstance(f, (str, os.PathLike))
                                                for f in files):
        return tuple(os.fspath(f) for f in files)
    raise UsageError(f"files must be a file name or a list of file names, not "
                     f"{_shown(files)}", option="files")


def _patterns(outputs: Sequence[str] | str | None) -> tuple[str, ...] | None:
    """``outputs`` as a tuple of patterns: a string is one pattern (``"mass.pos[1]"``),
    never a sequence of one-character patterns."""
    if outputs is None:
        return None
    if isinstance(outputs, str):
        return (outputs,)
    if isinstance(outputs, (list, tuple)) and all(isinstance(o, str) for o in outputs):
        return tuple(outputs)
    raise UsageError(f"outputs must be a name pattern or a list of them, not "
                     f"{_shown(outputs)}", option="outputs")


def _shown(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


@recursion_room()  # expressions up to ir.expr.MAX_DEPTH deep (docs/language.md, "Limits")
def compile_model(files: Files, model: str | None = None, *,
                  libraries: Sequence[str | os.PathLike[str]] = (),
                  backend: str | None = None, outputs: Sequence[str] | None = None,
                  parameters: Mapping[str, float] | None = None,
                  cache: bool = True) -> CompiledModel:
    """Flatten, simplify and generate code for ``model`` of ``files`` (cached on disk).

    ``outputs`` are flat names or patterns with ``*``/``?`` (default: every state and
    observed variable); ``parameters`` may set structural parameters (array sizes),
    which re-flattens the model; other parameters are inputs of the generated code
    and are better passed to :func:`simulate`. ``backend``: ``"numba"`` (the default
    where numba is installed: :func:`simulate` runs it in the compiled loop) or
    ``"python"`` (plain numpy, run in scipy's loop).
    """
    check_run_values(parameters=parameters)
    options = CompileOptions(_files(files), model, tuple(os.fspath(x) for x in libraries),
                             backend or default_backend(),
                             _patterns(outputs), (), cache)
    return _compile(options, parameters, chosen=backend is None)


STRING_FILE = "<string>"
"""The pseudo file name of a model given as text (errors say ``<string>:3:5``)."""


@recursion_room()
def load_model_from_string(text: str, model: str | None = None,
                           backend: str | None = None, *,
                           libraries: Sequence[str | os.PathLike[str]] = (),
                           outputs: Sequence[str] | None = None,
                           parameters: Mapping[str, float] | None = None,
                           cache: bool = True) -> CompiledModel:
    """Compile ``model`` of the Modelica ``text`` (a notebook cell, say) as
    :func:`compile_model` compiles files; errors are located in ``<string>``.

        >>> model = springc.load_model_from_string('''
        ... model Fall
        ...   Real h(start = 10, fixed = true);
        ... equation
        ...   der(h) = -9.81 * time;
        ... end Fall;''')
        >>> springc.simulate(model, stop=1.0)["h"][-1]
    """
    if not isinstance(text, str):
        raise UsageError(f"the model text must be a str, not {type(text).__name__}",
                         option="text")
    check_run_values(parameters=parameters)
    options = CompileOptions((), model, tuple(os.fspath(x) for x in libraries),
                             backend or default_backend(),
                             _patterns(outputs), (), cache,
                             ((STRING_FILE, text),))
    return _compile(options, parameters, chosen=backend is None)


NUMBA_LINES = 20_000
"""A generated module longer than this many lines is generated again for the python
backend where springc chose numba: numba's compilation grows faster than the code (a
sum of 20,000 parameters, 60,000 lines, compiled for over 50 minutes) while scipy's
loop runs such a model in seconds; large scenes in the vector layout stay far below
(1,000-mass chain: 2,300 lines)."""


def default_choice(backend: str | None, engine: str = "auto", solver: str = "auto"
                   ) -> str | None:
    """``backend`` as given; else ``None`` where the run's backend is the one
    :func:`compile_model` chooses itself (which also checks a numba module's size, and
    generates a model with delays or switching states for numba where it chose python
    for the C loop),
    else the run's (``"python"`` for ``--engine scipy``, ``"numba"`` for a solver the
    C loop does not run, the fixed-step ones, where it runs the others)."""
    if backend:
        return backend
    chosen = default_backend(engine, str(solver).lower())
    return None if chosen == default_backend() else chosen


@collector_paused()  # the whole compile, both backends (springc.collector)
def _compile(options: CompileOptions, parameters: Mapping[str, float] | None,
             chosen: bool = False) -> CompiledModel:
    try:
        compiled, base = _compile_as(options, parameters)
    except RunTimeCallRefused as refused:  # numba calls no C function at run time
        if not (chosen and options.backend == "numba"):
            raise
        options = replace(options, backend="python")
        compiled, base = _compile_as(options, parameters, refused.derived)
    other = None
    if chosen and options.backend == "numba" and compiled.source.count("\n") > NUMBA_LINES:
        other = "python"
    elif chosen and options.backend == "python" and _numba_instead(compiled):
        other = "numba"
    if other is not None:  # generated from the system derived for the first backend
        derived = compiled.compiled_from
        compiled.let_go()  # its module freed before the other one is generated
        del compiled
        compiled, _ = _compile_as(replace(options, backend=other), parameters, derived, base)
    return compiled.settled()


C_LOOP_KINDS = (ModuleKind.CONTINUOUS, ModuleKind.HYBRID)
"""The kinds of model the C loop runs: continuous ones, and hybrid ones between their
events (:mod:`springc.simulation.hybrid_compiled`; the event update in Python). A
hybrid model on numba would first compile its functions and numba's hybrid kernels
(minutes on a loaded machine: SimpleTriacCircuit), where the C loop library builds
in seconds."""


def _numba_instead(compiled: CompiledModel) -> bool:
    """Whether springc, having chosen python for the C loop, generates ``compiled``'s
    model for numba instead: the C loop runs continuous and hybrid models whose loop
    library builds (:data:`C_LOOP_KINDS`; :func:`springc.pipeline.loop_library`, built
    here once per cache entry); the compiled engine runs others on numba: delays,
    switching states, a model beyond the loop's size rule, one the C printer cannot
    print (a function with no C spelling), and one whose C the compiler refused (with a
    one-line note)."""
    if not (c_loop_runs(AUTO, None) and numba_available()) or calls_foreign(compiled.source):
        return False  # numba calls no C function at run time (native.foreign_calls)
    if compiled.kind not in C_LOOP_KINDS:
        return True
    from .pipeline import loop_library, note_refused  # the C printer: on this choice only

    try:
        loop_library(compiled)  # kept in the cache entry for the runs
    except CodegenError as error:
        note_refused(error, "numba's loop")
        return True
    return False


def _compile_as(options: CompileOptions, parameters: Mapping[str, float] | None,
                derived: Derived | None = None, base: CompiledModel | None = None
                ) -> tuple[CompiledModel, CompiledModel | None]:
    """The model of ``options`` with ``parameters``, and the unmodified model compiled
    to learn which of them are structural (None without parameters). ``derived`` is
    the system of the same model derived for another backend, ``base`` that backend's
    unmodified model: neither is derived again (a system does not depend on the
    backend)."""
    if not parameters:
        return compile_files(options, derived), None
    if base is None:
        # Which parameters are structural is known once the unmodified model is
        # compiled (all outputs: the selection may name variables that only the
        # modified one has).
        base = compile_files(replace(options, outputs=None))
        check_parameter_names(base, parameters)
        _check_integers(base, parameters)
    structural = {k: v for k, v in parameters.items() if k in base.structural}
    if not structural:
        return compile_files(options, derived or base.compiled_from), base
    return _with_structural(base, structural, options, derived), base


def _with_structural(compiled: CompiledModel, values: Mapping[str, float],
                     options: CompileOptions | None = None,
                     derived: Derived | None = None) -> CompiledModel:
    if not values:
        return compiled
    mods = tuple(sorted((k, modification_value(compiled, k, v)) for k, v in values.items()))
    if options is None:  # a compiled model given: compiled again from its files
        compiled.check_files(f"a new value of the structural parameter '{min(values)}' "
                             "would compile another model",
                             "compile the files again with compile_model(files, "
                             "parameters=...)")
    return compile_files(replace(options or compiled.options, modifications=mods), derived)


@recursion_room()
def simulate(model: CompiledModel | Files, *, model_name: str | None = None,
             start: float | None = None, stop: float | None = None,
             interval: float | None = None, solver: str = DEFAULT_SOLVER,
             rtol: float | None = None, atol: float | None = None,
             parameters: Mapping[str, float] | None = None,
             outputs: Sequence[str] | None = None, backend: str | None = None,
             libraries: Sequence[str | os.PathLike[str]] = (), cache: bool = True,
             progress: TextIO | None = None, step: float | None = None,
             max_steps: int | None = None, time_limit: float | None = None,
             engine: str = DEFAULT_ENGINE, error_control: str | None = None,
             error_estimate: str | None = None, event_rows: bool = False,
             settings: RunSettings | None = None) -> SimulationResult:
    """Simulate a compiled model (or compile ``model`` files first) on the output grid.

    Unset times and tolerances come from the model's ``experiment`` annotation, else
    start 0, stop 10 s, 500 intervals, rtol 1e-6, atol rtol/1000. ``solver`` is
    ``"auto"`` (dop853 or radau from a stiffness estimate), a scipy method, or a
    fixed-step one (``"verlet"``, ``"symplectic-euler"``, ``"rk4"``) with ``step``.
    ``parameters`` maps flat names to values; structural ones trigger a recompilation.
    A run stops with an error after ``max_steps`` integrator steps or ``time_limit``
    seconds (``None``: 20,000,000 steps, one hour). ``engine`` runs the steps:
    ``"compiled"`` (numba loops of :mod:`springc.integrate` for auto, dop853, rk45,
    radau, bdf and the fixed-step solvers), ``"scipy"`` (scipy's solvers stepped from
    Python), or ``"auto"`` (the default): compiled where numba is importable, the
    solver has a compiled loop and the model's backend is numba, else scipy (the
    summary, ``result.stats.engine_reason``, says why).
    ``error_control`` (``"tighten"``, the default; ``"warn"``, ``"off"``): estimate the
    global error reached on the grid (``result.error_estimate``: a companion run 1000x
    tighter, or Richardson for the fixed-step solvers) and hold each output variable to
    ``10 * (rtol * max|v| + atol)``; ``tighten`` runs 1000x tighter until it does (the
    summary and ``result.stats`` say so), ``warn`` only warns; a rule still broken is an
    :class:`AccuracyWarning` and ``result.stats.warning`` (see
    :mod:`springc.simulation.error_control`). ``error_estimate`` (``"off"``, ``"on"``,
    ``"auto"``) is deprecated: ``"off"``, ``"warn"``, ``"tighten"``.
    ``backend`` (files only) defaults to ``"numba"`` where the run can take the
    compiled loop, else ``"python"`` (``engine="scipy"``, lsoda, no numba).
    ``event_rows``: a model with events gets two more rows at each event, its left and
    right limits (default: one row per output time).
    ``settings``: the run's options as one value (:class:`springc.simulation.RunSettings`,
    as :func:`springc.simulation.run_settings` builds it from these keywords, which are
    then not read; the command line passes its own).
    """
    if settings is None:
        settings = run_settings(
            start=start, stop=stop, interval=interval, solver=solver, rtol=rtol, atol=atol,
            step=step, parameters=parameters, max_steps=max_steps, time_limit=time_limit,
            engine=engine, error_control=error_control, error_estimate=error_estimate,
            event_rows=event_rows, progress=progress)
    if error_estimate is not None:
        warnings.warn(estimate_deprecation(error_estimate, ("error_control", "error_estimate")),
                      DeprecationWarning, stacklevel=3)  # the caller's line (recursion_room)
    result = simulate_with(model, settings, CompileRequest(model_name, libraries, backend,
                                                           outputs, cache))
    if result.stats.warning:
        warnings.warn(f"{result.model}: {result.stats.warning}", AccuracyWarning,
                      stacklevel=3)  # the caller's line (recursion_room wraps this)
    return result


@dataclass(frozen=True)
class CompileRequest:
    """How :func:`simulate` compiles files it is given (a compiled model ignores it)."""

    model_name: str | None = None
    libraries: Sequence[str | os.PathLike[str]] = ()
    backend: str | None = None
    outputs: Sequence[str] | None = None
    cache: bool = True


def simulate_with(model: CompiledModel | Files, settings: RunSettings,
                  request: CompileRequest = CompileRequest()) -> SimulationResult:
    """The run of ``settings`` (:func:`springc.simulation.run_settings`: the value
    :func:`simulate`'s keywords and the command line's options build) on ``model``,
    compiled as ``request`` says where it is files; a broken tolerance is
    ``result.stats.warning``, left to the caller to say."""
    model, options = _compiled_for(model, settings, request)
    return simulate_model(model, options)


def _compiled_for(model: CompiledModel | Files, settings: RunSettings,
                  request: CompileRequest) -> tuple[CompiledModel, RunSettings]:
    """``model`` compiled for ``settings`` (files compiled; a structural parameter
    compiles again) and the settings of its run: the parameters that are not structural."""
    values = dict(settings.parameters)
    solver = str(settings.solver).lower()
    if not isinstance(model, CompiledModel):
        choose_engine(settings.engine, solver, request.backend, "engine", "backend")
        model = compile_model(model, request.model_name, libraries=request.libraries,
                              backend=default_choice(request.backend, settings.engine,
                                                     settings.solver),
                              outputs=request.outputs, cache=request.cache,
                              parameters=values)
        structural = {k for k, v in model.options.modifications}
    else:
        choose_engine(settings.engine, solver, model.module.BACKEND, "engine", "backend")
        check_parameter_names(model, values)
        _check_integers(model, values)
        structural = {k for k in values if k in model.structural}
        model = _with_structural(model, {k: values[k] for k in structural})
    return model, replace(settings, parameters={k: v for k, v in values.items()
                                                if k not in structural})


class AccuracyWarning(UserWarning):
    """A run whose estimated error breaks its tolerance (``error_control``)."""


def sweep(files: CompiledModel | Files, *, model: str | None = None,
          params: Mapping[str, str | Sequence[float]], samples: int | None = None,
          method: str = "lhs", seed: int = 0, workers: int | None = None,
          scheduler: str | None = None, outputs: Sequence[str] | None = None,
          parameters: Mapping[str, float] | None = None, start: float | None = None,
          stop: float | None = None, interval: float | None = None,
          solver: str = DEFAULT_SOLVER, rtol: float | None = None,
          atol: float | None = None, step: float | None = None,
          output: str | os.PathLike[str] | None = None, resume: bool = False,
          energy: str | None = None, libraries: Sequence[str | os.PathLike[str]] = (),
          backend: str | None = None, cache: bool = True,
          progress: TextIO | None = None, max_steps: int | None = None,
          time_limit: float | None = None, error_control: str = DEFAULT_ERROR_CONTROL,
          as_: str = "dataset") -> Any:
    """Run a parameter study and return it as an ``xarray.Dataset`` (``as_="dataset"``:
    each output over ``run`` x ``time`` with ``units`` attributes, the swept parameters
    as coordinates on ``run``, ``status``/``error``/solver statistics per run) or a
    ``pandas.DataFrame`` of the study table (``as_="dataframe"``).

    ``params`` maps each swept parameter to a list of values or a text as ``springc
    sweep --param`` takes (``"1e3:1e5:log:20"``, ``"0.5,1,2"``, ``"normal(1, 0.1)"``);
    a grid is their cartesian product, or ``samples`` draws (``method`` ``"lhs"`` or
    ``"mc"``, from ``seed``). Runs go to ``workers`` local processes (default: one per
    core) or to the Dask scheduler at ``scheduler``. ``parameters`` are fixed values
    for every run. With ``output`` (``.parquet``), the study table and its summary
    (``.summary.parquet``) are written, and ``resume`` continues an interrupted study.
    ``max_steps`` and ``time_limit`` bound each run, and ``error_control`` (``"tighten"``,
    ``"warn"``, ``"off"``) holds it to its tolerance, as in :func:`simulate`;
    ``backend`` defaults as there (numba: the runs take the compiled loop).
    """
    from .studies import (
        StudyOptions,
        check_outputs,
        parse_values,
        run_study,
        summary_path,
        to_dataset,
    )

    if as_ not in ("dataset", "dataframe"):
        raise UsageError(f"as_ must be 'dataset' or 'dataframe', not {as_!r}", option="as_")
    settings = run_settings(start=start, stop=stop, interval=interval, solver=solver,
                            rtol=rtol, atol=atol, step=step, parameters=parameters,
                            max_steps=max_steps, time_limit=time_limit,
                            error_control=error_control)
    specs = tuple(parse_values(name, spec if isinstance(spec, str) else
                               ",".join(repr(float(v)) for v in spec), option="params")
                  for name, spec in params.items())
    fixed = dict(settings.parameters)
    if isinstance(files, CompiledModel):
        check_parameter_names(files, fixed)
        _check_integers(files, fixed)
        compiled = _with_structural(files, {k: v for k, v in fixed.items()
                                            if k in files.structural})
    else:
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=default_choice(backend, solver=solver),
                                 outputs=outputs, parameters=fixed, cache=cache)
    rest = tuple((k, v) for k, v in fixed.items() if k not in compiled.structural)
    protected = tuple(compiled.options.files)
    target = os.fspath(output) if output is not None else None
    if target is not None:
        check_outputs(target, summary_path(target), protected, ("output", "output"))
    options = StudyOptions(specs, samples, method, seed, rest, workers=workers,
                           scheduler=scheduler, energy=energy).running(settings)
    study = run_study(compiled, options, target, resume=resume, protected=protected,
                      progress=progress)
    if as_ == "dataframe":
        return study.table.to_pandas()
    return to_dataset(study)



@recursion_room()
def export_fmu(files: Files, output: str | os.PathLike[str], model: str | None = None, *,
               fmi_version: int = 3,
               libraries: Sequence[str | os.PathLike[str]] = ()) -> FmuExport:
    """Write the FMU of ``model`` of ``files`` to ``output`` (``springc fmu``): FMI 3.0
    (``fmi_version=2``: FMI 2.0), Model Exchange and Co-Simulation, the C sources and
    a linux64 binary (sources only where no C compiler is found: ``.note`` says so).

        >>> springc.export_fmu("models/SpringMass.mdl", "SpringMass.fmu")
    """
    from .fileio import check_target
    from .fmu import check_version
    from .fmu import export_fmu as fmu_export

    version = check_version(fmi_version)
    names = _files(files)
    try:
        check_target(output, names)
    except OutputError as err:
        raise UsageError(err.message, option="output", hint=err.hint) from None
    options = CompileOptions(names, model, tuple(os.fspath(x) for x in libraries), "python",
                             None, (), False)
    return fmu_export(options, output, version)
