within Modelica.Mechanics.Rotational;
package Interfaces "Connectors and partial models of 1-dimensional rotational components"
  connector Flange "1-dimensional rotational flange of a shaft"
    SI.Angle phi "Absolute rotation angle of the flange";
    flow SI.Torque tau "Cut torque in the flange";
  end Flange;

  connector Flange_a "Left flange of a shaft (filled circle icon)"
    extends Flange;
  end Flange_a;

  connector Flange_b "Right flange of a shaft (empty circle icon)"
    extends Flange;
  end Flange_b;

  connector Support "Support (housing) flange of a rotational component"
    extends Flange;
  end Support;

  partial model PartialTwoFlanges "Component with two rotational flanges"
    Flange_a flange_a "Flange of the left shaft";
    Flange_b flange_b "Flange of the right shaft";
  end PartialTwoFlanges;

  partial model PartialCompliant "Compliant connection of two rotational flanges"
    SI.Angle phi_rel(start = 0) "Relative rotation angle (= flange_b.phi - flange_a.phi)";
    SI.Torque tau "Torque between the flanges (= flange_b.tau)";
    Flange_a flange_a "Left flange of the compliant shaft";
    Flange_b flange_b "Right flange of the compliant shaft";
  equation
    phi_rel = flange_b.phi - flange_a.phi;
    flange_b.tau = tau;
    flange_a.tau = -tau;
  end PartialCompliant;

  partial model PartialCompliantWithRelativeStates "Compliant connection of two rotational flanges with the relative angle and speed as preferred states"
    SI.Angle phi_rel(start = 0, stateSelect = stateSelect, nominal = if phi_nominal >= Modelica.Constants.eps then phi_nominal else 1) "Relative rotation angle (= flange_b.phi - flange_a.phi)";
    SI.AngularVelocity w_rel(start = 0, stateSelect = stateSelect) "Relative angular velocity (= der(phi_rel))";
    SI.AngularAcceleration a_rel(start = 0) "Relative angular acceleration (= der(w_rel))";
    SI.Torque tau "Torque between the flanges (= flange_b.tau)";
    Flange_a flange_a "Left flange of the compliant shaft";
    Flange_b flange_b "Right flange of the compliant shaft";
    parameter SI.Angle phi_nominal(displayUnit = "rad", min = 0.0) = 1e-4 "Nominal value of phi_rel (used for scaling)";
    parameter StateSelect stateSelect = StateSelect.prefer "Priority to use phi_rel and w_rel as states";
  equation
    phi_rel = flange_b.phi - flange_a.phi;
    w_rel = der(phi_rel);
    a_rel = der(w_rel);
    flange_b.tau = tau;
    flange_a.tau = -tau;
  end PartialCompliantWithRelativeStates;

  partial model PartialElementaryOneFlangeAndSupport2 "One flange and an optional support, for models written with equations"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    Flange_b flange "Flange of the shaft";
    Support support(phi = phi_support, tau = -flange.tau) if useSupport "Support (housing) of the component";
  protected
    SI.Angle phi_support "Absolute angle of the support flange";
  equation
    if not useSupport then
      phi_support = 0;
    end if;
  end PartialElementaryOneFlangeAndSupport2;

  partial model PartialElementaryTwoFlangesAndSupport2 "Two flanges and an optional support, for models written with equations"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    Flange_a flange_a "Flange of the left shaft";
    Flange_b flange_b "Flange of the right shaft";
    Support support(phi = phi_support, tau = -flange_a.tau - flange_b.tau) if useSupport "Support (housing) of the component";
  protected
    SI.Angle phi_support "Absolute angle of the support flange";
  equation
    if not useSupport then
      phi_support = 0;
    end if;
  end PartialElementaryTwoFlangesAndSupport2;

  partial model PartialTorque "A torque acting between a flange and its support"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    SI.Angle phi "Angle of the flange with respect to the support (= flange.phi - support.phi)";
  equation
    phi = flange.phi - phi_support;
  end PartialTorque;

  partial model PartialAbsoluteSensor "Measures one absolute flange variable"
    extends Modelica.Icons.RoundSensor;
    Flange_a flange "Flange whose motion is measured";
  equation
    0 = flange.tau;
  end PartialAbsoluteSensor;

  partial model PartialRelativeSensor "Measures one relative variable between two flanges"
    extends Modelica.Icons.RoundSensor;
    Flange_a flange_a "Left flange";
    Flange_b flange_b "Right flange";
  equation
    0 = flange_a.tau + flange_b.tau;
  end PartialRelativeSensor;
end Interfaces;
