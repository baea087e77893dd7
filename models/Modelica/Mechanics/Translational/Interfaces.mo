within Modelica.Mechanics.Translational;
package Interfaces "Connectors and partial models of 1-dimensional translational components"
  connector Flange "1-dimensional translational flange"
    SI.Position s "Absolute position of the flange";
    flow SI.Force f "Cut force directed into the flange";
  end Flange;

  connector Flange_a "Left flange (flange axis directed into the cut plane)"
    extends Flange;
  end Flange_a;

  connector Flange_b "Right flange (flange axis directed out of the cut plane)"
    extends Flange;
  end Flange_b;

  connector Support "Support (housing) flange of a component"
    extends Flange;
  end Support;

  model InternalSupport "Adapter of a conditional support: the support's force is given, its position read"
    input SI.Force f "External support force (must be computed by the enclosing model)";
    SI.Position s "External support position";
    Flange_a flange "Internal support flange (connected to the conditional support)";
  equation
    flange.f = f;
    flange.s = s;
  end InternalSupport;

  partial model PartialTwoFlanges "Component with two flanges"
    Flange_a flange_a "Left flange";
    Flange_b flange_b "Right flange";
  end PartialTwoFlanges;

  partial model PartialOneFlangeAndSupport "Component with one flange and an optional support (for graphical modeling)"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    Flange_b flange "Flange of the component";
    Support support if useSupport "Support (housing) of the component";
  protected
    Support internalSupport "Internal support: the support flange, or fixed at 0 without one";
    Components.Fixed fixed if not useSupport "Fixes the internal support at 0 without a support flange";
  equation
    connect(support, internalSupport);
    connect(internalSupport, fixed.flange);
  end PartialOneFlangeAndSupport;

  partial model PartialTwoFlangesAndSupport "Component with two flanges and an optional support (for graphical modeling)"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    Flange_a flange_a "Left flange";
    Flange_b flange_b "Right flange";
    Support support if useSupport "Support (housing) of the component";
  protected
    Support internalSupport "Internal support: the support flange, or fixed at 0 without one";
    Components.Fixed fixed if not useSupport "Fixes the internal support at 0 without a support flange";
  equation
    connect(support, internalSupport);
    connect(internalSupport, fixed.flange);
  end PartialTwoFlangesAndSupport;

  partial model PartialRigid "Rigid connection of two flanges: a body of length L"
    SI.Position s "Absolute position of the center of the component (s = flange_a.s + L/2 = flange_b.s - L/2)";
    parameter SI.Length L(start = 0) "Length of the component, from the left flange to the right flange";
    extends PartialTwoFlanges;
  equation
    flange_a.s = s - L/2;
    flange_b.s = s + L/2;
  end PartialRigid;

  partial model PartialCompliant "Compliant connection of two flanges"
    extends PartialTwoFlanges;
    SI.Position s_rel(start = 0) "Relative distance (= flange_b.s - flange_a.s)";
    SI.Force f "Force between the flanges (positive in the direction of the flange axis)";
  equation
    s_rel = flange_b.s - flange_a.s;
    flange_b.f = f;
    flange_a.f = -f;
  end PartialCompliant;

  partial model PartialCompliantWithRelativeStates "Compliant connection of two flanges with the relative position and velocity as preferred states"
    parameter StateSelect stateSelect = StateSelect.prefer "Priority to use s_rel and v_rel as states";
    parameter SI.Distance s_nominal = 1e-4 "Nominal value of s_rel (used for scaling)";
    SI.Position s_rel(start = 0, stateSelect = stateSelect, nominal = s_nominal) "Relative distance (= flange_b.s - flange_a.s)";
    SI.Velocity v_rel(start = 0, stateSelect = stateSelect) "Relative velocity (= der(s_rel))";
    SI.Force f "Force between the flanges (positive in the direction of the flange axis)";
    extends PartialTwoFlanges;
  equation
    s_rel = flange_b.s - flange_a.s;
    v_rel = der(s_rel);
    flange_b.f = f;
    flange_a.f = -f;
  end PartialCompliantWithRelativeStates;

  partial model PartialElementaryOneFlangeAndSupport2 "One flange and an optional support, for models written with equations"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    SI.Length s "Distance between the flange and the support (= flange.s - support.s)";
    Flange_b flange "Flange of the component";
    Support support(s = s_support, f = -flange.f) if useSupport "Support (housing) of the component";
  protected
    SI.Length s_support "Absolute position of the support flange";
  equation
    s = flange.s - s_support;
    if not useSupport then
      s_support = 0;
    end if;
  end PartialElementaryOneFlangeAndSupport2;

  partial model PartialElementaryTwoFlangesAndSupport2 "Two flanges and an optional support, for models written with equations"
    parameter Boolean useSupport = false "= true, if the support flange is enabled, otherwise it is fixed at 0";
    extends PartialTwoFlanges;
    Support support(s = s_support, f = -flange_a.f - flange_b.f) if useSupport "Support (housing) of the component";
    SI.Length s_a "Distance between the left flange and the support";
    SI.Length s_b "Distance between the right flange and the support";
  protected
    SI.Length s_support "Absolute position of the support flange";
  equation
    s_a = flange_a.s - s_support;
    s_b = flange_b.s - s_support;
    if not useSupport then
      s_support = 0;
    end if;
  end PartialElementaryTwoFlangesAndSupport2;

  partial model PartialForce "A force acting between a flange and its support"
    extends PartialElementaryOneFlangeAndSupport2;
    SI.Force f "Force acting on the component at the flange (= flange.f; the connected component is pushed with -f)";
  equation
    f = flange.f;
  end PartialForce;

  partial model PartialAbsoluteSensor "Measures one absolute flange variable"
    extends Modelica.Icons.RectangularSensor;
    Flange_a flange "Flange to be measured";
  equation
    0 = flange.f;
  end PartialAbsoluteSensor;

  partial model PartialRelativeSensor "Measures one relative variable between two flanges"
    extends Modelica.Icons.RectangularSensor;
    extends PartialTwoFlanges;
  equation
    0 = flange_a.f + flange_b.f;
  end PartialRelativeSensor;
end Interfaces;
