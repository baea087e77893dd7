within Modelica.Mechanics.Translational;
package Components "Masses, springs, dampers and other translational components"
  model Fixed "A flange fixed at the position s0"
    parameter SI.Position s0 = 0 "Fixed position of the flange";
    Interfaces.Flange_b flange "Flange fixed in the housing";
  equation
    flange.s = s0;
  end Fixed;

  model Mass "A sliding mass of length L: m*a = sum of the flange forces"
    parameter SI.Mass m(min = 0, start = 1) "Mass of the sliding mass";
    parameter StateSelect stateSelect = StateSelect.default "Priority to use s and v as states";
    extends Translational.Interfaces.PartialRigid(L = 0, s(start = 0, stateSelect = stateSelect));
    SI.Velocity v(start = 0, stateSelect = stateSelect) "Absolute velocity of the component";
    SI.Acceleration a(start = 0) "Absolute acceleration of the component";
  equation
    v = der(s);
    a = der(v);
    m*a = flange_a.f + flange_b.f;
  end Mass;

  model Rod "A massless rod of length L"
    extends Translational.Interfaces.PartialRigid;
  equation
    0 = flange_a.f + flange_b.f;
  end Rod;

  model Spring "A linear spring: f = c*(s_rel - s_rel0)"
    extends Translational.Interfaces.PartialCompliant;
    parameter SI.TranslationalSpringConstant c(final min = 0, start = 1) "Spring constant";
    parameter SI.Distance s_rel0 = 0 "Unstretched spring length";
  equation
    f = c*(s_rel - s_rel0);
  end Spring;

  model Damper "A linear damper: f = d*v_rel; its lost power may leave through a heat port"
    extends Translational.Interfaces.PartialCompliantWithRelativeStates;
    parameter SI.TranslationalDampingConstant d(final min = 0, start = 0) "Damping constant";
    extends Modelica.Thermal.HeatTransfer.Interfaces.PartialElementaryConditionalHeatPortWithoutT;
  equation
    f = d*v_rel;
    lossPower = f*v_rel;
  end Damper;

  model SpringDamper "A linear spring and a linear damper in parallel"
    extends Translational.Interfaces.PartialCompliantWithRelativeStates;
    parameter SI.TranslationalSpringConstant c(final min = 0, start = 1) "Spring constant";
    parameter SI.TranslationalDampingConstant d(final min = 0, start = 1) "Damping constant";
    parameter SI.Position s_rel0 = 0 "Unstretched spring length";
    extends Modelica.Thermal.HeatTransfer.Interfaces.PartialElementaryConditionalHeatPortWithoutT;
  protected
    SI.Force f_c "Spring force";
    SI.Force f_d "Damping force";
  equation
    f_c = c*(s_rel - s_rel0);
    f_d = d*v_rel;
    f = f_c + f_d;
    lossPower = f_d*v_rel;
  end SpringDamper;

  model ElastoGap "A spring and damper in parallel that act only in contact (s_rel < s_rel0), with a nonlinear spring characteristic"
    extends Modelica.Mechanics.Translational.Interfaces.PartialCompliantWithRelativeStates;
    parameter SI.TranslationalSpringConstant c(final min = 0, start = 1) "Spring constant";
    parameter SI.TranslationalDampingConstant d(final min = 0, start = 1) "Damping constant";
    parameter SI.Position s_rel0 = 0 "Unstretched spring length";
    parameter SI.Force f_ref(min = 0) = c*s_ref "Spring force at the reference compression s_ref";
    parameter SI.Length s_ref(min = Modelica.Constants.eps) = 1 "Reference compression";
    parameter Real n(final min = 1) = 1 "Exponent of the spring force: f_c = -f_ref*|(s_rel - s_rel0)/s_ref|^n";
    extends Modelica.Thermal.HeatTransfer.Interfaces.PartialElementaryConditionalHeatPortWithoutT;
    Boolean contact "= true, if the flanges are in contact";
  protected
    SI.Force f_c "Spring force";
    SI.Force f_d2 "Linear damping force";
    SI.Force f_d "Damping force, limited so that the contact force never pulls";
    Real ratio "Relative compression (s_rel - s_rel0)/s_ref";
  equation
    contact = s_rel < s_rel0;
    ratio = (s_rel - s_rel0)/s_ref;
    f_c = smooth(1, noEvent(if contact then -f_ref*abs(ratio)^n else 0));
    f_d2 = if contact then d*v_rel else 0;
    f_d = smooth(0, noEvent(if contact then min(max(f_d2, f_c), -f_c) else 0));
    f = f_c + f_d;
    lossPower = f_d*v_rel;
  end ElastoGap;
end Components;
