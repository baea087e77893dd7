within Modelica;
package Blocks "Input/output blocks (Modelica.Blocks)"
  import Modelica.Units.SI;
end Blocks;
