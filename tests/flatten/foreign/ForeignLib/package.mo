package ForeignLib "External C functions whose sources the library ships (tests)"
  function stats "The sum of u, k*u (negated if neg) and the count of positive entries"
    input Real u[:];
    input Integer k;
    input Boolean neg;
    output Real total;
    output Real scaled[size(u, 1)];
    output Integer count;
  external "C" total = foreignlib_stats(u, size(u, 1), k, neg, scaled, count)
    annotation(Include="#include \"foreignlib.h\"", Library="ForeignLib");
  end stats;

  function transposed "A 2-D array, row-major, with both sizes"
    input Real A[:, :];
    output Real T[size(A, 2), size(A, 1)];
  external "C" foreignlib_transpose(A, size(A, 1), size(A, 2), T)
    annotation(Include="#include \"foreignlib.h\"", Library="ForeignLib");
  end transposed;

  function root "sqrt(x); ModelicaError for x < 0"
    input Real x;
    output Real y;
  external "C" y = foreignlib_root(x)
    annotation(Include="#include \"foreignlib.h\"", Library={"ForeignLib", "m"});
  end root;

  function cube "The default external call: the C function 'cube' of the library"
    input Real x;
    output Real y;
  external "C"
    annotation(Include="#include \"foreignlib.h\"", Library="ForeignLib");
  end cube;

  function missing "A library this copy does not ship"
    input Real x;
    output Real y;
  external "C" y = other_function(x) annotation(Library="OtherLib");
  end missing;

  function unset "Its second output is not in the external call"
    input Real x;
    output Real y;
    output Real z;
  external "C" y = foreignlib_root(x)
    annotation(Include="#include \"foreignlib.h\"", Library="ForeignLib");
  end unset;

  function writeText "The MSL's Streams.print: a line on a file (none: the standard output)"
    input String string;
    input String fileName = "";
  external "C" ModelicaInternal_print(string, fileName)
    annotation(Library="ModelicaExternalC");
  end writeText;

  model M
    parameter Real u[3] = {1.5, -2, 4};
    parameter Integer k = 3;
    Real total;
    Real scaled[3];
    Integer count;
    Real T[3, 2] = transposed([1, 2, 3; 4, 5, 6]);
    Real r = root(6.25);
    Real c = cube(-1.5);
  equation
    (total, scaled, count) = stats(u, k, true);
  end M;

  model Fails
    parameter Real x = -4;
    Real y = root(x);
  end Fails;

  model RunTime
    Real y = root(time);
  end RunTime;

  model Sampled "stats of the four samples of time before each sample, at each sample"
    Real buf[4](each start = 0, each fixed = true);
    Real total(start = 0, fixed = true);
    Real scaled[4](each start = 0, each fixed = true);
    Integer count(start = 0, fixed = true);
  algorithm
    when sample(0.1, 0.1) then
      (total, scaled, count) := stats(buf, 2, false);
      buf := {buf[2], buf[3], buf[4], time};
    end when;
  end Sampled;

  model Missing
    Real y = missing(1);
  end Missing;
  model Unset
    Real y;
    Real z;
  equation
    (y, z) = unset(4);
  end Unset;
end ForeignLib;
