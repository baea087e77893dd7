within Modelica;
package Mechanics "Mechanical components (Modelica.Mechanics)"
  import Modelica.Units.SI;
end Mechanics;
