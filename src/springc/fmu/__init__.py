"""FMU export: a model -> an FMI 3.0 or FMI 2.0 FMU holding Model Exchange and
Co-Simulation (``export_fmu``).

``variables`` (the FMU's variables, value references and model structure from the
simplified system), ``description`` (modelDescription.xml, buildDescription.xml),
``glue`` (the per-model C file around the generated model code), ``package`` (the C
sources of ``c/``, the binary from the C compiler of
``springc.pipeline.find_compiler``, the archive), ``export``
(the driver). The C wrapper in ``c/`` implements the FMI functions around the model's
generated C code, with an embedded Dormand-Prince solver for Co-Simulation.
"""

from .export import FMI_VERSIONS, FmuExport, check_version, export_fmu
from .package import NO_COMPILER_NOTE

__all__ = ["FMI_VERSIONS", "NO_COMPILER_NOTE", "FmuExport", "check_version", "export_fmu"]
