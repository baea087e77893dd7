within Modelica.Mechanics.Translational;
package Sources "Forces and prescribed motions"
  model Force "A force given by a signal, acting between the flange and the support"
    extends Modelica.Mechanics.Translational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    Modelica.Blocks.Interfaces.RealInput f(unit = "N") "Driving force as an input signal (positive: the flange is pushed along the axis)";
  equation
    flange.f = -f;
  end Force;

  model ConstantForce "A constant force acting between the flange and the support"
    extends Modelica.Mechanics.Translational.Interfaces.PartialForce;
    parameter SI.Force f_constant "Nominal force (positive: the flange is pushed along the axis)";
  equation
    f = -f_constant;
  end ConstantForce;

  model Force2 "A force given by a signal, acting between two flanges (pushing them apart for f > 0)"
    extends Translational.Interfaces.PartialTwoFlanges;
    Modelica.Blocks.Interfaces.RealInput f(unit = "N") "Driving force as an input signal";
  equation
    flange_a.f = f;
    flange_b.f = -f;
  end Force2;

  model ConstantSpeed "A constant speed of the flange with respect to the support"
    extends Modelica.Mechanics.Translational.Interfaces.PartialForce;
    parameter SI.Velocity v_fixed "Fixed speed (if negative, the force acts in the opposite direction)";
    SI.Velocity v "Speed of the flange with respect to the support (= der(s))";
  equation
    v = der(s);
    v = v_fixed;
  end ConstantSpeed;

  model Position "Prescribes the flange position: exactly (exact = true) or through a critically damped second-order filter"
    extends Modelica.Mechanics.Translational.Interfaces.PartialElementaryOneFlangeAndSupport2(
      s(stateSelect = if exact then StateSelect.default else StateSelect.prefer));
    parameter Boolean exact = false "true: the position follows s_ref exactly; false: s_ref is filtered";
    parameter SI.Frequency f_crit = 50 "Critical frequency of the filter (if exact = false)";
    SI.Velocity v(start = 0, stateSelect = if exact then StateSelect.default else StateSelect.prefer) "Absolute velocity of the flange";
    SI.Acceleration a(start = 0) "Absolute acceleration of the flange";
    Modelica.Blocks.Interfaces.RealInput s_ref(unit = "m") "Reference position of the flange as an input signal";
  protected
    parameter SI.AngularFrequency w_crit = 2*Modelica.Constants.pi*f_crit "Critical angular frequency";
    constant Real af = 1.3617 "s coefficient of the Bessel filter";
    constant Real bf = 0.6180 "s*s coefficient of the Bessel filter";
  initial equation
    if not exact then
      s = s_ref;
    end if;
  equation
    if exact then
      s = s_ref;
      v = 0;
      a = 0;
    else
      v = der(s);
      a = der(v);
      a = ((s_ref - s)*w_crit - af*v)*(w_crit/bf);
    end if;
  end Position;

  model Speed "Prescribes the flange speed: exactly (exact = true) or through a first-order filter"
    extends Modelica.Mechanics.Translational.Interfaces.PartialElementaryOneFlangeAndSupport2(
      s(start = 0, fixed = true, stateSelect = StateSelect.prefer));
    parameter Boolean exact = false "true: the speed follows v_ref exactly; false: v_ref is filtered";
    parameter SI.Frequency f_crit = 50 "Critical frequency of the filter (if exact = false)";
    SI.Velocity v(stateSelect = if exact then StateSelect.default else StateSelect.prefer) "Absolute velocity of the flange";
    SI.Acceleration a "Absolute acceleration of the flange";
    Modelica.Blocks.Interfaces.RealInput v_ref(unit = "m/s") "Reference speed of the flange as an input signal";
  protected
    parameter SI.AngularFrequency w_crit = 2*Modelica.Constants.pi*f_crit "Critical angular frequency";
  initial equation
    if not exact then
      v = v_ref;
    end if;
  equation
    v = der(s);
    if exact then
      v = v_ref;
      a = 0;
    else
      a = der(v);
      a = (v_ref - v)*w_crit;
    end if;
  end Speed;

  model Accelerate "Prescribes the flange acceleration by a signal"
    extends Modelica.Mechanics.Translational.Interfaces.PartialElementaryOneFlangeAndSupport2(
      s(start = 0, fixed = true, stateSelect = StateSelect.prefer));
    SI.Velocity v(start = 0, fixed = true, stateSelect = StateSelect.prefer) "Absolute velocity of the flange";
    SI.Acceleration a "Absolute acceleration of the flange";
    Modelica.Blocks.Interfaces.RealInput a_ref(unit = "m/s2") "Absolute acceleration of the flange as an input signal";
  equation
    v = der(s);
    a = der(v);
    a = a_ref;
  end Accelerate;

  model Move "Prescribes the flange position, velocity and acceleration by the signals u = {s, v, a}"
    extends Modelica.Mechanics.Translational.Interfaces.PartialElementaryOneFlangeAndSupport2;
    Modelica.Blocks.Interfaces.RealInput u[3] "Position, velocity and acceleration of the flange as input signals";
  protected
    function position "The position in u = {s, v, a}, with v and a as its derivatives"
      extends Modelica.Icons.Function;
      input Real q_qd_qdd[3] "Position, velocity and acceleration";
      input Real dummy "Only there to give the derivatives their time argument";
      output Real q "Position";
    algorithm
      q := q_qd_qdd[1];
      annotation(derivative(noDerivative = q_qd_qdd) = position_der);
    end position;
    function position_der "The velocity in u = {s, v, a}"
      extends Modelica.Icons.Function;
      input Real q_qd_qdd[3] "Position, velocity and acceleration";
      input Real dummy "Only there to give the derivatives their time argument";
      input Real dummy_der "Derivative of dummy";
      output Real qd "Velocity";
    algorithm
      qd := q_qd_qdd[2];
      annotation(derivative(noDerivative = q_qd_qdd, order = 2) = position_der2);
    end position_der;
    function position_der2 "The acceleration in u = {s, v, a}"
      extends Modelica.Icons.Function;
      input Real q_qd_qdd[3] "Position, velocity and acceleration";
      input Real dummy "Only there to give the derivatives their time argument";
      input Real dummy_der "Derivative of dummy";
      input Real dummy_der2 "Second derivative of dummy";
      output Real qdd "Acceleration";
    algorithm
      qdd := q_qd_qdd[3];
    end position_der2;
  equation
    s = position(u, time);
  end Move;
end Sources;
