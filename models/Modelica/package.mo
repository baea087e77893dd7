within;
package Modelica "springc's Modelica-compatible library (class paths, parameter names, units and sign conventions of the Modelica Standard Library 4.x)"
  // Written for springc from the documented interfaces and equations of the Modelica
  // Standard Library; a copy of the real Standard Library on the library path (-L,
  // SPRINGC_PATH, MODELICAPATH) is found first and replaces this one.
  import Modelica.Units.SI;
end Modelica;
