within Modelica.Mechanics;
package Rotational "1-dimensional rotational mechanics (Modelica.Mechanics.Rotational)"
  // Sign conventions of the Standard Library: flange.phi is the absolute rotation angle
  // of a flange; flange.tau is the cut torque acting on the component at that flange,
  // positive in the direction of the axis; a connection makes the angles equal and the
  // torques sum to zero.
  import Modelica.Units.SI;
end Rotational;
