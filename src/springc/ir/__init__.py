"""The intermediate representations exchanged between stages.

Import the modules, not names: ``from springc.ir import expr, flat, dae, ode, syntax``.
Order inside: ``syntax`` and ``nodes`` (the expression tree) first, then ``builtins``
(the registry of built-in functions and event operators), ``expr`` (the tree's face,
with evaluation and differentiation), then ``flat``, ``dae``, ``ode``.
"""
