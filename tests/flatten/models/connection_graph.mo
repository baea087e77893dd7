package G
  record O
    Real c;
    Real s;
    function equalityConstraint
      input O o1;
      input O o2;
      output Real residue[1];
    algorithm
      residue := {o1.s * o2.c - o1.c * o2.s};
    end equalityConstraint;
  end O;
  function rot
    input O o;
    input Real phi;
    output O r;
  algorithm
    r := O(o.c * cos(phi) - o.s * sin(phi), o.s * cos(phi) + o.c * sin(phi));
  end rot;
  connector F
    O R;
    flow Real t;
  end F;
  model Ground
    F f;
  equation
    Connections.root(f.R);
    f.R = O(1, 0);
  end Ground;
  model Joint
    parameter Real phi = 0.1;
    F a, b;
  equation
    Connections.branch(a.R, b.R);
    if Connections.rooted(a.R) then
      b.R = rot(a.R, phi);
    else
      a.R = rot(b.R, -phi);
    end if;
    a.t + b.t = 0;
  end Joint;
  model Body
    parameter Integer p = 0;
    F f;
    Real root;
  equation
    Connections.potentialRoot(f.R, priority = p);
    if Connections.isRoot(f.R) then
      root = 1;
      f.R = O(cos(time), sin(time));
    else
      root = 0;
    end if;
  end Body;
  model Chain
    Ground g;
    Joint j;
    Body b;
  equation
    connect(g.f, j.a);
    connect(j.b, b.f);
  end Chain;
  model Priority
    Joint j;
    Body b1(p = 1), b2(p = 0);
  equation
    connect(b1.f, j.a);
    connect(j.b, b2.f);
  end Priority;
  model Loop
    Ground g;
    Joint j1, j2;
    Body b;
  equation
    connect(g.f, j1.a);
    connect(g.f, j2.a);
    connect(j1.b, b.f);
    connect(j2.b, b.f);
  end Loop;

  model NoRoot
    Joint j;
  end NoRoot;
  model RootInBinding
    Body b;
    Real r = if Connections.isRoot(b.f.R) then 1 else 0;
  end RootInBinding;
end G;
