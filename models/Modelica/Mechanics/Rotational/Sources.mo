within Modelica.Mechanics.Rotational;
package Sources "Torques and prescribed rotations"
  model Torque "A torque given by a signal, acting between the flange and the support"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    Modelica.Blocks.Interfaces.RealInput tau(unit = "N.m") "Accelerating torque acting at the flange (= -flange.tau)";
  equation
    flange.tau = -tau;
  end Torque;

  model ConstantTorque "A constant torque acting between the flange and the support"
    extends Rotational.Interfaces.PartialTorque;
    parameter SI.Torque tau_constant "Constant torque (positive: accelerating the flange)";
    SI.AngularVelocity w "Angular velocity of the flange with respect to the support (= der(phi))";
    SI.Torque tau "Accelerating torque acting at the flange (= -flange.tau)";
  equation
    w = der(phi);
    tau = -flange.tau;
    tau = tau_constant;
  end ConstantTorque;

  model ConstantSpeed "A constant angular velocity of the flange with respect to the support"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialTorque;
    SI.AngularVelocity w "Angular velocity of the flange with respect to the support (= der(phi))";
    parameter SI.AngularVelocity w_fixed "Fixed angular velocity";
  equation
    w = der(phi);
    w = w_fixed;
  end ConstantSpeed;

  model Speed "Prescribes the flange's angular velocity: exactly (exact = true) or through a first-order filter"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    parameter Boolean exact = false "true: the speed follows w_ref exactly; false: w_ref is filtered";
    parameter SI.Frequency f_crit = 50 "Critical frequency of the filter (if exact = false)";
    SI.Angle phi(start = 0, fixed = true, stateSelect = StateSelect.prefer) "Rotation angle of the flange with respect to the support";
    SI.AngularVelocity w(stateSelect = if exact then StateSelect.default else StateSelect.prefer) "Angular velocity of the flange with respect to the support";
    SI.AngularAcceleration a "Angular acceleration of the flange with respect to the support";
    Modelica.Blocks.Interfaces.RealInput w_ref(unit = "rad/s") "Reference angular velocity as an input signal";
  protected
    parameter SI.AngularFrequency w_crit = 2*Modelica.Constants.pi*f_crit "Critical angular frequency";
  initial equation
    if not exact then
      w = w_ref;
    end if;
  equation
    phi = flange.phi - phi_support;
    w = der(phi);
    if exact then
      w = w_ref;
      a = 0;
    else
      a = der(w);
      a = (w_ref - w)*w_crit;
    end if;
  end Speed;

  model Accelerate "Prescribes the flange's angular acceleration by a signal"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    SI.Angle phi(start = 0, fixed = true, stateSelect = StateSelect.prefer) "Rotation angle of the flange with respect to the support";
    SI.AngularVelocity w(start = 0, fixed = true, stateSelect = StateSelect.prefer) "Angular velocity of the flange with respect to the support";
    SI.AngularAcceleration a "Angular acceleration of the flange with respect to the support";
    Modelica.Blocks.Interfaces.RealInput a_ref(unit = "rad/s2") "Angular acceleration of the flange as an input signal";
  equation
    phi = flange.phi - phi_support;
    w = der(phi);
    a = der(w);
    a = a_ref;
  end Accelerate;

  model Position "Prescribes the flange angle: exactly (exact = true) or through a critically damped second-order filter"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    parameter Boolean exact = false "true: the angle follows phi_ref exactly; false: phi_ref is filtered";
    parameter SI.Frequency f_crit = 50 "Critical frequency of the filter (if exact = false)";
    SI.Angle phi(stateSelect = if exact then StateSelect.default else StateSelect.prefer) "Rotation angle of the flange with respect to the support";
    SI.AngularVelocity w(start = 0, stateSelect = if exact then StateSelect.default else StateSelect.prefer) "Angular velocity of the flange with respect to the support";
    SI.AngularAcceleration a(start = 0) "Angular acceleration of the flange with respect to the support";
    Modelica.Blocks.Interfaces.RealInput phi_ref(final quantity = "Angle", final unit = "rad", displayUnit = "deg") "Reference angle of the flange as an input signal";
  protected
    parameter SI.AngularFrequency w_crit = 2*Modelica.Constants.pi*f_crit "Critical angular frequency";
    constant Real af = 1.3617 "s coefficient of the Bessel filter";
    constant Real bf = 0.6180 "s*s coefficient of the Bessel filter";
  initial equation
    if not exact then
      phi = phi_ref;
    end if;
  equation
    phi = flange.phi - phi_support;
    if exact then
      phi = phi_ref;
      w = 0;
      a = 0;
    else
      w = der(phi);
      a = der(w);
      a = ((phi_ref - phi)*w_crit - af*w)*(w_crit/bf);
    end if;
  end Position;
end Sources;
