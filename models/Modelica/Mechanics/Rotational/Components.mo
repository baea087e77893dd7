within Modelica.Mechanics.Rotational;
package Components "Inertias, springs, dampers, gears and other rotational components"
  model Fixed "A flange fixed at the angle phi0"
    parameter SI.Angle phi0 = 0 "Fixed angle of the housing";
    Interfaces.Flange_b flange "Flange fixed in the housing";
  equation
    flange.phi = phi0;
  end Fixed;

  model Inertia "A rotational inertia: J*a = sum of the flange torques"
    extends Rotational.Interfaces.PartialTwoFlanges;
    parameter SI.Inertia J(min = 0, start = 1) "Moment of inertia";
    parameter StateSelect stateSelect = StateSelect.default "Priority to use phi and w as states";
    SI.Angle phi(stateSelect = stateSelect) "Absolute rotation angle of the component";
    SI.AngularVelocity w(stateSelect = stateSelect) "Absolute angular velocity of the component (= der(phi))";
    SI.AngularAcceleration a "Absolute angular acceleration of the component (= der(w))";
  equation
    phi = flange_a.phi;
    phi = flange_b.phi;
    w = der(phi);
    a = der(w);
    J*a = flange_a.tau + flange_b.tau;
  end Inertia;

  model Spring "A linear rotational spring: tau = c*(phi_rel - phi_rel0)"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialCompliant;
    parameter SI.RotationalSpringConstant c(final min = 0, start = 1.0e5) "Spring constant";
    parameter SI.Angle phi_rel0 = 0 "Unstretched spring angle";
  equation
    tau = c*(phi_rel - phi_rel0);
  end Spring;

  model Damper "A linear rotational damper: tau = d*w_rel; its lost power may leave through a heat port"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialCompliantWithRelativeStates;
    parameter SI.RotationalDampingConstant d(final min = 0, start = 0) "Damping constant";
    extends Modelica.Thermal.HeatTransfer.Interfaces.PartialElementaryConditionalHeatPortWithoutT;
  equation
    tau = d*w_rel;
    lossPower = tau*w_rel;
  end Damper;

  model SpringDamper "A linear rotational spring and damper in parallel"
    parameter SI.RotationalSpringConstant c(final min = 0, start = 1.0e5) "Spring constant";
    parameter SI.RotationalDampingConstant d(final min = 0, start = 0) "Damping constant";
    parameter SI.Angle phi_rel0 = 0 "Unstretched spring angle";
    extends Modelica.Mechanics.Rotational.Interfaces.PartialCompliantWithRelativeStates;
    extends Modelica.Thermal.HeatTransfer.Interfaces.PartialElementaryConditionalHeatPortWithoutT;
  protected
    SI.Torque tau_c "Spring torque";
    SI.Torque tau_d "Damping torque";
  equation
    tau_c = c*(phi_rel - phi_rel0);
    tau_d = d*w_rel;
    tau = tau_c + tau_d;
    lossPower = tau_d*w_rel;
  end SpringDamper;

  model IdealGear "An ideal gear without inertia: phi_a = ratio*phi_b"
    extends Modelica.Mechanics.Rotational.Interfaces.PartialElementaryTwoFlangesAndSupport2;
    parameter Real ratio(start = 1) "Transmission ratio (flange_a.phi/flange_b.phi)";
    SI.Angle phi_a "Angle of flange_a with respect to the support";
    SI.Angle phi_b "Angle of flange_b with respect to the support";
  equation
    phi_a = flange_a.phi - phi_support;
    phi_b = flange_b.phi - phi_support;
    phi_a = ratio*phi_b;
    0 = ratio*flange_a.tau + flange_b.tau;
  end IdealGear;
end Components;
