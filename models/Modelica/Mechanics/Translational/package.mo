within Modelica.Mechanics;
package Translational "1-dimensional translational mechanics (Modelica.Mechanics.Translational)"
  // Sign conventions of the Standard Library: flange.s is the absolute position of a
  // flange along the axis; flange.f is the cut force acting on the component at that
  // flange, positive in the direction of the axis; a connection makes the positions equal
  // and the forces sum to zero.
  import Modelica.Units.SI;
end Translational;
