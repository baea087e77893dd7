within Modelica;
package Math "Mathematical functions (Modelica.Math); each evaluates the built-in of the same name"
  function sin "Sine"
    input Modelica.Units.SI.Angle u;
    output Real y;
  algorithm
    y := sin(u);
  end sin;
  function cos "Cosine"
    input Modelica.Units.SI.Angle u;
    output Real y;
  algorithm
    y := cos(u);
  end cos;
  function tan "Tangent (u shall not be -pi/2, pi/2, 3*pi/2, ...)"
    input Modelica.Units.SI.Angle u;
    output Real y;
  algorithm
    y := tan(u);
  end tan;
  function asin "Inverse sine (-1 <= u <= 1)"
    input Real u;
    output Modelica.Units.SI.Angle y;
  algorithm
    y := asin(u);
  end asin;
  function acos "Inverse cosine (-1 <= u <= 1)"
    input Real u;
    output Modelica.Units.SI.Angle y;
  algorithm
    y := acos(u);
  end acos;
  function atan "Inverse tangent"
    input Real u;
    output Modelica.Units.SI.Angle y;
  algorithm
    y := atan(u);
  end atan;
  function atan2 "Four quadrant inverse tangent of u1/u2"
    input Real u1;
    input Real u2;
    output Modelica.Units.SI.Angle y;
  algorithm
    y := atan2(u1, u2);
  end atan2;
  function sinh "Hyperbolic sine"
    input Real u;
    output Real y;
  algorithm
    y := sinh(u);
  end sinh;
  function cosh "Hyperbolic cosine"
    input Real u;
    output Real y;
  algorithm
    y := cosh(u);
  end cosh;
  function tanh "Hyperbolic tangent"
    input Real u;
    output Real y;
  algorithm
    y := tanh(u);
  end tanh;
  function exp "Exponential, base e"
    input Real u;
    output Real y;
  algorithm
    y := exp(u);
  end exp;
  function log "Natural (base e) logarithm (u shall be > 0)"
    input Real u;
    output Real y;
  algorithm
    y := log(u);
  end log;
  function log10 "Base 10 logarithm (u shall be > 0)"
    input Real u;
    output Real y;
  algorithm
    y := log10(u);
  end log10;
  package Vectors "Functions on vectors"
    function norm "The p-norm of a vector (p = 2: Euclidean length)"
      input Real v[:] "Vector";
      input Real p(min = 1) = 2 "Type of the p-norm (often 1, 2 or Modelica.Constants.inf)";
      output Real result "p-norm of v";
    algorithm
      if p == 2 then
        result := sqrt(v*v);
      elseif p == 1 then
        result := sum(abs(v));
      elseif p >= Modelica.Constants.inf then
        result := max(abs(v));
      else
        result := sum(abs(v[i])^p for i in 1:size(v, 1))^(1/p);
      end if;
    end norm;
    function length "Euclidean length of a vector"
      input Real v[:] "Vector";
      output Real result "Length of v";
    algorithm
      result := sqrt(v*v);
    end length;
  end Vectors;
end Math;
