"""springc: a compiler and simulator for spring-mass models written in a Modelica subset."""
